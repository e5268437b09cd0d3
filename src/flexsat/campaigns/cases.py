"""One campaign case's row: what it was run from, its metrics and history, or its failure.

What every runner writes a case's row with (:func:`run_case`, one case in this process,
and :func:`~flexsat.campaigns.ensemble.run_ensemble`), so that their rows are the same
bit for bit; below both backends (:mod:`flexsat.campaigns.backends`) and the runner, so
that none imports another for it.
"""

from __future__ import annotations

import time
import traceback

from flexsat.campaigns.definition import ResolvedCase

__all__ = [
    "HISTORY_DT_S",
    "HISTORY_KEY",
    "case_history",
    "case_inputs",
    "case_row",
    "fail_row",
    "finish_row",
    "run_case",
]


HISTORY_KEY = "history"
"""Key of the decimated time history in a :func:`run_case` row
(not stored in the table)."""

HISTORY_DT_S = 0.1
"""Sampling interval of the stored case histories [s]."""


def case_history(ds, dt: float = HISTORY_DT_S) -> dict:
    """Time history of a slew decimated to every ``dt`` seconds, as float arrays.

    Keys are those of :data:`HISTORY_UNITS` and the law's declared diagnostics
    (``attrs["law_diagnostics"]``: ``lambda_act`` and ``jk`` for the ASMC, the
    twisting integral for the STSMC...), whose units and descriptions go under
    ``channels``; per-axis variables are (samples, 3) arrays,
    ``tip_displacement_max`` the largest tip-displacement magnitude over the
    appendages [m]. Variables a dataset lacks are left out. A partial (failed) run
    gives the history up to where it stopped.

    Parameters
    ----------
    ds : xarray.Dataset or RunRecords
        The slew's dataset (:class:`~flexsat.simulate.result.Result`'s), or its
        records (:class:`~flexsat.analysis.run_records.RunRecords`, read alike).
    dt : float
        Sampling interval [s].

    Returns
    -------
    dict
        Arrays by variable name (own copies, C-contiguous float64: cheap to send
        between processes), plus ``channels``.
    """
    import numpy as np

    # ds.variables: the arrays (a dataset's: without building a DataArray per lookup)
    t = np.asarray(ds.variables["time"].values, dtype=float)
    if t.size == 0:
        return {"time": t}
    grid = np.arange(t[0], t[-1] + 0.5 * dt, dt)
    index = np.clip(np.searchsorted(t, grid - 1e-9 * dt), 0, t.size - 1)
    # the grid increases, so the indices never decrease: their distinct values are
    # those that differ from the one before (np.unique's, without its sort)
    index = index[np.flatnonzero(np.diff(index, prepend=-1))]
    history = {"time": t[index]}
    for name in ("pointing_error_deg", "rate_error_deg_s", "tau_cmd", "total_energy"):
        if name in ds:
            history[name] = np.asarray(ds.variables[name].values, dtype=float)[index]
    channels = {}
    for name in ds.attrs.get("law_diagnostics", ()):
        if name in ds:
            history[name] = np.asarray(ds.variables[name].values, dtype=float)[index]
            attrs = ds.variables[name].attrs
            channels[name] = {key: attrs.get(key, "") for key in ("units", "description")}
    if channels:
        history["channels"] = channels
    if "tip_displacement" in ds:
        tips = np.asarray(ds.variables["tip_displacement"].values, dtype=float)[index]
        magnitude = np.linalg.norm(tips, axis=-1)  # (time, appendage)
        if magnitude.ndim == 2 and magnitude.shape[1]:
            history["tip_displacement_max"] = magnitude.max(axis=1)
    return history


def case_row(case: ResolvedCase) -> dict:
    """The head of a case's row: its id, inputs and seeds (what it was run from).

    Parameters
    ----------
    case : ResolvedCase
        The case as the campaign resolved it (configs as plain dicts, seeds).

    Returns
    -------
    dict
        ``case_id``, ``inputs_digest``, ``root_seed``, ``stream_index``,
        ``parameters`` and ``inputs`` (the plant and scenario, for replay).
    """
    return {
        "case_id": case.case_id,
        "inputs_digest": case.digest,
        "root_seed": case.root_seed,
        "stream_index": case.stream_index,
        "parameters": case.parameters,
        "inputs": {"plant": case.plant, "scenario": case.scenario},  # for replay
    }


