"""Campaign backends: the local process pool, the in-process ensemble, a Dask cluster.

:func:`backend` connects to (or starts) the one a run asks for and yields the function
that flies a stream of resolved cases and yields their rows as they finish. Every
backend flies the same resolved cases and writes the same rows
(:mod:`flexsat.campaigns.cases`); the runner (:mod:`flexsat.campaigns.runner`) and a
searching kind (:mod:`flexsat.campaigns.worstcase`) share it.
"""

from __future__ import annotations

import contextlib
import itertools
import os
from collections.abc import Callable, Iterable, Iterator

from flexsat.campaigns.cases import case_row, run_case
from flexsat.campaigns.definition import ResolvedCase
from flexsat.errors import ConfigError
from flexsat.pool import LocalPool

__all__ = ["DASK_BATCH", "QUIET_DASK", "RUNNERS", "backend", "run_batch"]


RUNNERS = ("pool", "ensemble")
"""Local runners of :func:`~flexsat.campaigns.runner.run_campaign`."""


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
def backend(
    workers: int | None, scheduler: str | None, dask_local: int | None, runner: str = "pool"
) -> Iterator[Callable[[Iterable[ResolvedCase], int], Iterator[dict]]]:
    """Connect to (or start) the backend, then yield ``execute(cases, size) -> rows``.

    Parameters
    ----------
    workers : int, optional
        Local worker processes (or the ensemble's threads); default all cores.
    scheduler : str, optional
        Address of a running Dask scheduler.
    dask_local : int, optional
        Start a Dask LocalCluster of this many single-threaded workers.
    runner : {"pool", "ensemble"}
        The local runner (:data:`RUNNERS`), when neither Dask option is given.

    Yields
    ------
    callable
        ``execute(cases, size)``: the rows of the cases, in the order they finish
        (``size``: at most how many cases will come, to size the pool).
    """
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
            raise ConfigError(f"cannot connect to the Dask scheduler {scheduler}: {exc}") from None
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
