"""Sun pointing: a body axis held on the Sun as seen from the satellite.

The Sun frame S: z toward the Sun, s (the ephemeris's satellite-to-Sun unit vector);
x = (Z x s) / ‖Z x s‖ with Z the ECI pole (never parallel: the Sun's declination stays
within 23.44 deg); y = z x x. The target is q_d = q_NS (x) q_off with q_off the
scenario's ``target_euler_deg`` read as the body's attitude in S (0, 0, 0: body z on
the Sun). S turns as s does (the year's 2e-7 rad/s and the orbit's parallax): with
s' from the ephemeris's slope (central difference over one grid step),
omega_N = s x s' + ((Z x s') . y / ‖Z x s‖) s, rotated into D; omega_dot_d is taken
as zero (about 1e-11 rad/s^2). docs/orbit.md, 'Pointing targets'.
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

__all__ = ["SUN_REFERENCE", "SunReferenceConfig", "sun_target"]


class SunReferenceConfig(PlantStageConfig):
    """Sun pointing along the scenario's orbit: ``[reference] kind = "sun"``.

    Needs the scenario's ``[orbit]``; ``target_euler_deg`` is the body's attitude in
    the Sun frame (module docstring).

    Parameters
    ----------
    kind : str
        The stage's registered name, ``"sun"``.
    """

    moving_target: ClassVar[bool] = True

    kind: Literal["sun"] = Field("sun", description="the stage's registered name")

    def packed(self, scenario, plant=None) -> np.ndarray:
        """q_off (4), rows n, the ephemeris table (n x 13), flattened."""
        return packed_target(scenario)


@njit(cache=True, error_model="numpy")
def sun_target(s0, s1, s2, d0, d1, d2, params, q_d, omega_d, omega_dot_d):
    """The Sun target from the unit Sun direction s and its rate s' (ECI).

    Parameters
    ----------
    s0, s1, s2 : float
        The unit Sun direction s, ECI [-].
    d0, d1, d2 : float
        Its rate s', ECI [1/s].
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
    rho = sqrt(s0 * s0 + s1 * s1)  # |Z x s|
    x0, x1, x2 = -s1 / rho, s0 / rho, 0.0
    y0, y1, y2 = s1 * x2 - s2 * x1, s2 * x0 - s0 * x2, s0 * x1 - s1 * x0
    target_attitude(frame_quaternion(x0, x1, x2, y0, y1, y2, s0, s1, s2), params, q_d)
    spin = (-d1 * y0 + d0 * y1) / rho  # (Z x s') . y / |Z x s|
    w0 = s1 * d2 - s2 * d1 + spin * s0
    w1 = s2 * d0 - s0 * d2 + spin * s1
    w2 = s0 * d1 - s1 * d0 + spin * s2
    w = rotate_to_body(q_d, w0, w1, w2)
    for i in range(3):
        omega_d[i] = w[i]
        omega_dot_d[i] = 0.0


@njit(cache=True)  # compiled with REFERENCE_SIGNATURE on first use
def sun_reference_step(t, params, state, q_d, omega_d, omega_dot_d, record):
    """The Sun target at t (contract in ``stages.registry``); ``state`` holds 3 rows."""
    n = int(params[EPHEMERIS_AT - 1])
    eph = params[EPHEMERIS_AT : EPHEMERIS_AT + n * ROW].reshape((n, ROW))
    half = 0.5 * (eph[1, 0] - eph[0, 0])
    now, before, after = state[:ROW], state[ROW : 2 * ROW], state[2 * ROW :]
    ephemeris_at(eph, t, now)
    ephemeris_at(eph, t - half, before)
    ephemeris_at(eph, t + half, after)
    span = after[0] - before[0]  # shorter at the table's ends, where t is held
    d = (0.0, 0.0, 0.0)
    if span > 0.0:
        d = ((after[7] - before[7]) / span, (after[8] - before[8]) / span,
             (after[9] - before[9]) / span)  # fmt: skip
    sun_target(now[7], now[8], now[9], d[0], d[1], d[2], params, q_d, omega_d, omega_dot_d)
    return 0


SUN_REFERENCE = StageSpec(
    role="reference", name="sun", config=SunReferenceConfig, step=sun_reference_step,
    state_size=3 * ROW,
    description="Sun pointing: the attitude in the Sun frame seen from the orbit (needs [orbit])",
)  # fmt: skip
