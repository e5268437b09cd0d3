"""The ephemeris a run reads: the orbit, the Sun and the shadow on a time grid, interpolated.

The table ``eph`` (n, 13), float64, C-contiguous, on a uniform grid from t = 0 (the
run's time, seconds since the orbit's epoch) to at least the end of the run, one row
per instant, columns :data:`EPHEMERIS_COLUMNS`:

- ``t`` [s]; ``rx, ry, rz`` [m] and ``vx, vy, vz`` [m/s], the satellite in the J2000
  frame (ECI);
- ``sx, sy, sz``: unit vector from the satellite to the Sun, ECI; ``sun_distance`` [m];
- ``lit``: the illuminated fraction of the solar disc, in [0, 1] (conical shadow with
  penumbra: 1 sunlit, 0 umbra);
- ``gmst`` [rad]: the rotation angle about z from ECI to the Earth-fixed frame
  (:func:`flexsat.orbit.time.earth_rotation_angle`), unwrapped (continuous in t).

:func:`ephemeris_at` interpolates it in compiled code without allocating.
docs/orbit.md, 'The ephemeris'.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import lru_cache
from math import ceil, floor, pi, sqrt

import numpy as np
from numba import njit

from flexsat.orbit.config import OrbitConfig
from flexsat.orbit.propagate import propagate_elements, propagate_tle, tle_epoch_jd
from flexsat.orbit.sun import illuminated_fraction, sun_position
from flexsat.orbit.time import (
    TT_MINUS_UTC_S,
    earth_rotation_angle,
    julian_date,
    parse_epoch,
)

__all__ = [
    "COLUMN",
    "EPHEMERIS_COLUMNS",
    "Ephemeris",
    "build_ephemeris",
    "ephemeris_at",
    "ephemeris_for_run",
    "fill_sun_and_shadow",
]

EPHEMERIS_COLUMNS = (
    "t", "rx", "ry", "rz", "vx", "vy", "vz", "sx", "sy", "sz", "sun_distance", "lit", "gmst",
)  # fmt: skip
"""The ephemeris table's columns, in order (module docstring)."""
COLUMN = {name: k for k, name in enumerate(EPHEMERIS_COLUMNS)}
"""Column index by name."""
_SECONDS_PER_DAY = 86400.0


@dataclass(frozen=True)
class Ephemeris:
    """The ephemeris of a run.

    Parameters
    ----------
    table : ndarray, shape (n, 13)
        float64, C-contiguous; columns :data:`EPHEMERIS_COLUMNS`, row k at t = k step_s
        [s, m, m/s, -, m, -, rad].
    epoch : str
        The UTC time of t = 0, ISO 8601.
    step_s : float
        The grid step [s].
    """

    table: np.ndarray
    epoch: str
    step_s: float

    @property
    def duration_s(self) -> float:
        """The last time of the grid [s]."""
        return float(self.table[-1, 0])


@njit(cache=True, error_model="numpy")
def fill_sun_and_shadow(eph, jd0_utc_whole, jd0_utc_fraction):
    """Fill the Sun direction, distance and illuminated fraction of every row.

    Parameters
    ----------
    eph : ndarray, shape (n, 13)
        The table, columns t and r filled; sx..lit written [in place].
    jd0_utc_whole, jd0_utc_fraction : float
        The epoch's Julian date (UTC), in two parts [d].
    """
    for k in range(eph.shape[0]):
        jd_tt = jd0_utc_whole + (jd0_utc_fraction + (eph[k, 0] + TT_MINUS_UTC_S) / _SECONDS_PER_DAY)
        xs, ys, zs = sun_position(jd_tt)
        dx, dy, dz = xs - eph[k, 1], ys - eph[k, 2], zs - eph[k, 3]
        d = sqrt(dx * dx + dy * dy + dz * dz)
        eph[k, 7], eph[k, 8], eph[k, 9], eph[k, 10] = dx / d, dy / d, dz / d, d
        eph[k, 11] = illuminated_fraction(
            eph[k, 1], eph[k, 2], eph[k, 3], eph[k, 7], eph[k, 8], eph[k, 9], d
        )


