"""Orbit propagation: two-body + J2 (scipy DOP853) from elements, SGP4 from a TLE.

The orbit is propagated once, before the attitude run, on the ephemeris grid
(docs/orbit.md, 'Propagation: once, then interpolated'). Positions and velocities are
in the J2000 frame (ECI) [m, m/s].
"""

from __future__ import annotations

from math import atan2, cos, radians, sin, sqrt

import numpy as np

from flexsat.errors import ConfigError
from flexsat.orbit.config import EARTH_J2, EARTH_MU_M3_S2, OrbitConfig
from flexsat.orbit.sun import EARTH_RADIUS_M
from flexsat.orbit.time import J2000_JD, TT_MINUS_UTC_S, precession_matrix

__all__ = [
    "PROPAGATION_ATOL_M",
    "PROPAGATION_RTOL",
    "elements_to_state",
    "j2_acceleration",
    "propagate_elements",
    "propagate_tle",
    "tle_epoch_jd",
    "true_anomaly",
]

PROPAGATION_RTOL = 1e-12
"""DOP853's relative tolerance [-]."""
PROPAGATION_ATOL_M = 1e-6
"""DOP853's absolute tolerance [m and m/s]: a micrometre on a 7,000 km radius."""


def true_anomaly(mean_anomaly: float, e: float) -> float:
    """The true anomaly of a mean anomaly (Kepler's equation, Newton's method).

    Parameters
    ----------
    mean_anomaly : float
        M [rad].
    e : float
        Eccentricity, in [0, 1) [-].

    Returns
    -------
    float
        nu [rad].
    """
    big_e = mean_anomaly if e < 0.8 else np.pi
    for _ in range(50):
        step = (big_e - e * sin(big_e) - mean_anomaly) / (1.0 - e * cos(big_e))
        big_e -= step
        if abs(step) < 1e-15:
            break
    return 2.0 * atan2(sqrt(1.0 + e) * sin(big_e / 2.0), sqrt(1.0 - e) * cos(big_e / 2.0))


def elements_to_state(orbit: OrbitConfig) -> np.ndarray:
    """Position and velocity of the orbit's osculating elements at its epoch.

    r = p / (1 + e cos nu) (cos nu P + sin nu Q), v = sqrt(mu / p) (-sin nu P +
    (e + cos nu) Q), with P, Q the perifocal axes rotated by R3(-RAAN) R1(-i)
    R3(-argp) (Vallado, algorithm 10, COE2RV).

    Parameters
    ----------
    orbit : OrbitConfig
        Keplerian elements (not a TLE).

    Returns
    -------
    ndarray, shape (6,)
        r [m], v [m/s], ECI.
    """
    a, e = orbit.semi_major_axis, orbit.eccentricity
    if orbit.mean_anomaly_deg is not None:
        nu = true_anomaly(radians(orbit.mean_anomaly_deg), e)
    else:
        nu = radians(orbit.true_anomaly_deg or 0.0)
    p = a * (1.0 - e * e)
    raan, inc, argp = (
        radians(orbit.raan_deg),
        radians(orbit.inclination_deg),
        radians(orbit.arg_perigee_deg),
    )
    cO, sO, ci, si, cw, sw = cos(raan), sin(raan), cos(inc), sin(inc), cos(argp), sin(argp)
    big_p = np.array([cO * cw - sO * sw * ci, sO * cw + cO * sw * ci, sw * si])
    big_q = np.array([-cO * sw - sO * cw * ci, -sO * sw + cO * cw * ci, cw * si])
    r = p / (1.0 + e * cos(nu)) * (cos(nu) * big_p + sin(nu) * big_q)
    v = sqrt(EARTH_MU_M3_S2 / p) * (-sin(nu) * big_p + (e + cos(nu)) * big_q)
    return np.concatenate([r, v])


def j2_acceleration(r: np.ndarray, j2: float = EARTH_J2) -> np.ndarray:
    """Gravity of the Earth to J2 (Vallado eq. 8-30), ECI, the pole along z.

    a = -mu r / ‖r‖^3 - (3/2) J2 mu R_E^2 / ‖r‖^5 (x (1 - 5 z^2/‖r‖^2),
    y (1 - 5 z^2/‖r‖^2), z (3 - 5 z^2/‖r‖^2)).

    Parameters
    ----------
    r : ndarray, shape (3,)
        Position [m].
    j2 : float
        The zonal coefficient (0: two-body) [-].

    Returns
    -------
    ndarray, shape (3,)
        Acceleration [m/s^2].
    """
    x, y, z = r
    r2 = x * x + y * y + z * z
    rn = sqrt(r2)
    k = -EARTH_MU_M3_S2 / (r2 * rn)
    f = 1.5 * j2 * EARTH_RADIUS_M**2 / r2
    zz = 5.0 * z * z / r2
    return k * np.array([x * (1.0 + f * (1.0 - zz)), y * (1.0 + f * (1.0 - zz)),
                         z * (1.0 + f * (3.0 - zz))])  # fmt: skip


