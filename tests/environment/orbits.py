"""Circular orbits as ephemeris tables, for the environment's tests.

The columns are the orbit package's (``EPHEMERIS_COLUMNS``); the tests build their own
so that they check the environment models against closed forms on an orbit whose
every quantity is known exactly.
"""

from __future__ import annotations

import numpy as np

from flexsat.environment.drag import EARTH_RADIUS, EARTH_ROTATION
from flexsat.environment.gravity_gradient import MU_EARTH
from flexsat.environment.srp import ASTRONOMICAL_UNIT


def circular_ephemeris(
    altitude_m: float,
    inclination_deg: float,
    duration_s: float,
    step_s: float,
    sun=(1.0, 0.0, 0.0),
    lit: float = 1.0,
) -> np.ndarray:
    """A circular orbit's ephemeris table (n, 13), ascending node on +X at t = 0.

    The Sun is fixed in direction ``sun`` at 1 AU; ``lit`` everywhere; GMST = omega_E t.
    """
    a = EARTH_RADIUS + altitude_m
    n = np.sqrt(MU_EARTH / a**3)
    t = np.arange(0.0, duration_s + step_s, step_s)
    inc = np.radians(inclination_deg)
    c, s = np.cos(n * t), np.sin(n * t)
    r = a * np.column_stack([c, np.cos(inc) * s, np.sin(inc) * s])
    v = a * n * np.column_stack([-s, np.cos(inc) * c, np.sin(inc) * c])
    sun = np.asarray(sun, dtype=float) / np.linalg.norm(sun)
    table = np.zeros((t.size, 13))
    table[:, 0], table[:, 1:4], table[:, 4:7] = t, r, v
    table[:, 7:10] = sun
    table[:, 10] = ASTRONOMICAL_UNIT
    table[:, 11] = lit
    table[:, 12] = EARTH_ROTATION * t
    return np.ascontiguousarray(table)
