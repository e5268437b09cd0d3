"""Aerodynamic drag on every surface, in an atmosphere that turns with the Earth.

The flow meets the satellite at v_rel = v - omega_E x r (ECI; the atmosphere
co-rotates with the Earth). A flat surface of area A, outward normal n and drag
coefficient C_D facing the flow (cos(alpha) = n . u > 0, u = v_rel / ‖v_rel‖) takes
(Vallado, *Fundamentals of Astrodynamics and Applications*, sec. 8.6.2;
docs/environment.md, 'Aerodynamic drag')::

    F = -1/2 rho C_D A cos(alpha) ‖v_rel‖^2 u

the projected area A cos(alpha) of a flat plate; a surface in the wake takes none.
The density rho at altitude h = ‖r‖ - R_E comes from the exponential atmosphere of
Vallado's Table 8-4 (rho = rho_0 exp(-(h - h_0) / H) in the band of base h_0),
the default, or from NRLMSIS 2.1 (``density = "nrlmsis"``, the optional
``pymsis`` package) tabulated along the ephemeris before the run and interpolated
linearly in time.
"""

from __future__ import annotations

from datetime import datetime, timedelta
from math import exp, sqrt
from typing import Annotated, Literal

import numpy as np
from numba import njit
from pydantic import Field

from flexsat.environment.registry import (
    EPH_GMST,
    EPH_R,
    EPH_T,
    EPH_V,
    SURF_AREA,
    SURF_DRAG,
    SURF_NORMAL,
    EnvironmentModelConfig,
    EnvironmentModelSpec,
    load_kernel,
)
from flexsat.errors import ConfigError

__all__ = ["DRAG", "EARTH_RADIUS", "EARTH_ROTATION", "VALLADO_ATMOSPHERE", "DragConfig",
           "drag_load", "exponential_density"]  # fmt: skip

EARTH_RADIUS = 6_378_137.0
"""The Earth's equatorial radius [m] (WGS 84)."""
EARTH_ROTATION = 7.292115e-5
"""The Earth's rotation rate [rad/s] (WGS 84)."""

VALLADO_ATMOSPHERE = np.array([
    # base altitude h_0 [km], nominal density rho_0 [kg/m^3], scale height H [km]
    (0.0, 1.225, 7.249), (25.0, 3.899e-2, 6.349), (30.0, 1.774e-2, 6.682),
    (40.0, 3.972e-3, 7.554), (50.0, 1.057e-3, 8.382), (60.0, 3.206e-4, 7.714),
    (70.0, 8.770e-5, 6.549), (80.0, 1.905e-5, 5.799), (90.0, 3.396e-6, 5.382),
    (100.0, 5.297e-7, 5.877), (110.0, 9.661e-8, 7.263), (120.0, 2.438e-8, 9.473),
    (130.0, 8.484e-9, 12.636), (140.0, 3.845e-9, 16.149), (150.0, 2.070e-9, 22.523),
    (180.0, 5.464e-10, 29.740), (200.0, 2.789e-10, 37.105), (250.0, 7.248e-11, 45.546),
    (300.0, 2.418e-11, 53.628), (350.0, 9.518e-12, 53.298), (400.0, 3.725e-12, 58.515),
    (450.0, 1.585e-12, 60.828), (500.0, 6.967e-13, 63.822), (600.0, 1.454e-13, 71.835),
    (700.0, 3.614e-14, 88.667), (800.0, 1.170e-14, 124.64), (900.0, 5.245e-15, 181.05),
    (1000.0, 3.019e-15, 268.00),
])  # fmt: skip
"""Vallado's exponential atmosphere (Table 8-4): h_0 [km], rho_0 [kg/m^3], H [km]."""

_OMEGA, _RE, _MODE, _TABLE = 0, 1, 2, 3  # packed; then the bands or the density column
_BANDS = VALLADO_ATMOSPHERE.shape[0]


class DragConfig(EnvironmentModelConfig):
    """Aerodynamic drag on the hub faces and the panels (module docstring)."""

    kind: Literal["drag"] = Field("drag", description="the model")
    density: Literal["exponential", "nrlmsis"] = Field(
        "exponential", description="atmosphere: Vallado's exponential table or NRLMSIS 2.1"
    )
    f107: Annotated[float, Field(ge=50.0, le=400.0)] = Field(
        150.0, description="NRLMSIS: daily and 81-day F10.7 solar flux [sfu]"
    )
    ap: Annotated[float, Field(ge=0.0, le=400.0)] = Field(
        4.0, description="NRLMSIS: daily geomagnetic index Ap [-]"
    )

    def packed(self, context) -> np.ndarray:
        """omega_E [rad/s], R_E [m], mode (0 exponential, 1 tabulated), then Vallado's
        bands (h_0 [m], rho_0 [kg/m^3], H [m]) or, tabulated: the table's step [s],
        its length and rho [kg/m^3] at each ephemeris row."""
        head = [EARTH_ROTATION, EARTH_RADIUS]
        if self.density == "exponential":
            bands = VALLADO_ATMOSPHERE * np.array([1e3, 1.0, 1e3])
            return np.concatenate([head, [0.0], bands.ravel()])
        rho = nrlmsis_density(context.ephemeris, context.epoch, self.f107, self.ap)
        step = float(context.ephemeris[1, EPH_T] - context.ephemeris[0, EPH_T])
        return np.concatenate([head, [1.0, step, rho.size], rho])