def propagate_elements(orbit: OrbitConfig, times_s: np.ndarray) -> np.ndarray:
    """Position and velocity at ``times_s`` after the epoch: two-body + J2, DOP853.

    Parameters
    ----------
    orbit : OrbitConfig
        Keplerian elements (``j2`` False: two-body only).
    times_s : ndarray, shape (n,)
        Increasing times since the epoch, the first 0 [s].

    Returns
    -------
    ndarray, shape (n, 6)
        r [m], v [m/s], ECI.
    """
    # imported here: scipy.integrate is slow to import, and every process that loads
    # the loop stages (any slew, the scenario models) reaches this module without
    # propagating an orbit (docs/performance.md, 'Start-up')
    from scipy.integrate import solve_ivp

    j2 = EARTH_J2 if orbit.j2 else 0.0

    def rhs(t: float, y: np.ndarray) -> np.ndarray:
        return np.concatenate([y[3:], j2_acceleration(y[:3], j2)])

    times_s = np.asarray(times_s, dtype=float)
    solution = solve_ivp(
        rhs, (times_s[0], times_s[-1]), elements_to_state(orbit), method="DOP853",
        t_eval=times_s, rtol=PROPAGATION_RTOL, atol=PROPAGATION_ATOL_M,
    )  # fmt: skip
    if not solution.success:  # pragma: no cover - a closed orbit above 100 km propagates
        raise ConfigError(f"orbit: the propagation failed ({solution.message})")
    return np.ascontiguousarray(solution.y.T)


def _satrec(orbit: OrbitConfig):
    """The sgp4 satellite record of the orbit's TLE (the ``orbit`` extra)."""
    try:
        from sgp4.api import Satrec
    except ImportError:
        raise ConfigError(
            "orbit.tle needs the sgp4 package: pip install 'flexsat[orbit]'"
        ) from None
    line1, line2 = (line.rstrip("\r\n") for line in orbit.tle)
    try:
        satellite = Satrec.twoline2rv(line1, line2)
    except (ValueError, IndexError) as error:
        raise ConfigError(f"orbit.tle: the element set does not parse ({error})") from None
    return satellite


def tle_epoch_jd(orbit: OrbitConfig) -> tuple[float, float]:
    """The TLE's epoch as a two-part Julian date (UTC).

    Parameters
    ----------
    orbit : OrbitConfig
        An orbit given by its TLE (the ``orbit`` extra's sgp4 reads it).

    Returns
    -------
    tuple of float
        The whole and fractional parts of the Julian date [d].
    """
    satellite = _satrec(orbit)
    return float(satellite.jdsatepoch), float(satellite.jdsatepochF)


def propagate_tle(orbit: OrbitConfig, times_s: np.ndarray) -> np.ndarray:
    """Position and velocity at ``times_s`` after the TLE's epoch: SGP4, to J2000.

    SGP4 gives TEME (true equator, mean equinox of date); it is taken to the mean
    equator of date by leaving out nutation (< 20 arcsec, the TLE's own error is
    kilometres) and to J2000 by the IAU 1976 precession's transpose.

    Parameters
    ----------
    orbit : OrbitConfig
        An orbit given by its ``tle``.
    times_s : ndarray, shape (n,)
        Times since the TLE's epoch [s].

    Returns
    -------
    ndarray, shape (n, 6)
        r [m], v [m/s], ECI (J2000).

    Raises
    ------
    ConfigError
        The element set does not parse, SGP4 reports an error, or sgp4 is missing.
    """
    satellite = _satrec(orbit)
    times_s = np.asarray(times_s, dtype=float)
    jd = np.full(times_s.shape, satellite.jdsatepoch)
    fraction = satellite.jdsatepochF + times_s / 86400.0
    errors, r_km, v_km_s = satellite.sgp4_array(jd, fraction)
    if np.any(errors):
        first = int(np.flatnonzero(errors)[0])
        raise ConfigError(
            f"orbit.tle: SGP4 fails {times_s[first]:g} s after the epoch (error code "
            f"{int(errors[first])}: the element set is not a valid near-Earth orbit, or it "
            f"decays during the run)"
        )
    t_centuries = (
        satellite.jdsatepoch + satellite.jdsatepochF - J2000_JD + TT_MINUS_UTC_S / 86400.0
    ) / 36525.0
    p = np.array(precession_matrix(t_centuries))
    state = np.empty((times_s.size, 6))
    state[:, :3] = r_km @ p * 1e3  # r_J2000 = P^T r_MOD, row vectors
    state[:, 3:] = v_km_s @ p * 1e3
    return state
