"""The geomagnetic field: the tilted dipole against its closed form and against IGRF."""

from __future__ import annotations

import numpy as np
import pytest

from flexsat.environment.magnetic import (
    IGRF_DIPOLE_NT,
    REFERENCE_RADIUS,
    MagneticConfig,
    field_at,
    magnetic_load,
)
from tests.environment.orbits import circular_ephemeris


def _params(**kw) -> np.ndarray:
    return MagneticConfig(**kw).packed(None)


def test_dipole_at_the_poles_and_the_equator() -> None:
    """On the dipole's own axis |B| = 2 |m| (a/r)^3, on its equator |m| (a/r)^3
    (Wertz, eq. H-23): 1e-12 relative, round-off only."""
    m = 1e-9 * np.array(IGRF_DIPOLE_NT)
    axis = m / np.linalg.norm(m)
    equator = np.cross(axis, [1.0, 0.0, 0.0])
    equator /= np.linalg.norm(equator)
    r = REFERENCE_RADIUS + 500e3
    for direction, factor in ((axis, 2.0), (equator, 1.0)):
        eph = np.zeros(13)
        eph[1:4] = r * direction  # GMST 0: ECI = ECEF
        B = np.array(field_at(eph, _params()))
        expected = factor * np.linalg.norm(m) * (REFERENCE_RADIUS / r) ** 3
        assert np.linalg.norm(B) == pytest.approx(expected, rel=1e-12)


def test_dipole_against_igrf_degree_one_along_an_orbit() -> None:
    """ppigrf's IGRF truncated at degree 1, at 2020-01-01 (the coefficients flexsat
    carries), along an inclined orbit with the Earth turning: the same field, so
    within 1e-6 relative (the coefficients' two decimals of nT over 29 400 nT
    and the frames' conversions, both in double precision)."""
    pytest.importorskip("ppigrf")
    from flexsat.environment.magnetic import igrf_field

    eph = circular_ephemeris(500e3, 97.4, 5400.0, 300.0)
    igrf = igrf_field(eph, "2020-01-01T00:00:00Z", max_degree=1)
    dipole = np.array([field_at(row, _params()) for row in eph])
    assert np.abs(dipole - igrf).max() < 1e-6 * np.abs(igrf).max()


@pytest.mark.parametrize("longitude_deg", [0.0, 90.0, -45.0, 170.0])
def test_full_igrf_against_the_librarys_own_geodetic_values(longitude_deg: float) -> None:
    """On the equator (geodetic = geocentric latitude, h = r - R_E) the ECI field
    flexsat tabulates, turned to east-north-up, against ppigrf's geodetic igrf() at the
    same point and date: the library's two routes to one field, so 1e-6 relative
    (its geodetic-to-geocentric conversion in double precision)."""
    pytest.importorskip("ppigrf")
    from datetime import datetime

    import ppigrf

    from flexsat.environment.drag import EARTH_RADIUS
    from flexsat.environment.magnetic import igrf_field

    lon = np.radians(longitude_deg)
    gmst = 0.7  # the Earth turned: ECI != ECEF
    eph = np.zeros((2, 13))
    eph[:, 0] = (0.0, 1.0)
    eph[:, 12] = gmst
    eph[:, 1:4] = (EARTH_RADIUS + 500e3) * np.array([np.cos(lon + gmst), np.sin(lon + gmst),
                                                     0.0])  # fmt: skip
    B_N = igrf_field(eph, "2026-01-01T00:00:00Z")[0]
    east = np.array([-np.sin(lon + gmst), np.cos(lon + gmst), 0.0])
    up = eph[0, 1:4] / np.linalg.norm(eph[0, 1:4])
    north = np.array([0.0, 0.0, 1.0])
    be, bn, bu = ppigrf.igrf(longitude_deg, 0.0, 500.0, datetime(2026, 1, 1))
    expected = 1e-9 * np.array([np.ravel(be)[0], np.ravel(bn)[0], np.ravel(bu)[0]])
    mine = np.array([B_N @ east, B_N @ north, B_N @ up])
    assert mine == pytest.approx(expected, rel=1e-6, abs=1e-6 * np.abs(expected).max())


def test_torque_on_the_residual_dipole() -> None:
    """tau = m_res x B_B, B_B = C_BN B_N: 1e-12 relative."""
    eph = circular_ephemeris(500e3, 51.6, 600.0, 10.0)[7]
    params = _params(residual_dipole_a_m2=(0.5, -0.2, 1.0))
    C_BN = np.array([[0.0, 1.0, 0.0], [-1.0, 0.0, 0.0], [0.0, 0.0, 1.0]])
    torque = np.zeros(3)
    magnetic_load(eph, C_BN, np.zeros((0, 4)), np.zeros((0, 10)), params, np.zeros((0, 3)),
                  torque)  # fmt: skip
    expected = np.cross([0.5, -0.2, 1.0], C_BN @ np.array(field_at(eph, params)))
    assert torque == pytest.approx(expected, rel=1e-12)
