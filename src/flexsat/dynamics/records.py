"""Compiled batch evaluation of the derived quantities of a recorded run (numba).

One call fills every derived time series from the recorded states, so post-
processing a 12 000-record run costs milliseconds instead of a Python loop.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from flexsat.compiled.linalg3 import (
    copy_into,
    euler_rate_bias,
    euler_rate_matrix,
    load_seg,
    mtv,
    mv,
    rot_zyx,
)
from flexsat.compiled.no_refcount import borrowed
from flexsat.compiled.status import STATUS_OK
from flexsat.dynamics.appendages.contract import (
    OBS_ELASTIC,
    OBS_KINETIC,
    OBS_LOCKED_INERTIA,
    OBS_MOMENTUM,
    OBS_SIZE,
)
from flexsat.dynamics.kernels import (
    accelerations,
    hub_joint_wrench,
    keep_solution,
    observe,
    tip_displacement,
)

__all__ = ["derive_records"]


@njit(cache=True)
def derive_records(
    q, qd, tau_B, joint_force, solved, packed,
    omega, omega_dot, tau_flex, H, H_rigid, kinetic, elastic, tips,
):  # fmt: skip
    """Fill the derived arrays, row by row, from recorded states.

    Parameters
    ----------
    q, qd : ndarray, shape (m, n_dof)
        Recorded generalized coordinates [m, rad] and rates [m/s, rad/s].
    tau_B : ndarray, shape (m, 3)
        Applied body torque at each record [N m].
    joint_force : ndarray, shape (m, n_dof)
        Generalized forces of the joint actuators held from each record, on the
        appendage coordinates (columns 6 and on; the hub's are not read) [N, N m per
        coordinate]; zeros without joint actuators.
    solved : ndarray, shape (m, 2, n_dof)
        Each record's q_ddot [m/s^2, rad/s^2] and constraint forces of the locked
        coordinates [N, N m per coordinate]
        (:func:`~flexsat.dynamics.kernels.keep_solution`): a row given (the compiled
        loop's, from the first stage of the RK4 step taken from that state) is used
        as is; a row whose first entry is NaN is solved for here and written.
    packed : PackedPlant
        ``Plant.packed``.
    omega, omega_dot, tau_flex, H, H_rigid : ndarray, shape (m, 3)
        Outputs: body rate [rad/s], angular acceleration [rad/s^2], joint torque on
        the hub [N m] (frame B), total and rigid-part angular momentum [N m s]
        (frame N).
    kinetic, elastic : ndarray, shape (m,)
        Outputs [J].
    tips : ndarray, shape (m, n, 3)
        Output: tip displacements, mount frames [m].

    Notes
    -----
    Each row's q_ddot is that of the plant under the applied torque and the joint
    forces, and tau_flex the wrench of the joints carrying those forces plus, on a
    locked plant, the locked coordinates' constraint forces (what
    :func:`~flexsat.dynamics.kernels.joint_forces` gives, from the kept solution). A
    row whose state is singular (the last state of a failed run) gets NaN
    accelerations and joint torque.
    """
    n = q.shape[1]
    _derive_rows(q, qd, tau_B, joint_force, solved, packed, omega, omega_dot, tau_flex, H,
                 H_rigid, kinetic, elastic, tips, np.zeros(n), np.empty(n), np.empty(6),
                 np.empty(OBS_SIZE))  # fmt: skip


@njit(cache=True)
def _derive_rows(
    q, qd, tau_B, joint_force, solved, packed,
    omega, omega_dot, tau_flex, H, H_rigid, kinetic, elastic, tips,
    Q, joint, wrench, obs,
):  # fmt: skip
    """:func:`derive_records` on work arrays its caller owns: Q and the joint forces
    (n_dof,), the hub wrench (6,), the observation row (``OBS_SIZE``); all borrowed
    (:mod:`flexsat.compiled.no_refcount`)."""
    q, qd, tau_B, joint_force, solved = borrowed((q, qd, tau_B, joint_force, solved))
    packed = borrowed(packed)
    omega, omega_dot, tau_flex, H = borrowed((omega, omega_dot, tau_flex, H))
    H_rigid, kinetic, elastic, tips = borrowed((H_rigid, kinetic, elastic, tips))
    Q, joint, wrench, obs = borrowed((Q, joint, wrench, obs))
    m, n = q.shape
    L = OBS_LOCKED_INERTIA
    for k in range(m):
        qk, qdk = q[k], qd[k]
        S = euler_rate_matrix(qk[3], qk[4])
        w = mv(S, load_seg(qdk, 3))
        omega[k, 0], omega[k, 1], omega[k, 2] = w
        Q[3], Q[4], Q[5] = mtv(S, load_seg(tau_B[k], 0))
        copy_into(Q[6:], joint_force[k, 6:])
        row = solved[k]
        qddk = row[0]
        status = STATUS_OK
        if np.isnan(qddk[0]):  # not given: solve for it
            status = accelerations(qk, qdk, Q, packed, qddk)
            keep_solution(qddk, packed, row)
        for i in range(n):  # joint_forces, from the kept solution
            joint[i] = Q[i] + row[1, i]
        status |= hub_joint_wrench(qk, qdk, qddk, joint, packed, wrench)
        if status == STATUS_OK:
            bias = euler_rate_bias(qk[3], qk[4], qdk[3], qdk[4], qdk[5])
            w_dot = mv(S, load_seg(qddk, 3))
            for a in range(3):
                omega_dot[k, a] = w_dot[a] + bias[a]
                tau_flex[k, a] = wrench[3 + a]
        else:
            omega_dot[k, :] = np.nan
            tau_flex[k, :] = np.nan
        observe(qk, qdk, packed, obs)
        for a in range(3):
            H[k, a] = obs[OBS_MOMENTUM + a]
        R_NB = rot_zyx(qk[3], qk[4], qk[5])
        Jw = (
            obs[L + 0] * w[0] + obs[L + 1] * w[1] + obs[L + 2] * w[2],
            obs[L + 3] * w[0] + obs[L + 4] * w[1] + obs[L + 5] * w[2],
            obs[L + 6] * w[0] + obs[L + 7] * w[1] + obs[L + 8] * w[2],
        )
        H_rigid[k, 0], H_rigid[k, 1], H_rigid[k, 2] = mv(R_NB, Jw)
        kinetic[k] = obs[OBS_KINETIC]
        elastic[k] = obs[OBS_ELASTIC]
        tip_displacement(qk, packed, tips[k])
