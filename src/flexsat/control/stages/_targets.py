"""What the orbit-target references share: the packed ephemeris and the target frames.

A reference that points at something on the orbit (the nadir, the Sun) packs the
run's ephemeris (:mod:`flexsat.orbit.ephemeris`) after its own parameters:
``[q_off (4), n_rows, table (n_rows x 13)]``, ``q_off`` the body's attitude in the
target frame (the scenario's ``target_euler_deg``), and uses its state as the
interpolation's scratch rows. The target is q_d = q_NT (x) q_off (R_NB = R_NT R_TB).
docs/orbit.md, 'Pointing targets'.
"""

from __future__ import annotations

from math import sqrt

import numpy as np
from numba import njit

from flexsat.control.quaternion import quaternion_product, target_quaternion
from flexsat.errors import ConfigError

__all__ = [
    "EPHEMERIS_AT",
    "ROW",
    "frame_quaternion",
    "packed_target",
    "rotate_to_body",
    "run_ephemeris",
    "target_attitude",
]

EPHEMERIS_AT = 5
"""Index in the packed parameters where the ephemeris table starts."""
ROW = 13
"""Columns of one ephemeris row (:data:`flexsat.orbit.ephemeris.EPHEMERIS_COLUMNS`)."""


def run_ephemeris(scenario):
    """The ephemeris of the scenario's ``[orbit]`` over its run (built once per run).

    Raises
    ------
    ConfigError
        The scenario has no ``[orbit]`` table.
    """
    from flexsat.orbit.ephemeris import ephemeris_for_run

    orbit = getattr(scenario, "orbit", None)
    if orbit is None:
        raise ConfigError(
            f"reference.kind = {scenario.reference.kind!r} points at a target on the orbit: "
            "add an [orbit] table to the scenario (docs/orbit.md, 'The orbit table')"
        )
    return ephemeris_for_run(orbit, scenario.duration_s)


def packed_target(scenario) -> np.ndarray:
    """``[q_off, n_rows, table]`` of a target reference (module docstring)."""
    table = run_ephemeris(scenario).table
    offset = target_quaternion(scenario.target_euler_deg)
    return np.concatenate([offset, [table.shape[0]], table.ravel()])


@njit(cache=True, error_model="numpy")
def frame_quaternion(x0, x1, x2, y0, y1, y2, z0, z1, z2):
    """The quaternion of R = [x y z] (the frame's unit axes as columns, orthonormal).

    Shepperd's method: the largest of 4 q0^2, 4 q1^2, 4 q2^2, 4 q3^2 chosen first.

    Returns
    -------
    tuple of 4 float
        Scalar first, q0 >= 0 [-].
    """
    trace = x0 + y1 + z2
    if trace >= x0 and trace >= y1 and trace >= z2:
        s = 2.0 * sqrt(1.0 + trace)
        q = (0.25 * s, (y2 - z1) / s, (z0 - x2) / s, (x1 - y0) / s)
    elif x0 >= y1 and x0 >= z2:
        s = 2.0 * sqrt(1.0 + x0 - y1 - z2)
        q = ((y2 - z1) / s, 0.25 * s, (y0 + x1) / s, (z0 + x2) / s)
    elif y1 >= z2:
        s = 2.0 * sqrt(1.0 + y1 - x0 - z2)
        q = ((z0 - x2) / s, (y0 + x1) / s, 0.25 * s, (z1 + y2) / s)
    else:
        s = 2.0 * sqrt(1.0 + z2 - x0 - y1)
        q = ((x1 - y0) / s, (z0 + x2) / s, (z1 + y2) / s, 0.25 * s)
    if q[0] < 0.0:
        return (-q[0], -q[1], -q[2], -q[3])
    return q


@njit(cache=True, error_model="numpy")
def rotate_to_body(q, v0, v1, v2):
    """R(q)^T v: the components in the rotated frame of a vector given in the parent.

    Parameters
    ----------
    q : tuple or ndarray, shape (4,)
        Scalar first, R(q) maps the rotated frame's components to the parent's [-].
    v0, v1, v2 : float
        The vector in the parent frame.

    Returns
    -------
    (float, float, float)
    """
    w, a, b, c = q[0], q[1], q[2], q[3]
    r00 = 1.0 - 2.0 * (b * b + c * c)
    r01 = 2.0 * (a * b - w * c)
    r02 = 2.0 * (a * c + w * b)
    r10 = 2.0 * (a * b + w * c)
    r11 = 1.0 - 2.0 * (a * a + c * c)
    r12 = 2.0 * (b * c - w * a)
    r20 = 2.0 * (a * c - w * b)
    r21 = 2.0 * (b * c + w * a)
    r22 = 1.0 - 2.0 * (a * a + b * b)
    return (
        r00 * v0 + r10 * v1 + r20 * v2,
        r01 * v0 + r11 * v1 + r21 * v2,
        r02 * v0 + r12 * v1 + r22 * v2,
    )


@njit(cache=True, error_model="numpy")
def target_attitude(q_frame, params, q_d):
    """q_d = q_frame (x) q_off, written into ``q_d`` (4,)."""
    q = quaternion_product(q_frame, (params[0], params[1], params[2], params[3]))
    for i in range(4):
        q_d[i] = q[i]
