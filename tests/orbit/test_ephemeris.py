"""The ephemeris table and its compiled interpolation; eclipse times against geometry."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.optimize import brentq

from flexsat.orbit import EPHEMERIS_COLUMNS, OrbitConfig, build_ephemeris, ephemeris_at
from flexsat.orbit.config import EARTH_MU_M3_S2
from flexsat.orbit.propagate import propagate_elements
from flexsat.orbit.sun import EARTH_RADIUS_M, SUN_RADIUS_M

ORBIT = OrbitConfig(epoch="2026-03-20T12:00:00Z", altitude_m=500e3, inclination_deg=97.4,
                    raan_deg=30.0)  # fmt: skip


def _at(table: np.ndarray, t: float) -> np.ndarray:
    out = np.empty(len(EPHEMERIS_COLUMNS))
    ephemeris_at(table, t, out)
    return out


def test_the_table_follows_the_contract():
    ephemeris = build_ephemeris(ORBIT, 100.0, 10.0)
    table = ephemeris.table
    assert len(EPHEMERIS_COLUMNS) == 13 and table.shape[1] == 13
    assert table.dtype == np.float64 and table.flags.c_contiguous
    np.testing.assert_array_equal(table[:, 0], np.arange(table.shape[0]) * 10.0)
    assert ephemeris.duration_s >= 100.0 + 10.0
    assert ephemeris.epoch == ORBIT.epoch and ephemeris.step_s == 10.0
    np.testing.assert_allclose(np.linalg.norm(table[:, 7:10], axis=1), 1.0, rtol=1e-15)
    assert ((table[:, 11] >= 0.0) & (table[:, 11] <= 1.0)).all()
    # gmst turns at the Earth's rate in inertial space, the rate of the Earth rotation
    # angle 2 pi 1.00273781191135448 / 86400 s (IERS Conventions 2010, eq. 5.15), not
    # the 7.2921158553e-5 rad/s of the moving equinox: 1e-7 is the time's resolution
    # in two parts (1e-7 s over a 10 s step) with margin
    rate = np.diff(table[:, 12]) / 10.0
    np.testing.assert_allclose(rate, 2 * np.pi * 1.00273781191135448 / 86400.0, rtol=1e-7)


def test_interpolation_between_the_rows_matches_the_propagation():
    table = build_ephemeris(ORBIT, 2000.0, 10.0).table
    times = np.arange(5.0, 2000.0, 10.0) + 0.37  # off the grid, every interval
    direct = propagate_elements(ORBIT, np.concatenate([[0.0], times]))[1:]
    interpolated = np.array([_at(table, t) for t in times])
    # cubic Hermite: (omega h)^4 |r| / 384 = 3e-4 m at h = 10 s; 5e-3 m is that bound
    # with the integrator's 1e-6 relative tolerance on each side (mm over 7,000 km)
    assert np.abs(interpolated[:, 1:4] - direct[:, :3]).max() < 5e-3
    # its derivative: (omega h)^3 |v| / 72 = 1.4e-4 m/s
    assert np.abs(interpolated[:, 4:7] - direct[:, 3:]).max() < 5e-4
    # at a grid node the row itself
    np.testing.assert_array_equal(_at(table, 40.0)[1:7], table[4, 1:7])


def test_eclipse_entry_and_exit_within_a_second_of_geometry():
    """The shadow's four contacts against an independent computation: the circular
    orbit in closed form, the Sun from astropy, the contact angles of the cones."""
    coordinates = pytest.importorskip("astropy.coordinates")
    from astropy import units
    from astropy.time import Time

    orbit = OrbitConfig(epoch="2026-06-21T00:00:00Z", altitude_m=600e3, inclination_deg=28.5,
                        raan_deg=100.0, j2=False)  # fmt: skip
    period = orbit.period_s
    table = build_ephemeris(orbit, period, 10.0).table
    # the independent orbit: r(t) = a (cos u P + sin u Q), u = n t (arg. of latitude 0)
    a = orbit.semi_major_axis
    n = np.sqrt(EARTH_MU_M3_S2 / a**3)
    raan, inc = np.radians(orbit.raan_deg), np.radians(orbit.inclination_deg)
    p_axis = np.array([np.cos(raan), np.sin(raan), 0.0])
    q_axis = np.array([-np.sin(raan) * np.cos(inc), np.cos(raan) * np.cos(inc), np.sin(inc)])
    # the Sun from astropy, every 10 minutes, interpolated (it moves 0.007 deg in that time)
    knots = np.arange(0.0, period + 600.0, 600.0)
    epoch = Time("2026-06-21T00:00:00", scale="utc")
    sun_knots = coordinates.get_sun(epoch + knots * units.s).cartesian.xyz.to("m").value

    def geometry(t: float) -> tuple[float, float, float]:
        r = a * (np.cos(n * t) * p_axis + np.sin(n * t) * q_axis)
        sun = np.array([np.interp(t, knots, sun_knots[i]) for i in range(3)])
        to_sun = sun - r
        sun_radius = np.arcsin(SUN_RADIUS_M / np.linalg.norm(to_sun))
        earth_radius = np.arcsin(EARTH_RADIUS_M / a)
        cosine = -r @ to_sun / (a * np.linalg.norm(to_sun))
        return np.arccos(cosine), sun_radius, earth_radius

    def penumbra(t: float) -> float:  # > 0 outside the penumbra's cone
        c, sun_radius, earth_radius = geometry(t)
        return c - (sun_radius + earth_radius)

    def umbra(t: float) -> float:  # > 0 outside the umbra's cone
        c, sun_radius, earth_radius = geometry(t)
        return c - (earth_radius - sun_radius)

    times = np.arange(0.0, period, 1.0)
    lit = np.array([_at(table, t)[11] for t in times])
    ours = {
        "penumbra entry": times[np.flatnonzero(lit < 1.0)[0]],
        "umbra entry": times[np.flatnonzero(lit == 0.0)[0]],
        "umbra exit": times[np.flatnonzero(lit == 0.0)[-1]],
        "penumbra exit": times[np.flatnonzero(lit < 1.0)[-1]],
    }

    # refine ours to 1 ms by bisection on the same predicates
    def refine(t0: float, inside) -> float:
        lo, hi = t0 - 1.0, t0
        if inside(lo):
            lo, hi = t0, t0 + 1.0
        for _ in range(10):
            mid = 0.5 * (lo + hi)
            if inside(mid) == inside(hi):
                hi = mid
            else:
                lo = mid
        return 0.5 * (lo + hi)

    ours = {
        "penumbra entry": refine(ours["penumbra entry"], lambda t: _at(table, t)[11] < 1.0),
        "umbra entry": refine(ours["umbra entry"], lambda t: _at(table, t)[11] == 0.0),
        "umbra exit": refine(ours["umbra exit"] + 1.0, lambda t: _at(table, t)[11] > 0.0),
        "penumbra exit": refine(ours["penumbra exit"] + 1.0,
                                lambda t: _at(table, t)[11] == 1.0),
    }  # fmt: skip
    theirs = {
        "penumbra entry": brentq(penumbra, ours["penumbra entry"] - 60, ours["umbra entry"]),
        "umbra entry": brentq(umbra, ours["penumbra entry"] + 1e-3, ours["umbra exit"] - 60),
        "umbra exit": brentq(umbra, ours["umbra exit"] - 60, ours["penumbra exit"]),
        "penumbra exit": brentq(penumbra, ours["umbra exit"] + 1e-3, ours["penumbra exit"] + 60),
    }
    for contact, t in ours.items():
        print(f"{contact}: {t:.3f} s (geometry {theirs[contact]:.3f} s)")
        # 1 s: the Sun's two theories differ by 0.01 deg at most, which the satellite
        # covers in 0.16 s at 0.063 deg/s; the penumbra lasts 9.6 s here
        assert t == pytest.approx(theirs[contact], abs=1.0), contact
    assert 5.0 < ours["umbra entry"] - ours["penumbra entry"] < 15.0  # a LEO penumbra
