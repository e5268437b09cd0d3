"""Calling one compiled function many times from Python, typed once.

A call from Python to a numba dispatcher types every argument first. For a tuple of
first-class functions (:class:`~flexsat.simulate.loops.LoopStages`) that typing
inspects each function's signature and compile result, about a millisecond per
call: more than the compiled work between two control instants of the Python
controller's loop (:func:`~flexsat.simulate.closedloop.run_slew` with a
``controller``). :class:`TypedOnce` types the arguments at the first call and
then calls the compiled overload chosen for them directly.

Passing a structure is costly too, whatever its typing: each call unboxes every
array and every first-class function in it (about 60 us for the nominal
:class:`~flexsat.dynamics.packed.PackedPlant`, whose kernels are first-class
functions). A numba typed list holding the structure crosses in one pointer
(:func:`typed_list`): a function called from Python at every evaluation takes it
that way (:func:`flexsat.simulate.openloop.listed_derivative`), as the ensemble's
compiled call takes its cases (:mod:`flexsat.simulate.batch`).
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from numba import njit
from numba.typed import List

__all__ = ["TypedOnce", "typed_append", "typed_list"]


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


@njit(cache=True)
def typed_list(item):
    """A numba typed list holding ``item``.

    Built by this cached function, the list's methods are compiled into it:
    ``numba.typed.List()`` and its ``append`` called from Python are compiled for
    the item's type in every process, uncached (2.8 s before the first batch of
    each campaign worker, CHANGELOG.md, 'Workers that start sooner').

    Parameters
    ----------
    item : numba-typed value
        The first item; it fixes the list's item type.

    Returns
    -------
    numba.typed.List
    """
    items = List()
    items.append(item)
    return items


@njit(cache=True)
def typed_append(items, item):
    """``items.append(item)``, cached (see :func:`typed_list`).

    Parameters
    ----------
    items : numba.typed.List
        A list made by :func:`typed_list`, appended to.
    item : numba-typed value
        Of the list's item type.
    """
    items.append(item)
