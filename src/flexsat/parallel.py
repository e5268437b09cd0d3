"""Forked processes side by side: what figure sets and the study's independent runs use.

- :func:`figure_workers`: how many processes (``FLEXSAT_FIGURE_WORKERS``, else up to 2).
- :func:`forked_map`: ``[job(item) for item in items]`` by forked processes.
- :func:`frozen_heap`, :func:`signals_deferred`, :func:`start_child` and
  :func:`die_with_parent`, from :mod:`flexsat.processes`: what starting a process
  and a child's first call need.

Forked processes start in milliseconds with the parent's memory, including every
numba kernel the parent already compiled or loaded from its disk cache, so a
child neither re-imports nor re-compiles anything. Kept free of matplotlib and
numba, so the command line can import it at start-up.
"""

from __future__ import annotations

import functools
import multiprocessing
import os
from collections.abc import Callable, Iterable

from flexsat.processes import die_with_parent, frozen_heap, signals_deferred, start_child

__all__ = [
    "die_with_parent",
    "figure_workers",
    "forked_map",
    "frozen_heap",
    "signals_deferred",
    "start_child",
]


def figure_workers() -> int:
    """Processes a figure set (or a set of runs) is shared by: ``FLEXSAT_FIGURE_WORKERS``,
    else up to 2.

    Drawing is pure Python in matplotlib and a run is one compiled loop, one core
    per process each; two processes halve a set's wall time on a 2-core machine.
    Processes are forked, so they start in milliseconds with the data already in
    memory; where forking is not available (Windows, macOS' default) the work is
    done in this process.
    """
    if "fork" not in multiprocessing.get_all_start_methods():
        return 1
    if multiprocessing.current_process().daemon:  # a pool's worker may not have children
        return 1
    given = os.environ.get("FLEXSAT_FIGURE_WORKERS")
    if given is not None and given.strip().isdigit():
        return max(1, int(given))
    return max(1, min(2, os.cpu_count() or 1))


def forked_map(job: Callable, items: Iterable, workers: int | None = None) -> list:
    """``[job(item) for item in items]``, by forked processes when there are several.

    The processes are a :class:`~flexsat.pool.LocalPool`'s, forked inside
    :func:`frozen_heap`, one item each at a time (items of uneven cost stay balanced).
    A process that dies (killed, out of memory) is replaced and its item run again,
    and every process exits with this one. :class:`multiprocessing.pool.Pool`, used
    before, did neither: a process killed while taking the next item from the
    pool's shared queue held the queue's lock for ever, so the map never returned,
    and a killed parent left its processes behind.

    Parameters
    ----------
    job : callable
        Called once per item; a closure is fine (forked processes inherit it, only
        the items and the results are pickled).
    items : iterable
        The job's arguments [-].
    workers : int, optional
        Processes; default :func:`figure_workers`, at most one per item.

    Returns
    -------
    list
        The results, in the order of ``items``.

    Raises
    ------
    Exception
        The first exception a job raised (the other processes are stopped), or a
        :class:`RuntimeError` for an item whose process died twice.
    """
    from flexsat.pool import LocalPool  # not at import: the CLI starts without it

    items = list(items)
    workers = min(figure_workers() if workers is None else workers, len(items))
    if workers <= 1:
        return [job(item) for item in items]
    results: list = [None] * len(items)
    run = functools.partial(_run_indexed, job)
    with LocalPool(run, workers, _died_twice, start_method="fork", depth=1) as pool:
        for index, ok, value in pool.map_unordered(enumerate(items)):
            if not ok:
                raise value
            results[index] = value
    return results


def _run_indexed(job: Callable, indexed: tuple) -> tuple:
    """``(index, True, job(item))``, or ``(index, False, exception)`` if the job raised."""
    index, item = indexed
    try:
        return index, True, job(item)
    except Exception as exc:  # raised in the parent, as the serial loop would
        return index, False, exc


def _died_twice(indexed: tuple, exitcode: int | None) -> tuple:
    index, _ = indexed
    return (
        index,
        False,
        RuntimeError(f"the forked process running item {index} died twice (exit code {exitcode})"),
    )
