"""Min-max torque allocation along a null direction of the wheel cluster.

The pseudo-inverse allocation u = -A^+ tau gives the least-squares motor torques,
not the smallest largest one: on the four-wheel pyramid it asks one motor for
3/4 sqrt(3) |tau_axis| when the command has equal components on the three axes,
while the cluster could deliver that torque with every motor at 2/3 of it. A
wheel cluster with more wheels than axes has a null space N(A) (A n = 0): moving
u along a null direction n changes no hub torque. :func:`minmax_shift` finds the
step s that minimises max_i |u_i + n_i s|, the exact min-max allocation when
N(A) is one-dimensional (four wheels spanning three axes) and an improvement
along one direction otherwise (docs/control.md, 'Reaction wheels').
"""

from __future__ import annotations

from numba import njit

__all__ = ["minmax_shift", "null_direction"]


@njit(cache=True)
def minmax_shift(u, direction, n):
    """The step s minimising max_i |u_i + s d_i| over the first ``n`` entries.

    f(s) = max_i |u_i + s d_i| is convex and piecewise linear: its minimum lies
    where a rising line u_i + s d_i (or its negative) meets a falling one, or at
    s = 0 when no entry moves. Every such meeting point is tried (O(n^3), n <= 6
    wheels): exact, and allocation-free.

    Parameters
    ----------
    u : ndarray, shape (>= n,)
        The motor torques before the shift [N m].
    direction : ndarray, shape (>= n,)
        A null direction of the cluster, A d = 0 [-].
    n : int
        The number of wheels.

    Returns
    -------
    float
        The step s [N m]; u + s d has the smallest largest magnitude.
    """
    best_s, best = 0.0, 0.0
    for i in range(n):
        best = max(best, abs(u[i]))
    for i in range(n):
        for j in range(n):
            for sign in (-1.0, 1.0):
                # u_i + s d_i = sign (u_j + s d_j): line i rising meets line j (or -j).
                slope = direction[i] - sign * direction[j]
                if slope == 0.0:
                    continue
                s = (sign * u[j] - u[i]) / slope
                worst = 0.0
                for k in range(n):
                    worst = max(worst, abs(u[k] + s * direction[k]))
                if worst < best:
                    best, best_s = worst, s
    return best_s


@njit(cache=True)
def null_direction(null, n, stride, out):
    """A unit null direction of the cluster from its null projector I - A^+ A.

    The projector's column with the largest diagonal entry, normalised: the null
    direction itself when N(A) is one-dimensional (the projector is then d d^T).

    Parameters
    ----------
    null : ndarray
        The projector, row-major with row stride ``stride`` [-].
    n : int
        The number of wheels.
    stride : int
        Entries per row of ``null``.
    out : ndarray, shape (>= n,)
        Written: the unit direction [-]; zeros when A has no null space.

    Returns
    -------
    bool
        Whether the cluster has a null direction.
    """
    j, largest = 0, 0.0
    for i in range(n):
        if null[stride * i + i] > largest:
            j, largest = i, null[stride * i + i]
    if largest < 1e-12:
        for i in range(n):
            out[i] = 0.0
        return False
    scale = 1.0 / largest**0.5
    for i in range(n):
        out[i] = null[stride * i + j] * scale
    return True
