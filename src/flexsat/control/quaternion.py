"""Attitude quaternions (scalar first, as the thesis): compiled helpers and the one
conversion point to scipy's scalar-last convention."""

from __future__ import annotations

from math import asin, cos, sin, sqrt

import numpy as np
from numba import njit

__all__ = [
    "euler_zyx_to_quaternion",
    "pointing_error",
    "pointing_errors",
    "quaternion_error",
    "quaternion_product",
    "target_quaternion",
]


@njit(cache=True)
def euler_zyx_to_quaternion(phi, theta, psi):
    """Scalar-first quaternion of R_NB = Rz(psi) Ry(theta) Rx(phi) (the sensor interface).

    Parameters
    ----------
    phi, theta, psi : float
        ZYX Euler angles: roll, pitch, yaw [rad].

    Returns
    -------
    tuple of 4 float
        Unit quaternion, scalar first [-].
    """
    c1, s1 = cos(0.5 * phi), sin(0.5 * phi)
    c2, s2 = cos(0.5 * theta), sin(0.5 * theta)
    c3, s3 = cos(0.5 * psi), sin(0.5 * psi)
    return (
        c1 * c2 * c3 + s1 * s2 * s3,
        s1 * c2 * c3 - c1 * s2 * s3,
        c1 * s2 * c3 + s1 * c2 * s3,
        c1 * c2 * s3 - s1 * s2 * c3,
    )


@njit(cache=True)
def quaternion_error(q_d, q):
    """q_e = q_d^-1 (x) q (eq. 4.1), sign chosen so that q_e0 >= 0 (the shorter rotation).

    Parameters
    ----------
    q_d, q : ndarray or tuple, shape (4,)
        Reference and actual attitude quaternions, scalar first [-].

    Returns
    -------
    tuple of 4 float
        The error quaternion, scalar first [-].
    """
    e0 = q_d[0] * q[0] + q_d[1] * q[1] + q_d[2] * q[2] + q_d[3] * q[3]
    e1 = -q_d[1] * q[0] + q_d[0] * q[1] + q_d[3] * q[2] - q_d[2] * q[3]
    e2 = -q_d[2] * q[0] - q_d[3] * q[1] + q_d[0] * q[2] + q_d[1] * q[3]
    e3 = -q_d[3] * q[0] + q_d[2] * q[1] - q_d[1] * q[2] + q_d[0] * q[3]
    if e0 < 0.0:
        return (-e0, -e1, -e2, -e3)
    return (e0, e1, e2, e3)


@njit(cache=True)
def quaternion_product(a, b):
    """a (x) b, scalar first (Hamilton product: R(a (x) b) = R(a) R(b)).

    Parameters
    ----------
    a, b : ndarray or tuple, shape (4,)
        Quaternions, scalar first [-].

    Returns
    -------
    tuple of 4 float
        Their product, scalar first [-].
    """
    return (
        a[0] * b[0] - a[1] * b[1] - a[2] * b[2] - a[3] * b[3],
        a[0] * b[1] + a[1] * b[0] + a[2] * b[3] - a[3] * b[2],
        a[0] * b[2] - a[1] * b[3] + a[2] * b[0] + a[3] * b[1],
        a[0] * b[3] + a[1] * b[2] - a[2] * b[1] + a[3] * b[0],
    )


def target_quaternion(euler_deg: tuple[float, float, float]) -> np.ndarray:
    """Exact scalar-first quaternion of target ZYX Euler angles (roll, pitch, yaw).

    The thesis's [0.8446, 0.1913, 0.4619, 0.1913] for 45 deg on each axis is this,
    printed to 4 decimals. scipy works scalar-last; this is the conversion point.

    Parameters
    ----------
    euler_deg : tuple of float
        Roll, pitch, yaw of the ZYX sequence [deg].

    Returns
    -------
    ndarray, shape (4,)
        Unit quaternion, scalar first [-].
    """
    from scipy.spatial.transform import Rotation  # here: scipy.spatial costs 0.25 s to import

    roll, pitch, yaw = euler_deg
    x, y, z, w = Rotation.from_euler("ZYX", [yaw, pitch, roll], degrees=True).as_quat()
    return np.array([w, x, y, z])


@njit(cache=True)
def pointing_error(q_d, q):
    """Absolute pointing error 2 asin ‖q_v,e‖ of attitude ``q`` from ``q_d``.

    Parameters
    ----------
    q_d, q : ndarray or tuple, shape (4,)
        Reference and actual attitude quaternions, scalar first [-].

    Returns
    -------
    float
        The error angle [rad].
    """
    e = quaternion_error(q_d, q)
    return 2.0 * asin(min(1.0, sqrt(e[1] ** 2 + e[2] ** 2 + e[3] ** 2)))


@njit(cache=True)
def pointing_errors(q_d, euler):
    """Pointing error of each ZYX Euler attitude from ``q_d``.

    Parameters
    ----------
    q_d : ndarray, shape (4,)
        Reference quaternion, scalar first [-].
    euler : ndarray, shape (m, 3)
        Roll, pitch, yaw of each attitude [rad].

    Returns
    -------
    ndarray, shape (m,)
        The error angles [rad].
    """
    out = np.empty(euler.shape[0])
    for k in range(euler.shape[0]):
        out[k] = pointing_error(q_d, euler_zyx_to_quaternion(euler[k, 0], euler[k, 1], euler[k, 2]))
    return out
