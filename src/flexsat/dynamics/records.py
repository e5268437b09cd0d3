"""Compiled batch evaluation of the derived quantities of a recorded run (numba).

One call fills every derived time series from the recorded states, so post-
processing a 12 000-record run costs milliseconds instead of a Python loop.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from flexsat.dynamics.kernels import (
    STATUS_OK,
    accelerations,
    hub_joint_wrench,
    kinetic_energy,
    locked_inertia,
    system_angular_momentum,
    tip_displacement,
)
from flexsat.dynamics.linalg3 import (
    euler_rate_bias,
    euler_rate_matrix,
    load_seg,
    mtv,
    mv,
    rot_zyx,
)

__all__ = ["derive_records"]


@njit(cache=True)
def derive_records(
    q, qd, tau_B, args, tip_point,
    omega, omega_dot, tau_flex, H, H_rigid, kinetic, elastic, tips,
):  # fmt: skip
    """Fill the derived arrays, row by row, from recorded states.

    Parameters
    ----------
    q, qd : ndarray, shape (m, n_dof)
    tau_B : ndarray, shape (m, 3)
        Applied body torque at each record [N m].
    args : tuple
        ``Plant.dynamics_args``.
    tip_point : ndarray, shape (n, 3)
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
    A row whose state is singular (the last state of a failed run) gets NaN
    accelerations and joint torque.
    """
    hub_mass, hub_J, hub_J_inv, mount_point, R_BM, com_offset = args[:6]
    panel_mass, panel_J, panel_J_inv, stiffness, damping = args[6:]
    m, n = q.shape
    Q = np.zeros(n)
    no_external = np.zeros(n)  # tau_flex: elastic and damping wrench only
    qdd = np.empty(n)
    wrench = np.empty(6)
    J_locked = np.empty((3, 3))
    H_row = np.empty(3)
    for k in range(m):
        qk, qdk = q[k], qd[k]
        S = euler_rate_matrix(qk[3], qk[4])
        w = mv(S, load_seg(qdk, 3))
        omega[k, 0], omega[k, 1], omega[k, 2] = w
        Q[3], Q[4], Q[5] = mtv(S, load_seg(tau_B[k], 0))
        status = accelerations(qk, qdk, Q, *args, qdd)
        status |= hub_joint_wrench(qk, qdk, no_external, mount_point, R_BM, com_offset,
                                   stiffness, damping, wrench)  # fmt: skip
        if status == STATUS_OK:
            bias = euler_rate_bias(qk[3], qk[4], qdk[3], qdk[4], qdk[5])
            w_dot = mv(S, load_seg(qdd, 3))
            for a in range(3):
                omega_dot[k, a] = w_dot[a] + bias[a]
                tau_flex[k, a] = wrench[3 + a]
        else:
            omega_dot[k, :] = np.nan
            tau_flex[k, :] = np.nan
        system_angular_momentum(qk, qdk, hub_mass, hub_J, mount_point, R_BM, com_offset,
                                panel_mass, panel_J, H_row)  # fmt: skip
        H[k, :] = H_row
        locked_inertia(qk, hub_J, mount_point, R_BM, com_offset, panel_mass, panel_J, J_locked)
        R_NB = rot_zyx(qk[3], qk[4], qk[5])
        Jw = (
            J_locked[0, 0] * w[0] + J_locked[0, 1] * w[1] + J_locked[0, 2] * w[2],
            J_locked[1, 0] * w[0] + J_locked[1, 1] * w[1] + J_locked[1, 2] * w[2],
            J_locked[2, 0] * w[0] + J_locked[2, 1] * w[1] + J_locked[2, 2] * w[2],
        )
        H_rigid[k, 0], H_rigid[k, 1], H_rigid[k, 2] = mv(R_NB, Jw)
        kinetic[k] = kinetic_energy(qk, qdk, hub_mass, hub_J, mount_point, R_BM, com_offset,
                                    panel_mass, panel_J)  # fmt: skip
        u = 0.0
        for i in range(stiffness.shape[0]):
            for j in range(6):
                u += 0.5 * stiffness[i, j] * qk[6 + 6 * i + j] ** 2
        elastic[k] = u
        tip_displacement(qk, tip_point, tips[k])
