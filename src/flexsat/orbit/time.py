"""Time scales and Earth orientation: epochs, Julian dates, precession, sidereal angle.

The inertial frame of flexsat's orbits is the mean equator and equinox of J2000 (ECI;
the GCRF to within its 0.02 arcsec frame bias). Times are UTC at the boundary (an
ISO 8601 epoch), Terrestrial Time (TT) for the Sun's ephemeris and precession, and
UT1 taken equal to UTC for the Earth's rotation (‖UT1 - UTC‖ < 0.9 s: 0.004 deg of
Earth rotation). docs/orbit.md, 'Frames and time'.
"""

from __future__ import annotations

from datetime import UTC, datetime
from math import cos, pi, radians, sin

import numpy as np
from numba import njit

__all__ = [
    "DEG_PER_ARCSEC",
    "J2000_JD",
    "TT_MINUS_UTC_S",
    "earth_rotation_angle",
    "julian_date",
    "parse_epoch",
    "precession_angles",
    "precession_matrix",
]

J2000_JD = 2451545.0
"""Julian date of the J2000 epoch, 2000-01-01 12:00 TT [d]."""
TT_MINUS_UTC_S = 69.184
"""TT - UTC [s]: 32.184 s + 37 leap seconds (TAI - UTC since 2017-01-01; none added since)."""
DEG_PER_ARCSEC = 1.0 / 3600.0
_SECONDS_PER_DAY = 86400.0
_ARCSEC = radians(DEG_PER_ARCSEC)


def parse_epoch(text: str) -> datetime:
    """An ISO 8601 UTC time as an aware datetime.

    Parameters
    ----------
    text : str
        ``"2026-03-20T12:00:00"``, with an optional ``Z`` or ``+00:00``; a time without
        an offset is UTC.

    Returns
    -------
    datetime
        The time, in UTC.

    Raises
    ------
    ValueError
        Not an ISO 8601 time, or an offset other than UTC.
    """
    try:
        moment = datetime.fromisoformat(text.strip())
    except ValueError:
        raise ValueError(
            f"{text!r} is not an ISO 8601 UTC time (e.g. 2026-03-20T12:00:00Z)"
        ) from None
    if moment.tzinfo is None:
        return moment.replace(tzinfo=UTC)
    if moment.utcoffset().total_seconds() != 0.0:
        raise ValueError(f"{text!r} is not in UTC: give the time in UTC (offset Z or +00:00)")
    return moment.astimezone(UTC)


def julian_date(moment: datetime) -> tuple[float, float]:
    """The Julian date of a UTC time, in two parts for precision.

    Parameters
    ----------
    moment : datetime
        An aware UTC time.

    Returns
    -------
    (float, float)
        Whole-day part (ending in .5) and the fraction of the day [d]: their sum is
        the Julian date (UTC).
    """
    midnight = moment.replace(hour=0, minute=0, second=0, microsecond=0)
    days = (midnight - datetime(2000, 1, 1, tzinfo=UTC)).days
    seconds = (moment - midnight).total_seconds()
    return J2000_JD - 0.5 + days, seconds / _SECONDS_PER_DAY


@njit(cache=True, error_model="numpy")
def precession_angles(t_centuries):
    """IAU 1976 precession angles zeta, theta, z (Lieske et al. 1977).

    Parameters
    ----------
    t_centuries : float
        Julian centuries of TT since J2000 [cy].

    Returns
    -------
    (float, float, float)
        zeta, theta, z [rad]; r_MOD = R3(-z) R2(theta) R3(-zeta) r_J2000 (Vallado,
        *Fundamentals of Astrodynamics and Applications*, 4th ed., eq. 3-88).
    """
    t = t_centuries
    zeta = (2306.2181 * t + 0.30188 * t * t + 0.017998 * t * t * t) * _ARCSEC
    theta = (2004.3109 * t - 0.42665 * t * t - 0.041833 * t * t * t) * _ARCSEC
    z = (2306.2181 * t + 1.09468 * t * t + 0.018203 * t * t * t) * _ARCSEC
    return zeta, theta, z


@njit(cache=True, error_model="numpy")
def precession_matrix(t_centuries):
    """The rotation from J2000 to the mean equator and equinox of date (IAU 1976).

    Parameters
    ----------
    t_centuries : float
        Julian centuries of TT since J2000 [cy].

    Returns
    -------
    tuple of three 3-tuples
        P (rows), r_MOD = P r_J2000; its transpose takes mean-of-date to J2000.
    """
    zeta, theta, z = precession_angles(t_centuries)
    cz, sz = cos(zeta), sin(zeta)
    ct, st = cos(theta), sin(theta)
    cZ, sZ = cos(z), sin(z)
    return (
        (cZ * ct * cz - sZ * sz, -cZ * ct * sz - sZ * cz, -cZ * st),
        (sZ * ct * cz + cZ * sz, -sZ * ct * sz + cZ * cz, -sZ * st),
        (st * cz, -st * sz, ct),
    )


def earth_rotation_angle(
    jd_utc: float | np.ndarray, jd_fraction: float | np.ndarray = 0.0
) -> float | np.ndarray:
    """The rotation angle about z from the J2000 frame to the Earth-fixed frame.

    GMST (IAU 1982, Vallado eq. 3-47, UT1 = UTC) less the precession in right
    ascension zeta + z since J2000, so that ``R3(angle) r_ECI`` is Earth-fixed to
    within the precession's pole tilt theta (0.15 deg in 2026), nutation (< 0.005
    deg) and polar motion. Unwrapped: continuous in time.

    Parameters
    ----------
    jd_utc : float or ndarray
        Julian date (UTC), or its whole-day part [d].
    jd_fraction : float or ndarray
        The rest of the Julian date [d]: the two parts keep the time to 1e-7 s
        (a Julian date alone resolves 4e-5 s).

    Returns
    -------
    float or ndarray
        The angle [rad], not reduced to [0, 2 pi).
    """
    t = ((np.asarray(jd_utc, dtype=float) - J2000_JD) + jd_fraction) / 36525.0
    gmst_s = (
        67310.54841 + (876600.0 * 3600.0 + 8640184.812866) * t + 0.093104 * t**2 - 6.2e-6 * t**3
    )
    gmst = gmst_s * (2.0 * pi / _SECONDS_PER_DAY)
    t_tt = t + TT_MINUS_UTC_S / _SECONDS_PER_DAY / 36525.0
    zeta = (2306.2181 * t_tt + 0.30188 * t_tt**2 + 0.017998 * t_tt**3) * _ARCSEC
    z = (2306.2181 * t_tt + 1.09468 * t_tt**2 + 0.018203 * t_tt**3) * _ARCSEC
    return gmst - zeta - z