def build_ephemeris(
    orbit_config: OrbitConfig, duration_s: float, step_s: float | None = None
) -> Ephemeris:
    """Propagate an orbit once and tabulate it, with the Sun and the shadow, for a run.

    Parameters
    ----------
    orbit_config : OrbitConfig
        The ``[orbit]`` table (elements: two-body + J2 by DOP853; a TLE: SGP4).
    duration_s : float
        The run's duration [s]; the grid covers [0, duration_s] and one step more.
    step_s : float, optional
        Grid step [s]; default ``orbit_config.ephemeris_step_s``.

    Returns
    -------
    Ephemeris
        The table on t = 0, step_s, ..., n step_s >= duration_s + step_s.

    Raises
    ------
    ConfigError
        A TLE SGP4 cannot propagate, or sgp4 missing for a TLE.
    """
    step = float(orbit_config.ephemeris_step_s if step_s is None else step_s)
    if not step > 0.0:
        raise ValueError(f"step_s must be > 0 s, got {step:g}")
    n = ceil(duration_s / step) + 2
    times = np.arange(n) * step
    if orbit_config.tle is not None:
        jd_whole, jd_fraction = tle_epoch_jd(orbit_config)
        # the TLE's epoch, to the microsecond, as an ISO string
        seconds = round(((jd_whole - floor(jd_whole)) + jd_fraction - 0.5) * 86400.0, 6)
        moment = np.datetime64("2000-01-01T12:00:00", "us") + np.timedelta64(
            round((floor(jd_whole) + 0.5 - 2451545.0) * 86400e6 + seconds * 1e6), "us"
        )
        epoch = f"{np.datetime_as_string(moment, unit='us')}Z"
        state = propagate_tle(orbit_config, times)
    else:
        epoch = orbit_config.epoch
        jd_whole, jd_fraction = julian_date(parse_epoch(epoch))
        state = propagate_elements(orbit_config, times)
    table = np.zeros((n, len(EPHEMERIS_COLUMNS)))
    table[:, 0] = times
    table[:, 1:7] = state
    fill_sun_and_shadow(table, jd_whole, jd_fraction)
    angle = earth_rotation_angle(jd_whole, jd_fraction + times / _SECONDS_PER_DAY)
    table[:, 12] = angle - 2.0 * pi * floor(angle[0] / (2.0 * pi))
    return Ephemeris(table=np.ascontiguousarray(table), epoch=epoch, step_s=step)


@lru_cache(maxsize=4)
def ephemeris_for_run(orbit_config: OrbitConfig, duration_s: float) -> Ephemeris:
    """The ephemeris of a run, built once for every reader of the run (memoized).

    The references and the environment read the same table; a run's stages are
    packed more than once (the layout, the data), and the propagation is not redone.
    The table is shared: read it, do not write it.

    Parameters
    ----------
    orbit_config : OrbitConfig
        The ``[orbit]`` table.
    duration_s : float
        The run's duration [s].

    Returns
    -------
    Ephemeris
        :func:`build_ephemeris` at the orbit's ``ephemeris_step_s``.
    """
    return build_ephemeris(orbit_config, duration_s)


@njit(cache=True, error_model="numpy")
def ephemeris_at(eph, t, out):
    """The ephemeris at time ``t``, interpolated, written into ``out`` (no allocation).

    r is the cubic Hermite interpolant of the two bracketing rows' r and v, and v its
    derivative (both exact to O(h^4) and O(h^3) in the step h); sun_distance and gmst
    are linear, s linear and renormalised; ``lit`` is evaluated from the interpolated
    geometry (:func:`flexsat.orbit.sun.illuminated_fraction`), so that a penumbra
    shorter than the grid step is resolved. ``t`` outside the grid is held at its end.

    Parameters
    ----------
    eph : ndarray, shape (n, 13)
        The table (module docstring), n >= 2 [s, m, m/s, -, m, -, rad].
    t : float
        Time since the epoch [s].
    out : ndarray, shape (13,)
        The columns at ``t`` [written].
    """
    n = eph.shape[0]
    h = eph[1, 0] - eph[0, 0]
    t = min(max(t, eph[0, 0]), eph[n - 1, 0])
    k = int((t - eph[0, 0]) / h)
    if k > n - 2:
        k = n - 2
    tau = (t - eph[k, 0]) / h
    t2 = tau * tau
    t3 = t2 * tau
    h00 = 2.0 * t3 - 3.0 * t2 + 1.0
    h10 = t3 - 2.0 * t2 + tau
    h01 = -2.0 * t3 + 3.0 * t2
    h11 = t3 - t2
    d00 = (6.0 * t2 - 6.0 * tau) / h
    d10 = 3.0 * t2 - 4.0 * tau + 1.0
    d01 = (-6.0 * t2 + 6.0 * tau) / h
    d11 = 3.0 * t2 - 2.0 * tau
    out[0] = t
    for i in range(3):
        r0, r1 = eph[k, 1 + i], eph[k + 1, 1 + i]
        v0, v1 = eph[k, 4 + i], eph[k + 1, 4 + i]
        out[1 + i] = h00 * r0 + h10 * h * v0 + h01 * r1 + h11 * h * v1
        out[4 + i] = d00 * r0 + d10 * v0 + d01 * r1 + d11 * v1
    for j in range(7, 13):
        out[j] = (1.0 - tau) * eph[k, j] + tau * eph[k + 1, j]
    norm = sqrt(out[7] * out[7] + out[8] * out[8] + out[9] * out[9])
    out[7] /= norm
    out[8] /= norm
    out[9] /= norm
    out[11] = illuminated_fraction(out[1], out[2], out[3], out[7], out[8], out[9], out[10])