def case_inputs(case: ResolvedCase):
    """The validated ``(Plant, SlewScenario)`` of a resolved case.

    Parameters
    ----------
    case : ResolvedCase
        The case as the campaign resolved it.

    Returns
    -------
    tuple of (Plant, SlewScenario)
        The truth plant and the slew scenario the case flies.
    """
    from flexsat.config.models import SatelliteConfig
    from flexsat.dynamics.plant import Plant
    from flexsat.simulate import SlewScenario

    plant = Plant.from_config(SatelliteConfig.model_validate(case.plant))
    return plant, SlewScenario.model_validate(case.scenario)


def finish_row(row: dict, records) -> None:
    """Fill a row from its slew's records: history, status and metrics (the stored
    scenario's requirements, control effort).

    Parameters
    ----------
    row : dict
        The case's row (from :func:`case_row`), filled in place.
    records : RunRecords or xarray.Dataset
        The finished slew's records
        (:func:`~flexsat.simulate.closedloop.finish_slew` with ``as_records=True``: no
        dataset built), or its result's dataset: the same row.
    """
    from flexsat.analysis.effort import effort_metrics
    from flexsat.analysis.requirements import slew_metrics

    row[HISTORY_KEY] = case_history(records)
    metrics = slew_metrics(records)
    metrics.update(effort_metrics(records))
    metrics.pop("wall_time_s")
    status, message = metrics.pop("status"), metrics.pop("message")
    row.update(status=status, error=message, metrics=metrics)


def fail_row(row: dict, exc: Exception) -> None:
    """Mark a row failed by ``exc``: its type, message and the function that raised.

    Parameters
    ----------
    row : dict
        The case's row (from :func:`case_row`), marked in place.
    exc : Exception
        What stopped the case.
    """
    last = traceback.extract_tb(exc.__traceback__)[-1]
    row.update(status="failed", error=f"{type(exc).__name__}: {exc} ({last.name})", metrics={})


def run_case(case: ResolvedCase) -> dict:
    """Run one resolved case; never raises: failures come back as a failed row.

    The row also holds, under :data:`HISTORY_KEY`, the decimated time history of
    the case (:func:`case_history`); :func:`~flexsat.campaigns.runner.run_campaign`
    stores it apart from the table. A case that fails before simulating has no history.

    Parameters
    ----------
    case : ResolvedCase
        The case to fly.

    Returns
    -------
    dict
        The case's row: ``case_id``, ``status``, ``message``, ``parameters``,
        ``inputs``, ``metrics`` (:func:`flexsat.analysis.slew_metrics`, SI or the
        key's unit), ``case_wall_time_s`` and ``case_cpu_time_s`` (the case's own
        wall and CPU time [s]).
    """
    from flexsat.simulate.batch import fly_whole
    from flexsat.simulate.closedloop import finish_slew, prepare_slew

    row = case_row(case)
    start, cpu = time.perf_counter(), time.process_time()
    if case.error:  # refused while streaming: a failed row, nothing to run
        row.update(status="failed", error=case.error, metrics={}, case_wall_time_s=0.0,
                   case_cpu_time_s=0.0)  # fmt: skip
        return row
    try:  # run_slew's steps, its result kept as records (no xarray dataset)
        run = prepare_slew(*case_inputs(case))
        flight = time.perf_counter()
        status, done, rows = fly_whole(run)
        wall = time.perf_counter() - flight
        finish_row(row, finish_slew(run, status, done, rows, wall, as_records=True))
    except Exception as exc:  # a failed case is data, not a crash of the campaign
        fail_row(row, exc)
    row["case_wall_time_s"] = time.perf_counter() - start
    # the process's CPU: a worker (or this process) runs one case at a time
    row["case_cpu_time_s"] = time.process_time() - cpu
    return row
