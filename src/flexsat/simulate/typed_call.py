"""Calling one compiled function many times from Python, typed once.

A call from Python to a numba dispatcher types every argument first. For a tuple of
first-class functions (:class:`~flexsat.simulate.loops.LoopStages`) that typing
inspects each function's signature and compile result, about a millisecond per
call: more than the compiled work between two control instants of the Python
controller's loop (:func:`~flexsat.simulate.closedloop.run_slew` with a
``controller``). :class:`TypedOnce` types the arguments at the first call and
then calls the compiled overload chosen for them directly.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

__all__ = ["TypedOnce"]


class TypedOnce:
    """A dispatcher's call whose arguments are typed at the first call only.

    The first call types the arguments (the dispatcher's own typing) and compiles
    the overload for those types, or loads it from the cache, as the dispatcher
    would; every call, the first included, calls that overload directly. Every later
    call must pass arguments of those same types (the same arrays and structures,
    scalars of the same kind): the overload does not check them.

    Parameters
    ----------
    dispatcher : callable
        A function compiled with ``@njit`` (a numba dispatcher).
    """

    def __init__(self, dispatcher: Callable[..., Any]) -> None:
        self._dispatcher = dispatcher
        self._entry = None

    def __call__(self, *args: Any) -> Any:
        if self._entry is None:
            dispatcher = self._dispatcher
            # the dispatcher's own typing of each argument, once
            types = tuple(dispatcher.typeof_pyval(arg) for arg in args)
            if types not in dispatcher.overloads:
                dispatcher.compile(types)  # from the disk cache if it holds them
            self._entry = dispatcher.overloads[types].entry_point
        return self._entry(*args)
