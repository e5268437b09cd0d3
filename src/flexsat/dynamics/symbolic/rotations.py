"""Elementary rotations and the ZYX Euler-rate matrix, as SymPy matrices."""

from __future__ import annotations

import sympy as sp

__all__ = ["euler_rate_matrix", "rot_x", "rot_y", "rot_z", "rot_zyx"]


def rot_x(a: sp.Expr) -> sp.Matrix:
    """Rotation by ``a`` about X: child-frame components to parent-frame components.

    Parameters
    ----------
    a : sympy.Expr
        Angle [rad].

    Returns
    -------
    sympy.Matrix
        3 x 3 rotation matrix [-].
    """
    c, s = sp.cos(a), sp.sin(a)
    return sp.Matrix([[1, 0, 0], [0, c, -s], [0, s, c]])


def rot_y(a: sp.Expr) -> sp.Matrix:
    """Rotation by ``a`` about Y: child-frame components to parent-frame components.

    Parameters
    ----------
    a : sympy.Expr
        Angle [rad].

    Returns
    -------
    sympy.Matrix
        3 x 3 rotation matrix [-].
    """
    c, s = sp.cos(a), sp.sin(a)
    return sp.Matrix([[c, 0, s], [0, 1, 0], [-s, 0, c]])


def rot_z(a: sp.Expr) -> sp.Matrix:
    """Rotation by ``a`` about Z: child-frame components to parent-frame components.

    Parameters
    ----------
    a : sympy.Expr
        Angle [rad].

    Returns
    -------
    sympy.Matrix
        3 x 3 rotation matrix [-].
    """
    c, s = sp.cos(a), sp.sin(a)
    return sp.Matrix([[c, -s, 0], [s, c, 0], [0, 0, 1]])


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
    return rot_z(a_z) * rot_y(a_y) * rot_x(a_x)


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
