"""Closed-loop slews: a control law flies the flexible plant (thesis section 5.1)."""

from __future__ import annotations

import os
import tempfile
import time
from pathlib import Path
from typing import NamedTuple, Protocol

import numpy as np
import xarray as xr

from flexsat.analysis.run_records import RunRecords
from flexsat.config import nominal
from flexsat.config.models import SatelliteConfig
from flexsat.control.laws import get_law
from flexsat.control.quaternion import pointing_errors, target_quaternion
from flexsat.control.stages import JOINT_ACTUATORS, REFERENCES
from flexsat.dynamics.attitude import identity_frame
from flexsat.dynamics.plant import Plant
from flexsat.dynamics.rigid import design_coordinates, rigid_inertia
from flexsat.errors import ConfigError
from flexsat.simulate.batch import batch_item, fly_entry, slew_timing
from flexsat.simulate.layout import LoopLayout
from flexsat.simulate.loops import LoopData, LoopStages
from flexsat.simulate.openloop import initial_state
from flexsat.simulate.python_loop import python_loop
from flexsat.simulate.result import Result, build_dataset, build_records
from flexsat.simulate.run_setup import (
    PROGRESS_MIN_STEPS,
    check_run_size,
    chunk_steps,
    progress_bar,
    run_attributes,
)
from flexsat.simulate.scenario import SlewScenario
from flexsat.simulate.stage_chain import loop_data, loop_layout, loop_stages
from flexsat.simulate.stream import RecordStream, check_disk_space
from flexsat.simulate.targets import reference_track, tracking_errors

