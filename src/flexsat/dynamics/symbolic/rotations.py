"""Elementary rotations and the ZYX Euler-rate matrix, as SymPy matrices."""

from __future__ import annotations

import sympy as sp

__all__ = ["euler_rate_matrix", "rot_zyx", "rotation"]


_AXES = {"x": 0, "y": 1, "z": 2}


def rotation(axis: str, a: sp.Expr) -> sp.Matrix:
    """Elementary rotation by ``a`` about ``axis``: child-frame components to
    parent-frame components.

    Parameters
    ----------
    axis : {"x", "y", "z"}
        The rotation axis, shared by both frames.
    a : sympy.Expr
        Angle [rad].

    Returns
    -------
    sympy.Matrix
        3 x 3 rotation matrix [-].
    """
    k = _AXES[axis]
    i, j = (k + 1) % 3, (k + 2) % 3  # the plane turned, in right-handed order
    c, s = sp.cos(a), sp.sin(a)
    R = sp.eye(3)
    R[i, i], R[i, j], R[j, i], R[j, j] = c, -s, s, c
    return R


def rot_zyx(a_x: sp.Expr, a_y: sp.Expr, a_z: sp.Expr) -> sp.Matrix:
    """ZYX Euler rotation ``Rz(a_z) Ry(a_y) Rx(a_x)`` (thesis eq. 2.25).

    Parameters
    ----------
    a_x, a_y, a_z : sympy.Expr
        Roll, pitch and yaw angles [rad].

    Returns
    -------
    sympy.Matrix
        3 x 3 rotation matrix, child (body) to parent components [-].
    """
    return rotation("z", a_z) * rotation("y", a_y) * rotation("x", a_x)


def euler_rate_matrix(a_x: sp.Expr, a_y: sp.Expr) -> sp.Matrix:
    """Matrix ``S`` mapping ZYX Euler-angle rates to the body rate (thesis eq. 2.28).

    ``omega = S(a_x, a_y) @ [a_x_dot, a_y_dot, a_z_dot]``, body-frame components.

    Parameters
    ----------
    a_x, a_y : sympy.Expr
        Roll and pitch angles [rad].

    Returns
    -------
    sympy.Matrix
        S, 3 x 3 [-].
    """
    return sp.Matrix(
        [
            [1, 0, -sp.sin(a_y)],
            [0, sp.cos(a_x), sp.cos(a_y) * sp.sin(a_x)],
            [0, -sp.sin(a_x), sp.cos(a_y) * sp.cos(a_x)],
        ]
    )
