"""Compiled closed loop: reference, sensing chain, joint actuator, law, actuation chain.

Each control instant runs them in that order; the RK4 plant steps in between (numba).

The stages and the law are numba first-class functions handed over in tuples
(:class:`LoopStages`), typed by their signatures. The chains' tuples are padded to a
multiple of :data:`~flexsat.simulate.coupled.CHAIN_SLOTS` entries and the loop runs
the active ones only (``n_sensor``, ``n_actuator``), so it is compiled once for every
chain of up to that many stages (a longer one adds a specialization), cached across
processes, and runs any law or stage of those signatures, a user's own included.
They run every ``control_every`` plant steps and their outputs are held in between
(zero-order hold). An actuation stage with a derivative integrates its states with
the plant inside each RK4 step (:mod:`flexsat.simulate.coupled`). Nothing is
allocated inside the loop.

The hub attitude is re-based between steps (:mod:`flexsat.dynamics.attitude`); once a
run has switched, the sensing chain reads the plant state relative to the inertial
frame N (:func:`~flexsat.dynamics.attitude.inertial_view`), so the laws' q_d and the
sensors' outputs stay relative to N whatever the reference frame.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
from numba import njit

from flexsat.compiled.linalg3 import copy_into
from flexsat.compiled.no_refcount import borrowed
from flexsat.compiled.status import STATUS_CONTROL_FAILED, STATUS_OK
from flexsat.dynamics.attitude import inertial_view, is_identity, rebase
from flexsat.dynamics.integrators import augmented_derivative, rk4_step
from flexsat.dynamics.kernels import hub_cs, keep_solution
from flexsat.environment.loads import (
    EnvironmentData,
    applied_forces,
    attitude_cbn,
    environment_loads,
    ephemeris_row,
)
from flexsat.simulate.coupled import LITERAL_STAGES, LoopFlow, chain_wrench, rk4_coupled_step

__all__ = [
    "LoopClock",
    "LoopData",
    "LoopRecords",
    "LoopStages",
    "rk4_closed_loop",
    "run_actuators",
    "run_sensors",
]


class LoopClock(NamedTuple):
    """Timing of one compiled call.

    Attributes
    ----------
    t0 : float
        Time of the first step [s].
    dt : float
        RK4 step [s].
    n_steps : int
        Steps to take.
    final : bool
        Also control and record at t0 + n_steps dt (the run's last record).
    control_every : int
        Plant steps per control period.
    record_every : int
        Plant steps per record.
    continuous : bool
        An actuation stage integrates states in the RK4 steps.
    """

    t0: float  # time of the first step [s]
    dt: float  # RK4 step [s]
    n_steps: int  # steps to take
    final: bool  # also control and record at t0 + n_steps dt (the run's last record)
    control_every: int  # plant steps per control period
    record_every: int  # plant steps per record
    continuous: bool  # an actuation stage integrates states in the RK4 steps


class LoopStages(NamedTuple):
    """The compiled steps, tuples of first-class functions (chains in order).

    The chains' tuples (and :class:`LoopData`'s per-stage tuples) are padded to a
    multiple of :data:`~flexsat.simulate.coupled.CHAIN_SLOTS` entries; the loop calls
    the first ``n_sensor`` and ``n_actuator`` only.

    Attributes
    ----------
    sensor : tuple
        ``SENSOR_SIGNATURE`` functions: the sensing chain, padded.
    law : tuple
        One ``LAW_SIGNATURE`` function.
    actuator : tuple
        ``ACTUATOR_SIGNATURE`` functions: the actuation chain, padded.
    derivative : tuple
        ``DERIVATIVE_SIGNATURE`` functions, one per actuation stage, padded.
    reference : tuple
        One ``REFERENCE_SIGNATURE`` function.
    joint_actuator : tuple
        One ``JOINT_ACTUATOR_SIGNATURE`` function.
    n_sensor, n_actuator : int
        Stages of the sensing and of the actuation chain.
    """

    sensor: tuple  # (SENSOR_SIGNATURE, ...): the sensing chain, padded
    law: tuple  # (LAW_SIGNATURE,)
    actuator: tuple  # (ACTUATOR_SIGNATURE, ...): the actuation chain, padded
    derivative: tuple  # (DERIVATIVE_SIGNATURE, ...): one per actuation stage, padded
    reference: tuple  # (REFERENCE_SIGNATURE,)
    joint_actuator: tuple  # (JOINT_ACTUATOR_SIGNATURE,)
    n_sensor: int  # stages of the sensing chain
    n_actuator: int  # stages of the actuation chain


class LoopData(NamedTuple):
    """Every array the loop reads or writes besides the plant state (float64, C order).

    The record-row pieces are views into ``held`` at the offsets of a
    :class:`~flexsat.simulate.layout.LoopLayout`; the states are views into one
    control-state vector. Stage parameters, states and records are tuples with one
    array per stage of the chain.

    Attributes
    ----------
    J_design : ndarray, shape (3, 3)
        The law's design inertia, hub frame B [kg m^2]; the joint actuator may update
        it in place before the law (its own copy: the run's initial one is kept).
    q_d : ndarray, shape (4,)
        Reference quaternion, scalar first [-].
    omega_d, omega_dot_d : ndarray, shape (3,)
        Reference rate [rad/s] and acceleration [rad/s^2], frame D.
    law_gains, law_state : ndarray
        The law's packed gains and state [per law].
    sensor_params, sensor_state : tuple of ndarray
        Each sensing stage's packed parameters and state [per stage] (padded with
        empty arrays like :class:`LoopStages`' chains).
    actuator_params, actuator_state : tuple of ndarray
        Each actuation stage's packed parameters and state [per stage] (padded).
    q_meas : ndarray, shape (4,)
        Measured attitude quaternion, scalar first [-].
    omega_meas : ndarray, shape (3,)
        Measured body rate [rad/s].
    held : ndarray, shape (record_size,)
        The control record row held between instants [per channel].
    tau_cmd, tau_applied : ndarray, shape (3,)
        Views into ``held``: commanded and applied torque [N m].
    law_diag : ndarray
        View into ``held``: the law's diagnostics [per channel].
    sensor_record, actuator_record : tuple of ndarray
        Views into ``held``: each stage's records [per channel] (padded).
    tau_between : ndarray, shape (3,)
        A stage's input inside the actuation chain [N m].
    flow : LoopFlow
        Work arrays of the coupled RK4 step.
    reference_params, reference_state : ndarray
        The reference's packed parameters and state [per stage].
    reference_record : ndarray
        View into ``held``: its records [per channel].
    joint_params, joint_state : ndarray
        The joint actuator's packed parameters and state [per stage].
    joint_record : ndarray
        View into ``held``: its records [per channel].
    Q : ndarray, shape (n_dof,)
        Generalized forces on the appendage coordinates, ``Q[6:]``, held [N or N m].
    env : EnvironmentData
        The environment's loads (:mod:`flexsat.environment.loads`): evaluated every
        ``env.every`` steps (a control instant) when ``env.active``, held like the
        torque; inactive without an ``[environment]`` table (the loop then never reads
        it).
    """

    J_design: np.ndarray  # (3, 3) [kg m^2]
    q_d: np.ndarray  # (4,) reference quaternion
    omega_d: np.ndarray  # (3,) [rad/s]
    omega_dot_d: np.ndarray  # (3,) [rad/s^2]
    law_gains: np.ndarray
    law_state: np.ndarray
    sensor_params: tuple
    sensor_state: tuple
    actuator_params: tuple
    actuator_state: tuple
    q_meas: np.ndarray  # (4,) sensor output
    omega_meas: np.ndarray  # (3,) sensor output [rad/s]
    held: np.ndarray  # (record_size,) the control record row held between instants
    tau_cmd: np.ndarray  # views into held ...
    tau_applied: np.ndarray
    law_diag: np.ndarray
    sensor_record: tuple
    actuator_record: tuple
    tau_between: np.ndarray  # (3,) a stage's input inside the actuation chain [N m]
    flow: LoopFlow  # work arrays of the coupled RK4 step
    reference_params: np.ndarray
    reference_state: np.ndarray
    reference_record: np.ndarray  # view into held
    joint_params: np.ndarray
    joint_state: np.ndarray
    joint_record: np.ndarray  # view into held
    Q: np.ndarray  # (n_dof,) generalized forces on the appendage coordinates, Q[6:], held
    env: EnvironmentData  # the environment's held loads (inactive without [environment])


class LoopRecords(NamedTuple):
    """Record buffers and the first row this call writes.

    Attributes
    ----------
    t : ndarray, shape (m,)
        Record times [s].
    x : ndarray, shape (m, x_size)
        Recorded plant states [SI].
    ctrl : ndarray, shape (m, record_size)
        Recorded control rows [per channel].
    start : int
        First row this call writes.
    frame : ndarray, shape (m, 9)
        Attitude reference R_NF of each recorded state, row-major [-].
    Q : ndarray, shape (m, n_dof)
        The joint actuator's generalized forces ``LoopData.Q`` held from each record
        (the plant steps under them from the recorded state), zero on the hub
        coordinates [N, N m per coordinate].
    solved : ndarray, shape (m, 2, n_dof)
        What the plant's solve gave at each recorded state, from the first stage of
        the RK4 step taken from it: q_ddot [m/s^2, rad/s^2] and the locked
        coordinates' constraint forces [N, N m per coordinate]
        (:func:`~flexsat.dynamics.kernels.keep_solution`). Written without continuous
        actuation stages; rows the loop does not write (the last record, one whose
        step failed, every row of a coupled run) stay as they are (NaN from
        :func:`~flexsat.simulate.closedloop.prepare_slew`) and
        :func:`~flexsat.dynamics.records.derive_records` solves for them.
    """

    t: np.ndarray  # (m,) [s]
    x: np.ndarray  # (m, x_size)
    ctrl: np.ndarray  # (m, record_size)
    start: int
    frame: np.ndarray  # (m, 9) attitude reference R_NF of each recorded state
    Q: np.ndarray  # (m, n_dof) joint forces held from each record, hub columns zero
    solved: np.ndarray  # (m, 2, n_dof) q_ddot and constraint forces of each record


@njit(cache=True, inline="always")
def run_sensors(x, n, t, stages, d):
    """The sensing chain at one control instant: each stage refines q_meas, omega_meas.

    Parameters
    ----------
    x : ndarray, shape (2 n + 2,)
        Plant state relative to N [SI].
    n : int
        Number of generalized coordinates.
    t : float
        Time [s].
    stages : LoopStages
        The compiled steps.
    d : LoopData
        Its ``q_meas``, ``omega_meas``, stage states and records are written.

    Returns
    -------
    int
        0, or the OR of the stages' non-zero statuses.
    """
    count = stages.n_sensor
    status = 0
    # The first LITERAL_STAGES stages by literal index (see _sense), the rest of a
    # longer chain by a loop variable.
    if count > 0:
        status |= _sense(0, x, n, t, stages, d)
    if count > 1:
        status |= _sense(1, x, n, t, stages, d)
    if count > 2:
        status |= _sense(2, x, n, t, stages, d)
    if count > 3:
        status |= _sense(3, x, n, t, stages, d)
    for i in range(LITERAL_STAGES, count):
        status |= _sense(i, x, n, t, stages, d)
    return status


@njit(cache=True, inline="always")
def _sense(i, x, n, t, stages, d):
    """Sensing stage ``i``. Inlined, a literal ``i`` makes every tuple access static:
    indexing the padded tuples with a loop variable copies each tuple to the stack on
    every access, which inside the loop cost about as much as the call itself
    (CHANGELOG.md, 'Stages by literal index')."""
    return stages.sensor[i](x, n, t, d.sensor_params[i], d.sensor_state[i], d.q_meas,
                            d.omega_meas, d.sensor_record[i])  # fmt: skip


@njit(cache=True, inline="always")
def run_actuators(x, n, t, control_dt, continuous, stages, d):
    """The actuation chain at one control instant, from ``tau_cmd`` to ``tau_applied``.

    Each stage after the first reads the previous one's output. With continuous
    stages the chain's output is held for the RK4 steps and ``tau_applied`` records
    the total torque on the hub at this instant (held output plus the stages' wrench).

    Parameters
    ----------
    x : ndarray, shape (2 n + 2,)
        Plant state [SI].
    n : int
        Number of generalized coordinates.
    t : float
        Time [s].
    control_dt : float
        Control period [s].
    continuous : bool
        Some stage integrates states (``derivative``).
    stages : LoopStages
        The compiled steps.
    d : LoopData
        Its ``tau_applied``, stage states and records are written.

    Returns
    -------
    int
        0, or the OR of the stages' non-zero statuses.
    """
    status = stages.actuator[0](
        d.tau_cmd, t, control_dt, d.actuator_params[0], d.actuator_state[0], d.tau_applied,
        d.actuator_record[0],
    )  # fmt: skip
    count = stages.n_actuator
    if count > 1:  # by literal index, as run_sensors
        status |= _actuate(1, t, control_dt, stages, d)
    if count > 2:
        status |= _actuate(2, t, control_dt, stages, d)
    if count > 3:
        status |= _actuate(3, t, control_dt, stages, d)
    for i in range(LITERAL_STAGES, count):
        status |= _actuate(i, t, control_dt, stages, d)
    if continuous:
        flow = d.flow
        copy_into(flow.held, d.tau_applied)
        copy_into(flow.eval, flow.state)
        status |= chain_wrench(x, n, t, hub_cs(x), stages.derivative, d.actuator_params, flow)
        for a in range(3):
            d.tau_applied[a] += flow.wrench[a]
    return status


@njit(cache=True, inline="always")
def _actuate(i, t, control_dt, stages, d):
    """Actuation stage ``i`` > 0 on the previous stage's output (a literal ``i``: as
    :func:`_sense`)."""
    copy_into(d.tau_between, d.tau_applied)
    return stages.actuator[i](d.tau_between, t, control_dt, d.actuator_params[i],
                              d.actuator_state[i], d.tau_applied, d.actuator_record[i])  # fmt: skip


@njit(cache=True)
def rk4_closed_loop(x, clock, stages, d, records, plant, frame):
    """Run ``clock.n_steps`` closed-loop steps from ``clock.t0``; ``x`` advanced in place.

    At each step k (time t0 + k dt): re-base the attitude if due, run the reference,
    the sensing chain, the joint actuator (its ``Q`` held like the torque; it may
    update ``d.J_design`` for the law), the law and the actuation chain if k is a
    control instant (then the environment's loads, ``d.env``, when it is active), record
    if k is a record instant, then take one RK4 step under the held torque and joint
    forces ``d.Q`` (plus the environment's held torque and generalized forces, when it
    is active; coupled with the chain's continuous states if any), whose first
    stage gives the record's q_ddot (:class:`LoopRecords`, without continuous stages). Chunk
    boundaries must be multiples of ``control_every`` and ``record_every``.

    Parameters
    ----------
    x : ndarray, shape (2 n_dof + 2,)
        Plant state [q, q_dot, W_in, W_diss] [SI], advanced in place.
    clock : LoopClock
        Timing of this call.
    stages : LoopStages
        The compiled steps.
    d : LoopData
        Parameters, states and the held record row.
    records : LoopRecords
        Record buffers.
    plant : PackedPlant
        The plant's named structure (``Plant.packed``), passed to ``rk4_step``.
    frame : ndarray, shape (9,)
        The attitude reference R_NF of ``x`` [-], updated in place.

    Returns
    -------
    status : int
        0, ``STATUS_CONTROL_FAILED`` or a plant status.
    steps_done : int
        Steps completed.
    records_written : int
        Rows written.
    """
    # the caller owns them for the call: no reference counting inside the loop
    x, d, records, plant, frame = borrowed((x, d, records, plant, frame))
    n = plant.n_dof
    scratch = np.empty((5, x.shape[0]))
    view = np.empty(x.shape[0])  # x relative to N, for the sensing chain, once switched
    control_dt = clock.control_every * clock.dt
    row = records.start
    for k in range(clock.n_steps + (1 if clock.final else 0)):
        t = clock.t0 + k * clock.dt
        rebase(x, n, frame)
        instant = k % clock.control_every == 0
        recorded = k % clock.record_every == 0
        if instant:
            status = stages.reference[0](t, d.reference_params, d.reference_state, d.q_d,
                                         d.omega_d, d.omega_dot_d, d.reference_record)  # fmt: skip
            sensed = x
            if not is_identity(frame):
                inertial_view(x, n, frame, view)
                sensed = view
            status |= run_sensors(sensed, n, t, stages, d)
            # before the law: it may update the design inertia the law reads now
            status |= stages.joint_actuator[0](x, n, t, control_dt, d.q_d, d.J_design,
                                               d.joint_params, d.joint_state, d.Q,
                                               d.joint_record)  # fmt: skip
            status |= stages.law[0](
                d.q_d, d.omega_d, d.omega_dot_d, d.q_meas, d.omega_meas, d.J_design,
                d.law_gains, d.law_state, t, control_dt, d.tau_cmd, d.law_diag,
            )  # fmt: skip
            status |= run_actuators(x, n, t, control_dt, clock.continuous, stages, d)
            if d.env.active:  # held until the next evaluation, like the torque
                env = d.env
                if (int(clock.t0 / clock.dt + 0.5) + k) % env.every == 0:  # the run's step
                    ephemeris_row(env.ephemeris, t, env.row)
                    attitude_cbn(x, frame, env.C_BN)
                    status |= environment_loads(env, d.held)
                applied_forces(env, d.Q, d.flow.held, clock.continuous)
            if status != 0:
                return STATUS_CONTROL_FAILED, k, row - records.start
        if recorded:
            records.t[row] = t
            copy_into(records.x[row], x)
            copy_into(records.frame[row], frame)
            copy_into(records.ctrl[row], d.held)
            records.Q[row, :6] = 0.0  # d.Q[:6] holds the integrator's last hub forces
            copy_into(records.Q[row, 6:], d.env.applied[6:] if d.env.active else d.Q[6:])
            row += 1
        if k == clock.n_steps:
            break
        Q = d.env.applied if d.env.active else d.Q  # the joint actuator's + the environment's
        if clock.continuous:
            # at an instant, run_actuators evaluated the chain's rates at (x, t)
            status = rk4_coupled_step(x, t, clock.dt, n, Q, scratch, stages.derivative,
                                      d.actuator_params, d.flow, plant, instant)  # fmt: skip
        else:
            torque = (d.tau_applied[0], d.tau_applied[1], d.tau_applied[2])
            if d.env.active:
                e = d.env.torque
                torque = (torque[0] + e[0], torque[1] + e[1], torque[2] + e[2])
            status = STATUS_OK
            if recorded:  # the first RK4 stage, kept for the record (LoopRecords.solved)
                status = augmented_derivative(x, torque, n, Q, scratch[0], plant, hub_cs(x))
                if status == STATUS_OK:
                    keep_solution(scratch[0, n : 2 * n], plant, records.solved[row - 1])
            if status == STATUS_OK:
                status = rk4_step(x, clock.dt, torque, n, Q, scratch, plant, recorded)
        if status != STATUS_OK:
            return status, k, row - records.start
    return STATUS_OK, clock.n_steps, row - records.start
