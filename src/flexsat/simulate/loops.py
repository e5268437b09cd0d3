"""Compiled closed loop: sensor -> law -> actuator -> RK4 plant (numba).

The stages and the law are numba first-class functions handed over in tuples
(:class:`LoopStages`), typed by their signatures: the loop is compiled once, cached
across processes, and runs any law or stage of those signatures, a user's own
included. They run every ``control_every`` plant steps and their outputs are held
in between (zero-order hold). Nothing is allocated inside the loop.

The hub attitude is re-based between steps (:mod:`flexsat.dynamics.attitude`); once a
run has switched, the sensor reads the plant state relative to the inertial frame N
(:func:`~flexsat.dynamics.attitude.inertial_view`), so the laws' q_d and the sensors'
outputs stay relative to N whatever the reference frame.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
from numba import njit

from flexsat.dynamics.attitude import inertial_view, is_identity, rebase
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


class LoopRecords(NamedTuple):
    """Record buffers and the first row this call writes."""

    t: np.ndarray  # (m,) [s]
    x: np.ndarray  # (m, x_size)
    ctrl: np.ndarray  # (m, record_size)
    start: int
    frame: np.ndarray  # (m, 9) attitude reference R_NF of each recorded state


@njit(cache=True)
def rk4_closed_loop(x, clock, stages, d, records, plant, frame):
    """Run ``clock.n_steps`` closed-loop steps from ``clock.t0``; ``x`` advanced in place.

    At each step k (time t0 + k dt): re-base the attitude if due, run sensor, law and
    actuator if k is a control instant, record if k is a record instant, then take
    one RK4 step. Chunk boundaries must be multiples of ``control_every`` and
    ``record_every``. ``plant`` is the plant's named structure (``Plant.packed``),
    passed to ``rk4_step``; ``frame`` (9,) the attitude reference R_NF of ``x``,
    updated in place.

    Returns
    -------
    status, steps_done, records_written
    """
    n = plant.n_dof
    scratch = np.empty((5, x.shape[0]))
    Q = np.empty(n)
    view = np.empty(x.shape[0])  # x relative to N, for the sensor, once switched
    control_dt = clock.control_every * clock.dt
    row = records.start
    for k in range(clock.n_steps + (1 if clock.final else 0)):
        t = clock.t0 + k * clock.dt
        rebase(x, n, frame)
        if k % clock.control_every == 0:
            sensed = x
            if not is_identity(frame):
                inertial_view(x, n, frame, view)
                sensed = view
            status = stages.sensor[0](sensed, n, t, d.sensor_params, d.sensor_state,
                                      d.q_meas, d.omega_meas, d.sensor_record)  # fmt: skip
            status |= stages.law[0](
                d.q_d, d.omega_d, d.omega_dot_d, d.q_meas, d.omega_meas, d.J_design,
                d.law_gains, d.law_state, t, control_dt, d.tau_cmd, d.law_diag,
            )  # fmt: skip
            status |= stages.actuator[0](
                d.tau_cmd, t, control_dt, d.actuator_params, d.actuator_state, d.tau_applied,
                d.actuator_record,
            )  # fmt: skip
            if status != 0:
                return STATUS_CONTROL_FAILED, k, row - records.start
        if k % clock.record_every == 0:
            records.t[row] = t
            records.x[row, :] = x
            records.frame[row, :] = frame
            records.ctrl[row, :] = d.held
            row += 1
        if k == clock.n_steps:
            break
        torque = (d.tau_applied[0], d.tau_applied[1], d.tau_applied[2])
        status = rk4_step(x, clock.dt, torque, n, Q, scratch, plant)
        if status != STATUS_OK:
            return status, k, row - records.start
    return STATUS_OK, clock.n_steps, row - records.start
