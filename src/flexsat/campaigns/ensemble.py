"""The ensemble runner: many campaign cases flown in one compiled call.

Cases are taken from the stream a batch at a time. Each case is prepared in Python
(config → :class:`~flexsat.dynamics.plant.Plant` → packed arrays and record
buffers, :func:`~flexsat.simulate.closedloop.prepare_slew`); the loops of a batch
are flown together, those of one structure in one call of
:func:`~flexsat.simulate.batch.fly_batch` with ``numba.prange`` across the cases
(threads = workers), each case writing only its own arrays; then each case is
post-processed (metrics, history) as :func:`~flexsat.campaigns.runner.run_case`
does. The compiled call releases the GIL and runs in a background thread while this
thread post-processes the previous batch and prepares the next: the Python work
overlaps the compiled work. The rows are those of
:func:`~flexsat.campaigns.runner.run_case`, bit for bit (docs/campaigns.md,
"The ensemble runner").
"""

from __future__ import annotations

import itertools
import threading
import time
from collections.abc import Iterable, Iterator
from concurrent.futures import ThreadPoolExecutor

from flexsat.campaigns.cases import case_inputs, case_row, fail_row, finish_row
from flexsat.campaigns.definition import ResolvedCase

__all__ = ["BATCH_PER_THREAD", "run_ensemble"]

BATCH_PER_THREAD = 4
"""Cases per compiled call and per thread: enough to balance the threads, few
enough that an interrupted run loses little (the batch in flight)."""


def run_ensemble(cases: Iterable[ResolvedCase], threads: int = 1,
                 batch: int | None = None) -> Iterator[dict]:  # fmt: skip
    """Rows of :func:`~flexsat.campaigns.runner.run_case` for each case, batch by batch.

    Parameters
    ----------
    cases : iterable of ResolvedCase
        The cases, consumed a batch at a time (a stream is never held whole).
    threads : int
        numba threads flying a batch's cases (the workers of this process).
    batch : int, optional
        Cases per compiled call; default :data:`BATCH_PER_THREAD` per thread.

    Yields
    ------
    dict
        Each case's row, in the order of ``cases``, as soon as its batch is
        post-processed. Never raises for a case: failures are failed rows.
    """
    size = batch or BATCH_PER_THREAD * max(1, threads)
    source = iter(cases)
    clock = time.pthread_getcpuclockid(threading.get_ident())  # this thread's CPU clock
    with ThreadPoolExecutor(max_workers=1, thread_name_prefix="flexsat-ensemble") as flyer:
        pending = None  # (batch, future) flying in the background
        while True:
            chunk = _prepare(list(itertools.islice(source, size)))
            flying = None
            if chunk:
                flying = (chunk, flyer.submit(_fly, chunk, threads, clock))
            if pending is not None:
                yield from _finish(*pending)
            if flying is None:
                return
            pending = flying


class _Case:
    """One case of a batch: its row, its prepared slew (None if it failed before) and
    its wall and CPU time so far [s] (preparation, its share of the batch's loop,
    finishing)."""

    __slots__ = ("cpu", "row", "run", "wall")

    def __init__(self, row: dict, run, wall: float, cpu: float) -> None:
        self.row, self.run, self.wall, self.cpu = row, run, wall, cpu


def _prepare(cases: list[ResolvedCase]) -> list[_Case]:
    from flexsat.simulate.closedloop import prepare_slew

    prepared = []
    for case in cases:
        start, cpu = time.perf_counter(), time.thread_time()
        row, run = case_row(case), None
        if case.error:  # refused while streaming: a failed row, nothing to run
            row.update(status="failed", error=case.error, metrics={}, case_wall_time_s=0.0,
                       case_cpu_time_s=0.0)  # fmt: skip
        else:
            try:
                run = prepare_slew(*case_inputs(case))
            except Exception as exc:  # a failed case is data, not a crash of the campaign
                fail_row(row, exc)
        prepared.append(_Case(row, run, time.perf_counter() - start, time.thread_time() - cpu))
    return prepared


def _fly(chunk: list[_Case], threads: int, clock: int):
    """The batch's loops in one compiled call (background thread): (flown, wall [s],
    CPU [s]) of the call, from its start (not from its wait behind the previous
    batch). The CPU is the process's while the call runs, less that of the thread
    whose CPU clock is ``clock`` (the caller's, which meanwhile stores and prepares
    the other batches)."""
    from flexsat.simulate.batch import fly_prepared

    start, cpu, other = time.perf_counter(), time.process_time(), time.clock_gettime(clock)
    flown = fly_prepared([c.run for c in chunk if c.run is not None], threads)
    cpu = time.process_time() - cpu - (time.clock_gettime(clock) - other)
    return flown, time.perf_counter() - start, max(0.0, cpu)


def _finish(chunk: list[_Case], future) -> Iterator[dict]:
    from flexsat.simulate.closedloop import finish_slew

    failure = None
    try:
        flown, wall, flight_cpu = future.result()
    except Exception as exc:  # the compiled call itself failed: every case of it fails
        flown, wall, flight_cpu, failure = None, 0.0, 0.0, exc
    if failure is not None:
        for c in chunk:
            if c.run is not None:
                fail_row(c.row, failure)
                c.run = None
    ran = [c for c in chunk if c.run is not None]
    share = wall / max(1, len(ran))  # each case's share of the batch's loop time
    share_cpu = flight_cpu / max(1, len(ran))
    for k, c in enumerate(ran):
        start, cpu = time.perf_counter(), time.thread_time()
        status, done, rows = (int(v) for v in flown[k])
        try:
            finish_row(c.row, finish_slew(c.run, status, done, rows, share, as_records=True))
        except Exception as exc:  # a failed case is data, not a crash of the campaign
            fail_row(c.row, exc)
        c.wall += share + time.perf_counter() - start
        c.cpu += share_cpu + time.thread_time() - cpu
        c.run = None  # the records are no longer needed
    for c in chunk:
        c.row.setdefault("case_wall_time_s", c.wall)
        c.row.setdefault("case_cpu_time_s", c.cpu)
        yield c.row
