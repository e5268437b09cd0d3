"""Forked processes side by side: what figure sets and the study's independent runs use.

- :func:`figure_workers`: how many processes (``FLEXSAT_FIGURE_WORKERS``, else up to 2).
- :func:`forked_map`: ``[job(item) for item in items]`` by forked processes.

Forked processes start in milliseconds with the parent's memory, including every
numba kernel the parent already compiled or loaded from its disk cache, so a
child neither re-imports nor re-compiles anything. Kept free of matplotlib and
numba, so the command line can import it at start-up.
"""

from __future__ import annotations

import multiprocessing
import os
from collections.abc import Callable, Iterable

__all__ = ["figure_workers", "forked_map"]


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


_JOB: Callable | None = None  # the job of the running map, inherited by the forks


def _run_job(item):
    return _JOB(item)


def forked_map(job: Callable, items: Iterable, workers: int | None = None) -> list:
    """``[job(item) for item in items]``, by forked processes when there are several.

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
    """
    global _JOB
    items = list(items)
    workers = min(figure_workers() if workers is None else workers, len(items))
    if workers <= 1:
        return [job(item) for item in items]
    _JOB = job
    try:
        with multiprocessing.get_context("fork").Pool(workers) as pool:
            return pool.map(_run_job, items, chunksize=1)
    finally:
        _JOB = None
