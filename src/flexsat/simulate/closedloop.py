"""Closed-loop slews: a control law flies the flexible plant (thesis section 5.1)."""

from __future__ import annotations

import math
import time
from typing import NamedTuple, Protocol

import numpy as np
from numba import njit

from flexsat.compiled.first_class import first_class
from flexsat.compiled.status import STATUS_CONTROL_FAILED
from flexsat.compiled.typed_call import TypedOnce, typed_list
from flexsat.config import nominal
from flexsat.config.models import SatelliteConfig
from flexsat.control.laws import LAW_SIGNATURE, get_law
from flexsat.control.quaternion import pointing_errors, target_quaternion
from flexsat.control.stages import ACTUATORS, JOINT_ACTUATORS, REFERENCES, SENSORS
from flexsat.control.stages.registry import (
    ACTUATOR_SIGNATURE,
    DERIVATIVE_SIGNATURE,
    JOINT_ACTUATOR_SIGNATURE,
    REFERENCE_SIGNATURE,
    SENSOR_SIGNATURE,
    no_derivative,
)
from flexsat.dynamics.attitude import identity_frame, inertial_view, is_identity, rebase
from flexsat.dynamics.integrators import rk4_hold
from flexsat.dynamics.plant import Plant
from flexsat.dynamics.rigid import design_coordinates, rigid_inertia
from flexsat.errors import ConfigError, SimulationError
from flexsat.simulate.batch import fly, slew_timing
from flexsat.simulate.common import PROGRESS_MIN_STEPS, progress_bar, run_attributes
from flexsat.simulate.coupled import CHAIN_SLOTS, LoopFlow, rk4_coupled_hold
from flexsat.simulate.layout import LoopLayout
from flexsat.simulate.loops import LoopData, LoopStages, run_actuators, run_sensors
from flexsat.simulate.openloop import initial_state
from flexsat.simulate.result import Result, build_dataset
from flexsat.simulate.scenario import SlewScenario

__all__ = [
    "Controller",
    "PreparedSlew",
    "design_inertia",
    "finish_slew",
    "flown_chain",
    "loop_layout",
    "loop_stages",
    "prepare_slew",
    "run_slew",
    "slew_design_inertia",
]


class Controller(Protocol):
    """A plain-Python control law, for prototyping your own (slower than the built-ins).

    Called at every control instant with the time [s], the measured attitude
    quaternion ``q`` (scalar first, shape (4,)) and body rate ``omega_B`` [rad/s],
    shape (3,); returns the commanded body torque [N m], shape (3,). The loop clips
    it to the software limit RF * T_max, then applies the actuator and disturbance
    model of the scenario. Keep any state you need on the object. See
    ``examples/python_controller.py``.
    """

    def __call__(self, t: float, q: np.ndarray, omega_B: np.ndarray) -> np.ndarray: ...


def design_inertia(config: SatelliteConfig | None = None) -> np.ndarray:
    """J_tot of a rigidized satellite [kg m^2], shape (3, 3): the controllers' design model.

    Parameters
    ----------
    config : SatelliteConfig, optional
        The user's nominal configuration; default the thesis's nominal satellite. A
        drive's angle is frozen at its initial value (the plate's ``sadm_angle_deg``).
    """
    plant = Plant.from_config(config or nominal())
    return _rigid_at_start(plant, SlewScenario())


def slew_design_inertia(plant: Plant, scenario: SlewScenario) -> np.ndarray:
    """The design inertia a slew's controller uses [kg m^2], shape (3, 3).

    The scenario's ``design_inertia_kg_m2`` if given, else J_tot of the rigidized
    ``plant`` configuration, a solar-array drive's angle frozen at its initial value
    (:func:`~flexsat.dynamics.rigid.design_coordinates`). Uncertainty studies perturb
    the truth plant only: they give the nominal design model explicitly (campaigns
    write it into each case's scenario from the base configuration).

    Parameters
    ----------
    plant : Plant
        The truth plant.
    scenario : SlewScenario
        The slew.

    Returns
    -------
    ndarray, shape (3, 3)
        J, hub frame B [kg m^2].
    """
    if scenario.design_inertia_kg_m2 is not None:
        return np.array(scenario.design_inertia_kg_m2, dtype=float)
    return _rigid_at_start(plant, scenario)


