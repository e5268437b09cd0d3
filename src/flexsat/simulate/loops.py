"""Compiled closed loop: sensor, control law, actuators and the RK4 plant (numba).

The controller is sampled every ``control_every`` plant steps and its torque held
in between (zero-order hold). Nothing is allocated inside the loop.
"""

from __future__ import annotations

import numpy as np
from numba import njit

from flexsat.control.actuation import applied_torque
from flexsat.control.laws import DIAG_SIZE, control_law
from flexsat.control.quaternion import euler_zyx_to_quaternion
from flexsat.dynamics.integrators import rk4_step
from flexsat.dynamics.kernels import STATUS_OK
from flexsat.dynamics.linalg3 import euler_rate_matrix, load_seg, mv

__all__ = ["CTRL_RECORD_SIZE", "rk4_closed_loop"]

CTRL_RECORD_SIZE = 6 + DIAG_SIZE  # tau_cmd (3), tau_applied (3), law diagnostics


@njit(cache=True)
def rk4_closed_loop(
    x, t0, dt, n_steps, final, control_every, record_every, kind, gains, J_design, q_d,
    dist, memory, held, args, rec_t, rec_x, rec_ctrl, rec_start,
):  # fmt: skip
    """Run ``n_steps`` closed-loop steps from time t0, x advanced in place.

    At each step k (time t0 + k dt): update the command if k is a control instant,
    record if k is a record instant, then take one RK4 step. With ``final`` true the
    loop also controls and records at t0 + n_steps dt without stepping (the last
    record of a run). ``held`` (CTRL_RECORD_SIZE,) carries the command held between
    calls; ``memory`` (2,) the law's state. Chunk boundaries must be multiples of
    ``control_every`` and ``record_every``.

    Returns
    -------
    status, steps_done, records_written
    """
    n = (x.shape[0] - 2) // 2
    scratch = np.empty((5, x.shape[0]))
    Q = np.empty(n)
    diag = np.empty(DIAG_SIZE)
    row = rec_start
    for k in range(n_steps + (1 if final else 0)):
        t = t0 + k * dt
        if k % control_every == 0:
            q_meas = euler_zyx_to_quaternion(x[3], x[4], x[5])  # ideal sensor
            omega_B = mv(euler_rate_matrix(x[3], x[4]), load_seg(x, n + 3))
            tau_cmd = control_law(
                kind, gains, J_design, q_d, q_meas, omega_B, control_every * dt, memory, diag
            )
            tau_app = applied_torque(tau_cmd, t, dist)
            held[0], held[1], held[2] = tau_cmd
            held[3], held[4], held[5] = tau_app
            held[6:] = diag
        if k % record_every == 0:
            rec_t[row] = t
            rec_x[row, :] = x
            rec_ctrl[row, :] = held
            row += 1
        if k == n_steps:
            break
        status = rk4_step(x, dt, (held[3], held[4], held[5]), n, Q, scratch, args)
        if status != STATUS_OK:
            return status, k, row - rec_start
    return STATUS_OK, n_steps, row - rec_start
