"""Nadir (LVLH) pointing: the target attitude turns with the orbit's local vertical frame.

The LVLH frame L: z toward nadir, -r/‖r‖; y against the orbit normal, -h/‖h‖ with
h = r x v; x = y x z (along the velocity on a circular orbit), r and v from the run's
ephemeris (:mod:`flexsat.orbit.ephemeris`). The target is q_d = q_NL (x) q_off with
q_off the scenario's ``target_euler_deg`` read as the body's attitude in L (0, 0, 0:
body z at nadir). L turns about the orbit normal at ‖h‖ / ‖r‖^2, so
omega_d = -(‖h‖ / ‖r‖^2) y_L and omega_dot_d = (2 ‖h‖ (r . v) / ‖r‖^4) y_L, both
in the reference frame D; the out-of-plane turn J2 adds (the node's 1e-6 rad/s) is
left out. docs/orbit.md, 'Pointing targets'.
"""

from __future__ import annotations

from math import sqrt
from typing import ClassVar, Literal

import numpy as np
from numba import njit
from pydantic import Field

from flexsat.control.stages._targets import (
    EPHEMERIS_AT,
    ROW,
    frame_quaternion,
    packed_target,
    rotate_to_body,
    target_attitude,
)
from flexsat.control.stages.registry import PlantStageConfig, StageSpec
from flexsat.orbit.ephemeris import ephemeris_at

__all__ = ["NADIR_REFERENCE", "NadirReferenceConfig", "lvlh_target"]


class NadirReferenceConfig(PlantStageConfig):
    """Nadir pointing along the scenario's orbit: ``[reference] kind = "nadir"``.

    Needs the scenario's ``[orbit]``; ``target_euler_deg`` is the body's attitude in
    the LVLH frame (module docstring).

    Parameters
    ----------
    kind : str
        The stage's registered name, ``"nadir"``.
    """

    moving_target: ClassVar[bool] = True

    kind: Literal["nadir"] = Field("nadir", description="the stage's registered name")

    def packed(self, scenario, plant=None) -> np.ndarray:
        """q_off (4), rows n, the ephemeris table (n x 13), flattened."""
        return packed_target(scenario)


@njit(cache=True, error_model="numpy")
def lvlh_target(row, params, q_d, omega_d, omega_dot_d):
    """The nadir target from one ephemeris row: q_d, omega_d, omega_dot_d (frame D).

    The LVLH frame: z to nadir, y against the orbit normal; its rate ‖h‖/r^2 and
    acceleration -2 ‖h‖ (r . v)/r^4 about -y (docs/orbit.md, 'Pointing targets').

    Parameters
    ----------
    row : ndarray, shape (13,)
        The ephemeris at the instant (``EPHEMERIS_COLUMNS``) [s, m, m/s, -, m, -, rad].
    params : ndarray
        The stage's packed parameters: q_off (4), the rows, the table
        (:func:`~flexsat.control.stages._targets.packed_target`) [-, -, SI].
    q_d : ndarray, shape (4,)
        The target attitude, quaternion of D in ECI, scalar first [-], written.
    omega_d : ndarray, shape (3,)
        The target's angular rate, frame D [rad/s], written.
    omega_dot_d : ndarray, shape (3,)
        The target's angular acceleration, frame D [rad/s^2], written.
    """
    rx, ry, rz, vx, vy, vz = row[1], row[2], row[3], row[4], row[5], row[6]
    r2 = rx * rx + ry * ry + rz * rz
    r = sqrt(r2)
    hx, hy, hz = ry * vz - rz * vy, rz * vx - rx * vz, rx * vy - ry * vx
    h = sqrt(hx * hx + hy * hy + hz * hz)
    z0, z1, z2 = -rx / r, -ry / r, -rz / r
    y0, y1, y2 = -hx / h, -hy / h, -hz / h
    x0, x1, x2 = y1 * z2 - y2 * z1, y2 * z0 - y0 * z2, y0 * z1 - y1 * z0
    target_attitude(frame_quaternion(x0, x1, x2, y0, y1, y2, z0, z1, z2), params, q_d)
    rate = h / r2
    rate_dot = -2.0 * h * (rx * vx + ry * vy + rz * vz) / (r2 * r2)
    w = rotate_to_body(q_d, -rate * y0, -rate * y1, -rate * y2)
    a = rotate_to_body(q_d, -rate_dot * y0, -rate_dot * y1, -rate_dot * y2)
    for i in range(3):
        omega_d[i] = w[i]
        omega_dot_d[i] = a[i]


@njit(cache=True)  # compiled with REFERENCE_SIGNATURE on first use
def nadir_reference_step(t, params, state, q_d, omega_d, omega_dot_d, record):
    """The LVLH target at t (contract in ``stages.registry``); ``state`` holds the row."""
    n = int(params[EPHEMERIS_AT - 1])
    eph = params[EPHEMERIS_AT : EPHEMERIS_AT + n * ROW].reshape((n, ROW))
    ephemeris_at(eph, t, state)
    lvlh_target(state, params, q_d, omega_d, omega_dot_d)
    return 0


NADIR_REFERENCE = StageSpec(
    role="reference", name="nadir", config=NadirReferenceConfig, step=nadir_reference_step,
    state_size=ROW,
    description="nadir pointing: the attitude in the orbit's LVLH frame (needs [orbit])",
)  # fmt: skip
