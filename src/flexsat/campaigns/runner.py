"""Running campaign cases: a local process pool (default) or a Dask cluster.

Cases are resolved in the parent (:func:`resolve_cases`), so every backend and
worker count runs the same inputs and the stored rows are identical bit for bit.
A case that raises or diverges is stored as failed with its message; the campaign
goes on.
"""

from __future__ import annotations

import json
import os
import time
import traceback
from collections.abc import Iterator
from concurrent.futures import ProcessPoolExecutor, as_completed
from pathlib import Path

from rich.progress import BarColumn, MofNCompleteColumn, Progress, TextColumn, TimeRemainingColumn

from flexsat.campaigns.definition import CampaignDefinition, ResolvedCase, resolve_cases
from flexsat.campaigns.store import HISTORY_UNITS, CampaignStore
from flexsat.config.models import SatelliteConfig

__all__ = [
    "HISTORY_DT_S",
    "HISTORY_KEY",
    "HISTORY_UNITS",
    "case_history",
    "replay_case",
    "run_campaign",
    "run_case",
    "summarize",
]


def replay_case(store: str | Path, case_id: str):
    """Re-run one stored case alone from its stored inputs; returns its ``Result``."""
    from flexsat.config.models import SatelliteConfig
    from flexsat.dynamics.plant import Plant
    from flexsat.errors import ConfigError
    from flexsat.simulate import SlewScenario, run_slew

    path = CampaignStore(store).cases_dir / f"{case_id}.json"
    if not path.exists():
        raise ConfigError(f"no case {case_id!r} in {store}")
    inputs = json.loads(path.read_text())["inputs"]
    plant = Plant.from_config(SatelliteConfig.model_validate(inputs["plant"]))
    return run_slew(plant, SlewScenario.model_validate(inputs["scenario"]))


def summarize(store: str | Path) -> dict:
    """Pass rates and the worst cases of a stored campaign."""
    rows = CampaignStore(store).rows()
    n = len(rows)

    def rate(key: str) -> float:
        return sum(bool(r["metrics"].get(key)) for r in rows) / n if n else float("nan")

    errors = [
        (r["metrics"]["final_pointing_error_deg"], r["case_id"])
        for r in rows
        if r["status"] == "ok" and r["metrics"].get("final_pointing_error_deg") is not None
    ]
    worst = sorted(errors, reverse=True)[:5]
    return {
        "cases": n,
        "failed": sum(r["status"] != "ok" for r in rows),
        "r1_pass_rate": rate("r1_pass"),
        "r2_pass_rate": rate("r2_pass"),
        "r3_pass_rate": rate("r3_pass"),
        "worst_final_pointing_error_deg": worst[0][0] if worst else float("nan"),
        "worst_cases": [{"case_id": c, "final_pointing_error_deg": e} for e, c in worst],
    }


HISTORY_KEY = "history"
"""Key of the decimated time history in a :func:`run_case` row (not stored in the table)."""

HISTORY_DT_S = 0.1
"""Sampling interval of the stored case histories [s]."""


def case_history(ds, dt: float = HISTORY_DT_S) -> dict:
    """Time history of a slew decimated to every ``dt`` seconds, as plain lists.

    Keys are those of :data:`HISTORY_UNITS`: ``tau_cmd`` and ``jk`` are lists of
    [x, y, z] per sample, ``tip_displacement_max`` the largest tip-displacement
    magnitude over the appendages [m]. Variables a dataset lacks are left out.
    A partial (failed) run gives the history up to where it stopped.
    """
    import numpy as np

    t = np.asarray(ds["time"].values, dtype=float)
    if t.size == 0:
        return {"time": []}
    grid = np.arange(t[0], t[-1] + 0.5 * dt, dt)
    index = np.unique(np.clip(np.searchsorted(t, grid - 1e-9 * dt), 0, t.size - 1))
    history = {"time": t[index].tolist()}
    for name in ("pointing_error_deg", "rate_error_deg_s", "tau_cmd", "total_energy",
                 "lambda_act", "jk"):  # fmt: skip
        if name in ds:
            history[name] = np.asarray(ds[name].values, dtype=float)[index].tolist()
    if "tip_displacement" in ds:
        tips = np.asarray(ds["tip_displacement"].values, dtype=float)[index]
        magnitude = np.linalg.norm(tips, axis=-1)  # (time, appendage)
        if magnitude.ndim == 2 and magnitude.shape[1]:
            history["tip_displacement_max"] = magnitude.max(axis=1).tolist()
    return history