def _rigid_at_start(plant: Plant, scenario: SlewScenario) -> np.ndarray:
    """J_tot of the rigidized ``plant``, its free coordinates (drives) where the slew
    starts them, shape (3, 3) [kg m^2]."""
    return rigid_inertia(plant, design_coordinates(plant, initial_state(plant, scenario)[0]))


def run_slew(
    plant: Plant,
    scenario: SlewScenario | None = None,
    design_J: np.ndarray | None = None,
    progress: bool | None = None,
    controller: Controller | None = None,
) -> Result:
    """Simulate a closed-loop slew of the flexible plant.

    Parameters
    ----------
    plant : Plant
        The truth model (may differ from the design model: uncertainty studies).
    scenario : SlewScenario, optional
        Default: the thesis's 45/45/45 deg ASMC slew with disturbances at maximum.
    design_J : ndarray, shape (3, 3), optional
        The controller's inertia [kg m^2]; default :func:`slew_design_inertia`.
    progress : bool, optional
        Progress bar; default only for runs of at least 200 000 steps.
    controller : Controller, optional
        A plain-Python law used instead of ``scenario.controller`` (whose compiled
        form runs inside the RK4 loop). The sensor and actuator stages of the
        scenario still run; the law's diagnostics are recorded as NaN.

    Returns
    -------
    Result
        As :func:`flexsat.simulate.run_openloop`, plus the pointing and rate errors,
        the law's declared diagnostics and the stages' records (each a variable with
        its units) and, in the attributes, what the law's plots need. A diverging
        run stops cleanly with its history and ``status = "failed"``.
    """
    scenario = scenario or SlewScenario()
    run = prepare_slew(plant, scenario, design_J)
    layout = run.layout
    if controller is not None and (
        layout.reference.name != REFERENCES.default
        or layout.joint_actuator.name != JOINT_ACTUATORS.default
    ):
        raise ConfigError("a Python controller flies the step reference without joint "
                          "actuators: remove [reference] and [joint_actuator]")  # fmt: skip
    steps = scenario.n_steps
    show = steps >= PROGRESS_MIN_STEPS if progress is None else progress
    if controller is None:  # compile or load the loop now (no chunk): the wall time is the run's
        fly(*_fly_arguments(run, 0, 0, 0))
    start = time.perf_counter()
    with progress_bar(show, scenario.duration_s) as (bar, task):
        if controller is None:
            status, done, rows = _compiled_loop(run, bar, task)
        else:
            status, done, rows = _python_loop(plant, scenario, run.x, run.frame, run.stages,
                                              run.data, run.rec_t, run.rec_x, run.rec_ctrl,
                                              run.rec_frame, bar, task, controller,
                                              layout.continuous)  # fmt: skip
    return finish_slew(run, status, done, rows, time.perf_counter() - start, controller is None)


