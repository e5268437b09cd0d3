"""Running campaign cases: a local process pool (default) or a Dask cluster.

Cases are resolved in the parent, streamed as the backend consumes them
(:class:`~flexsat.campaigns.definition.CaseStream`), so every backend and worker
count runs the same inputs and the stored rows are identical bit for bit.
A case that raises or diverges is stored as failed with its message; the campaign
goes on. Ctrl-C or SIGTERM stops the run at once (pending cases cancelled, workers
stopped) and says how many cases are stored and how to resume.
"""

from __future__ import annotations

import contextlib
import itertools
import math
import os
import re
import signal
import time
from collections.abc import Iterable, Iterator
from pathlib import Path

from rich.progress import BarColumn, MofNCompleteColumn, Progress, TextColumn, TimeRemainingColumn

from flexsat.campaigns.cases import (
    HISTORY_DT_S,
    HISTORY_KEY,
    case_history,
    case_inputs,
    case_row,
    fail_row,
    finish_row,
)
from flexsat.campaigns.definition import (
    CampaignDefinition,
    CaseDigest,
    CaseStream,
    ResolvedCase,
    campaign_fingerprint,
)
from flexsat.campaigns.store import HISTORY_UNITS, CampaignStore
from flexsat.config.models import SatelliteConfig
from flexsat.errors import ConfigError, FlexsatError, shorten
from flexsat.pool import LocalPool

__all__ = [
    "HISTORY_DT_S",
    "HISTORY_KEY",
    "HISTORY_UNITS",
    "RUNNERS",
    "SUMMARY_ROWS",
    "WORST_BY",
    "WORST_CASES",
    "CampaignInterrupted",
    "case_history",
    "replay_case",
    "run_batch",
    "run_campaign",
    "run_case",
    "summarize",
]


RUNNERS = ("pool", "ensemble")
"""Local runners of :func:`run_campaign`."""

_DRAW_S = 0.1  # s between redraws of the progress bar (rich's own rate, 10 per s)
_CASE_ID = re.compile(r"^[A-Za-z0-9_+\-][A-Za-z0-9_.+\-]*$")


def replay_case(store: str | Path, case_id: str):
    """Re-run one stored case alone from its stored inputs.

    Parameters
    ----------
    store : str or Path
        The campaign's store folder.
    case_id : str
        The id of the case (a row of ``results.parquet``).

    Returns
    -------
    Result
        The case's slew, as :func:`flexsat.simulate.run_slew` returns it.

    Raises
    ------
    ConfigError
        ``store`` holds no campaign, ``case_id`` is not a case id (no path
        separators) or not in the store, or its stored inputs are refused.
    """
    from flexsat.config.load import validate_config
    from flexsat.dynamics.plant import Plant
    from flexsat.simulate import SlewScenario, run_slew

    store = CampaignStore(store)
    if not (store.root / "campaign.json").is_file():
        raise ConfigError(f"{store.root} is not a campaign store (no campaign.json)")
    if not _CASE_ID.match(case_id):
        raise ConfigError(
            f"{shorten(repr(case_id))} is not a case id (letters, digits and _ . + -)"
        )
    path = store.cases_dir / f"{case_id}.json"
    if not path.exists():
        raise ConfigError(f"no case {case_id!r} in {store.root}")
    row = store.row(case_id)
    inputs = row.get("inputs") or {}
    source = f"case {case_id!r}"
    plant = Plant.from_config(validate_config(inputs.get("plant"), source=f"{source} (plant)"))
    scenario = validate_config(
        inputs.get("scenario"), source=f"{source} (scenario)", model=SlewScenario
    )
    return run_slew(plant, scenario)


WORST_CASES = 5
"""Worst cases listed per requirement and for the pointing error."""

WORST_BY = (
    ("R1", "r1_pass", "ape_deg", "deg"),
    ("R2", "r2_pass", "max_rate_error_deg_s", "deg/s"),
    ("R3", "r3_pass", "max_commanded_torque_nm", "N m"),
    ("pointing", None, "final_pointing_error_deg", "deg"),
)
"""What the worst cases are ranked by: (name, verdict key or None, metric, unit). R1 by
the absolute pointing error over the window, R2 by the largest residual rate over it,
R3 by the peak commanded torque (the largest axis), the pointing error at the end."""


