"""Open-loop simulation: a torque profile applied to the flexible plant (thesis section 3.3)."""

from __future__ import annotations

import itertools
import os
import tempfile
import time
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np
from numba import njit

from flexsat.compiled.status import STATUS_STEP_BUDGET, STATUS_STEP_TOO_SMALL
from flexsat.compiled.typed_call import typed_list
from flexsat.dynamics.attitude import SWITCH_PITCH, identity_frame, rebase
from flexsat.dynamics.initial import initial_state
from flexsat.dynamics.integrators import (
    STATUS_NOT_FINITE,
    applied_torque,
    augmented_derivative,
    rk4_open_loop,
)
from flexsat.dynamics.kernels import STATUS_OK, hub_cs
from flexsat.dynamics.plant import Plant
from flexsat.simulate.openloop_scenario import OpenLoopScenario, thesis_openloop
from flexsat.simulate.run_setup import (
    PROGRESS_MIN_STEPS,
    check_run_size,
    chunk_steps,
    progress_bar,
    run_attributes,
)

if TYPE_CHECKING:  # xarray (0.4 s to import) loads only when a dataset is built
    import xarray as xr

    from flexsat.analysis.run_records import RunRecords
    from flexsat.simulate.result import Result

__all__ = [
    "DOP853_MIN_STEP_FRACTION",
    "DOP853_STEP_BUDGET",
    "commanded_torques",
    "initial_state",
    "listed_derivative",
    "run_openloop",
]

DOP853_MIN_STEP_FRACTION = 1e-2
"""An accepted DOP853 step below this fraction of ``dt_s`` stops the run as diverging."""
DOP853_STEP_BUDGET = 4
"""DOP853 may take at most this many times the run's fixed-step count (duration / dt_s)."""


def _profile(scenario: OpenLoopScenario):
    end = scenario.duration_s + 1.0
    seg_start = np.array([s.start_s for s in scenario.torque], dtype=float)
    seg_end = np.array([end if s.end_s is None else s.end_s for s in scenario.torque], dtype=float)
    seg_torque = np.array([s.torque_nm for s in scenario.torque], dtype=float).reshape(-1, 3)
    return seg_start, seg_end, seg_torque, np.array(scenario.disturbance_torque_nm, dtype=float)


def run_openloop(
    plant: Plant,
    scenario: OpenLoopScenario | None = None,
    progress: bool | None = None,
    *,
    record_path: str | Path | None = None,
    record_budget_bytes: float | None = None,
    records: bool = False,
) -> Result | RunRecords:
    """Simulate the plant under the scenario's torque profile.

    Parameters
    ----------
    plant : Plant
        The satellite.
    scenario : OpenLoopScenario, optional
        Default: the thesis's scenario (1 N m about Z for 10 s, free to 120 s).
    progress : bool, optional
        Show a progress bar; default: only for runs of at least 200 000 steps.
    record_path : str or Path, optional
        Stream the records to this NetCDF file while the run goes (RK4 only); by
        default only a run whose records do not fit in memory is streamed, to a
        temporary file.
    record_budget_bytes : float, optional
        Memory the records may use before they are streamed [bytes]; default: half the
        machine's memory (:func:`flexsat.simulate.run_setup.check_run_size`).
    records : bool
        Return the records as plain arrays
        (:class:`~flexsat.analysis.run_records.RunRecords`, what the dataset would
        hold, bit for bit) instead of a :class:`Result`: no ``xarray.Dataset`` is built
        and xarray is not imported (what ``flexsat openloop`` without ``--out`` needs,
        docs/performance.md, 'Start-up'). A run that is streamed still returns a
        :class:`Result`.

    Returns
    -------
    Result or RunRecords
        Recorded every ``record_dt_s``. A diverging run stops at the failing step and
        returns its history up to there with ``status = "failed"`` and a message
        that names the time; it does not raise. A streamed run's dataset reads its
        file lazily (``result.path``).

    Raises
    ------
    ConfigError
        Before it starts, if its records fit neither in memory nor (RK4) on the
        disk they would be streamed to.
    """
    scenario = scenario or thesis_openloop()
    rk4 = scenario.solver == "rk4"
    estimate = check_run_size(plant.n_dof, scenario, record_budget_bytes, can_stream=rk4)
    stream = None
    if rk4 and (record_path is not None or not estimate.fits_in_memory):
        from flexsat.simulate.stream import RecordStream, check_disk_space

        path = Path(record_path) if record_path is not None else _temporary_record_file()
        check_disk_space(path.parent, estimate.record_bytes * estimate.records)
        stream = RecordStream(path)
    q0, qd0 = initial_state(plant, scenario)
    profile = _profile(scenario)
    attrs = run_attributes(plant, scenario, "open-loop", 0, -1.0, 0.0, 0)
    attrs["solver"] = scenario.solver
    blocks: list[xr.Dataset | RunRecords] = []
    as_records = records and stream is None
    building = [0.0]  # seconds spent building record blocks, not integrating

    def keep(t, X, tau, F) -> None:
        begin = time.perf_counter()
        block = _block(plant, t, X, tau, F, profile, attrs, stream, as_records)
        if stream is None:
            blocks.append(block)
        else:
            stream.append(block)
        building[0] += time.perf_counter() - begin

    if rk4:  # compile or load the kernel now: the run's wall time is the integration's
        scratch = np.zeros((1, plant.layout.size))
        rk4_open_loop(scratch[0], 0.0, scenario.dt_s, 0, 1, *profile, plant.packed,
                      identity_frame(), np.zeros(1), scratch, np.zeros((1, 3)),
                      np.zeros((1, 9)), 0)  # fmt: skip
    start = time.perf_counter()
    if rk4:
        capacity = None
        if stream is not None:  # a quarter of the budget per buffer, whole chunks of records
            capacity = max(1, int(0.25 * estimate.available_bytes / estimate.record_bytes))
        status, t_fail, steps = _run_rk4(plant, scenario, q0, qd0, profile, progress, keep,
                                         capacity)  # fmt: skip
    else:
        t, X, F, tau, status, t_fail, steps = _run_dop853(plant, scenario, q0, qd0, profile)
        keep(t, X, tau, F)
    wall = time.perf_counter() - start - building[0]
    final = run_attributes(plant, scenario, "open-loop", status, t_fail, wall, steps)
    if as_records:
        (held,) = blocks  # one block of every record
        held.attrs.update(final)
        return held
    from flexsat.simulate.result import Result

    if stream is not None:
        return Result(stream.finish(final), stream.path)
    (dataset,) = blocks  # held in memory: one block of every record
    dataset.attrs.update(final)
    return Result(dataset)


