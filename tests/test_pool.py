"""The local worker pool: items in flight per worker, deaths, nothing lost or repeated."""

from __future__ import annotations

import gc
import os
import subprocess
import sys
import threading
from pathlib import Path

import pytest

from flexsat.pool import DEPTH, LocalPool, safe_start_method

# Both ways a worker starts: fork (the default on Linux from a one-thread process) and
# spawn (elsewhere, and from this test runner's worker, which runs threads).
START_METHODS = pytest.mark.parametrize("method", ["fork", "spawn"])


def _square(item):
    return item, item * item


def _dies_once(item):
    """Kills its worker the first time it meets item 3 (a marker file remembers)."""
    value, folder = item
    marker = Path(folder) / "died"
    if value == 3 and not marker.exists():
        marker.touch()
        os._exit(9)
    return value, value * value


def _always_dies(item):
    value, _ = item
    if value == 3:
        os._exit(9)
    return value, value * value


def _frozen(item):
    return item, gc.get_freeze_count()


def _lost(item, exitcode):
    return item[0], ("lost", exitcode)


@START_METHODS
def test_every_item_comes_back_once_and_workers_hold_their_next_item(method):
    with LocalPool(_square, 2, _lost, start_method=method) as pool:
        results = []
        for result in pool.map_unordered(range(40)):
            if not results:  # the worker that answered still holds the item it queued
                held = [len(w.items) for w in pool._workers]
                assert sum(held) >= 2 * DEPTH - 1
            results.append(result)
    assert sorted(results) == [(i, i * i) for i in range(40)]


@START_METHODS
def test_a_worker_killed_with_an_item_queued_loses_nothing(tmp_path, method):
    # item 3 kills its worker once; the item queued behind it never started and is
    # run by the new worker without counting an attempt; 3 is run again and passes
    items = [(i, str(tmp_path)) for i in range(12)]
    with LocalPool(_dies_once, 2, _lost, start_method=method) as pool:
        results = list(pool.map_unordered(items))
    assert sorted(results) == [(i, i * i) for i in range(12)]


@START_METHODS
def test_an_item_that_always_kills_its_worker_is_handed_to_on_lost(tmp_path, method):
    items = [(i, str(tmp_path)) for i in range(8)]
    with LocalPool(_always_dies, 2, _lost, start_method=method) as pool:
        results = dict(pool.map_unordered(items))
    assert results.pop(3) == ("lost", 9)
    assert results == {i: i * i for i in range(8) if i != 3}


def test_workers_fork_only_from_a_process_with_one_thread():
    # A fresh interpreter runs one thread: on Linux it forks its workers.
    fresh = subprocess.run(
        [sys.executable, "-c", "from flexsat.pool import safe_start_method as m; "
                               "print(m())"],
        capture_output=True, text=True, check=True,
    )  # fmt: skip
    assert fresh.stdout.strip() == ("fork" if sys.platform.startswith("linux") else "spawn")
    # A second thread (held alive here) makes the pool spawn: a fork would copy its locks.
    release = threading.Event()
    other = threading.Thread(target=release.wait)
    other.start()
    try:
        assert safe_start_method() == "spawn"
    finally:
        release.set()
        other.join()


def test_a_forked_worker_starts_with_the_parents_objects_frozen():
    # Its garbage collections skip them, so they never copy the parent's pages; the
    # parent is unfrozen once the workers have started.
    with LocalPool(_frozen, 1, _lost, start_method="fork") as pool:
        assert gc.get_freeze_count() == 0
        [(_, frozen)] = list(pool.map_unordered([0]))
    assert frozen > 10_000  # the parent's objects: flexsat, numpy, pytest (measured ~10^5)