class PreparedSlew(NamedTuple):
    """One slew ready for the compiled loop: its arrays, its stages, its record buffers.

    What :func:`prepare_slew` builds and :func:`finish_slew` turns into a
    :class:`~flexsat.simulate.result.Result`; the loop advances ``x`` and ``frame``
    in place and fills the record buffers (rows of NaN until written).

    Attributes
    ----------
    plant : Plant
        The satellite [-].
    scenario : SlewScenario
        The slew [-].
    law : object
        The registered law (:mod:`flexsat.control.laws`) [-].
    layout : LoopLayout
        Where the states and records live [-].
    J : ndarray, shape (3, 3)
        Design inertia [kg m^2].
    x : ndarray, shape (x_size,)
        Plant state [m, rad, m/s, rad/s, J], advanced in place.
    frame : ndarray, shape (9,)
        Attitude reference R_NF of ``x`` [-], updated in place.
    data : LoopData
        The loop's arrays [-].
    stages : LoopStages
        The compiled law and stages [-].
    rec_t : ndarray, shape (m,)
        Record times [s].
    rec_x : ndarray, shape (m, x_size)
        Recorded plant states [m, rad, m/s, rad/s, J].
    rec_ctrl : ndarray, shape (m, record_size)
        Recorded control rows [SI units of each channel].
    rec_frame : ndarray, shape (m, 9)
        Recorded attitude references R_NF [-].
    rec_Q : ndarray, shape (m, n_dof)
        Recorded joint-actuator forces held from each record, hub columns zero
        [N, N m per coordinate].
    rec_solved : ndarray, shape (m, 2, n_dof)
        q_ddot and the locked coordinates' constraint forces of each record where the
        compiled loop has them, NaN elsewhere
        (:class:`~flexsat.simulate.loops.LoopRecords`) [m/s^2, rad/s^2; N, N m].
    """

    plant: Plant
    scenario: SlewScenario
    law: object  # the registered law (flexsat.control.laws)
    layout: LoopLayout
    J: np.ndarray  # (3, 3) design inertia [kg m^2]
    x: np.ndarray  # (x_size,) plant state, advanced in place
    frame: np.ndarray  # (9,) attitude reference R_NF of x, updated in place
    data: LoopData
    stages: LoopStages
    rec_t: np.ndarray  # (m,) [s]
    rec_x: np.ndarray  # (m, x_size)
    rec_ctrl: np.ndarray  # (m, record_size)
    rec_frame: np.ndarray  # (m, 9)
    rec_Q: np.ndarray  # (m, n_dof)
    rec_solved: np.ndarray  # (m, 2, n_dof), NaN where the loop has not written it


def prepare_slew(plant: Plant, scenario: SlewScenario,
                 design_J: np.ndarray | None = None) -> PreparedSlew:  # fmt: skip
    """Everything a slew's compiled loop reads and writes, allocated once.

    Parameters
    ----------
    plant : Plant
        The truth model.
    scenario : SlewScenario
        The slew.
    design_J : ndarray, shape (3, 3), optional
        The controller's inertia [kg m^2]; default :func:`slew_design_inertia`.

    Returns
    -------
    PreparedSlew
        Initial state, loop data, stages and record buffers sized for the whole run
        (``n_steps // record_every + 2`` rows: the last good state of a failed run too).
    """
    J = np.ascontiguousarray(
        slew_design_inertia(plant, scenario) if design_J is None else design_J, dtype=float
    )
    law = get_law(scenario.controller.kind)
    layout = loop_layout(plant, scenario)
    q0, qd0 = initial_state(plant, scenario)
    n_records = scenario.n_steps // scenario.record_every + 2  # + the last good state
    data = _loop_data(layout, scenario, J, plant)
    stages = loop_stages(scenario)
    return PreparedSlew(
        plant, scenario, law, layout, J, np.concatenate([q0, qd0, [0.0, 0.0]]),
        identity_frame(),  # attitude reference R_NF (flexsat.dynamics.attitude)
        data, stages, np.full(n_records, np.nan),
        np.full((n_records, layout.plant.size), np.nan),
        np.full((n_records, layout.record_size), np.nan), np.full((n_records, 9), np.nan),
        np.zeros((n_records, plant.n_dof)),  # a Python law's loop applies none
        np.full((n_records, 2, plant.n_dof), np.nan),
    )  # fmt: skip


