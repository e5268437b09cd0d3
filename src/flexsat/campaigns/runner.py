"""Running a campaign into its store: the cases, their rows and histories, the signals.

Cases are resolved in the parent, streamed as the backend consumes them
(:class:`~flexsat.campaigns.definition.CaseStream`), so every backend and worker
count runs the same inputs and the stored rows are identical bit for bit.
A case that raises or diverges is stored as failed with its message; the campaign
goes on. Ctrl-C or SIGTERM stops the run at once (pending cases cancelled, workers
stopped) and says how many cases are stored and how to resume.

The backends that fly the cases (local pool, ensemble, Dask) are in
:mod:`flexsat.campaigns.backends`, a case's row in :mod:`flexsat.campaigns.cases`, the
summary in :mod:`flexsat.campaigns.summary` and the replay of one case in
:mod:`flexsat.campaigns.replay`; their public names are importable from here too.
A campaign whose kind searches (:mod:`flexsat.campaigns.kinds`) is handed to the kind.
"""

from __future__ import annotations

import contextlib
import signal
import time
from collections.abc import Iterator
from pathlib import Path

from rich.progress import BarColumn, MofNCompleteColumn, Progress, TextColumn, TimeRemainingColumn

from flexsat.campaigns.backends import RUNNERS, backend, run_batch
from flexsat.campaigns.cases import HISTORY_DT_S, HISTORY_KEY, case_history, run_case
from flexsat.campaigns.definition import (
    CampaignDefinition,
    CaseDigest,
    CaseStream,
    ResolvedCase,
    campaign_fingerprint,
)
from flexsat.campaigns.kinds import KINDS
from flexsat.campaigns.replay import replay_case
from flexsat.campaigns.store import HISTORY_UNITS, CampaignStore
from flexsat.campaigns.summary import SUMMARY_ROWS, WORST_BY, WORST_CASES, summarize
from flexsat.config.models import SatelliteConfig
from flexsat.errors import ConfigError, FlexsatError

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


_DRAW_S = 0.1  # s between redraws of the progress bar (rich's own rate, 10 per s)


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
        :meth:`CampaignStore.record_run`), the store paths; for a kind that searches
        (``[worst_case]``), what its search returns
        (:func:`~flexsat.campaigns.worstcase.run_worst_case`: the worst case found).

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
    for name, table in definition.tables().items():
        kind = KINDS.get(name)
        if kind.search is not None:  # a search, not a fixed set of cases: it runs alone
            return kind.search(definition, table, satellite, out, workers=workers,
                               resume=resume, scheduler=scheduler, dask_local=dask_local,
                               runner=runner, backend=backend)  # fmt: skip
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
            with (
                backend(workers, scheduler, dask_local, runner) as execute,
                store.opened(
                    campaign_fingerprint(definition, satellite, cases), definition.name, resume
                ),
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


def _interrupted(
    definition: CampaignDefinition,
    store: CampaignStore,
    cases: CaseStream | None,
    stop: _Interrupted,
) -> CampaignInterrupted:
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
