"""Forked processes: the results of a forked map, and the frozen heap they start from."""

from __future__ import annotations

import gc
import os
import signal
import subprocess
import sys

import pytest

from flexsat.parallel import figure_workers, forked_map, frozen_heap, signals_deferred


def test_frozen_heap_freezes_the_objects_only_while_processes_start():
    before = gc.get_freeze_count()
    with frozen_heap():
        assert gc.get_freeze_count() > before
    assert gc.get_freeze_count() == before


@pytest.mark.skipif(figure_workers() < 2, reason="no forked processes here")
def test_forked_map_starts_its_processes_with_the_heap_frozen():
    # The children's collections skip the parent's objects (no copied pages for them);
    # the parent collects them again once its pool is started.
    counts = forked_map(lambda _: gc.get_freeze_count(), [0, 1], workers=2)
    assert all(count > 0 for count in counts)
    assert gc.get_freeze_count() == 0


def test_forked_map_returns_the_serial_results_in_order():
    items = list(range(7))
    assert forked_map(lambda x: x * x, items, workers=2) == [x * x for x in items]
    assert forked_map(lambda x: x * x, items, workers=1) == [x * x for x in items]


def _killed_once(marker_dir):
    """A job whose process is killed (SIGKILL, as by the out-of-memory killer) the first
    time it runs item 3, and for item 5 every time."""

    def job(x):
        marker = marker_dir / f"ran-{x}"
        if x == 5 or (x == 3 and not marker.exists()):
            marker.touch()
            os.kill(os.getpid(), signal.SIGKILL)
        return x * x

    return job


def test_forked_map_runs_again_the_item_of_a_killed_process(tmp_path):
    # multiprocessing's Pool, used before, never returned here: the killed process
    # could hold the lock of the pool's shared queue.
    job = _killed_once(tmp_path)
    assert forked_map(job, [0, 1, 2, 3, 4], workers=2) == [0, 1, 4, 9, 16]
    assert (tmp_path / "ran-3").exists()  # it did die once


def test_forked_map_names_an_item_whose_process_died_twice(tmp_path):
    # Item 5 is the second of [4, 5, 6]: its index, 1, is named.
    with pytest.raises(RuntimeError, match=r"running item 1 died twice \(exit code -9\)"):
        forked_map(_killed_once(tmp_path), [4, 5, 6], workers=2)


def test_forked_map_raises_the_jobs_own_exception():
    def job(x):
        if x == 2:
            raise ValueError(f"item {x} is bad")
        return x

    with pytest.raises(ValueError, match="item 2 is bad"):
        forked_map(job, range(4), workers=2)


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="prctl is Linux's")
def test_die_with_parent_asks_the_kernel_for_sigkill():
    # PR_GET_PDEATHSIG (2) reads back the signal the kernel sends as the parent dies;
    # in a child process, so that this one's parent is left alone.
    script = (
        "import ctypes, os\n"
        "from flexsat.parallel import die_with_parent\n"
        "die_with_parent(os.getppid())\n"
        "signal = ctypes.c_int()\n"
        "ctypes.CDLL(None).prctl(2, ctypes.byref(signal))\n"
        "print(signal.value)\n"
    )
    out = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True,
                         check=True).stdout  # fmt: skip
    assert int(out) == signal.SIGKILL


class _Stop(Exception):
    pass


def test_a_signal_during_a_processes_start_reaches_its_handler_after_it():
    # A handler that raises inside an interpreter's after-fork callback is lost
    # ("Exception ignored"): inside the block the signal is only noted, and its own
    # handler runs, and raises, once the block ends.
    def stop(signum, frame):
        raise _Stop(signum)

    previous = signal.signal(signal.SIGINT, stop)
    try:
        reached = False
        with pytest.raises(_Stop), signals_deferred():
            signal.raise_signal(signal.SIGINT)
            reached = True  # not raised in the block
        assert reached
        assert signal.getsignal(signal.SIGINT) is stop  # the handler is back
    finally:
        signal.signal(signal.SIGINT, previous)