def finish_slew(run: PreparedSlew, status: int, done: int, rows: int, wall: float,
                compiled_law: bool = True) -> Result:  # fmt: skip
    """The :class:`~flexsat.simulate.result.Result` of a slew the loop has flown.

    Parameters
    ----------
    run : PreparedSlew
        The slew, its buffers filled by the loop.
    status : int
        The loop's status (0: finished; else :mod:`flexsat.compiled.status`).
    done : int
        Steps taken.
    rows : int
        Record rows written.
    wall : float
        Wall time of the loop [s] (an attribute of the result).
    compiled_law : bool
        The scenario's compiled law flew it (False: a Python controller).

    Returns
    -------
    Result
    """
    plant, scenario, law, layout, J, x, frame, data = run[:8]
    records = run.rec_t, run.rec_x, run.rec_ctrl, run.rec_frame, run.rec_Q, run.rec_solved
    rec_t, rec_x, rec_ctrl, rec_frame, rec_Q, _ = records
    t_fail = done * scenario.dt_s if status else -1.0
    if status:  # keep the last good state as the final record
        rec_t[rows], rec_x[rows], rec_ctrl[rows], rec_frame[rows] = t_fail, x, data.held, frame
        rec_Q[rows, :6], rec_Q[rows, 6:] = 0.0, data.Q[6:]  # as the loop records them
        rows += 1
    rec_t, rec_x, rec_ctrl, rec_frame, rec_Q, rec_solved = (a[:rows] for a in records)
    attrs = run_attributes(plant, scenario, "closed-loop", status, t_fail, wall, done)
    attrs["controller"] = law.name if compiled_law else "python"
    attrs["controller_label"] = law.label if compiled_law else "Python law"
    attrs["sensor"] = " > ".join(s.name for s in layout.sensors)
    attrs["actuator"] = " > ".join(s.name for s in layout.actuators)
    if compiled_law:
        attrs.update(scenario.controller.plot_attributes())
        attrs["law_diagnostics"] = [channel.name for channel in law.diagnostics]
    attrs["reference"] = layout.reference.name
    attrs["joint_actuator"] = layout.joint_actuator.name
    attrs["design_inertia"] = J.ravel().tolist()
    target = target_quaternion(scenario.target_euler_deg)
    attrs["target_quaternion"] = target.tolist()
    # gain (3), environment (3), sloshing ratio and Hz, residual (3), T_max
    attrs["realised_disturbances"] = scenario.disturbances.packed(scenario.actuator).tolist()
    at = layout.plant  # where each piece of the plant state lives
    ta = ("time", "axis")

    def added(data_vars: dict) -> dict:
        """The control channels, pointing and rate errors, from the records."""
        more = {}
        for channel, columns in layout.channels():
            dims = ta if channel.per_axis else ("time", "unit") if channel.per_unit else "time"
            values = rec_ctrl[:, columns] if len(dims) == 2 else rec_ctrl[:, columns.start]
            attributes = {"units": channel.units, "long_name": channel.description}
            more[channel.name] = (dims, values, attributes)
        # of the true attitude (relative to N), whatever the sensor measured
        q_N, omega = data_vars["q"][1], data_vars["omega"][1]
        pointing = pointing_errors(target, np.ascontiguousarray(q_N[:, at.attitude]))
        more["pointing_error_deg"] = (
            "time", np.degrees(pointing),
            {"units": "deg", "long_name": "2 asin |q_v,e| of the true attitude from the "
             "target: absolute pointing error"},
        )  # fmt: skip
        with np.errstate(over="ignore", invalid="ignore"):  # a diverged run's last state
            rate_error = np.degrees(np.linalg.norm(omega, axis=1))
        more["rate_error_deg_s"] = (
            "time", rate_error,
            {"units": "deg/s", "long_name": "|omega - omega_d|: residual rate (jitter)"},
        )  # fmt: skip
        return more

    ds = build_dataset(
        plant, rec_t, rec_x[:, at.q], rec_x[:, at.qd], rec_x[:, at.work_in],
        rec_x[:, at.dissipated], rec_ctrl[:, layout.tau_cmd], rec_ctrl[:, layout.tau_applied],
        attrs, frames=rec_frame, joint_force=rec_Q, solved=rec_solved, more=added,
    )  # fmt: skip
    return Result(ds)


def flown_chain(scenario: SlewScenario) -> tuple[list, int]:
    """The stages the loop runs, in order, and how many of them sense.

    :meth:`SlewScenario.stage_chain` less the sensing stages whose work nothing reads:
    a stage without state or records each of whose outputs a later stage overwrites
    (``StageSpec.overwrites``) before any stage reads it (a stage that neither
    ``overwrites`` nor ``leaves`` an output reads it; the law reads both). So the
    ideal ``[sensor]`` ahead of a gyro and a star tracker, whose outputs they replace
    before the estimator reads them, is not run (about 0.1 us per control instant);
    every output is the same, bit for bit.

    Parameters
    ----------
    scenario : SlewScenario
        The slew.

    Returns
    -------
    chain : list of (str, StageConfig)
        The flown stages with their field paths: sensing, then actuation.
    n_sensors : int
        How many of them sense.
    """
    chain = scenario.stage_chain()
    n = 1 + len(scenario.sensor_stages)
    specs = [SENSORS.get(c.kind) for _, c in chain[:n]]

    def unread(i: int) -> bool:
        spec = specs[i]
        if spec.state_size or spec.records or not spec.overwrites:
            return False
        for output in spec.overwrites:
            for later in specs[i + 1 :]:
                if output in later.overwrites:
                    break  # replaced before anyone read it
                if output not in later.leaves:
                    return False  # read
            else:
                return False  # the law reads it
        return True

    sensing = [entry for i, entry in enumerate(chain[:n]) if not unread(i)]
    return sensing + chain[n:], len(sensing)


