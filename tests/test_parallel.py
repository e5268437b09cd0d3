"""Forked processes: the results of a forked map, and the frozen heap they start from."""

from __future__ import annotations

import gc

import pytest

from flexsat.parallel import figure_workers, forked_map, frozen_heap


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
