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
    "copy_into",
    "cross",
    "dot",
    "euler_rate_bias",
    "euler_rate_bias_cs",
    "euler_rate_matrix",
    "euler_rate_matrix_cs",
    "euler_rate_matrix_inv",
    "euler_rate_matrix_inv_cs",
    "inverse3",
    "load_block33",
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
def copy_into(dst, src):
    """``dst[:] = src`` for 1-D arrays of one length, element by element.

    The same bits as the slice assignment, which the compiled kernels avoid: for
    every array assigned into a slice, numba (0.61 and later) compiles a formatted
    error message for a shape mismatch (integer and string formatting), about 5 s of
    compilation per process on a first run, again for each error model.

    Parameters
    ----------
    dst : ndarray, shape (n,)
        Output: a copy of ``src`` [any].
    src : ndarray, shape (n,)
        The values [any].
    """
    for i in range(src.shape[0]):
        dst[i] = src[i]


@njit(cache=True, error_model="numpy")
def add(a, b):
    """a + b for 3-vectors.

    Parameters
    ----------
    a, b : tuple of 3 float
        The vectors, in one unit [any].

    Returns
    -------
    tuple of 3 float
        Their sum [unit of a].
    """
    return (a[0] + b[0], a[1] + b[1], a[2] + b[2])


@njit(cache=True, error_model="numpy")
def sub(a, b):
    """a - b for 3-vectors.

    Parameters
    ----------
    a, b : tuple of 3 float
        The vectors, in one unit [any].

    Returns
    -------
    tuple of 3 float
        Their difference [unit of a].
    """
    return (a[0] - b[0], a[1] - b[1], a[2] - b[2])


@njit(cache=True, error_model="numpy")
def scale(s, a):
    """s a for a 3-vector.

    Parameters
    ----------
    s : float
        The factor [any].
    a : tuple of 3 float
        The vector [any].

    Returns
    -------
    tuple of 3 float
        The scaled vector [unit of s times unit of a].
    """
    return (s * a[0], s * a[1], s * a[2])


@njit(cache=True, error_model="numpy")
def dot(a, b):
    """a . b for 3-vectors.

    Parameters
    ----------
    a, b : tuple of 3 float
        The vectors, components in one frame [any].

    Returns
    -------
    float
        Their scalar product [unit of a times unit of b].
    """
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


@njit(cache=True, error_model="numpy")
def cross(a, b):
    """a x b for 3-vectors.

    Parameters
    ----------
    a, b : tuple of 3 float
        The vectors, components in one frame [any].

    Returns
    -------
    tuple of 3 float
        Their cross product, same frame [unit of a times unit of b].
    """
    return (
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    )


@njit(cache=True, error_model="numpy")
def mv(m, x):
    """m @ x.

    Parameters
    ----------
    m : tuple of 3 rows of 3 float
        The 3x3 matrix [any].
    x : tuple of 3 float
        The vector [any].

    Returns
    -------
    tuple of 3 float
        The product [unit of m times unit of x].
    """
    return (dot(m[0], x), dot(m[1], x), dot(m[2], x))


@njit(cache=True, error_model="numpy")
def mtv(m, x):
    """m.T @ x.

    Parameters
    ----------
    m : tuple of 3 rows of 3 float
        The 3x3 matrix [any]; for a rotation matrix, m.T maps parent to body components.
    x : tuple of 3 float
        The vector [any].

    Returns
    -------
    tuple of 3 float
        The product [unit of m times unit of x].
    """
    return (
        m[0][0] * x[0] + m[1][0] * x[1] + m[2][0] * x[2],
        m[0][1] * x[0] + m[1][1] * x[1] + m[2][1] * x[2],
        m[0][2] * x[0] + m[1][2] * x[1] + m[2][2] * x[2],
    )


@njit(cache=True, error_model="numpy")
def transpose(m):
    """m.T for a 3x3 matrix.

    Parameters
    ----------
    m : tuple of 3 rows of 3 float
        The matrix [any].

    Returns
    -------
    tuple of 3 rows of 3 float
        Its transpose [unit of m].
    """
    return (
        (m[0][0], m[1][0], m[2][0]),
        (m[0][1], m[1][1], m[2][1]),
        (m[0][2], m[1][2], m[2][2]),
    )


@njit(cache=True, error_model="numpy")
def mm(a, b):
    """a @ b for 3x3 matrices.

    Parameters
    ----------
    a, b : tuple of 3 rows of 3 float
        The matrices [any].

    Returns
    -------
    tuple of 3 rows of 3 float
        The product [unit of a times unit of b].
    """
    bt = transpose(b)
    return (
        (dot(a[0], bt[0]), dot(a[0], bt[1]), dot(a[0], bt[2])),
        (dot(a[1], bt[0]), dot(a[1], bt[1]), dot(a[1], bt[2])),
        (dot(a[2], bt[0]), dot(a[2], bt[1]), dot(a[2], bt[2])),
    )


@njit(cache=True, error_model="numpy")
def mtm(a, b):
    """a.T @ b for 3x3 matrices.

    Parameters
    ----------
    a, b : tuple of 3 rows of 3 float
        The matrices [any].

    Returns
    -------
    tuple of 3 rows of 3 float
        The product [unit of a times unit of b].
    """
    return mm(transpose(a), b)


