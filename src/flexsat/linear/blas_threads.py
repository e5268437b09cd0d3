"""One BLAS thread for the robustness analysis's many small dense problems.

The mu bounds, the D-K iteration and the H-infinity synthesis factor thousands of
matrices of a few tens of rows. A multi-threaded BLAS (OpenBLAS by default uses
every core) gains nothing on matrices that small and, on a machine whose cores are
busy, its threads wait on each other at every call: on two loaded cores
:func:`flexsat.linear.mu.analyze` took 38 times the CPU time with two BLAS threads
as with one (docs/linear.md, 'One BLAS thread'). :func:`one_blas_thread` limits the
BLAS of the process to one thread for the duration of a call, through
threadpoolctl, and restores it afterwards.
"""

from __future__ import annotations

import functools
from collections.abc import Callable
from typing import ParamSpec, TypeVar

__all__ = ["one_blas_thread"]

P = ParamSpec("P")
R = TypeVar("R")


def one_blas_thread(func: Callable[P, R]) -> Callable[P, R]:
    """Decorate ``func`` to run with the process's BLAS limited to one thread.

    Parameters
    ----------
    func : callable
        A function whose dense algebra is on small matrices.

    Returns
    -------
    callable
        The same function; while it runs, every BLAS library loaded in the process
        uses one thread (the limits before the call are restored after it, also
        when it raises).
    """

    @functools.wraps(func)
    def limited(*args: P.args, **kwargs: P.kwargs) -> R:
        from threadpoolctl import threadpool_limits

        with threadpool_limits(limits=1, user_api="blas"):
            return func(*args, **kwargs)

    return limited
