"""Forked processes side by side: what figure sets and the study's independent runs use.

- :func:`figure_workers`: how many processes (``FLEXSAT_FIGURE_WORKERS``, else up to 2).
- :func:`forked_map`: ``[job(item) for item in items]`` by forked processes.
- :func:`frozen_heap`: what a fork is started inside of, so the children's garbage
  collections leave the parent's objects (and their memory pages) alone.
- :func:`signals_deferred`: what a process is started inside of, so that a Ctrl-C
  landing during the fork is not lost.
- :func:`start_child`: what a child process calls first: Ctrl-C is its parent's to
  handle, and it never outlives its parent, even one killed with SIGKILL
  (:func:`die_with_parent`).

Forked processes start in milliseconds with the parent's memory, including every
numba kernel the parent already compiled or loaded from its disk cache, so a
child neither re-imports nor re-compiles anything. Kept free of matplotlib and
numba, so the command line can import it at start-up.
"""

from __future__ import annotations

import contextlib
import ctypes
import functools
import gc
import multiprocessing
import os
import signal
import sys
import threading
import time
from collections.abc import Callable, Iterable, Iterator
from contextlib import contextmanager

__all__ = [
    "die_with_parent",
    "figure_workers",
    "forked_map",
    "frozen_heap",
    "signals_deferred",
    "start_child",
]

_STOP_SIGNALS = (signal.SIGINT, signal.SIGTERM)

_PARENT_POLL_S = 0.2  # how often a child checks that its parent is alive
_PR_SET_PDEATHSIG = 1  # prctl(2) option: signal sent to this process when its parent dies


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


@contextmanager
def frozen_heap() -> Iterator[None]:
    """Start forked processes inside this: the objects that exist are frozen meanwhile.

    A forked process shares the parent's memory pages until it writes to one; a
    garbage collection in it writes to every object it examines (its ``gc`` header),
    so each collection copies most of the parent's pages, one page fault at a time.
    :func:`gc.freeze` moves the existing objects out of the collector's reach: the
    children never examine them, and the parent is unfrozen (collects them again) as
    soon as the block ends. Measured on the quick study (2 cores, about 20 forks of a
    process holding the compiled kernels): about 1 s less system time.
    """
    gc.freeze()
    try:
        yield
    finally:
        gc.unfreeze()


@contextmanager
def signals_deferred() -> Iterator[None]:
    """Start processes inside this: SIGINT and SIGTERM are noted meanwhile, and given
    to their handlers once the block ends.

    A signal's Python handler runs wherever the interpreter next checks for signals.
    During a fork that can be inside one of its after-fork callbacks (logging's lock
    release, for one), where an exception is printed as "Exception ignored" and lost:
    a Ctrl-C that landed as a process started was dropped and the run went on. Only
    the main thread may change handlers; elsewhere the block runs as it is.
    """
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    noted: list[int] = []
    previous = {signum: signal.signal(signum, lambda signum, _: noted.append(signum))
                for signum in _STOP_SIGNALS}  # fmt: skip
    try:
        yield
    finally:
        for signum, handler in previous.items():
            signal.signal(signum, signal.SIG_DFL if handler is None else handler)
        for signum in dict.fromkeys(noted):
            signal.raise_signal(signum)  # its handler runs here, in this thread


def start_child(parent_pid: int) -> None:
    """What a child process runs first. Ctrl-C is its parent's to handle (ignored here:
    a terminal sends it to the whole group), SIGTERM ends it (a forked child had its
    parent's handlers), and it exits with its parent (:func:`die_with_parent`).

    Parameters
    ----------
    parent_pid : int
        The parent's process id, as the parent saw it (``os.getpid()`` there) [-].
    """
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    signal.signal(signal.SIGTERM, signal.SIG_DFL)
    die_with_parent(parent_pid)


def die_with_parent(parent_pid: int) -> None:
    """Have this child process exit when its parent ``parent_pid`` dies.

    On Linux the kernel sends it SIGKILL as the parent dies (``PR_SET_PDEATHSIG``):
    immediate, even while it holds the GIL in a compiled loop. Everywhere, a daemon
    thread also checks every 0.2 s that the parent is still there (it covers other
    systems and a parent that died before the kernel was asked) and exits if not.

    Parameters
    ----------
    parent_pid : int
        The parent's process id, as the parent saw it (``os.getpid()`` there) [-].
    """
    if sys.platform.startswith("linux"):
        with contextlib.suppress(OSError, AttributeError):
            # the process's own symbols, libc's among them: ctypes.util.find_library
            # would run ldconfig, about 4 ms at every start
            ctypes.CDLL(None, use_errno=True).prctl(_PR_SET_PDEATHSIG, signal.SIGKILL)
    threading.Thread(target=_exit_with_parent, args=(parent_pid,), daemon=True).start()


def _exit_with_parent(parent_pid: int) -> None:
    while os.getppid() == parent_pid:
        time.sleep(_PARENT_POLL_S)
    os._exit(1)


def forked_map(job: Callable, items: Iterable, workers: int | None = None) -> list:
    """``[job(item) for item in items]``, by forked processes when there are several.

    The processes are a :class:`~flexsat.campaigns.pool.LocalPool`'s, forked inside
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
    from flexsat.campaigns.pool import LocalPool  # not at import: the CLI starts without it

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
    return index, False, RuntimeError(
        f"the forked process running item {index} died twice (exit code {exitcode})"
    )
