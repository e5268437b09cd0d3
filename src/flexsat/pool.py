"""A local pool of worker processes that stops when told to and never outlives its parent.

Unlike :class:`concurrent.futures.ProcessPoolExecutor`, which is handed every case
up front and waits for all of them, :class:`LocalPool` gives each worker at most
:data:`DEPTH` items at a time (by default): the one it runs and the next, queued in
its pipe, so that it never waits while the parent stores a result and prepares the
next item. So:

- leaving the pool (an exception, Ctrl-C, SIGTERM turned into ``KeyboardInterrupt``)
  cancels what is pending and stops the workers at once (SIGTERM, then SIGKILL
  after a grace period);
- a worker that dies (killed, out of memory) is replaced and its item given to the
  new worker; an item that kills its worker twice is handed to ``on_lost``;
- a worker whose parent dies (even by SIGKILL, as the out-of-memory killer does)
  notices within a fraction of a second and exits.

Workers are forked where that is safe: on Linux, from a parent that runs no thread
but its main one. A forked worker starts with the parent's imported modules and
loaded machine code (copy-on-write), instead of importing flexsat and loading the
compiled code from numba's disk cache, about 2.5 s of each worker's start
(CHANGELOG.md, 'Forked workers'). A thread's locks would be copied held, so
a parent with other threads (a Jupyter kernel, a Dask client, a test runner's
worker) and other systems (macOS's system libraries are not fork-safe) use
``spawn``: a fresh interpreter that shares nothing with the parent. A forked worker
resets the signal handlers it inherits, and holds copies of the parent's open files
(the store's lock among them) until it exits: it exits with the parent.
"""

from __future__ import annotations

import itertools
import multiprocessing
import os
import sys
import threading
import time
from collections import deque
from collections.abc import Callable, Iterable, Iterator
from multiprocessing.connection import wait

from flexsat.processes import frozen_heap, signals_deferred, start_child

__all__ = ["DEPTH", "LocalPool", "safe_start_method"]

DEPTH = 2
"""Items given to a worker at a time: the one it runs and the next. With one, a
worker waited for the parent to store its result and resolve the next case, about a
tenth of a reduced campaign case (CHANGELOG.md, 'A reduced case at 20 ms')."""

_GRACE_S = 1.0  # time given to a worker to exit on SIGTERM before SIGKILL
_ATTEMPTS = 2  # runs of an item whose worker died before it is given up


class LocalPool:
    """Run ``function`` on items in ``n_workers`` processes, ``depth`` items per worker.

    Use it as a context manager; leaving the block stops every worker.

    Parameters
    ----------
    function : callable
        Importable (module-level) function of one item; it must not raise.
    n_workers : int
        Worker processes.
    on_lost : callable
        ``on_lost(item, exitcode)`` gives the result of an item whose worker died
        ``_ATTEMPTS`` times running it.
    start_method : {"fork", "spawn"}, optional
        How workers start; by default ``fork`` where it is safe (module docstring),
        decided as each worker starts.
    depth : int, optional
        Items given to a worker at a time, :data:`DEPTH` by default. One suits items
        of uneven cost (figures): an idle worker then takes the next item instead of
        waiting behind one queued to a busy worker.
    """

    def __init__(
        self,
        function: Callable,
        n_workers: int,
        on_lost: Callable,
        start_method: str | None = None,
        depth: int = DEPTH,
    ) -> None:
        self.function, self.n_workers, self.on_lost = function, n_workers, on_lost
        self.start_method, self.depth = start_method, depth
        self._workers: list[_Worker] = []

    def __enter__(self) -> LocalPool:
        self._workers = [self._start() for _ in range(self.n_workers)]
        return self

    def __exit__(self, *exc) -> None:
        self.close()

    def _start(self) -> _Worker:
        context = multiprocessing.get_context(self.start_method or safe_start_method())
        ours, theirs = context.Pipe()
        process = context.Process(
            target=_serve, args=(theirs, self.function, os.getpid()), daemon=True
        )
        # a forked worker's collections leave the parent's pages alone; a Ctrl-C during
        # the fork reaches its handler after it
        with frozen_heap(), signals_deferred():
            process.start()
        theirs.close()
        return _Worker(process, ours)

    def map_unordered(self, items: Iterable) -> Iterator:
        """Results of ``function(item)`` as they come, in completion order."""
        source = iter(items)  # pulled as workers have room: never all up front
        pending: deque = deque()  # items of a worker that died, to run again first
        attempts: dict[int, int] = {}
        while True:
            for k in range(len(self._workers)):
                self._fill(k, pending, source)
            busy = [w for w in self._workers if w.items]
            if not busy:
                return
            ready = wait([w.conn for w in busy] + [w.process.sentinel for w in busy])
            for worker in busy:
                if worker.conn in ready and worker.conn.poll():
                    try:
                        result = worker.conn.recv()
                    except (EOFError, OSError):  # died while sending: handled below
                        result = None
                    else:
                        done = worker.items.popleft()  # a worker runs its items in order
                        attempts.pop(id(done), None)  # ids are reused once it is gone
                        yield result  # meanwhile the worker runs its queued item
                        continue
                if worker.process.sentinel in ready or not worker.process.is_alive():
                    running, queued = worker.items[0], list(worker.items)[1:]
                    self._replace(worker)  # joins it: its exit code is known after
                    exitcode = worker.process.exitcode
                    pending.extendleft(reversed(queued))  # never started: no attempt
                    attempts[id(running)] = attempts.get(id(running), 0) + 1
                    if attempts[id(running)] >= _ATTEMPTS:
                        del attempts[id(running)]
                        yield self.on_lost(running, exitcode)
                    else:
                        pending.appendleft(running)

    def _fill(self, k: int, pending: deque, source: Iterator) -> None:
        """Give worker ``k`` items (those to run again first) until it holds ``depth``."""
        while len(self._workers[k].items) < self.depth:
            if not pending:
                pending.extend(itertools.islice(source, 1))
            if not pending:
                return
            item = pending.popleft()
            try:
                self._workers[k].give(item)
            except OSError:  # it died: a new worker takes its items, this one included
                lost = list(self._workers[k].items)
                self._replace(self._workers[k])
                pending.extendleft(reversed(lost))

    def _replace(self, worker: _Worker) -> None:
        worker.stop()
        self._workers[self._workers.index(worker)] = self._start()

    def close(self) -> None:
        """Stop every worker: SIGTERM, then SIGKILL after a grace period."""
        for worker in self._workers:
            worker.process.terminate()
        deadline = time.monotonic() + _GRACE_S
        for worker in self._workers:
            worker.process.join(max(0.0, deadline - time.monotonic()))
            worker.stop()
        self._workers = []


class _Worker:
    def __init__(self, process, conn) -> None:
        self.process, self.conn, self.items = process, conn, deque()

    def give(self, item) -> None:
        self.items.append(item)
        self.conn.send(item)

    def stop(self) -> None:
        if self.process.is_alive():
            self.process.kill()
        self.process.join()
        self.conn.close()


def _serve(conn, function: Callable, parent_pid: int) -> None:
    """Worker loop: run each received item, send the result back; exit with the parent."""
    start_child(parent_pid)  # Ctrl-C is the parent's; SIGTERM ends it; exits with the parent
    while True:
        try:
            item = conn.recv()
        except (EOFError, OSError):  # the parent closed the pipe
            return
        conn.send(function(item))


def safe_start_method() -> str:
    """``"fork"`` on Linux from a process whose only thread is its main one, else ``"spawn"``."""
    single = threading.active_count() == 1
    return "fork" if sys.platform.startswith("linux") and single else "spawn"
