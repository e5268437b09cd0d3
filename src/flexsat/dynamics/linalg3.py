"""Allocation-free 3-vector and 3x3-matrix algebra for the compiled kernels.

Vectors are 3-tuples and matrices are 3-tuples of row 3-tuples, so numba keeps
them in registers: no heap allocation happens in the inner loop. Written by hand
because numpy's small-array operations allocate on every call inside numba.
Compiled with ``error_model="numpy"`` like the kernels (see
:mod:`flexsat.dynamics.kernels`): the divisions in :func:`euler_rate_matrix_inv` are
not zero-tested; callers check ``cos(theta)`` first.

Rotation convention (thesis eq. 2.25): ``rot_zyx(phi, theta, psi) = Rz(psi) Ry(theta)
Rx(phi)`` maps body components to parent components, and the body rate is
``omega = S(phi, theta) @ [phi_dot, theta_dot, psi_dot]`` (eq. 2.28).
"""

from __future__ import annotations

from math import cos, sin

from numba import njit

__all__ = [
    "add",
    "add_block",
    "cross",
    "dot",
    "euler_rate_bias",
    "euler_rate_bias_cs",
    "euler_rate_matrix",
    "euler_rate_matrix_cs",
    "euler_rate_matrix_inv",
    "load_m33",
    "load_m33_at",
    "load_seg",
    "load_v3",
    "mm",
    "mtm",
    "mtv",
    "mv",
    "rot_zyx",
    "rot_zyx_cs",
    "scale",
    "scale_m",
    "skew",
    "sub",
    "transpose",
]


@njit(cache=True, error_model="numpy")
def add(a, b):
    return (a[0] + b[0], a[1] + b[1], a[2] + b[2])


@njit(cache=True, error_model="numpy")
def sub(a, b):
    return (a[0] - b[0], a[1] - b[1], a[2] - b[2])


@njit(cache=True, error_model="numpy")
def scale(s, a):
    return (s * a[0], s * a[1], s * a[2])


@njit(cache=True, error_model="numpy")
def dot(a, b):
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


@njit(cache=True, error_model="numpy")
def cross(a, b):
    return (
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    )


@njit(cache=True, error_model="numpy")
def mv(m, x):
    """m @ x."""
    return (dot(m[0], x), dot(m[1], x), dot(m[2], x))


@njit(cache=True, error_model="numpy")
def mtv(m, x):
    """m.T @ x."""
    return (
        m[0][0] * x[0] + m[1][0] * x[1] + m[2][0] * x[2],
        m[0][1] * x[0] + m[1][1] * x[1] + m[2][1] * x[2],
        m[0][2] * x[0] + m[1][2] * x[1] + m[2][2] * x[2],
    )


@njit(cache=True, error_model="numpy")
def transpose(m):
    return (
        (m[0][0], m[1][0], m[2][0]),
        (m[0][1], m[1][1], m[2][1]),
        (m[0][2], m[1][2], m[2][2]),
    )


@njit(cache=True, error_model="numpy")
def mm(a, b):
    """a @ b."""
    bt = transpose(b)
    return (
        (dot(a[0], bt[0]), dot(a[0], bt[1]), dot(a[0], bt[2])),
        (dot(a[1], bt[0]), dot(a[1], bt[1]), dot(a[1], bt[2])),
        (dot(a[2], bt[0]), dot(a[2], bt[1]), dot(a[2], bt[2])),
    )


@njit(cache=True, error_model="numpy")
def mtm(a, b):
    """a.T @ b."""
    return mm(transpose(a), b)


@njit(cache=True, error_model="numpy")
def skew(v):
    """[v]x, the matrix with skew(v) @ x == cross(v, x)."""
    return ((0.0, -v[2], v[1]), (v[2], 0.0, -v[0]), (-v[1], v[0], 0.0))


@njit(cache=True, error_model="numpy")
def rot_zyx(phi, theta, psi):
    """Rz(psi) Ry(theta) Rx(phi): body (child) components to parent components (eq. 2.25)."""
    return rot_zyx_cs(cos(phi), sin(phi), cos(theta), sin(theta), cos(psi), sin(psi))