def _specs(scenario: SlewScenario) -> tuple:
    """The registered law, sensing and actuation stages, reference and joint actuator."""
    chain, n_sensors = flown_chain(scenario)
    sensors = tuple(SENSORS.get(c.kind) for _, c in chain[:n_sensors])
    actuators = tuple(ACTUATORS.get(c.kind) for _, c in chain[n_sensors:])
    return (get_law(scenario.controller.kind), sensors, actuators,
            REFERENCES.get(scenario.reference.kind),
            JOINT_ACTUATORS.get(scenario.joint_actuator.kind))  # fmt: skip


def loop_layout(plant: Plant, scenario: SlewScenario) -> LoopLayout:
    """Where a slew's states and records live: its law, its two stage chains, its
    reference generator and its joint actuator.

    Parameters
    ----------
    plant : Plant
        The plant flown (its state layout).
    scenario : SlewScenario
        The slew (its law and stages, by kind).

    Returns
    -------
    LoopLayout
        The offsets of the plant state, control state and record row.
    """
    return LoopLayout(plant.layout, *_specs(scenario))


def loop_stages(scenario: SlewScenario) -> LoopStages:
    """The compiled law and stages of a slew, as the loop takes them.

    Each is compiled with its role's signature on first use and cached on disk
    (:func:`flexsat.compiled.first_class.first_class`); no plant is needed. The chains are
    padded to a multiple of :data:`~flexsat.simulate.coupled.CHAIN_SLOTS` entries.

    Parameters
    ----------
    scenario : SlewScenario
        The slew (its law and stages, by kind).

    Returns
    -------
    LoopStages
        The first-class functions and the chains' lengths.
    """
    law, sensors, actuators, reference, joint_actuator = _specs(scenario)
    return LoopStages(
        _padded(tuple(first_class(s.step, SENSOR_SIGNATURE) for s in sensors)),
        (first_class(law.step, LAW_SIGNATURE),),
        _padded(tuple(first_class(s.step, ACTUATOR_SIGNATURE) for s in actuators)),
        _padded(tuple(first_class(s.derivative or no_derivative, DERIVATIVE_SIGNATURE)
                      for s in actuators)),
        (first_class(reference.step, REFERENCE_SIGNATURE),),
        (first_class(joint_actuator.step, JOINT_ACTUATOR_SIGNATURE),),
        len(sensors), len(actuators),
    )  # fmt: skip


def _padded(entries: tuple, filler=None) -> tuple:
    """``entries`` padded to a multiple of :data:`~flexsat.simulate.coupled.CHAIN_SLOTS`
    with ``filler`` (default: the first entry), so every chain of up to that many
    stages has one numba type and shares one compiled loop; the loop never reads the
    padding (it runs the chain's own stages, ``LoopStages.n_sensor``, ``n_actuator``).
    Arrays are padded with an empty array of their type."""
    if filler is None:
        filler = entries[0][:0] if isinstance(entries[0], np.ndarray) else entries[0]
    return entries + (filler,) * (-len(entries) % CHAIN_SLOTS)


