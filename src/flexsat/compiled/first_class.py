"""numba first-class functions: a compiled kernel handed to the loops by its signature.

A :class:`FirstClassKernel` is what the packed plant, the control laws and the loop
stages hold for each compiled piece: numba types it by its signature, not by its
identity, so a loop compiles once for every kernel of that signature (a user's own
included) and calls it indirectly.
"""

from __future__ import annotations

from numba import types
from numba.experimental.function_type import _get_wrapper_address

__all__ = ["FirstClassKernel", "first_class"]


class FirstClassKernel:
    """A compiled kernel as numba passes it to compiled code: typed by its signature.

    numba would type a dispatcher in a tuple the same way, but it looks the machine
    code address up again on every call from Python (about 0.1 ms per function);
    this object resolves it once (numba's wrapper-address protocol).

    Parameters
    ----------
    dispatcher : numba dispatcher
        The kernel, compiled with ``signature``.
    signature : numba signature
        Its contract signature.
    """

    def __init__(self, dispatcher, signature) -> None:
        self._numba_type_ = types.FunctionType(signature)
        self._address = _get_wrapper_address(dispatcher, signature)
        self.dispatcher = dispatcher
        self.signature = signature

    def __wrapper_address__(self) -> int:
        return self._address

    def __call__(self, *args):
        return self.dispatcher(*args)

    def __reduce__(self):
        # The address is per process: another process resolves it again.
        return first_class, (self.dispatcher, self.signature)


_KERNELS: dict[tuple[int, str], FirstClassKernel] = {}
_BY_IDENTITY: dict[tuple[int, int], FirstClassKernel] = {}


def first_class(dispatcher, signature) -> FirstClassKernel:
    """The :class:`FirstClassKernel` of a dispatcher with ``signature`` (cached).

    A kernel declared without its signature (``@njit(cache=True)``) is compiled with it
    here, on the first plant that uses its model (or loaded from numba's disk cache):
    importing flexsat then compiles no model a run does not use. A kernel declared
    with its signature was compiled at import.

    Parameters
    ----------
    dispatcher : numba dispatcher
        The kernel.
    signature : numba signature
        Its contract signature.

    Returns
    -------
    FirstClassKernel
        The same object for the same dispatcher and signature.

    Raises
    ------
    TypeError
        If the kernel was declared with other signatures only, or does not compile
        with ``signature``.
    """
    # First by identity: a plant packs a dozen kernels, and the signature's text takes
    # tens of microseconds to build.
    known = _BY_IDENTITY.get((id(dispatcher), id(signature)))
    if known is not None:
        return known
    # Then by the signature's text: an unpickled kernel (another process) brings an
    # equal signature that is a new object, and must find the same entry.
    key = (id(dispatcher), str(signature))
    if key not in _KERNELS:
        name = getattr(dispatcher, "__name__", dispatcher)
        if signature.args not in dispatcher.signatures:
            try:
                dispatcher.compile(signature)
            except Exception as error:  # numba's typing errors, or compilation disabled
                first_line = str(error).strip().splitlines()[0] if str(error).strip() else ""
                raise TypeError(f"{name!r} must compile with its contract signature "
                                f"{signature} (declare it @njit(cache=True) or with that "
                                f"signature): {first_line}") from None  # fmt: skip
        _KERNELS[key] = FirstClassKernel(dispatcher, signature)
    kernel = _KERNELS[key]
    if kernel.signature is signature:  # the kernel holds both: their ids stay theirs
        _BY_IDENTITY[id(dispatcher), id(signature)] = kernel
    return kernel
