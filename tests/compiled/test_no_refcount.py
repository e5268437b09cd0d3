"""Borrowed array views: the same memory, no reference counting, nothing else changed."""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
from numba import njit, types
from numba.core import cgutils
from numba.core.runtime import _nrt_python, rtsys
from numba.extending import intrinsic

from flexsat.compiled.no_refcount import borrowed


class _Inner(NamedTuple):
    a: np.ndarray
    scale: float


class _Outer(NamedTuple):
    x: np.ndarray
    inner: _Inner
    rows: tuple


@njit
def _write_through(x, outer):
    x, outer = borrowed(x), borrowed(outer)
    x[0] = 1.5
    outer.x[:] = 2.0 * outer.inner.scale
    outer.inner.a[1, 1] = -3.0
    for i in range(len(outer.rows)):
        outer.rows[i][i] = 10.0 + i
    view = x[1:]  # a view of a borrowed array is borrowed too
    view[0] = 7.0
    return x.sum() + outer.inner.scale


@intrinsic
def _has_meminfo(typingctx, arr):
    """Whether the array carries a memory record, read through numba's data model."""

    def codegen(context, builder, signature, args):
        array = context.make_array(signature.args[0])(context, builder, value=args[0])
        null = cgutils.get_null_value(array.meminfo.type)
        return builder.icmp_unsigned("!=", array.meminfo, null)

    return types.boolean(arr), codegen


@njit
def _meminfo_cleared(x):
    return _has_meminfo(x), _has_meminfo(borrowed(x)), _has_meminfo(borrowed(x)[1:])


def test_writes_reach_the_callers_arrays_through_nested_tuples() -> None:
    x = np.zeros(3)
    outer = _Outer(np.zeros(2), _Inner(np.zeros((2, 2)), 0.25), (np.zeros(2), np.zeros(2)))
    total = _write_through(x, outer)
    np.testing.assert_array_equal(x, [1.5, 7.0, 0.0])
    np.testing.assert_array_equal(outer.x, [0.5, 0.5])
    assert outer.inner.a[1, 1] == -3.0
    np.testing.assert_array_equal(outer.rows[0], [10.0, 0.0])
    np.testing.assert_array_equal(outer.rows[1], [0.0, 11.0])
    assert total == 1.5 + 7.0 + 0.25  # the scalar member passed through unchanged


def test_borrowed_views_carry_no_memory_record() -> None:
    owned, borrowed_x, borrowed_view = _meminfo_cleared(np.ones(4))
    assert owned and not borrowed_x and not borrowed_view


def test_no_allocation_is_freed_or_leaked_by_borrowing() -> None:
    """numba's allocation statistics (its own runtime counters): a borrowed call
    frees nothing the caller owns and leaks nothing."""
    x = np.arange(3.0)
    outer = _Outer(np.zeros(2), _Inner(np.zeros((2, 2)), 0.0), (np.zeros(2), np.zeros(2)))
    _write_through(x, outer)  # compiled
    _nrt_python.memsys_enable_stats()  # off by default (NUMBA_NRT_STATS)
    before = rtsys.get_allocation_stats()
    for _ in range(1000):
        _write_through(x, outer)
    after = rtsys.get_allocation_stats()
    _nrt_python.memsys_disable_stats()
    assert after.alloc - before.alloc == after.free - before.free
    assert after.mi_alloc - before.mi_alloc == after.mi_free - before.mi_free
    np.testing.assert_array_equal(x, [1.5, 7.0, 2.0])