def _loop_data(layout: LoopLayout, scenario: SlewScenario, J: np.ndarray,
               plant: Plant) -> LoopData:  # fmt: skip
    """The arrays of one run, record-row pieces as views into ``held``."""
    held = np.zeros(layout.record_size)
    state = np.zeros(layout.state_size)
    chain = [c for _, c in flown_chain(scenario)[0]]
    n_sensors = len(layout.sensors)

    def packed(values) -> np.ndarray:
        return np.ascontiguousarray(values, dtype=float)

    # The coupled RK4 step carries each stage's integrated entries (the block ends with
    # the last stage that integrates any, StageConfig.integrated_size).
    block, last = layout.continuous_state, -1
    if layout.continuous:
        last = max(i for i, s in enumerate(layout.actuators) if s.derivative is not None)
        size = chain[n_sensors + last].integrated_size()
        if size is not None:
            block = slice(block.start, layout.actuator_states[last].start + size)
    m = block.stop - block.start
    evaluation, rate = np.zeros(m), np.zeros(m)

    def local(array: np.ndarray, pieces: tuple[slice, ...]) -> tuple:
        """Each stage's part of a flow array (empty for a stage outside the block)."""
        return tuple(array[max(p.start, block.start) - block.start :
                           min(p.stop, block.stop) - block.start]
                     if p.start < block.stop and block.start < p.stop else array[:0]
                     for p in pieces)  # fmt: skip

    flow = LoopFlow(
        state=state[block], eval=evaluation,
        eval_views=_padded(local(evaluation, layout.actuator_states), evaluation[:0]),
        dot=rate, dot_views=_padded(local(rate, layout.actuator_states), rate[:0]),
        rates=np.zeros(m), wrench=np.zeros(3), held=np.zeros(3), omega=np.zeros(3),
        n_derivative=last + 1,
    )  # fmt: skip

    return LoopData(
        J_design=J.copy(),  # a joint actuator may update it in place (sadm_drive, "measured")
        q_d=packed(target_quaternion(scenario.target_euler_deg)),  # the reference writes these
        omega_d=np.zeros(3),
        omega_dot_d=np.zeros(3),
        law_gains=packed(scenario.controller.gains(scenario.actuator)),
        law_state=state[layout.law_state],
        sensor_params=_padded(tuple(packed(c.packed(scenario)) for c in chain[:n_sensors])),
        sensor_state=_padded(tuple(state[p] for p in layout.sensor_states)),
        actuator_params=_padded(tuple(packed(c.packed(scenario)) for c in chain[n_sensors:])),
        actuator_state=_padded(tuple(state[p] for p in layout.actuator_states)),
        q_meas=np.zeros(4),
        omega_meas=np.zeros(3),
        held=held,
        tau_cmd=held[layout.tau_cmd],
        tau_applied=held[layout.tau_applied],
        law_diag=held[layout.law_diag],
        sensor_record=_padded(tuple(held[p] for p in layout.sensor_records)),
        actuator_record=_padded(tuple(held[p] for p in layout.actuator_records)),
        tau_between=np.zeros(3),
        flow=flow,
        reference_params=packed(scenario.reference.packed(scenario, plant)),
        reference_state=state[layout.reference_state],
        reference_record=held[layout.reference_record],
        joint_params=packed(scenario.joint_actuator.packed(scenario, plant)),
        joint_state=state[layout.joint_state],
        joint_record=held[layout.joint_record],
        Q=np.zeros(layout.plant.n_dof),
    )


def _compiled_loop(run: PreparedSlew, bar, task) -> tuple[int, int, int]:
    """The whole loop, stages and law included, in compiled chunks (one call without a bar)."""
    per_call = 1 if bar is not None else run.scenario.n_steps + 1
    status, done, rows = 0, 0, 0
    while True:
        status, done, rows = fly(*_fly_arguments(run, done, rows, per_call))
        if bar is not None:
            bar.update(task, completed=done * run.scenario.dt_s)
        if status != 0 or done == run.scenario.n_steps:
            return status, done, rows


def _fly_arguments(run: PreparedSlew, done: int, rows: int, max_chunks: int) -> tuple:
    """:func:`~flexsat.simulate.batch.fly`'s arguments for ``run`` from step ``done``."""
    return (run.x, slew_timing(run), run.stages, run.data, run.rec_t, run.rec_x, run.rec_ctrl,
            run.rec_frame, run.rec_Q, run.rec_solved, run.plant.packed, run.frame, done, rows,
            max_chunks)  # fmt: skip


