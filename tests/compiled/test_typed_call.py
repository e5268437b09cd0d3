"""A compiled function called through :class:`TypedOnce` gives the dispatcher's results."""

from __future__ import annotations

import numpy as np
from numba import njit

from flexsat.compiled.typed_call import TypedOnce


@njit
def _scaled_sum(x, scale, out):
    out[0] = scale * x.sum()
    return out[0] > 0.0


def test_later_calls_run_the_first_calls_overload():
    call = TypedOnce(_scaled_sum)
    x, out = np.arange(4.0), np.zeros(1)
    assert call(x, 2.0, out) and out[0] == 12.0  # through the dispatcher: it compiles
    x[:] = -1.0
    assert not call(x, 0.5, out) and out[0] == -2.0  # the overload itself, same types
    assert len(_scaled_sum.overloads) == 1


def test_the_first_call_types_its_arguments_once():
    # The first call compiles (or loads) the overload for its arguments' types and
    # calls it: the dispatcher's typing runs once per argument, not twice (once to
    # dispatch, once to find the overload).
    @njit
    def double(x):
        return 2.0 * x

    typed = []
    dispatcher_typeof = double.typeof_pyval

    def counting(value):
        typed.append(value)
        return dispatcher_typeof(value)

    double.typeof_pyval = counting
    call = TypedOnce(double)
    assert call(1.5) == 3.0 and call(2.0) == 4.0
    assert typed == [1.5] and len(double.overloads) == 1
