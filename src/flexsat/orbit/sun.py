"""The Sun: its low-precision analytic ephemeris and the Earth's conical shadow (numba).

The Sun's geocentric position follows the low-accuracy analytic theory of Meeus
(*Astronomical Algorithms*, 2nd ed., ch. 25; the same kind as the Astronomical
Almanac's low-precision formulae, 0.01 deg), in the mean equator and equinox of date,
rotated to J2000 by the IAU 1976 precession. The shadow is the conical model with penumbra
(Montenbruck and Gill, *Satellite Orbits*, 2000, sec. 3.4.2): the fraction of the
Sun's disc the Earth's disc leaves visible. docs/orbit.md, 'The Sun and the shadow'.
"""

from __future__ import annotations

from math import acos, asin, cos, pi, radians, sin, sqrt

from numba import njit

from flexsat.orbit.time import J2000_JD, precession_matrix

__all__ = [
    "AU_M",
    "EARTH_RADIUS_M",
    "SUN_RADIUS_M",
    "illuminated_fraction",
    "sun_position",
]

AU_M = 149597870700.0
"""Astronomical unit [m] (IAU 2012)."""
SUN_RADIUS_M = 695700000.0
"""Nominal solar radius [m] (IAU 2015 B3)."""
EARTH_RADIUS_M = 6378137.0
"""Earth's equatorial radius [m] (WGS-84), the shadow's and the orbit's."""


@njit(cache=True, error_model="numpy")
def sun_position(jd_tt):
    """Geocentric position of the Sun in the J2000 frame (ECI), aberration included.

    Meeus, *Astronomical Algorithms*, 2nd ed., ch. 25 (low accuracy), T in Julian
    centuries of TT since J2000: mean longitude L0 = 280.46646 + 36000.76983 T
    + 0.0003032 T^2, mean anomaly M = 357.52911 + 35999.05029 T - 0.0001537 T^2,
    equation of the centre C = (1.914602 - 0.004817 T - 0.000014 T^2) sin M
    + (0.019993 - 0.000101 T) sin 2M + 0.000289 sin 3M [deg]; longitude
    L0 + C - 0.00569 deg (annual aberration), on the mean ecliptic and equinox of date
    (latitude < 1.2 arcsec, neglected); distance R = 1.000001018 (1 - e^2) /
    (1 + e cos(M + C)) AU, e = 0.016708634 - 0.000042037 T; mean obliquity
    eps = 23.4392911 - 0.0130042 T [deg]; then the IAU 1976 precession's transpose to
    J2000. Nutation is left out (it moves the equinox of date, not the J2000 frame).

    Parameters
    ----------
    jd_tt : float
        Julian date, Terrestrial Time [d].

    Returns
    -------
    (float, float, float)
        The Sun's position, ECI [m].
    """
    t = (jd_tt - J2000_JD) / 36525.0
    mean_longitude = 280.46646 + 36000.76983 * t + 0.0003032 * t * t
    m = radians(357.52911 + 35999.05029 * t - 0.0001537 * t * t)
    centre = (
        (1.914602 - 0.004817 * t - 0.000014 * t * t) * sin(m)
        + (0.019993 - 0.000101 * t) * sin(2.0 * m)
        + 0.000289 * sin(3.0 * m)
    )
    longitude = radians(mean_longitude + centre - 0.00569)
    e = 0.016708634 - 0.000042037 * t
    distance = 1.000001018 * (1.0 - e * e) / (1.0 + e * cos(m + radians(centre))) * AU_M
    eps = radians(23.4392911 - 0.0130042 * t)
    x = distance * cos(longitude)
    y = distance * cos(eps) * sin(longitude)
    z = distance * sin(eps) * sin(longitude)
    p = precession_matrix(t)
    return (
        p[0][0] * x + p[1][0] * y + p[2][0] * z,
        p[0][1] * x + p[1][1] * y + p[2][1] * z,
        p[0][2] * x + p[1][2] * y + p[2][2] * z,
    )


@njit(cache=True, error_model="numpy")
def illuminated_fraction(rx, ry, rz, sx, sy, sz, sun_distance):
    """Fraction of the Sun's disc visible from the satellite (conical shadow, penumbra).

    With a = asin(R_sun / d) the Sun's apparent radius, b = asin(R_E / ‖r‖) the
    Earth's and c the angle between them seen from the satellite: 1 for c >= a + b,
    0 for c <= b - a (umbra), 1 - b^2 / a^2 in an annular eclipse (c <= a - b), else
    1 - A / (pi a^2) with A the area of the discs' overlap (Montenbruck and Gill,
    eqs. 3.85-3.87).

    Parameters
    ----------
    rx, ry, rz : float
        Satellite position, ECI [m].
    sx, sy, sz : float
        Unit vector from the satellite to the Sun, ECI [-].
    sun_distance : float
        Satellite-Sun distance [m].

    Returns
    -------
    float
        Illuminated fraction in [0, 1] (1 sunlit, 0 umbra).
    """
    r = sqrt(rx * rx + ry * ry + rz * rz)
    a = asin(min(SUN_RADIUS_M / sun_distance, 1.0))
    b = asin(min(EARTH_RADIUS_M / r, 1.0))
    cos_c = -(rx * sx + ry * sy + rz * sz) / r
    c = acos(max(-1.0, min(1.0, cos_c)))
    if c >= a + b:
        return 1.0
    if c <= b - a:
        return 0.0
    if c <= a - b:
        return 1.0 - (b * b) / (a * a)
    x = (c * c + a * a - b * b) / (2.0 * c)
    y = sqrt(max(a * a - x * x, 0.0))
    area = a * a * acos(max(-1.0, min(1.0, x / a)))
    area += b * b * acos(max(-1.0, min(1.0, (c - x) / b))) - c * y
    return max(0.0, min(1.0, 1.0 - area / (pi * a * a)))