@njit(cache=True, error_model="numpy")
def rot_zyx_cs(c1, s1, c2, s2, c3, s3):
    """:func:`rot_zyx` from the cosines and sines of (phi, theta, psi)."""
    return (
        (c3 * c2, c3 * s2 * s1 - s3 * c1, c3 * s2 * c1 + s3 * s1),
        (s3 * c2, s3 * s2 * s1 + c3 * c1, s3 * s2 * c1 - c3 * s1),
        (-s2, c2 * s1, c2 * c1),
    )


@njit(cache=True, error_model="numpy")
def euler_rate_matrix(phi, theta):
    """S(Theta) of eq. 2.28: body rate = S @ ZYX Euler-angle rates."""
    return euler_rate_matrix_cs(cos(phi), sin(phi), cos(theta), sin(theta))


@njit(cache=True, error_model="numpy")
def euler_rate_matrix_cs(c1, s1, c2, s2):
    """:func:`euler_rate_matrix` from the cosines and sines of (phi, theta)."""
    return ((1.0, 0.0, -s2), (0.0, c1, c2 * s1), (0.0, -s1, c2 * c1))


@njit(cache=True, error_model="numpy")
def euler_rate_matrix_inv(phi, theta):
    """S(Theta)^-1; singular at theta = +-90 deg (the caller checks cos(theta))."""
    c1, s1 = cos(phi), sin(phi)
    c2, s2 = cos(theta), sin(theta)
    t2 = s2 / c2
    return ((1.0, s1 * t2, c1 * t2), (0.0, c1, -s1), (0.0, s1 / c2, c1 / c2))


@njit(cache=True, error_model="numpy")
def euler_rate_bias(phi, theta, dphi, dtheta, dpsi):
    """dS/dt @ Theta_dot: the part of the body angular acceleration not from Theta_ddot."""
    return euler_rate_bias_cs(cos(phi), sin(phi), cos(theta), sin(theta), dphi, dtheta, dpsi)


@njit(cache=True, error_model="numpy")
def euler_rate_bias_cs(c1, s1, c2, s2, dphi, dtheta, dpsi):
    """:func:`euler_rate_bias` from the cosines and sines of (phi, theta)."""
    return (
        -c2 * dtheta * dpsi,
        -s1 * dphi * dtheta + (c2 * c1 * dphi - s2 * s1 * dtheta) * dpsi,
        -c1 * dphi * dtheta - (c2 * s1 * dphi + s2 * c1 * dtheta) * dpsi,
    )


@njit(cache=True, error_model="numpy")
def load_v3(a, i):
    """Row i of an (n, 3) array as a tuple."""
    return (a[i, 0], a[i, 1], a[i, 2])


@njit(cache=True, error_model="numpy")
def load_m33(a, i):
    """Matrix i of an (n, 3, 3) array as nested tuples."""
    return (
        (a[i, 0, 0], a[i, 0, 1], a[i, 0, 2]),
        (a[i, 1, 0], a[i, 1, 1], a[i, 1, 2]),
        (a[i, 2, 0], a[i, 2, 1], a[i, 2, 2]),
    )


@njit(cache=True, error_model="numpy")
def load_m33_at(x, k):
    """x[k:k+9] (a row-major 3x3 matrix) as nested tuples."""
    return (
        (x[k], x[k + 1], x[k + 2]),
        (x[k + 3], x[k + 4], x[k + 5]),
        (x[k + 6], x[k + 7], x[k + 8]),
    )


@njit(cache=True, error_model="numpy")
def add_block(M, r0, c0, A, s):
    """M[r0:r0+3, c0:c0+3] += s A and, off the diagonal, the transposed block."""
    for a in range(3):
        for b in range(3):
            M[r0 + a, c0 + b] += s * A[a][b]
            if r0 != c0:
                M[c0 + b, r0 + a] += s * A[a][b]


@njit(cache=True, error_model="numpy")
def load_seg(x, k):
    """x[k:k+3] as a tuple."""
    return (x[k], x[k + 1], x[k + 2])


@njit(cache=True, error_model="numpy")
def scale_m(s, m):
    """s * m for a 3x3 matrix."""
    return (scale(s, m[0]), scale(s, m[1]), scale(s, m[2]))