def _temporary_record_file() -> Path:
    handle, name = tempfile.mkstemp(prefix="flexsat-openloop-", suffix=".nc")
    os.close(handle)
    return Path(name)


def _block(plant, t, X, tau, F, profile, attrs, stream,
           records: bool = False) -> xr.Dataset | RunRecords:  # fmt: skip
    """The dataset of consecutive records (all of a run's, or one streamed block); with
    ``records``, the same as plain arrays (no dataset)."""
    from flexsat.simulate.result import build_dataset, build_records

    lay = plant.layout
    seg_start, seg_end, seg_torque, _ = profile
    tau_cmd = commanded_torques(np.ascontiguousarray(t), seg_start, seg_end, seg_torque)
    energy0 = None if stream is None else stream.energy0
    return (build_records if records else build_dataset)(
        plant, t, X[:, lay.q], X[:, lay.qd], X[:, lay.work_in], X[:, lay.dissipated], tau_cmd,
        tau, dict(attrs), energy0, frames=F,
    )  # fmt: skip


def _run_rk4(plant, scenario, q0, qd0, profile, progress, keep, capacity=None):
    """The compiled RK4 loop in chunks; ``keep(t, X, tau, F)`` takes each block of records
    (F: the attitude reference of each record).

    With ``capacity`` None every record is held and handed over once at the end;
    otherwise the buffer holds about ``capacity`` records (whole chunks of them) and
    is handed over each time it is full. The chunks, and so the arithmetic, are
    the same either way. Returns (status, t_fail, steps done).
    """
    n_steps, every, dt = scenario.n_steps, scenario.record_every, scenario.dt_s
    n_records = n_steps // every + 1
    chunk = chunk_steps(every)
    per_chunk = chunk // every
    size = n_records if capacity is None else min(n_records, max(capacity, per_chunk + 1))
    rec_t = np.empty(size)
    rec_x = np.empty((size, plant.layout.size))
    rec_tau = np.empty((size, 3))
    rec_frame = np.empty((size, 9))
    x = np.concatenate([q0, qd0, [0.0, 0.0]])
    frame = identity_frame()
    rec_t[0], rec_x[0], rec_frame[0] = 0.0, x, frame
    rec_tau[0] = applied_torque(0.0, *profile)
    base = 0  # index in the run of the buffer's first record
    handed_t = -1.0  # time of the last record handed over [s]
    show = n_steps >= PROGRESS_MIN_STEPS if progress is None else progress
    done, status = 0, 0
    with progress_bar(show, scenario.duration_s) as (bar, task):
        while done < n_steps and status == 0:
            steps = min(chunk, n_steps - done)
            row = done // every + 1 - base
            if row + -(-steps // every) > size:  # the buffer is full: hand it over
                keep(
                    rec_t[:row].copy(),
                    rec_x[:row].copy(),
                    rec_tau[:row].copy(),
                    rec_frame[:row].copy(),
                )
                handed_t = float(rec_t[row - 1])
                base += row
                row = 0
            status, ran = rk4_open_loop(
                x, done * dt, dt, steps, every, *profile, plant.packed, frame,
                rec_t, rec_x, rec_tau, rec_frame, row,
            )  # fmt: skip
            done += ran
            if bar is not None:
                bar.update(task, completed=done * dt)
    kept = done // every + 1 - base
    t_fail = done * dt if status else -1.0
    if status and kept == 0 and done * dt > handed_t:  # failed before the block's first record
        kept = 1
    if status and kept > 0:
        # Keep the last good state too, even between two records.
        rec_t[kept - 1 : kept] = done * dt
        rec_x[kept - 1], rec_frame[kept - 1] = x, frame
        rec_tau[kept - 1] = applied_torque(done * dt, *profile)
    if kept > 0:
        keep(rec_t[:kept], rec_x[:kept], rec_tau[:kept], rec_frame[:kept])
    return status, t_fail, done


@njit(cache=True)
def commanded_torques(t, seg_start, seg_end, seg_torque):
    """The commanded torque of each record: the active segments, without the disturbance.

    :func:`~flexsat.dynamics.integrators.applied_torque` at each time in one compiled
    call (the same sums, bit for bit): called from Python once per record it took
    about 0.1 s of a 120 s open loop's 12 001 records (docs/performance.md, 'Start-up').

    Parameters
    ----------
    t : ndarray, shape (m,)
        Record times [s].
    seg_start, seg_end : ndarray, shape (k,)
        Start and end of each torque segment [s]; a segment is active on [start, end).
    seg_torque : ndarray, shape (k, 3)
        Each segment's torque, hub frame B [N m].

    Returns
    -------
    ndarray, shape (m, 3)
        The commanded torque at each record, hub frame B [N m].
    """
    out = np.empty((t.shape[0], 3))
    none = np.zeros(3)  # the disturbance is not commanded
    for i in range(t.shape[0]):
        out[i, 0], out[i, 1], out[i, 2] = applied_torque(t[i], seg_start, seg_end, seg_torque,
                                                         none)  # fmt: skip
    return out


@njit(cache=True)
def listed_derivative(x, torque_B, n, Q, dx, plants):
    """:func:`~flexsat.dynamics.integrators.augmented_derivative` of the plant held in
    a typed list, for a solver that calls it from Python at every evaluation.

    Passed as it is, the :class:`~flexsat.dynamics.packed.PackedPlant` would be
    unboxed at every call, each array and kernel of it: about 60 us, ten times the
    rest of the call (:mod:`flexsat.compiled.typed_call`).

    Parameters
    ----------
    x : ndarray, shape (2 n + 2,)
        Augmented state [q, q_dot, W_in, W_diss] (SI: m, rad, m/s, rad/s, J).
    torque_B : tuple of 3 float
        Applied torque on the hub, hub frame B [N m].
    n : int
        Number of generalized coordinates.
    Q : ndarray, shape (n,)
        Generalized forces on the joints [N, N m per coordinate].
    dx : ndarray, shape (2 n + 2,)
        Written: the state's rate [SI per s].
    plants : numba.typed.List of PackedPlant
        :func:`~flexsat.compiled.typed_call.typed_list` of ``Plant.packed``.

    Returns
    -------
    int
        ``STATUS_OK`` or the kernel's status.
    """
    return augmented_derivative(x, torque_B, n, Q, dx, plants[0], hub_cs(x))


def _run_dop853(plant, scenario, q0, qd0, profile):
    """Adaptive DOP853 (scipy), stepped piecewise between torque switching times.

    Each piece also ends where |pitch| reaches ``SWITCH_PITCH`` (a terminal event,
    located on the step's dense output): the attitude is re-based there
    (:func:`flexsat.dynamics.attitude.rebase`) and the piece continues from the event.
    A run that diverges stops there, like RK4: the records up to the failure and the
    last good state are kept, with its status. It diverges when a step fails (a
    non-finite state or a kernel's singularity), when an accepted step falls below
    ``DOP853_MIN_STEP_FRACTION`` of ``dt_s`` (the motion is then far faster than the
    run's time step resolves: RK4 at ``dt_s`` would overflow), or when the steps
    exceed ``DOP853_STEP_BUDGET`` times the run's fixed-step count.
    """
    # imported here: scipy.integrate costs 0.2 s to import, and every process that
    # imports the simulator (a campaign worker, any CLI command) would pay it
    from scipy.integrate import DOP853
    from scipy.optimize import brentq

    n = plant.n_dof
    seg_start, seg_end, _, _ = profile
    every = scenario.record_every
    t_rec = np.arange(scenario.n_steps // every + 1) * scenario.record_dt_s
    breaks = np.unique(
        np.clip(np.concatenate([[0.0, scenario.duration_s], seg_start, seg_end]), 0.0, t_rec[-1])
    )
    x = np.concatenate([q0, qd0, [0.0, 0.0]])
    plants = typed_list(plant.packed)  # passed to the compiled derivative in one pointer
    X = np.empty((t_rec.size, x.size))
    X[0] = x
    frame = identity_frame()
    F = np.empty((t_rec.size, 9))
    F[0] = frame
    Q = np.zeros(n)  # no joint actuators
    evaluations = 0
    kernel_status = STATUS_OK
    h_min = DOP853_MIN_STEP_FRACTION * scenario.dt_s
    budget = DOP853_STEP_BUDGET * max(scenario.n_steps, 1)
    accepted = 0

    def switch(y):  # positive after each rebase
        return SWITCH_PITCH - abs(y[4])

    status, t_fail = STATUS_OK, -1.0
    pieces = list(itertools.pairwise(breaks))
    while pieces and not status:
        a, b = pieces.pop(0)
        rebase(x, n, frame)
        torque = applied_torque(0.5 * (a + b), *profile)

        def rhs(t, y, torque=torque):
            nonlocal evaluations, kernel_status
            evaluations += 1
            dy = np.empty_like(y)
            code = listed_derivative(y, torque, n, Q, dy, plants)
            if code != STATUS_OK:  # a joint's singularity: make the step fail here
                kernel_status = code
                dy[:] = np.nan
            return dy

        with np.errstate(over="ignore", invalid="ignore"):  # its first step's guess
            solver = DOP853(rhs, a, x, b, rtol=scenario.rtol, atol=scenario.atol)
        t_end, first = a, True
        while solver.status == "running":
            t_old, g_old = solver.t, switch(solver.y)
            with np.errstate(over="ignore", invalid="ignore"):  # a diverging step: refused
                solver.step()
            if solver.status == "failed" or not np.all(np.isfinite(solver.y)):
                status = kernel_status or STATUS_NOT_FINITE
                break
            accepted += 1
            dense = solver.dense_output()
            t_end = solver.t
            event = g_old > 0.0 and switch(solver.y) <= 0.0
            if event:  # the pitch switch: end the piece there
                t_end = brentq(lambda s, dense=dense: switch(dense(s)), t_old, solver.t,
                               xtol=1e-12 * max(1.0, abs(solver.t)))  # fmt: skip
            inside = (t_rec > t_old) & (t_rec <= t_end)
            if inside.any():
                X[inside] = dense(t_rec[inside]).T
                F[inside] = frame
            if event:
                x = dense(t_end)
                rebase(x, n, frame, 0.0)
                if t_end < b:
                    pieces.insert(0, (t_end, b))
                break
            x = solver.y.copy()
            # (a piece's first step is the starting guess's: it may be far below the rest)
            if not first and solver.t < b and solver.step_size < h_min:
                status = STATUS_STEP_TOO_SMALL
            elif accepted > budget:
                status = STATUS_STEP_BUDGET
            if status:
                break
            first = False
        if status:
            t_fail = float(t_end)
    if status:
        kept = int(np.searchsorted(t_rec, t_fail, side="right"))
        t_rec = np.append(t_rec[:kept], t_fail) if t_fail > t_rec[kept - 1] else t_rec[:kept]
        X = np.vstack([X[:kept], x]) if t_rec.size > kept else X[:kept]
        F = np.vstack([F[:kept], frame]) if t_rec.size > kept else F[:kept]
    tau = np.array([applied_torque(t, *profile) for t in t_rec]).reshape(-1, 3)
    return t_rec, X, F, tau, status, t_fail, evaluations
