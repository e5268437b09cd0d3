"""Compiled closed loop: reference, sensor -> law -> actuator, joint actuator -> RK4 plant.

The stages and the law are numba first-class functions handed over in tuples
(:class:`LoopStages`), typed by their signatures: the loop is compiled once, cached
across processes, and runs any law or stage of those signatures, a user's own
included. They run every ``control_every`` plant steps and their outputs are held
in between (zero-order hold). Nothing is allocated inside the loop.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
from numba import njit

from flexsat.dynamics.integrators import rk4_step
from flexsat.dynamics.status import STATUS_CONTROL_FAILED, STATUS_OK

__all__ = [
    "LoopClock",
    "LoopData",
    "LoopRecords",
    "LoopStages",
    "rk4_closed_loop",
]



class LoopClock(NamedTuple):
    """Timing of one compiled call."""

    t0: float  # time of the first step [s]
    dt: float  # RK4 step [s]
    n_steps: int  # steps to take
    final: bool  # also control and record at t0 + n_steps dt (the run's last record)
    control_every: int  # plant steps per control period
    record_every: int  # plant steps per record


class LoopStages(NamedTuple):
    """The compiled steps, each a 1-tuple holding a first-class function."""

    sensor: tuple  # (SENSOR_SIGNATURE,)
    law: tuple  # (LAW_SIGNATURE,)
    actuator: tuple  # (ACTUATOR_SIGNATURE,)
    reference: tuple  # (REFERENCE_SIGNATURE,)
    joint_actuator: tuple  # (JOINT_ACTUATOR_SIGNATURE,)


class LoopData(NamedTuple):
    """Every array the loop reads or writes besides the plant state (float64, C order).

    The record-row pieces are views into ``held`` at the offsets of a
    :class:`~flexsat.simulate.layout.LoopLayout`; the states are views into one
    control-state vector.
    """

    J_design: np.ndarray  # (3, 3) [kg m^2]
    q_d: np.ndarray  # (4,) reference quaternion
    omega_d: np.ndarray  # (3,) [rad/s]
    omega_dot_d: np.ndarray  # (3,) [rad/s^2]
    law_gains: np.ndarray
    law_state: np.ndarray
    sensor_params: np.ndarray
    sensor_state: np.ndarray
    actuator_params: np.ndarray
    actuator_state: np.ndarray
    q_meas: np.ndarray  # (4,) sensor output
    omega_meas: np.ndarray  # (3,) sensor output [rad/s]
    held: np.ndarray  # (record_size,) the control record row held between instants
    tau_cmd: np.ndarray  # views into held ...
    tau_applied: np.ndarray
    law_diag: np.ndarray
    sensor_record: np.ndarray
    actuator_record: np.ndarray
    reference_params: np.ndarray
    reference_state: np.ndarray
    reference_record: np.ndarray  # view into held
    joint_params: np.ndarray
    joint_state: np.ndarray
    joint_record: np.ndarray  # view into held
    Q: np.ndarray  # (n_dof,) generalized forces on the appendage coordinates, Q[6:], held


class LoopRecords(NamedTuple):
    """Record buffers and the first row this call writes."""

    t: np.ndarray  # (m,) [s]
    x: np.ndarray  # (m, x_size)
    ctrl: np.ndarray  # (m, record_size)
    start: int


@njit(cache=True)
def rk4_closed_loop(x, clock, stages, d, records, plant):
    """Run ``clock.n_steps`` closed-loop steps from ``clock.t0``; ``x`` advanced in place.

    At each step k (time t0 + k dt): run the reference, sensor, law, actuator and
    joint actuator if k is a control instant, record if k is a record instant, then
    take one RK4 step under the held torque and joint forces ``d.Q``. Chunk
    boundaries must be multiples of ``control_every`` and ``record_every``.
    ``plant`` is the plant's named structure (``Plant.packed``), passed to ``rk4_step``.

    Returns
    -------
    status, steps_done, records_written
    """
    n = plant.n_dof
    scratch = np.empty((5, x.shape[0]))
    control_dt = clock.control_every * clock.dt
    row = records.start
    for k in range(clock.n_steps + (1 if clock.final else 0)):
        t = clock.t0 + k * clock.dt
        if k % clock.control_every == 0:
            status = stages.reference[0](t, d.reference_params, d.reference_state, d.q_d,
                                         d.omega_d, d.omega_dot_d, d.reference_record)  # fmt: skip
            status |= stages.sensor[0](x, n, t, d.sensor_params, d.sensor_state, d.q_meas,
                                      d.omega_meas, d.sensor_record)  # fmt: skip
            status |= stages.law[0](
                d.q_d, d.omega_d, d.omega_dot_d, d.q_meas, d.omega_meas, d.J_design,
                d.law_gains, d.law_state, t, control_dt, d.tau_cmd, d.law_diag,
            )  # fmt: skip
            status |= stages.actuator[0](
                d.tau_cmd, t, control_dt, d.actuator_params, d.actuator_state, d.tau_applied,
                d.actuator_record,
            )  # fmt: skip
            status |= stages.joint_actuator[0](x, n, t, control_dt, d.q_d, d.joint_params,
                                               d.joint_state, d.Q, d.joint_record)  # fmt: skip
            if status != 0:
                return STATUS_CONTROL_FAILED, k, row - records.start
        if k % clock.record_every == 0:
            records.t[row] = t
            records.x[row, :] = x
            records.ctrl[row, :] = d.held
            row += 1
        if k == clock.n_steps:
            break
        torque = (d.tau_applied[0], d.tau_applied[1], d.tau_applied[2])
        status = rk4_step(x, clock.dt, torque, n, d.Q, scratch, plant)
        if status != STATUS_OK:
            return status, k, row - records.start
    return STATUS_OK, clock.n_steps, row - records.start
