"""A compiled function called through :class:`TypedOnce` gives the dispatcher's results."""

from __future__ import annotations

import numpy as np
from numba import njit

from flexsat.simulate.typed_call import TypedOnce


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