__all__ = [
    "Controller",
    "PreparedSlew",
    "design_inertia",
    "finish_slew",
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
    *,
    record_path: str | Path | None = None,
    record_budget_bytes: float | None = None,
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
    record_path : str or Path, optional
        Stream the records to this NetCDF file while the run goes, block by block
        (:mod:`flexsat.simulate.stream`; the compiled law only); by default only a run
        whose records do not fit in memory is streamed, to a temporary file.
    record_budget_bytes : float, optional
        Memory the records may use before they are streamed [bytes]; default: half the
        machine's memory (:func:`flexsat.simulate.run_setup.check_run_size`).

    Returns
    -------
    Result
        As :func:`flexsat.simulate.run_openloop`, plus the pointing and rate errors,
        the law's declared diagnostics and the stages' records (each a variable with
        its units) and, in the attributes, what the law's plots need. A diverging
        run stops cleanly with its history and ``status = "failed"``. A streamed
        run's dataset reads its file lazily (``result.path``).

    Raises
    ------
    ConfigError
        Records that fit neither in memory nor on the disk they would be streamed
        to; streaming asked of a Python controller's run.
    """
    scenario = scenario or SlewScenario()
    stream, block_rows = None, None
    if record_path is not None or record_budget_bytes is not None:
        estimate = check_run_size(plant.n_dof, scenario, record_budget_bytes, can_stream=True)
        if record_path is not None or not estimate.fits_in_memory:
            if controller is not None:
                raise ConfigError("record_path: a Python controller's run keeps its records "
                                  "in memory; run it without record_path")  # fmt: skip
            path = Path(record_path) if record_path is not None else _temporary_record_file()
            check_disk_space(path.parent, estimate.record_bytes * estimate.records)
            stream = RecordStream(path)
            # a quarter of the budget per block, at least two chunks of records
            per_chunk = chunk_steps(scenario.record_every, scenario.control_every)
            per_chunk //= scenario.record_every
            budget = int(0.25 * estimate.available_bytes / estimate.record_bytes)
            block_rows = max(2 * per_chunk, budget) + 2
    run = prepare_slew(plant, scenario, design_J, block_rows)
    layout = run.layout
    if controller is not None and (
        layout.reference.name != REFERENCES.default
        or layout.joint_actuator.name != JOINT_ACTUATORS.default
    ):
        raise ConfigError("a Python controller flies the step reference without joint "
                          "actuators: remove [reference] and [joint_actuator]")  # fmt: skip
    steps = scenario.n_steps
    show = steps >= PROGRESS_MIN_STEPS if progress is None else progress
    flight = None
    if controller is None:  # compile or load the loop now: the wall time is the run's
        flight = fly_entry(batch_item(run))  # typed once, called untyped (docs/performance.md)
    start = time.perf_counter()
    with progress_bar(show, scenario.duration_s) as (bar, task):
        if controller is None:
            status, done, rows = _compiled_loop(run, bar, task, stream, flight)
        else:
            status, done, rows = python_loop(plant, scenario, run.x, run.frame, run.stages,
                                             run.data, run.rec_t, run.rec_x, run.rec_ctrl,
                                             run.rec_frame, bar, task, controller,
                                             layout.continuous)  # fmt: skip
    return finish_slew(run, status, done, rows, time.perf_counter() - start, controller is None,
                       stream)  # fmt: skip


def _temporary_record_file() -> Path:
    handle, name = tempfile.mkstemp(prefix="flexsat-slew-", suffix=".nc")
    os.close(handle)
    return Path(name)


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


def prepare_slew(plant: Plant, scenario: SlewScenario, design_J: np.ndarray | None = None,
                 record_rows: int | None = None) -> PreparedSlew:  # fmt: skip
    """Everything a slew's compiled loop reads and writes, allocated once.

    Parameters
    ----------
    plant : Plant
        The truth model.
    scenario : SlewScenario
        The slew.
    design_J : ndarray, shape (3, 3), optional
        The controller's inertia [kg m^2]; default :func:`slew_design_inertia`.
    record_rows : int, optional
        Rows of the record buffers when the run streams its records in blocks
        (at most the whole run's).

    Returns
    -------
    PreparedSlew
        Initial state, loop data, stages and record buffers sized for the whole run
        (``n_steps // record_every + 2`` rows: the last good state of a failed run too),
        or for one streamed block.
    """
    J = np.ascontiguousarray(
        slew_design_inertia(plant, scenario) if design_J is None else design_J, dtype=float
    )
    law = get_law(scenario.controller.kind)
    layout = loop_layout(plant, scenario)
    q0, qd0 = initial_state(plant, scenario)
    n_records = scenario.n_steps // scenario.record_every + 2  # + the last good state
    if record_rows is not None:
        n_records = min(n_records, record_rows)
    data = loop_data(layout, scenario, J, plant)
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
                compiled_law: bool = True, stream: RecordStream | None = None, *,
                as_records: bool = False) -> Result | RunRecords:  # fmt: skip
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
    stream : RecordStream, optional
        Where the run's earlier blocks of records went: the buffers' ``rows`` are
        its last block.
    as_records : bool
        Return what the result's dataset would hold as plain arrays instead, without
        building the dataset (a campaign case's row; a run without ``stream``).

    Returns
    -------
    Result or RunRecords
    """
    scenario, x, frame, data = run.scenario, run.x, run.frame, run.data
    records = run.rec_t, run.rec_x, run.rec_ctrl, run.rec_frame, run.rec_Q, run.rec_solved
    rec_t, rec_x, rec_ctrl, rec_frame, rec_Q, _ = records
    t_fail = done * scenario.dt_s if status else -1.0
    if status:  # keep the last good state as the final record
        rec_t[rows], rec_x[rows], rec_ctrl[rows], rec_frame[rows] = t_fail, x, data.held, frame
        rec_Q[rows, :6], rec_Q[rows, 6:] = 0.0, data.Q[6:]  # as the loop records them
        rows += 1
    attrs = _slew_attributes(run, status, t_fail, wall, done, compiled_law)
    if stream is None:
        if as_records:  # no xarray dataset (docs/performance.md, "Campaign cases")
            return _slew_block(run, rows, attrs, build=build_records)
        return Result(_slew_block(run, rows, attrs))
    if rows:
        stream.append(_slew_block(run, rows, attrs, stream.energy0))
    return Result(stream.finish(attrs), stream.path)


def _slew_attributes(run: PreparedSlew, status: int, t_fail: float, wall: float, done: int,
                     compiled_law: bool = True) -> dict:  # fmt: skip
    """The dataset attributes of a slew (its configs, status, law, stages, target)."""
    plant, scenario, law, layout, J = run[:5]
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
    return attrs


def _slew_block(run: PreparedSlew, rows: int, attrs: dict, energy0: float | None = None,
                build=build_dataset) -> xr.Dataset | RunRecords:  # fmt: skip
    """The dataset of the first ``rows`` records of the buffers (a run's, or a block);
    ``build``: :func:`~flexsat.simulate.result.build_records` for the plain arrays."""
    plant, scenario, _, layout = run[:4]
    data = run.data
    records = run.rec_t, run.rec_x, run.rec_ctrl, run.rec_frame, run.rec_Q, run.rec_solved
    rec_t, rec_x, rec_ctrl, rec_frame, rec_Q, rec_solved = (a[:rows] for a in records)
    target = np.asarray(attrs["target_quaternion"], dtype=float)
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
        if scenario.reference.moving_target:  # against the target the reference produced
            q_d, omega_d = reference_track(layout.reference.step, rec_t, data)
            pointing, omega = tracking_errors(q_d, omega_d, q_N[:, at.attitude], omega)
            more["reference_quaternion"] = (
                ("time", "quat"), q_d,
                {"units": "1", "long_name": "the reference attitude q_d the reference stage "
                 "produced, scalar first"},
            )  # fmt: skip
        else:
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

    return build(
        plant, rec_t, rec_x[:, at.q], rec_x[:, at.qd], rec_x[:, at.work_in],
        rec_x[:, at.dissipated], rec_ctrl[:, layout.tau_cmd], rec_ctrl[:, layout.tau_applied],
        dict(attrs), energy0, frames=rec_frame, joint_force=rec_Q, solved=rec_solved,
        more=added,
    )  # fmt: skip


def _compiled_loop(run: PreparedSlew, bar, task, stream: RecordStream | None = None,
                   flight=None) -> tuple[int, int, int]:  # fmt: skip
    """The whole loop, stages and law included, in compiled chunks (one call without a bar
    or a stream); a streamed run hands each full buffer of records to ``stream``.
    ``flight``: :func:`~flexsat.simulate.batch.fly`'s entry point for the run's types
    (:func:`~flexsat.simulate.batch.fly_entry`; default found here)."""
    flight = flight or fly_entry(batch_item(run))
    scenario = run.scenario
    per_call = 1 if (bar is not None or stream is not None) else scenario.n_steps + 1
    # records of one chunk, plus the final step's and a failed run's last good state
    per_chunk = chunk_steps(scenario.record_every, scenario.control_every)
    room = per_chunk // scenario.record_every + 2
    status, done, rows = 0, 0, 0
    attrs = None
    while True:
        status, done, rows = flight(*_fly_arguments(run, done, rows, per_call))
        if bar is not None:
            bar.update(task, completed=done * scenario.dt_s)
        if status != 0 or done == scenario.n_steps:
            return status, done, rows
        if stream is not None and rows + room > run.rec_t.size:
            attrs = attrs or _slew_attributes(run, 0, -1.0, 0.0, 0)
            stream.append(_slew_block(run, rows, attrs, stream.energy0))
            run.rec_solved[:] = np.nan  # written only where the loop has it: no stale rows
            rows = 0


def _fly_arguments(run: PreparedSlew, done: int, rows: int, max_chunks: int) -> tuple:
    """:func:`~flexsat.simulate.batch.fly`'s arguments for ``run`` from step ``done``."""
    return (run.x, slew_timing(run), run.stages, run.data, run.rec_t, run.rec_x, run.rec_ctrl,
            run.rec_frame, run.rec_Q, run.rec_solved, run.plant.packed, run.frame, done, rows,
            max_chunks)  # fmt: skip
