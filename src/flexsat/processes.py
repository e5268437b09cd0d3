"""What a process that starts others needs: frozen heap, deferred signals, a child's first call.

- :func:`frozen_heap`: what a fork is started inside of, so the children's garbage
  collections leave the parent's objects (and their memory pages) alone.
- :func:`signals_deferred`: what a process is started inside of, so that a Ctrl-C
  landing during the fork is not lost.
- :func:`start_child`: what a child process calls first: Ctrl-C is its parent's to
  handle, and it never outlives its parent, even one killed with SIGKILL
  (:func:`die_with_parent`).

The bottom of the process machinery: the local pool (:mod:`flexsat.pool`) and the
forked map (:mod:`flexsat.parallel`, which exports these too) are built on it.
"""

from __future__ import annotations

import contextlib
import ctypes
import gc
import os
import signal
import sys
import threading
import time
from collections.abc import Iterator
from contextlib import contextmanager

__all__ = ["die_with_parent", "frozen_heap", "signals_deferred", "start_child"]

_STOP_SIGNALS = (signal.SIGINT, signal.SIGTERM)

_PARENT_POLL_S = 0.2  # how often a child checks that its parent is alive
_PR_SET_PDEATHSIG = 1  # prctl(2) option: signal sent to this process when its parent dies


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