@njit(cache=True)
def _listed_sensors(x, n, t, loop):
    """:func:`~flexsat.simulate.loops.run_sensors` on the structures in ``loop``, a typed
    list of one (stages, data, packed plant) tuple: unboxed as one pointer, where
    the structures themselves would unbox every array and first-class function at
    every call (:mod:`flexsat.compiled.typed_call`)."""
    stages, d, _ = loop[0]
    return run_sensors(x, n, t, stages, d)


@njit(cache=True)
def _listed_actuators(x, n, t, control_dt, continuous, loop):
    """:func:`~flexsat.simulate.loops.run_actuators` on ``loop`` (:func:`_listed_sensors`)."""
    stages, d, _ = loop[0]
    return run_actuators(x, n, t, control_dt, continuous, stages, d)


@njit(cache=True)
def _listed_coupled_hold(x, t0, dt, n_steps, loop):
    """:func:`~flexsat.simulate.coupled.rk4_coupled_hold` on ``loop`` (:func:`_listed_sensors`)."""
    stages, d, packed = loop[0]
    return rk4_coupled_hold(x, t0, dt, n_steps, stages.derivative, d.actuator_params, d.flow,
                            packed)  # fmt: skip


@njit(cache=True)
def _listed_hold(x, dt, n_steps, frame, loop):
    """:func:`~flexsat.dynamics.integrators.rk4_hold` under the held ``tau_applied``, on
    ``loop`` (:func:`_listed_sensors`)."""
    _, d, packed = loop[0]
    torque = (d.tau_applied[0], d.tau_applied[1], d.tau_applied[2])
    return rk4_hold(x, dt, n_steps, torque, packed, frame)


def _python_loop(plant, scenario, x, frame, stages, d, rec_t, rec_x, rec_ctrl, rec_frame, bar,
                 task, controller, continuous):  # fmt: skip
    """Python controller at each control instant between the compiled stages; the plant
    steps compiled in between."""
    n = plant.n_dof
    steps, every, control = scenario.n_steps, scenario.record_every, scenario.control_every
    block = math.gcd(every, control)
    control_dt = control * scenario.dt_s
    limit = scenario.actuator.reduction_factor * scenario.actuator.t_max_nm
    d.law_diag[:] = np.nan
    view = np.empty_like(x)
    # the same arguments at every instant: typed once, and the loop's structures in a
    # typed list, unboxed as one pointer (flexsat.compiled.typed_call)
    loop = typed_list((stages, d, plant.packed))
    sensors, actuators = TypedOnce(_listed_sensors), TypedOnce(_listed_actuators)
    coupled_hold, hold = TypedOnce(_listed_coupled_hold), TypedOnce(_listed_hold)
    rows, status, k = 0, 0, 0
    while True:
        t = k * scenario.dt_s
        if k % control == 0:
            sensed = x
            if not is_identity(frame):  # re-based between steps: the sensors read N
                inertial_view(x, n, frame, view)
                sensed = view
            status = sensors(sensed, n, t, loop)
            tau_cmd = np.asarray(controller(t, d.q_meas.copy(), d.omega_meas.copy()), dtype=float)
            if tau_cmd.shape != (3,) or not np.all(np.isfinite(tau_cmd)):
                raise SimulationError(f"controller returned {tau_cmd!r} at t = {t:.6g} s")
            d.tau_cmd[:] = np.clip(tau_cmd, -limit, limit)
            status |= actuators(x, n, t, control_dt, continuous, loop)
            if status:
                return STATUS_CONTROL_FAILED, k, rows
        if k % every == 0:
            rec_t[rows], rec_x[rows], rec_ctrl[rows], rec_frame[rows] = t, x, d.held, frame
            rows += 1
        if k == steps:
            return 0, k, rows
        if continuous:  # re-based once per block (a few steps: far from the pole)
            rebase(x, n, frame)
            status, ran = coupled_hold(x, t, scenario.dt_s, block, loop)
        else:
            status, ran = hold(x, scenario.dt_s, block, frame, loop)
        k += ran
        if status:
            return status, k, rows
        if bar is not None and k % 10_000 < block:
            bar.update(task, completed=t)