def nrlmsis_density(eph: np.ndarray, epoch: str, f107: float, ap: float) -> np.ndarray:
    """NRLMSIS 2.1 mass density at every row of an ephemeris table.

    Parameters
    ----------
    eph : ndarray, shape (n, 13)
        The ephemeris (:data:`~flexsat.environment.registry.EPHEMERIS_COLUMNS`)
        [s, m, m/s, -, m, -, rad].
    epoch : str
        Its epoch, ISO 8601 UTC.
    f107 : float
        Daily and 81-day mean F10.7 [sfu].
    ap : float
        Daily Ap [-].

    Returns
    -------
    ndarray, shape (n,)
        Mass density [kg/m^3] (geocentric latitude and longitude, altitude above a
        sphere of radius R_E).
    """
    try:
        import pymsis
    except ImportError:
        raise ConfigError("environment.drag.density = 'nrlmsis' needs the optional pymsis "
                          "package: pip install 'flexsat[environment]'") from None  # fmt: skip
    start = datetime.fromisoformat(epoch.replace("Z", "+00:00")).replace(tzinfo=None)
    dates = np.array([np.datetime64(start + timedelta(seconds=float(t))) for t in eph[:, EPH_T]])
    c, s = np.cos(eph[:, EPH_GMST]), np.sin(eph[:, EPH_GMST])
    x, y, z = eph[:, EPH_R], eph[:, EPH_R + 1], eph[:, EPH_R + 2]
    xe, ye = c * x + s * y, -s * x + c * y  # ECI -> ECEF, about z by GMST
    r = np.sqrt(x * x + y * y + z * z)
    lat, lon = np.degrees(np.arcsin(z / r)), np.degrees(np.arctan2(ye, xe))
    n = eph.shape[0]
    out = pymsis.calculate(dates, lon, lat, (r - EARTH_RADIUS) / 1e3, np.full(n, f107),
                           np.full(n, f107), np.full((n, 7), ap))  # fmt: skip
    return np.ascontiguousarray(np.reshape(out, (n, -1))[:, 0], dtype=float)


@njit(cache=True)
def exponential_density(params, altitude):
    """The density of Vallado's exponential atmosphere at an altitude (E.6).

    Parameters
    ----------
    params : ndarray
        The drag model's packed parameters, its bands of Vallado's table from slot 3
        (h_0 [m], rho_0 [kg/m^3], H [m] each).
    altitude : float
        Height above the equatorial radius [m].

    Returns
    -------
    float
        rho [kg/m^3], of the band whose base is the highest at or below ``altitude``.
    """
    band = 0
    for b in range(_BANDS):
        if altitude >= params[_TABLE + 3 * b]:
            band = b
    h0, rho0, scale = params[_TABLE + 3 * band], params[_TABLE + 3 * band + 1], params[
        _TABLE + 3 * band + 2]  # fmt: skip
    return rho0 * exp(-(altitude - h0) / scale)


@njit(cache=True)
def _tabulated(params, t):
    step, n = params[_TABLE], int(params[_TABLE + 1])
    u = max(0.0, t / step)
    i = min(int(u), n - 2)
    w = min(1.0, u - i)
    return (1.0 - w) * params[_TABLE + 2 + i] + w * params[_TABLE + 3 + i]


@njit(cache=True)  # compiled with LOAD_SIGNATURE on first use
@load_kernel
def drag_load(eph, C_BN, points, surfaces, params, force, torque):
    """The drag force on each surface's centre facing the flow, frame B (module docstring).

    {contract}
    """
    rx, ry, rz = eph[EPH_R], eph[EPH_R + 1], eph[EPH_R + 2]
    w = params[_OMEGA]
    vx, vy, vz = eph[EPH_V] + w * ry, eph[EPH_V + 1] - w * rx, eph[EPH_V + 2]
    if params[_MODE] == 0.0:
        rho = exponential_density(params, sqrt(rx * rx + ry * ry + rz * rz) - params[_RE])
    else:
        rho = _tabulated(params, eph[EPH_T])
    speed = sqrt(vx * vx + vy * vy + vz * vz)
    if speed == 0.0:
        return 0
    u0 = (C_BN[0, 0] * vx + C_BN[0, 1] * vy + C_BN[0, 2] * vz) / speed
    u1 = (C_BN[1, 0] * vx + C_BN[1, 1] * vy + C_BN[1, 2] * vz) / speed
    u2 = (C_BN[2, 0] * vx + C_BN[2, 1] * vy + C_BN[2, 2] * vz) / speed
    q = 0.5 * rho * speed * speed
    k = points.shape[0]
    for j in range(surfaces.shape[0]):
        row = surfaces[j]
        c = row[SURF_NORMAL] * u0 + row[SURF_NORMAL + 1] * u1 + row[SURF_NORMAL + 2] * u2
        if c <= 0.0:
            continue
        a = -q * row[SURF_DRAG] * row[SURF_AREA] * c
        force[k + j, 0] += a * u0
        force[k + j, 1] += a * u1
        force[k + j, 2] += a * u2
    return 0


DRAG = EnvironmentModelSpec(
    name="drag", config=DragConfig, load=drag_load,
    description="aerodynamic drag on every surface, co-rotating exponential or NRLMSIS atmosphere",
)  # fmt: skip
