"""Compiled fixed-step RK4 loop for the open-loop plant (numba).

The whole loop runs in compiled code; the only allocations happen once per call,
before the first step. The state integrated is x = [q, q_dot, W_in, W_diss]: the
work done by the applied torque and the energy dissipated by the joint dampers are
integrated with the same RK4 stages as the motion, so the energy balance
E(t) - E(0) - W_in(t) + W_diss(t) measures the integrator alone.

The hub's Euler angles are relative to a reference frame R_NF (``frame``) that the
loops re-base between steps (:func:`flexsat.dynamics.attitude.rebase`), so no run meets
the ZYX singularity.

Torque profile: piecewise-constant segments [start, end) with a body torque each,
plus a constant disturbance torque, held over each step at its start value (zero-
order hold, the same convention as a sampled controller).
"""

from __future__ import annotations

import numpy as np
from numba import njit

from flexsat.compiled.linalg3 import copy_into, euler_rate_matrix_cs, mtv
from flexsat.compiled.no_refcount import borrowed
from flexsat.compiled.status import STATUS_NOT_FINITE, STATUS_OK
from flexsat.dynamics.appendages.contract import HUB_DISSIPATION
from flexsat.dynamics.attitude import rebase
from flexsat.dynamics.kernels import accelerations_cs, hub_cs

__all__ = [
    "STATUS_NOT_FINITE",
    "applied_torque",
    "augmented_derivative",
    "rk4_combine",
    "rk4_hold",
    "rk4_open_loop",
    "rk4_stage",
    "rk4_step",
]


@njit(cache=True)
def applied_torque(t, seg_start, seg_end, seg_torque, disturbance):
    """Body torque at time t: active segments plus the disturbance, hub frame B.

    Parameters
    ----------
    t : float
        Time [s].
    seg_start, seg_end : ndarray, shape (k,)
        Start and end of each torque segment [s]; a segment is active on [start, end).
    seg_torque : ndarray, shape (k, 3)
        Each segment's torque, hub frame B [N m].
    disturbance : ndarray, shape (3,)
        Constant disturbance torque, hub frame B [N m].

    Returns
    -------
    tuple of 3 float
        The applied torque, hub frame B [N m].
    """
    tx, ty, tz = disturbance[0], disturbance[1], disturbance[2]
    for k in range(seg_start.shape[0]):
        if seg_start[k] <= t < seg_end[k]:
            tx += seg_torque[k, 0]
            ty += seg_torque[k, 1]
            tz += seg_torque[k, 2]
    return (tx, ty, tz)


@njit(cache=True, inline="always")
def augmented_derivative(x, torque_B, n, Q, dx, packed, cs):
    """dx/dt of the augmented state [q, q_dot, W_in, W_diss] under a body torque.

    Shared by the compiled RK4 loops and the adaptive scipy solver. W_in integrates the
    power of every applied generalized force, hub torque and joint actuators.

    Parameters
    ----------
    x : ndarray, shape (2 n + 2,)
        Augmented state: q [m, rad], q_dot [m/s, rad/s], W_in [J], W_diss [J].
    torque_B : tuple of 3 float
        Body torque on the hub, hub frame B [N m].
    n : int
        Number of generalized coordinates n_dof.
    Q : ndarray, shape (n,)
        Generalized forces [N, N m per coordinate]: on input ``Q[6:]`` holds those
        applied to the appendage coordinates (joint actuators; zero without),
        ``Q[:6]`` is overwritten with the hub's.
    dx : ndarray, shape (2 n + 2,)
        Output: the derivative [unit of x per s].
    packed : PackedPlant
        The plant's packed arrays and kernels (:class:`~flexsat.dynamics.packed.PackedPlant`).
    cs : tuple of 6 float
        The cosines and sines of the hub angles of ``x``,
        :func:`~flexsat.dynamics.kernels.hub_cs` ``(x)`` [-]: a caller that needs them
        too (the coupled step's body rate) computes them once for both.

    Returns
    -------
    int
        ``STATUS_OK`` or a kernel status.
    """
    q = x[:n]
    qd = x[n : 2 * n]
    Q[0], Q[1], Q[2] = 0.0, 0.0, 0.0
    S = euler_rate_matrix_cs(cs[0], cs[1], cs[2], cs[3])
    Q[3], Q[4], Q[5] = mtv(S, torque_B)  # Q_Theta = S^T tau
    copy_into(dx[:n], qd)
    status = accelerations_cs(cs, q, qd, Q, packed, dx[n : 2 * n])
    power_in = 0.0
    for j in range(3, n):
        power_in += Q[j] * qd[j]
    dx[2 * n] = power_in
    dx[2 * n + 1] = packed.hub[HUB_DISSIPATION]  # q_dot^T C q_dot, left by accelerations
    return status


