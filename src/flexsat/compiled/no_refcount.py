"""Borrowed array views for the compiled hot loops: no reference counting inside.

numba counts references to every array it passes, slices or unpacks: each function
entry, each view such as ``x[:n]``, each array taken from a tuple adds an atomic
increment and a decrement on the array's memory record. In the RK4 loops that is
hundreds of atomic operations per step, measured at a quarter of the ideal closed
loop's time and a third of the avionics chain's (``docs/performance.md``, 'Reference
counting').

:func:`borrowed` returns the same arrays (same data, shape and strides) without
their memory record: numba's reference-counting calls see a null record and return
at once, for every view and callee derived from them. A compiled loop borrows its
arguments on entry; the caller owns them and keeps them alive for the call, so
nothing is freed under the loop. A borrowed array must not outlive the call that
borrowed it: it is never returned, boxed to Python or stored in a container.

numba has no public switch for this (its ``_nrt`` option drops reference counting
for a whole function, allocations included, and is internal), hence the small
intrinsic below.
"""

from __future__ import annotations

from numba import types
from numba.core import cgutils
from numba.extending import intrinsic

__all__ = ["borrowed"]


def _borrow(context, builder, typ, value):
    """``value`` of numba type ``typ`` with every array's memory record cleared."""
    if isinstance(typ, types.Array):
        array = context.make_array(typ)(context, builder, value=value)
        array.meminfo = cgutils.get_null_value(array.meminfo.type)
        array.parent = cgutils.get_null_value(array.parent.type)
        return array._getvalue()
    if isinstance(typ, types.BaseTuple):  # tuples and named tuples, nested
        for i, member in enumerate(typ.types):
            item = _borrow(context, builder, member, builder.extract_value(value, i))
            value = builder.insert_value(value, item, i)
    return value


@intrinsic
def borrowed(typingctx, value):
    """``value`` with each array in it borrowed: the same data, no reference counting.

    Parameters
    ----------
    value : ndarray, or tuple or named tuple (nested) holding arrays
        Arrays the caller owns for the whole call. Other members (numbers, compiled
        functions) pass through unchanged.

    Returns
    -------
    same type as ``value``
        The borrowed arrays: writes through them change the caller's arrays. They
        must not be returned or stored beyond the call.
    """

    def codegen(context, builder, signature, args):
        return _borrow(context, builder, signature.args[0], args[0])

    return value(value), codegen