SUMMARY_ROWS = (
    ("cases", "cases stored"),
    ("computed_this_run", "computed by this run"),
    ("resumed_this_run", "resumed from the store by this run"),
    ("failed", "failed cases (stopped or refused)"),
    ("r1_pass_rate", "R1 pass rate (absolute pointing)"),
    ("r2_pass_rate", "R2 pass rate (residual rate)"),
    ("r3_pass_rate", "R3 pass rate (torque limit)"),
    ("worst_final_pointing_error_deg", "worst final pointing error [deg]"),
    ("cpu_time_s", "CPU time of the stored cases [s]"),
    ("case_wall_time_s", "wall time of the stored cases, summed [s]"),
    ("campaign_wall_time_s", "wall time of every run into the store [s]"),
    ("runs", "runs recorded in the store"),
    ("run_wall_time_s", "wall time of this run [s]"),
)
"""The rows of a campaign's summary table (CLI and report): key in the summary, and
the label that says what it counts."""


def summarize(store: str | Path) -> dict:
    """Pass rates, the worst cases and the cost of a stored campaign.

    Parameters
    ----------
    store : str or Path
        The campaign's store folder.

    Returns
    -------
    dict
        ``cases`` (stored), ``failed``, the pass rate of each requirement
        (``r1_pass_rate``..., fractions in [0, 1]), ``worst_by_requirement`` (for R1,
        R2, R3 and the final pointing error, :data:`WORST_BY`: the metric, its unit,
        the failing count and the :data:`WORST_CASES` worst cases, failing ones first,
        then by the metric, largest first: ``case_id``, ``value``, ``passes``) and
        ``worst_cases``, those by final pointing error alone [deg]. ``cpu_time_s``: the
        stored cases' own CPU time, summed [s] (a case stored without it counts its
        wall time); ``case_wall_time_s``: their own wall times, summed [s] (what a
        run stopped before recording itself spent is in both);
        ``campaign_wall_time_s``: the wall times of the runs recorded in the store,
        summed [s] (``runs`` of them). Also ``requirements`` (per
        requirement: passes, the exact 95 % interval of the pass rate and the failing
        case ids), ``metrics`` (per metric: min, 5/50/95 %, max) and
        ``cases_for_3sigma_at_95`` (the cases needed, with no failure, to claim
        99.73 % at 95 % confidence); see :mod:`flexsat.campaigns.statistics`.
    """
    from flexsat.campaigns.statistics import (
        cases_needed,
        metric_statistics,
        requirement_statistics,
    )

    opened = CampaignStore(store)
    table = opened.table()
    rows = opened.rows()
    n = len(rows)

    def rate(key: str) -> float:
        return sum(bool(r["metrics"].get(key)) for r in rows) / n if n else float("nan")

    def seconds(row: dict, key: str) -> float:
        value = row.get(key, row.get("case_wall_time_s"))
        return value if isinstance(value, int | float) and math.isfinite(value) else 0.0

    worst_by = [_worst(rows, *spec) for spec in WORST_BY]
    pointing = [c for c in worst_by[-1]["cases"] if c["value"] is not None]
    worst_cases = [
        {"case_id": c["case_id"], "final_pointing_error_deg": c["value"]} for c in pointing
    ]
    runs = opened.runs()
    return {
        "cases": n,
        "failed": sum(r["status"] != "ok" for r in rows),
        "r1_pass_rate": rate("r1_pass"),
        "r2_pass_rate": rate("r2_pass"),
        "r3_pass_rate": rate("r3_pass"),
        "worst_final_pointing_error_deg": pointing[0]["value"] if pointing else float("nan"),
        "worst_cases": worst_cases,
        "worst_by_requirement": worst_by,
        "cpu_time_s": sum(seconds(r, "case_cpu_time_s") for r in rows),
        "case_wall_time_s": sum(seconds(r, "case_wall_time_s") for r in rows),
        "campaign_wall_time_s": sum(float(r.get("wall_time_s", 0.0)) for r in runs),
        "runs": len(runs),
        "requirements": requirement_statistics(table).to_dict("records") if n else [],
        "metrics": metric_statistics(table).to_dict("records") if n else [],
        "cases_for_3sigma_at_95": cases_needed(0.9973, 0.95),
    }