@njit(cache=True, inline="always")
def rk4_stage(x, h, k, stage):
    """An RK4 stage's state, ``stage = x + h k``, element by element.

    Parameters
    ----------
    x : ndarray, shape (m,)
        State at the start of the step [SI, per element].
    h : float
        The stage's step, ``dt / 2`` or ``dt`` [s].
    k : ndarray, shape (m,)
        The derivative the stage follows [SI per s].
    stage : ndarray, shape (m,)
        Overwritten with the stage's state [SI, per element].
    """
    for j in range(x.shape[0]):
        stage[j] = x[j] + h * k[j]


@njit(cache=True, inline="always")
def rk4_combine(x, dt, k1, k2, k3, k4, out):
    """The RK4 step's end, ``out = x + dt/6 (k1 + 2 k2 + 2 k3 + k4)``, checked finite.

    Parameters
    ----------
    x : ndarray, shape (m,)
        State at the start of the step [SI, per element].
    dt : float
        Step [s].
    k1, k2, k3, k4 : ndarray, shape (m,)
        The four stages' derivatives [SI per s].
    out : ndarray, shape (m,)
        Overwritten with the state at the end of the step, up to the first element
        that is not finite [SI, per element].

    Returns
    -------
    bool
        Every element of ``out`` is finite.
    """
    for j in range(x.shape[0]):
        out[j] = x[j] + dt / 6.0 * (k1[j] + 2.0 * k2[j] + 2.0 * k3[j] + k4[j])
        if not np.isfinite(out[j]):
            return False
    return True


@njit(cache=True)
def rk4_step(x, dt, torque_B, n, Q, scratch, packed, first=False):
    """One RK4 step of the augmented state x, in place, under a held body torque.

    Parameters
    ----------
    x : ndarray, shape (2 n + 2,)
        Augmented state [q, q_dot, W_in, W_diss] (SI: m, rad, m/s, rad/s, J); on a
        non-zero status it is left unchanged.
    dt : float
        Step [s].
    torque_B : tuple of 3 float
        Held body torque, hub frame B [N m].
    n : int
        Number of generalized coordinates n_dof.
    Q : ndarray, shape (n,)
        Generalized forces held on the appendage coordinates in ``Q[6:]`` [N, N m per
        coordinate] (zeros without joint actuators; :func:`augmented_derivative`).
    scratch : ndarray, shape (5, len(x))
        Work array the caller allocates once [-].
    packed : PackedPlant
        The plant's packed arrays and kernels.
    first : bool
        ``scratch[0]`` already holds the first stage, the derivative at ``x`` (a
        caller that keeps it: the closed loop's records).

    Returns
    -------
    int
        ``STATUS_OK``, a kernel status or ``STATUS_NOT_FINITE``.
    """
    x, Q, scratch, packed = borrowed(x), borrowed(Q), borrowed(scratch), borrowed(packed)
    k1, k2, k3, k4, stage = scratch[0], scratch[1], scratch[2], scratch[3], scratch[4]
    status = STATUS_OK
    if not first:
        status = augmented_derivative(x, torque_B, n, Q, k1, packed, hub_cs(x))
    rk4_stage(x, 0.5 * dt, k1, stage)
    status |= augmented_derivative(stage, torque_B, n, Q, k2, packed, hub_cs(stage))
    rk4_stage(x, 0.5 * dt, k2, stage)
    status |= augmented_derivative(stage, torque_B, n, Q, k3, packed, hub_cs(stage))
    rk4_stage(x, dt, k3, stage)
    status |= augmented_derivative(stage, torque_B, n, Q, k4, packed, hub_cs(stage))
    if status != STATUS_OK:
        return status
    if not rk4_combine(x, dt, k1, k2, k3, k4, stage):
        return STATUS_NOT_FINITE
    copy_into(x, stage)
    return STATUS_OK