@njit(cache=True, error_model="numpy")
def inverse3(a):
    """The inverse of a non-singular 3x3 matrix: its adjugate over its determinant.

    Straight-line arithmetic in registers, one division: for the small solves inside
    the dynamics kernels (a hub's or a joint's 3 x 3 blocks), where a loop with
    pivoting would cost several times more.

    Parameters
    ----------
    a : tuple of 3 rows of 3 float
        The matrix [any].

    Returns
    -------
    tuple of 3 rows of 3 float
        Its inverse [1 / unit of a].
    """
    c0 = cross(a[1], a[2])
    c1 = cross(a[2], a[0])
    c2 = cross(a[0], a[1])
    f = 1.0 / dot(a[0], c0)
    return transpose((scale(f, c0), scale(f, c1), scale(f, c2)))


@njit(cache=True, error_model="numpy")
def skew(v):
    """[v]x, the matrix with skew(v) @ x == cross(v, x).

    Parameters
    ----------
    v : tuple of 3 float
        The vector [any].

    Returns
    -------
    tuple of 3 rows of 3 float
        The skew-symmetric matrix [unit of v].
    """
    return ((0.0, -v[2], v[1]), (v[2], 0.0, -v[0]), (-v[1], v[0], 0.0))


@njit(cache=True, error_model="numpy")
def rot_zyx(phi, theta, psi):
    """Rz(psi) Ry(theta) Rx(phi): body (child) components to parent components (eq. 2.25).

    Parameters
    ----------
    phi, theta, psi : float
        ZYX Euler angles: roll, pitch, yaw [rad].

    Returns
    -------
    tuple of 3 rows of 3 float
        The rotation matrix [-].
    """
    return rot_zyx_cs(cos(phi), sin(phi), cos(theta), sin(theta), cos(psi), sin(psi))


@njit(cache=True, error_model="numpy")
def rot_zyx_cs(c1, s1, c2, s2, c3, s3):
    """:func:`rot_zyx` from the cosines and sines of (phi, theta, psi).

    Parameters
    ----------
    c1, s1, c2, s2, c3, s3 : float
        Cosines and sines of roll, pitch and yaw [-].

    Returns
    -------
    tuple of 3 rows of 3 float
        The rotation matrix [-].
    """
    return (
        (c3 * c2, c3 * s2 * s1 - s3 * c1, c3 * s2 * c1 + s3 * s1),
        (s3 * c2, s3 * s2 * s1 + c3 * c1, s3 * s2 * c1 - c3 * s1),
        (-s2, c2 * s1, c2 * c1),
    )


@njit(cache=True, error_model="numpy")
def euler_rate_matrix(phi, theta):
    """S(Theta) of eq. 2.28: body rate = S @ ZYX Euler-angle rates.

    Parameters
    ----------
    phi, theta : float
        Roll and pitch [rad] (S does not depend on yaw).

    Returns
    -------
    tuple of 3 rows of 3 float
        S [-].
    """
    return euler_rate_matrix_cs(cos(phi), sin(phi), cos(theta), sin(theta))


@njit(cache=True, error_model="numpy")
def euler_rate_matrix_cs(c1, s1, c2, s2):
    """:func:`euler_rate_matrix` from the cosines and sines of (phi, theta).

    Parameters
    ----------
    c1, s1, c2, s2 : float
        Cosines and sines of roll and pitch [-].

    Returns
    -------
    tuple of 3 rows of 3 float
        S [-].
    """
    return ((1.0, 0.0, -s2), (0.0, c1, c2 * s1), (0.0, -s1, c2 * c1))


@njit(cache=True, error_model="numpy")
def euler_rate_matrix_inv(phi, theta):
    """S(Theta)^-1; singular at theta = +-90 deg (the caller checks cos(theta)).

    Parameters
    ----------
    phi, theta : float
        Roll and pitch [rad].

    Returns
    -------
    tuple of 3 rows of 3 float
        S^-1: ZYX Euler-angle rates = S^-1 @ body rate [-].
    """
    return euler_rate_matrix_inv_cs(cos(phi), sin(phi), cos(theta), sin(theta))


@njit(cache=True, error_model="numpy")
def euler_rate_matrix_inv_cs(c1, s1, c2, s2):
    """:func:`euler_rate_matrix_inv` from the cosines and sines of (phi, theta).

    Parameters
    ----------
    c1, s1, c2, s2 : float
        Cosines and sines of roll and pitch [-].

    Returns
    -------
    tuple of 3 rows of 3 float
        S^-1 [-].
    """
    t2 = s2 / c2
    return ((1.0, s1 * t2, c1 * t2), (0.0, c1, -s1), (0.0, s1 / c2, c1 / c2))