def run_case(case: ResolvedCase) -> dict:
    """Run one resolved case; never raises: failures come back as a failed row.

    The row also holds, under :data:`HISTORY_KEY`, the decimated time history of
    the case (:func:`case_history`); :func:`run_campaign` stores it apart from the
    table. A case that fails before simulating has no history.
    """
    from flexsat.analysis.requirements import slew_metrics
    from flexsat.config.models import SatelliteConfig
    from flexsat.dynamics.plant import Plant
    from flexsat.simulate import SlewScenario, run_slew

    row = {
        "case_id": case.case_id,
        "root_seed": case.root_seed,
        "stream_index": case.stream_index,
        "parameters": case.parameters,
        "inputs": {"plant": case.plant, "scenario": case.scenario},  # for replay
    }
    start = time.perf_counter()
    try:
        plant = Plant.from_config(SatelliteConfig.model_validate(case.plant))
        scenario = SlewScenario.model_validate(case.scenario)
        result = run_slew(plant, scenario, progress=False)
        row[HISTORY_KEY] = case_history(result.dataset)
        metrics = slew_metrics(result.dataset)  # the stored scenario's requirements
        metrics.pop("wall_time_s")
        status, message = metrics.pop("status"), metrics.pop("message")
        row.update(status=status, error=message, metrics=metrics)
    except Exception as exc:  # a failed case is data, not a crash of the campaign
        last = traceback.extract_tb(exc.__traceback__)[-1]
        row.update(status="failed", error=f"{type(exc).__name__}: {exc} ({last.name})", metrics={})
    row["case_wall_time_s"] = time.perf_counter() - start
    return row


def run_campaign(
    definition: CampaignDefinition,
    satellite: SatelliteConfig,
    out: str | Path,
    workers: int | None = None,
    resume: bool = False,
    n_random: int | None = None,
    scheduler: str | None = None,
    dask_local: int | None = None,
    progress: bool = True,
) -> dict:
    """Run (or finish) a campaign into the store at ``out``.

    Parameters
    ----------
    workers : int, optional
        Local worker processes; default all cores. 1 runs in this process.
    resume : bool
        Skip the cases already in the store (refused if the store was made by a
        different definition).
    scheduler : str, optional
        Address of a running Dask scheduler (``tcp://host:port``).
    dask_local : int, optional
        Start a Dask LocalCluster with this many single-threaded worker processes.

    Returns
    -------
    dict
        ``cases``, ``ran`` (this call), ``failed``, ``wall_time_s``, the store paths.
    """
    cases = resolve_cases(definition, satellite, n_random)
    store = CampaignStore(out)
    store.open(definition.fingerprint(), definition.name, resume)
    done = store.finished()
    todo = [case for case in cases if case.case_id not in done]
    start = time.perf_counter()
    failed = 0
    columns = (TextColumn(f"campaign {definition.name}"), BarColumn(), MofNCompleteColumn(),
               TextColumn("failed {task.fields[failed]}"), TimeRemainingColumn())  # fmt: skip
    with Progress(*columns, disable=not progress, transient=True) as bar:
        task = bar.add_task("cases", total=len(cases), completed=len(cases) - len(todo), failed=0)
        for row in _execute(todo, workers, scheduler, dask_local):
            history = row.pop(HISTORY_KEY, None)
            if history is not None:  # before the case: a stored case has its history
                store.write_history(row["case_id"], history, status=row["status"])
            store.write_case(row)
            failed += row["status"] != "ok"
            bar.update(task, advance=1, failed=failed)
    parquet, csv = store.write_tables()
    return {
        "campaign": definition.name,
        "cases": len(cases),
        "ran": len(todo),
        "failed": sum(row["status"] != "ok" for row in store.rows()),
        "wall_time_s": time.perf_counter() - start,
        "parquet": str(parquet),
        "csv": str(csv),
    }


def _execute(todo, workers, scheduler, dask_local) -> Iterator[dict]:
    if scheduler or dask_local:
        yield from _dask(todo, scheduler, dask_local)
        return
    workers = workers or os.cpu_count() or 1
    if workers == 1:
        for case in todo:
            yield run_case(case)
        return
    with ProcessPoolExecutor(max_workers=workers) as pool:
        futures = [pool.submit(run_case, case) for case in todo]
        for future in as_completed(futures):
            yield future.result()


def _dask(todo, scheduler, dask_local) -> Iterator[dict]:
    from dask.distributed import Client, LocalCluster
    from dask.distributed import as_completed as dask_completed

    cluster = None
    if scheduler is None:
        cluster = LocalCluster(
            n_workers=dask_local, threads_per_worker=1, processes=True,
            host="127.0.0.1", dashboard_address=None,
        )  # fmt: skip
    client = Client(cluster if cluster is not None else scheduler)
    try:
        futures = client.map(run_case, todo, pure=False)
        for future in dask_completed(futures):
            yield future.result()
    finally:
        client.close()
        if cluster is not None:
            cluster.close()
