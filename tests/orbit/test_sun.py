"""The Sun's ephemeris against astropy, and the conical shadow against geometry."""

from __future__ import annotations

import numpy as np
import pytest

from flexsat.orbit.sun import (
    AU_M,
    EARTH_RADIUS_M,
    SUN_RADIUS_M,
    illuminated_fraction,
    sun_position,
)
from flexsat.orbit.time import TT_MINUS_UTC_S, earth_rotation_angle, precession_angles


def _angle_deg(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    cosine = (a * b).sum(axis=-1) / np.linalg.norm(a, axis=-1) / np.linalg.norm(b, axis=-1)
    return np.degrees(np.arccos(np.clip(cosine, -1.0, 1.0)))


def test_sun_direction_within_a_hundredth_of_a_degree_of_astropy_over_a_year():
    coordinates = pytest.importorskip("astropy.coordinates")
    from astropy import units
    from astropy.time import Time

    # every 2 days of 2026: get_sun is astropy's built-in (no ephemeris download), GCRS
    times = Time("2026-01-01T00:00:00", scale="utc") + np.arange(0.0, 366.0, 2.0) * units.day
    reference = coordinates.get_sun(times).cartesian.xyz.to("m").value.T
    ours = np.array([sun_position(t.tt.jd1 + t.tt.jd2) for t in times])
    error = _angle_deg(ours, reference)
    print(f"Sun direction: worst {error.max():.5f} deg, mean {error.mean():.5f} deg")
    # 0.01 deg: the low-accuracy theory's stated accuracy (Meeus ch. 25); measured
    # 0.0094 deg worst, the Moon's and the planets' pull the theory leaves out
    assert error.max() < 0.01
    # distance: the theory's radius vector, measured 2e-5 relative; 1e-4 is the
    # Moon's barycentric wobble (4,700 km / 1 AU = 3e-5) with margin
    np.testing.assert_allclose(np.linalg.norm(ours, axis=1),
                               np.linalg.norm(reference, axis=1), rtol=1e-4)  # fmt: skip


def test_sidereal_angle_against_vallado_example():
    # Vallado, Fundamentals of Astrodynamics and Applications, example 3-5:
    # 1992 August 20, 12:14 UT1 -> GMST = 152.578787810 deg
    jd = 2448855.009722  # the example's JD (UT1, taken as UTC)
    zeta, _, z = precession_angles((jd - 2451545.0 + TT_MINUS_UTC_S / 86400.0) / 36525.0)
    gmst = np.degrees(earth_rotation_angle(jd) + zeta + z) % 360.0
    # 5e-4 deg: the example's JD has 1e-6 d (0.086 s, 3.6e-4 deg of rotation) of rounding
    assert gmst == pytest.approx(152.578787810, abs=5e-4)


def _overlap_fraction(a: float, b: float, c: float, n: int = 2001) -> float:
    """Visible fraction of a disc of radius a whose centre is c from a disc of radius b,
    by counting grid points (independent of the closed-form lens area)."""
    x, y = np.meshgrid(np.linspace(-a, a, n), np.linspace(-a, a, n))
    inside_sun = x * x + y * y <= a * a
    hidden = (x - c) ** 2 + y * y <= b * b
    return 1.0 - (inside_sun & hidden).sum() / inside_sun.sum()


@pytest.mark.parametrize("depth", [0.1, 0.3, 0.5, 0.7, 0.9])
def test_penumbra_fraction_against_counted_area(depth):
    r = EARTH_RADIUS_M + 500e3
    d = AU_M
    a = np.arcsin(SUN_RADIUS_M / d)
    b = np.arcsin(EARTH_RADIUS_M / r)
    c = (a + b) - depth * 2.0 * a  # from first contact (depth 0) to umbra (depth 1)
    # satellite at +x*r; the Sun seen at angle c from the Earth's centre direction (-x)
    s = np.array([-np.cos(c), np.sin(c), 0.0])
    lit = illuminated_fraction(r, 0.0, 0.0, *s, d)
    # the grid count's error: the discs' edges over a 2001-point grid, about 2e-3
    assert lit == pytest.approx(_overlap_fraction(a, b, c), abs=3e-3)


def test_full_sun_and_umbra():
    r = EARTH_RADIUS_M + 500e3
    assert illuminated_fraction(r, 0.0, 0.0, 1.0, 0.0, 0.0, AU_M) == 1.0  # Sun overhead
    assert illuminated_fraction(r, 0.0, 0.0, -1.0, 0.0, 0.0, AU_M) == 0.0  # Earth between
    # annular: a satellite so far that the Earth looks smaller than the Sun
    far = EARTH_RADIUS_M / np.sin(0.5 * np.arcsin(SUN_RADIUS_M / AU_M))
    expected = 1.0 - (np.arcsin(EARTH_RADIUS_M / far) / np.arcsin(SUN_RADIUS_M / AU_M)) ** 2
    assert illuminated_fraction(far, 0.0, 0.0, -1.0, 0.0, 0.0, AU_M) == pytest.approx(
        expected, rel=1e-12
    )  # the closed form b^2 / a^2, to rounding
