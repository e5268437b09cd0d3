"""Solar radiation pressure on a flat plate against its closed form."""

from __future__ import annotations

import numpy as np
import pytest

from flexsat.environment.registry import SURFACE_SIZE
from flexsat.environment.srp import ASTRONOMICAL_UNIT, SOLAR_PRESSURE, srp_load


def _plate(normal, area, spec, diff) -> np.ndarray:
    row = np.zeros((1, SURFACE_SIZE))
    row[0, 3:6], row[0, 6], row[0, 7], row[0, 8], row[0, 9] = normal, area, spec, diff, 2.2
    return row


def _force(sun_B, lit, surfaces, distance=ASTRONOMICAL_UNIT) -> np.ndarray:
    eph = np.zeros(13)
    eph[7:10], eph[10], eph[11] = sun_B, distance, lit
    force = np.zeros((surfaces.shape[0], 3))
    params = np.array([SOLAR_PRESSURE, ASTRONOMICAL_UNIT])
    srp_load(eph, np.eye(3), np.zeros((0, 4)), surfaces, params, force, np.zeros(3))
    return force


@pytest.mark.parametrize("incidence_deg", [0.0, 30.0, 60.0, 85.0])
def test_flat_plate_against_the_closed_form(incidence_deg: float) -> None:
    """F = -P A cos(t) [(1 - c_s) s + 2 (c_s cos(t) + c_d/3) n] (Montenbruck & Gill,
    eq. 3.76), written here by components in the plate's plane (x) and along its
    normal (z): the same operations in another order, so 1e-12 relative."""
    spec, diff, area = 0.3, 0.2, 2.5
    t = np.radians(incidence_deg)
    sun = np.array([np.sin(t), 0.0, np.cos(t)])
    force = _force(sun, 1.0, _plate((0.0, 0.0, 1.0), area, spec, diff))[0]
    P = SOLAR_PRESSURE
    fx = -P * area * np.cos(t) * (1.0 - spec) * np.sin(t)
    fz = -P * area * np.cos(t) * ((1.0 - spec) * np.cos(t) + 2.0 * (spec * np.cos(t) + diff / 3.0))
    assert force == pytest.approx([fx, 0.0, fz], rel=1e-12, abs=1e-12 * P * area)


def test_a_perfect_mirror_at_normal_incidence_takes_twice_the_pressure() -> None:
    """c_s = 1 at normal incidence: F = -2 P A n; a black plate (c_a = 1) -P A s."""
    P, area = SOLAR_PRESSURE, 1.0
    mirror = _force(np.array([0.0, 0.0, 1.0]), 1.0, _plate((0.0, 0.0, 1.0), area, 1.0, 0.0))
    black = _force(np.array([0.0, 0.0, 1.0]), 1.0, _plate((0.0, 0.0, 1.0), area, 0.0, 0.0))
    assert mirror[0] == pytest.approx([0.0, 0.0, -2.0 * P * area], rel=1e-14)
    assert black[0] == pytest.approx([0.0, 0.0, -P * area], rel=1e-14)


def test_zero_in_umbra_half_in_half_penumbra_and_none_on_the_dark_side() -> None:
    """The lit fraction scales the force (0 in umbra); the side facing away takes none."""
    sun = np.array([0.0, 0.0, 1.0])
    plate = _plate((0.0, 0.0, 1.0), 1.0, 0.1, 0.1)
    assert np.all(_force(sun, 0.0, plate) == 0.0)
    assert _force(sun, 0.5, plate) == pytest.approx(0.5 * _force(sun, 1.0, plate), rel=1e-15)
    assert np.all(_force(-sun, 1.0, plate) == 0.0)


def test_inverse_square_of_the_sun_distance() -> None:
    """At 0.5 AU, four times the force at 1 AU (exact up to round-off)."""
    sun, plate = np.array([0.0, 0.0, 1.0]), _plate((0.0, 0.0, 1.0), 1.0, 0.1, 0.1)
    near = _force(sun, 1.0, plate, 0.5 * ASTRONOMICAL_UNIT)
    assert near == pytest.approx(4.0 * _force(sun, 1.0, plate), rel=1e-14)