@njit(cache=True, error_model="numpy")
def euler_rate_bias(phi, theta, dphi, dtheta, dpsi):
    """dS/dt @ Theta_dot: the part of the body angular acceleration not from Theta_ddot.

    Parameters
    ----------
    phi, theta : float
        Roll and pitch [rad].
    dphi, dtheta, dpsi : float
        ZYX Euler-angle rates [rad/s].

    Returns
    -------
    tuple of 3 float
        dS/dt @ Theta_dot, body frame B [rad/s^2].
    """
    return euler_rate_bias_cs(cos(phi), sin(phi), cos(theta), sin(theta), dphi, dtheta, dpsi)


@njit(cache=True, error_model="numpy")
def euler_rate_bias_cs(c1, s1, c2, s2, dphi, dtheta, dpsi):
    """:func:`euler_rate_bias` from the cosines and sines of (phi, theta).

    Parameters
    ----------
    c1, s1, c2, s2 : float
        Cosines and sines of roll and pitch [-].
    dphi, dtheta, dpsi : float
        ZYX Euler-angle rates [rad/s].

    Returns
    -------
    tuple of 3 float
        dS/dt @ Theta_dot, body frame B [rad/s^2].
    """
    return (
        -c2 * dtheta * dpsi,
        -s1 * dphi * dtheta + (c2 * c1 * dphi - s2 * s1 * dtheta) * dpsi,
        -c1 * dphi * dtheta - (c2 * s1 * dphi + s2 * c1 * dtheta) * dpsi,
    )


@njit(cache=True, error_model="numpy")
def load_v3(a, i):
    """Row i of an (n, 3) array as a tuple.

    Parameters
    ----------
    a : ndarray, shape (n, 3)
        The rows [any].
    i : int
        The row.

    Returns
    -------
    tuple of 3 float
        a[i] [unit of a].
    """
    return (a[i, 0], a[i, 1], a[i, 2])


@njit(cache=True, error_model="numpy")
def load_m33(a, i):
    """Matrix i of an (n, 3, 3) array as nested tuples.

    Parameters
    ----------
    a : ndarray, shape (n, 3, 3)
        The matrices [any].
    i : int
        The matrix.

    Returns
    -------
    tuple of 3 rows of 3 float
        a[i] [unit of a].
    """
    return (
        (a[i, 0, 0], a[i, 0, 1], a[i, 0, 2]),
        (a[i, 1, 0], a[i, 1, 1], a[i, 1, 2]),
        (a[i, 2, 0], a[i, 2, 1], a[i, 2, 2]),
    )


@njit(cache=True, error_model="numpy")
def load_m33_at(x, k):
    """x[k:k+9] (a row-major 3x3 matrix) as nested tuples.

    Parameters
    ----------
    x : ndarray, shape (n,)
        A packed array [any].
    k : int
        Offset of the matrix's first entry.

    Returns
    -------
    tuple of 3 rows of 3 float
        The matrix [unit of x].
    """
    return (
        (x[k], x[k + 1], x[k + 2]),
        (x[k + 3], x[k + 4], x[k + 5]),
        (x[k + 6], x[k + 7], x[k + 8]),
    )


@njit(cache=True, error_model="numpy")
def load_block33(x, k, r0, c0):
    """The 3x3 block at row r0, column c0 of a row-major 6x6 matrix packed at x[k:k+36].

    Parameters
    ----------
    x : ndarray, shape (n,)
        A packed array [any].
    k : int
        Offset of the 6x6 matrix's first entry.
    r0, c0 : int
        Row and column of the block's first entry (0 or 3).

    Returns
    -------
    tuple of 3 rows of 3 float
        The block [unit of x].
    """
    i = k + 6 * r0 + c0
    return (
        (x[i], x[i + 1], x[i + 2]),
        (x[i + 6], x[i + 7], x[i + 8]),
        (x[i + 12], x[i + 13], x[i + 14]),
    )


@njit(cache=True, error_model="numpy")
def add_block(M, r0, c0, A, s):
    """M[r0:r0+3, c0:c0+3] += s A and, off the diagonal, the transposed block.

    Parameters
    ----------
    M : ndarray, shape (n, n)
        The symmetric matrix accumulated into, in place [any].
    r0, c0 : int
        Row and column of the block's first entry.
    A : tuple of 3 rows of 3 float
        The block [unit of M over unit of s].
    s : float
        Its factor [any].
    """
    for a in range(3):
        for b in range(3):
            M[r0 + a, c0 + b] += s * A[a][b]
            if r0 != c0:
                M[c0 + b, r0 + a] += s * A[a][b]


@njit(cache=True, error_model="numpy")
def load_seg(x, k):
    """x[k:k+3] as a tuple.

    Parameters
    ----------
    x : ndarray, shape (n,)
        A packed array [any].
    k : int
        Offset of the vector's first entry.

    Returns
    -------
    tuple of 3 float
        The vector [unit of x].
    """
    return (x[k], x[k + 1], x[k + 2])


@njit(cache=True, error_model="numpy")
def scale_m(s, m):
    """s * m for a 3x3 matrix.

    Parameters
    ----------
    s : float
        The factor [any].
    m : tuple of 3 rows of 3 float
        The matrix [any].

    Returns
    -------
    tuple of 3 rows of 3 float
        The scaled matrix [unit of s times unit of m].
    """
    return (scale(s, m[0]), scale(s, m[1]), scale(s, m[2]))