@njit(cache=True)
def rk4_hold(x, dt, n_steps, torque_B, packed, frame):
    """``n_steps`` RK4 steps under one held body torque.

    Parameters
    ----------
    x : ndarray, shape (2 n_dof + 2,)
        Augmented state [q, q_dot, W_in, W_diss] [SI], advanced in place.
    dt : float
        Step [s].
    n_steps : int
        Number of steps.
    torque_B : tuple of 3 float
        Held body torque, hub frame B [N m].
    packed : PackedPlant
        The plant's packed arrays and kernels.
    frame : ndarray, shape (9,)
        The attitude reference R_NF (row-major) [-], re-based before each step.

    Returns
    -------
    status : int
        ``STATUS_OK`` or the failing step's status.
    done : int
        Steps completed without error.
    """
    x, packed, frame = borrowed(x), borrowed(packed), borrowed(frame)
    n = packed.n_dof
    scratch = np.empty((5, x.shape[0]))
    Q = np.zeros(n)  # no joint actuators
    for k in range(n_steps):
        rebase(x, n, frame)
        status = rk4_step(x, dt, torque_B, n, Q, scratch, packed)
        if status != STATUS_OK:
            return status, k
    return STATUS_OK, n_steps


@njit(cache=True)
def rk4_open_loop(
    x, t0, dt, n_steps, record_every, seg_start, seg_end, seg_torque, disturbance, packed,
    frame, rec_t, rec_x, rec_tau, rec_frame, rec_start,
):  # fmt: skip
    """Advance x in place by ``n_steps`` RK4 steps, recording every ``record_every`` steps.

    Parameters
    ----------
    x : ndarray, shape (2 n_dof + 2,)
        Augmented state [q, q_dot, W_in, W_diss], advanced in place.
    t0, dt : float
        Time of x and step [s]; step k starts at t0 + k dt.
    n_steps : int
        Number of steps.
    record_every : int
        Steps between two records.
    seg_start, seg_end : ndarray, shape (k,)
        Start and end of each torque segment [s].
    seg_torque : ndarray, shape (k, 3)
        Each segment's torque, hub frame B [N m].
    disturbance : ndarray, shape (3,)
        Constant disturbance torque, hub frame B [N m].
    packed : PackedPlant
        ``Plant.packed``.
    frame : ndarray, shape (9,)
        Attitude reference R_NF of x (row-major) [-], re-based before each step and
        updated in place (:mod:`flexsat.dynamics.attitude`).
    rec_t, rec_x, rec_tau, rec_frame : ndarray
        Record buffers, shapes (m,) [s], (m, 2 n_dof + 2) [SI, as x], (m, 3) [N m],
        (m, 9) [-]; the state after step k is written at row rec_start + (k + 1) /
        record_every - 1 when (k + 1) is a multiple of ``record_every``, with the torque
        held during the next step and the state's reference frame.
    rec_start : int
        First row of the record buffers to write.

    Returns
    -------
    status : int
        0, a kernel status, or ``STATUS_NOT_FINITE``.
    steps_done : int
        Steps completed without error (x is the state after them).
    """
    x, packed, frame = borrowed(x), borrowed(packed), borrowed(frame)
    rec_t, rec_x, rec_tau, rec_frame = borrowed((rec_t, rec_x, rec_tau, rec_frame))
    n = packed.n_dof
    scratch = np.empty((5, x.shape[0]))
    Q = np.zeros(n)  # no joint actuators
    row = rec_start
    for k in range(n_steps):
        t = t0 + k * dt
        torque = applied_torque(t, seg_start, seg_end, seg_torque, disturbance)
        rebase(x, n, frame)
        status = rk4_step(x, dt, torque, n, Q, scratch, packed)
        if status != STATUS_OK:
            return status, k
        if (k + 1) % record_every == 0:
            t_next = t0 + (k + 1) * dt
            rec_t[row] = t_next
            copy_into(rec_x[row], x)
            copy_into(rec_frame[row], frame)
            tau = applied_torque(t_next, seg_start, seg_end, seg_torque, disturbance)
            rec_tau[row, 0], rec_tau[row, 1], rec_tau[row, 2] = tau
            row += 1
    return STATUS_OK, n_steps
