"""Orbit propagation: conservation without J2, the J2 nodal regression, SGP4 for a TLE."""

from __future__ import annotations

import numpy as np
import pytest

from flexsat.orbit import OrbitConfig, build_ephemeris
from flexsat.orbit.config import EARTH_J2, EARTH_MU_M3_S2
from flexsat.orbit.propagate import (
    elements_to_state,
    propagate_elements,
    propagate_tle,
    true_anomaly,
)
from flexsat.orbit.sun import EARTH_RADIUS_M

ISS_TLE = (
    "1 25544U 98067A   26060.50000000  .00016717  00000-0  10270-3 0  9006",
    "2 25544  51.6400 208.9163 0006317  69.9862  25.2906 15.49560532  1009",
)


def test_two_body_conserves_energy_and_angular_momentum():
    orbit = OrbitConfig(
        semi_major_axis_m=7.0e6, eccentricity=0.05, inclination_deg=40.0, j2=False,
        true_anomaly_deg=10.0,
    )  # fmt: skip
    table = build_ephemeris(orbit, 3.0 * orbit.period_s, 10.0).table
    r, v = table[:, 1:4], table[:, 4:7]
    energy = 0.5 * (v * v).sum(axis=1) - EARTH_MU_M3_S2 / np.linalg.norm(r, axis=1)
    h = np.cross(r, v)
    # DOP853 at rtol 1e-12 over three orbits (about 1,000 steps): the measured drift is
    # 3e-12 of the energy and 1.5e-12 of |h|; 1e-10 is the tolerance's order times the
    # steps, and a wrong force (even J2, 1e-3) would be 1e7 times larger.
    assert np.abs(energy / energy[0] - 1.0).max() < 1e-10
    assert np.linalg.norm(h - h[0], axis=1).max() / np.linalg.norm(h[0]) < 1e-10
    # and the elements' state is the Keplerian one: energy -mu / 2a, |h| = sqrt(mu p)
    a, e = orbit.semi_major_axis, orbit.eccentricity
    assert energy[0] == pytest.approx(-EARTH_MU_M3_S2 / (2.0 * a), rel=1e-13)  # rounding
    assert np.linalg.norm(h[0]) == pytest.approx(np.sqrt(EARTH_MU_M3_S2 * a * (1 - e * e)),
                                                 rel=1e-13)  # fmt: skip


def test_kepler_equation_is_solved():
    for e in (0.0, 0.1, 0.7, 0.95):
        for mean in np.linspace(-3.0, 3.0, 13):
            nu = true_anomaly(mean, e)
            big_e = 2.0 * np.arctan(np.sqrt((1 - e) / (1 + e)) * np.tan(nu / 2.0))
            # Newton's method stops at a 1e-15 step: M back to rounding of a few ulps
            assert big_e - e * np.sin(big_e) == pytest.approx(mean, abs=1e-12)


def test_perigee_radius_and_inclination_of_the_elements_state():
    orbit = OrbitConfig(semi_major_axis_m=8.0e6, eccentricity=0.1, inclination_deg=63.4,
                        raan_deg=40.0, arg_perigee_deg=90.0, true_anomaly_deg=0.0)  # fmt: skip
    state = elements_to_state(orbit)
    assert np.linalg.norm(state[:3]) == pytest.approx(8.0e6 * 0.9, rel=1e-14)  # rounding
    h = np.cross(state[:3], state[3:])
    assert np.degrees(np.arccos(h[2] / np.linalg.norm(h))) == pytest.approx(63.4, abs=1e-10)
    # argument of perigee 90 deg: the perigee is the northernmost point, z = r sin i
    assert state[2] == pytest.approx(8.0e6 * 0.9 * np.sin(np.radians(63.4)), rel=1e-12)


def test_j2_nodal_regression_rate():
    orbit = OrbitConfig(altitude_m=500e3, eccentricity=0.001, inclination_deg=51.6)
    times = np.arange(0.0, 86400.0 + 1.0, 30.0)
    state = propagate_elements(orbit, times)
    h = np.cross(state[:, :3], state[:, 3:])
    raan = np.unwrap(np.arctan2(h[:, 0], -h[:, 1]))
    rate = np.polyfit(times, raan, 1)[0]
    a, e, i = orbit.semi_major_axis, orbit.eccentricity, np.radians(orbit.inclination_deg)
    n = np.sqrt(EARTH_MU_M3_S2 / a**3)
    p = a * (1 - e * e)
    expected = -1.5 * n * EARTH_J2 * (EARTH_RADIUS_M / p) ** 2 * np.cos(i)
    # 1 %: the secular rate of first order in J2; the osculating a and e differ from the
    # mean ones by O(J2) (0.1 % of the rate), and the short-period terms (period T/2)
    # average out of a one-day fit over 15 orbits.
    assert rate == pytest.approx(expected, rel=0.01)
    per_day = np.degrees([rate, expected]) * 86400.0
    print(f"nodal rate {per_day[0]:.4f} deg/day, theory {per_day[1]:.4f} deg/day")


def test_tle_matches_sgp4_and_astropy_teme():
    sgp4_api = pytest.importorskip("sgp4.api")
    orbit = OrbitConfig(tle=ISS_TLE)
    times = np.linspace(0.0, 5400.0, 10)
    table = build_ephemeris(orbit, 5400.0, 600.0).table
    satellite = sgp4_api.Satrec.twoline2rv(*ISS_TLE)
    errors, r_km, v_km_s = satellite.sgp4_array(
        np.full(times.shape, satellite.jdsatepoch), satellite.jdsatepochF + times / 86400.0
    )
    assert not errors.any()
    state = propagate_tle(orbit, times)
    # the frame change is a rotation: the library's |r| and |v| to rounding
    np.testing.assert_allclose(np.linalg.norm(state[:, :3], axis=1),
                               np.linalg.norm(r_km, axis=1) * 1e3, rtol=1e-14)  # fmt: skip
    np.testing.assert_allclose(np.linalg.norm(state[:, 3:], axis=1),
                               np.linalg.norm(v_km_s, axis=1) * 1e3, rtol=1e-14)  # fmt: skip
    # the ephemeris's grid rows are those states (rows 0, 1, ... at 600 s)
    np.testing.assert_allclose(table[:10, 1:7], propagate_tle(orbit, table[:10, 0]), rtol=0,
                               atol=1e-6)  # fmt: skip
    # TEME -> J2000 against astropy's own transformation (with nutation): the
    # nutation left out is at most 20 arcsec (measured 9 arcsec, 0.0026 deg)
    coordinates = pytest.importorskip("astropy.coordinates")
    from astropy import units
    from astropy.time import Time

    obstime = Time(satellite.jdsatepoch, satellite.jdsatepochF, format="jd", scale="utc")
    obstime = obstime + times * units.s
    teme = coordinates.TEME(coordinates.CartesianRepresentation(r_km.T * units.km),
                            obstime=obstime)  # fmt: skip
    gcrs = teme.transform_to(coordinates.GCRS(obstime=obstime)).cartesian.xyz.to("m").value.T
    cosine = (gcrs * state[:, :3]).sum(axis=1) / np.linalg.norm(gcrs, axis=1)
    cosine /= np.linalg.norm(state[:, :3], axis=1)
    assert np.degrees(np.arccos(np.clip(cosine, -1, 1))).max() < 20.0 / 3600.0