def _worst(rows: list[dict], name: str, verdict: str | None, metric: str, unit: str) -> dict:
    """The worst cases by one requirement (see :data:`WORST_BY`)."""
    ranked = []
    for row in rows:
        ok = row["status"] == "ok"
        value = row["metrics"].get(metric) if ok else None
        if isinstance(value, list):  # per axis: the largest
            value = max(value) if value else None
        if not isinstance(value, int | float) or not math.isfinite(value):
            value = None
        passes = None if verdict is None else bool(ok and row["metrics"].get(verdict))
        if verdict is None and value is None:
            continue  # no value to rank by
        # failing first, then the largest value; a case without a value after those with one
        ranked.append(((passes is True, value is None, -(value or 0.0), row["case_id"]),
                       {"case_id": row["case_id"], "value": value, "passes": passes}))  # fmt: skip
    ranked.sort(key=lambda item: item[0])
    return {
        "requirement": name, "verdict": verdict, "metric": metric, "unit": unit,
        "failing": sum(entry["passes"] is False for _, entry in ranked),
        "cases": [entry for _, entry in ranked[:WORST_CASES]],
    }  # fmt: skip


def run_case(case: ResolvedCase) -> dict:
    """Run one resolved case; never raises: failures come back as a failed row.

    The row also holds, under :data:`HISTORY_KEY`, the decimated time history of
    the case (:func:`case_history`); :func:`run_campaign` stores it apart from the
    table. A case that fails before simulating has no history.

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
    from flexsat.simulate import run_slew

    row = case_row(case)
    start, cpu = time.perf_counter(), time.process_time()
    if case.error:  # refused while streaming: a failed row, nothing to run
        row.update(status="failed", error=case.error, metrics={}, case_wall_time_s=0.0,
                   case_cpu_time_s=0.0)  # fmt: skip
        return row
    try:
        plant, scenario = case_inputs(case)
        finish_row(row, run_slew(plant, scenario, progress=False))
    except Exception as exc:  # a failed case is data, not a crash of the campaign
        fail_row(row, exc)
    row["case_wall_time_s"] = time.perf_counter() - start
    # the process's CPU: a worker (or this process) runs one case at a time
    row["case_cpu_time_s"] = time.process_time() - cpu
    return row


class CampaignInterrupted(FlexsatError):
    """A campaign stopped by Ctrl-C or SIGTERM; the finished cases are stored."""


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
    runner: str = "pool",
) -> dict:
    """Run (or finish) a campaign into the store at ``out``.

    Parameters
    ----------
    definition : CampaignDefinition
        The campaign (:func:`load_campaign`).
    satellite : SatelliteConfig
        The base satellite.
    out : str or Path
        The store folder.
    workers : int, optional
        Local worker processes; default all cores. 1 runs in this process.
    resume : bool
        Skip the cases already in the store (refused if the store was made with
        other inputs: definition, satellite config, number of cases).
    n_random : int, optional
        Number of random cases of a ``[random]`` campaign (``--cases``).
    scheduler : str, optional
        Address of a running Dask scheduler (``tcp://host:port``). Connecting to
        it means trusting it: it runs the code it is sent.
    dask_local : int, optional
        Start a Dask LocalCluster with this many single-threaded worker processes.
    progress : bool
        Show a progress bar on the terminal.
    runner : {"pool", "ensemble"}
        Local runs only: ``pool``, one case per worker process at a time;
        ``ensemble``, batches of cases flown in one compiled call in this process
        across ``workers`` threads (:mod:`flexsat.campaigns.ensemble`). Both store
        the same rows; Dask tasks always fly their batch as an ensemble.

    Returns
    -------
    dict
        ``cases``, ``case_counts`` (:meth:`CaseStream.counts`), ``ran`` (computed by
        this call), ``resumed`` (found stored by this call), ``failed``,
        ``wall_time_s`` (this call's; each run's is also recorded in the store,
        :meth:`CampaignStore.record_run`), the store paths; for a
        ``[worst_case]`` search, what :func:`~flexsat.campaigns.worstcase.run_worst_case`
        returns (the worst case found).

    Raises
    ------
    ConfigError
        Before any case runs: bad cases, a store that is not writable, in use or
        made with other inputs, an unreachable scheduler.
    CampaignInterrupted
        On Ctrl-C or SIGTERM, after stopping the workers; it says how many cases
        are stored and how to resume (exit code 130 or 143).
    FlexsatError
        When the store cannot be written (full disk...), after stopping the workers.
    """
    if runner not in RUNNERS:
        raise ConfigError(f"runner: {runner!r} is not one of {', '.join(RUNNERS)}")
    if definition.worst_case is not None:  # a search, not a fixed set of cases
        from flexsat.campaigns.worstcase import run_worst_case

        return run_worst_case(definition, definition.worst_case, satellite, out,
                              workers=workers, resume=resume, scheduler=scheduler,
                              dask_local=dask_local, runner=runner,
                              backend=_backend)  # fmt: skip
    store = CampaignStore(out)
    if store.root.exists() and not store.root.is_dir():
        raise ConfigError(f"--out {store.root}: exists and is not a folder")
    start = time.perf_counter()
    failed = 0
    cases = None
    # From the first step: a signal while the cases are prepared (which compiles the
    # plant's kernels on a first run) stops the campaign too, even where the process
    # started with SIGINT ignored (a background job, a test runner's worker).
    with _Interrupts() as interrupts:
        try:
            cases = CaseStream(definition, satellite, n_random)  # checks what it can up front
            with _backend(workers, scheduler, dask_local, runner) as execute, store.opened(
                campaign_fingerprint(definition, satellite, cases), definition.name, resume
            ):
                todo = _Todo(cases, store)
                columns = (TextColumn(f"campaign {definition.name}"), BarColumn(),
                           MofNCompleteColumn(), TextColumn("failed {task.fields[failed]}"),
                           TimeRemainingColumn())  # fmt: skip
                # Drawn from this thread (no refresh thread), so the local pool can fork
                # its workers (flexsat.pool); at most every 0.1 s, as rich would.
                with Progress(*columns, disable=not progress, transient=True,
                              auto_refresh=False) as bar:  # fmt: skip
                    task = bar.add_task("cases", total=len(cases), completed=0, failed=0)
                    drawn = time.monotonic()
                    try:
                        for row in execute(todo, len(cases)):
                            history = row.pop(HISTORY_KEY, None)
                            with interrupts.deferred():  # a signal never cuts a write in half
                                if history is not None:  # a stored case has its history
                                    store.write_history(row["case_id"], history,
                                                        status=row["status"])  # fmt: skip
                                store.write_case(row)
                            failed += row["status"] != "ok"
                            draw = time.monotonic() - drawn >= _DRAW_S
                            drawn = time.monotonic() if draw else drawn
                            bar.update(task, completed=todo.skipped + todo.ran_done(),
                                       failed=failed, refresh=draw)  # fmt: skip
                    except OSError as exc:
                        raise _write_error(store, cases, exc) from None
                try:
                    store.record_case_inputs(todo.digest.hexdigest())
                    table = store.write_tables()
                    wall = time.perf_counter() - start
                    store.record_run(todo.ran, todo.skipped, wall)
                except OSError as exc:
                    raise _write_error(store, cases, exc) from None
        except _Interrupted as stop:
            raise _interrupted(definition, store, cases, stop) from None
    return {
        "campaign": definition.name,
        "cases": len(cases),
        "case_counts": cases.counts(),
        "ran": todo.ran,
        "resumed": todo.skipped,
        "failed": int(table["status"].ne("ok").sum()) if "status" in table else 0,
        "wall_time_s": wall,
        "parquet": str(store.tables[0]),
        "csv": str(store.tables[1]),
    }


def _interrupted(definition: CampaignDefinition, store: CampaignStore,
                 cases: CaseStream | None, stop: _Interrupted) -> CampaignInterrupted:
    """The error of a campaign stopped by a signal: what is stored and how to resume."""
    if cases is None:
        where = "while preparing its cases, before any ran; run the same command to start it"
    else:
        where = (f"{store.finished()} of {len(cases)} cases are stored in {store.root}; "
                 "run the same command with --resume to finish it")  # fmt: skip
    interrupted = CampaignInterrupted(
        f"campaign {definition.name} interrupted ({stop.name}): {where}"
    )
    interrupted.exit_code = 128 + stop.signum  # the shell's convention
    return interrupted


class _Todo:
    """The cases still to run, streamed: stored ones are skipped after checking that
    they were made from the same inputs; the digest over every case is built on the way.
    """

    def __init__(self, cases: CaseStream, store: CampaignStore) -> None:
        self.cases, self.store = cases, store
        self.stored = store.stored_ids()
        self.digest = CaseDigest()
        self.skipped = self.ran = 0
        self._results = 0

    def ran_done(self) -> int:
        self._results += 1
        return self._results

    def __iter__(self) -> Iterator[ResolvedCase]:
        for case in self.cases:
            self.digest.add(case)
            if case.case_id in self.stored:
                digest = self.store.stored_digest(case.case_id)
                if digest == case.digest:
                    self.skipped += 1
                    continue
                if digest is not None:
                    raise ConfigError(
                        f"{self.store.root}: case {case.case_id!r} is stored with other "
                        f"inputs (stored {digest!r}, given {case.digest!r}); refusing to "
                        "resume into it. Use another --out"
                    )
            self.ran += 1
            yield case


def _write_error(store: CampaignStore, cases: CaseStream, exc: OSError) -> FlexsatError:
    return FlexsatError(
        f"cannot write to the campaign store {store.root}: {exc.strerror or exc}; "
        f"{store.finished()} of {len(cases)} cases are stored; fix it and "
        "run the same command with --resume to finish"
    )


class _Interrupted(BaseException):
    """Ctrl-C or SIGTERM, raised where the main process is (never caught as an Exception)."""

    def __init__(self, signum: int) -> None:
        super().__init__(signum)
        self.signum, self.name = signum, signal.Signals(signum).name


class _Interrupts:
    """While active, SIGINT and SIGTERM raise :class:`_Interrupted` in the main thread.

    Inside :meth:`deferred` (the store's writes, whose libraries hold locks) a signal
    is kept and raised at the end of the block instead. Once one signal is taken,
    later ones are ignored: the stop under way ends cleanly.
    """

    def __init__(self) -> None:
        self.pending: int | None = None
        self.deferring = False
        self.previous: dict = {}

    def _handler(self, signum, frame) -> None:
        if self.deferring or self.pending is not None:  # deferred, or already stopping
            self.pending = signum if self.pending is None else self.pending
            return
        self.pending = signum
        raise _Interrupted(signum)

    def __enter__(self) -> _Interrupts:
        try:
            for signum in (signal.SIGINT, signal.SIGTERM):
                self.previous[signum] = signal.signal(signum, self._handler)
        except ValueError:  # not the main thread: leave the signals alone
            pass
        return self

    def __exit__(self, *exc) -> None:
        for signum, old in self.previous.items():
            signal.signal(signum, old)

    @contextlib.contextmanager
    def deferred(self) -> Iterator[None]:
        self.deferring = True
        try:
            yield
        finally:
            self.deferring = False
            if self.pending is not None:
                raise _Interrupted(self.pending)


def _lost_case(case: ResolvedCase, exitcode: int | None) -> dict:
    """The failed row of a case whose worker process died running it (twice)."""
    return {
        **case_row(case),
        "status": "failed",
        "error": f"its worker process died running it (exit code {exitcode}), twice",
        "metrics": {},
        "case_wall_time_s": float("nan"),
        "case_cpu_time_s": float("nan"),
    }


@contextlib.contextmanager
def _backend(workers, scheduler, dask_local, runner="pool"):
    """Connect to (or start) the backend, then yield ``execute(cases, size) -> rows``
    (``size``: at most how many cases will come, to size the pool)."""
    if scheduler or dask_local:
        with _dask_client(scheduler, dask_local) as client:
            yield lambda todo, size: _dask(client, todo, size)
        return
    workers = workers or os.cpu_count() or 1
    if runner == "ensemble":
        from flexsat.campaigns.ensemble import run_ensemble

        yield lambda todo, size: run_ensemble(todo, threads=workers)
        return

    def execute(todo: Iterable[ResolvedCase], size: int) -> Iterator[dict]:
        source = iter(todo)
        first = list(itertools.islice(source, 2))  # no workers for one case or none
        if workers == 1 or len(first) <= 1:
            for case in itertools.chain(first, source):
                yield run_case(case)
            return
        n = min(workers, size)
        with LocalPool(run_case, n, _lost_case) as pool:
            yield from pool.map_unordered(itertools.chain(first, source))

    yield execute


QUIET_DASK = {
    "distributed.worker.profile.enabled": False,  # the dashboard's sampler, every 10 ms
    "distributed.admin.tick.interval": "1s",  # the event loops' block detector, 20 ms
    "distributed.admin.system-monitor.interval": "5s",  # dashboard metrics, 500 ms
    "distributed.scheduler.work-stealing": False,  # a window of tasks per thread: balanced
}
"""Dask settings of a campaign's cluster and client. Dask's defaults feed its
dashboard, which a campaign does not start: an idle LocalCluster of 2 workers took
3.5 CPU-s per 30 s on its own (12 % of a core), 1.0 CPU-s with these
(CHANGELOG.md, 'Dask: a quiet cluster')."""


@contextlib.contextmanager
def _dask_client(scheduler, dask_local):
    import dask
    from dask.distributed import Client, LocalCluster

    with dask.config.set(QUIET_DASK):  # the workers of a LocalCluster inherit them
        cluster = None
        if scheduler is None:
            cluster = LocalCluster(
                n_workers=dask_local, threads_per_worker=1, processes=True,
                host="127.0.0.1", dashboard_address=None,
                preload=["flexsat.campaigns.dask_worker"],
            )  # fmt: skip
        try:
            client = Client(cluster if cluster is not None else scheduler, timeout="10s")
        except (OSError, TimeoutError, ValueError) as exc:
            if cluster is not None:
                cluster.close()
            raise ConfigError(
                f"cannot connect to the Dask scheduler {scheduler}: {exc}"
            ) from None
        try:
            yield client
        finally:
            client.close()
            if cluster is not None:
                cluster.close()


DASK_BATCH = 32
"""Cases per Dask task, at most: a task's overhead (its scheduling, its transfer, the
worker's event loop) is paid once per batch. Batches shrink as fewer than
``4 * DASK_BATCH`` cases per worker thread remain to submit (:func:`_dask_batch`).
1000 reduced cases on a LocalCluster of two workers took 34.2–37.6 s with 8 per task,
30.8 s with 32 (CHANGELOG.md, 'Workers that start sooner')."""


def _dask_batch(remaining: int, threads: int) -> int:
    """Cases in the next Dask task when at most ``remaining`` cases are left to submit
    to ``threads`` worker threads: at most :data:`DASK_BATCH`, and few enough that each
    thread still gets four tasks. So a worker lost mid-run loses a task that another
    re-runs, not the campaign's share, and the last tasks are short: the workers finish
    together instead of one waiting for the other's last full batch."""
    return max(1, min(DASK_BATCH, remaining // (4 * max(1, threads))))


def run_batch(cases: list[ResolvedCase]) -> list[dict]:
    """Rows of :func:`run_case` for each case, in one task (never raises): the batch
    flown as one ensemble (:func:`flexsat.campaigns.ensemble.run_ensemble`, one thread).

    Parameters
    ----------
    cases : list of ResolvedCase
        The batch.

    Returns
    -------
    list of dict
        One row per case, in order.
    """
    from flexsat.campaigns.ensemble import run_ensemble

    return list(run_ensemble(cases, threads=1, batch=len(cases)))


def _dask(client, todo, size: int) -> Iterator[dict]:
    """Batches of cases submitted as they are streamed, a few per worker in flight
    (``size``: at most how many cases will come)."""
    from dask.distributed import as_completed as dask_completed

    source = iter(todo)
    threads = max(1, sum(client.nthreads().values()))
    window, submitted = 2 * threads, 0

    def submit(completed) -> bool:
        nonlocal submitted
        batch = list(itertools.islice(source, _dask_batch(size - submitted, threads)))
        submitted += len(batch)
        if batch:
            completed.add(client.submit(run_batch, batch, pure=False))
        return bool(batch)

    completed = dask_completed([])
    try:
        for _ in range(window):
            if not submit(completed):
                break
        for future in completed:
            yield from future.result()
            future.release()
            submit(completed)
    finally:
        client.cancel(list(completed.futures))
