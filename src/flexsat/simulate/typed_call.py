"""Calling one compiled function many times from Python, typed once.

A call from Python to a numba dispatcher types every argument first. For a tuple of
first-class functions (:class:`~flexsat.simulate.loops.LoopStages`) that typing
inspects each function's signature and compile result, about a millisecond per
call: more than the compiled work between two control instants of the Python
controller's loop (:func:`~flexsat.simulate.closedloop.run_slew` with a
``controller``). :class:`TypedOnce` types the arguments at the first call and then
calls the compiled overload chosen for them directly.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

__all__ = ["TypedOnce"]


class TypedOnce:
    """A dispatcher's call whose arguments are typed at the first call only.

    The first call goes through the dispatcher (compiling or loading from the cache
    as usual); the next ones call the overload compiled for the first call's
    argument types. Every later call must pass arguments of those same types (the
    same arrays and structures, scalars of the same kind): the overload does not
    check them.

    Parameters
    ----------
    dispatcher : callable
        A function compiled with ``@njit`` (a numba dispatcher).
    """

    def __init__(self, dispatcher: Callable[..., Any]) -> None:
        self._dispatcher = dispatcher
        self._entry = None

    def __call__(self, *args: Any) -> Any:
        if self._entry is not None:
            return self._entry(*args)
        result = self._dispatcher(*args)
        # the dispatcher's own typing of each argument, as at the first call
        types = tuple(self._dispatcher.typeof_pyval(arg) for arg in args)
        self._entry = self._dispatcher.overloads[types].entry_point
        return result
