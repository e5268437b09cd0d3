"""The geomagnetic field, and its torque on the satellite's residual magnetic dipole.

Default: the tilted dipole, the degree-1 terms of IGRF (Wertz, *Spacecraft
Attitude Determination and Control*, sec. 5.1, eq. H-23; docs/environment.md,
'Geomagnetic field')::

    B = (R_E / r)^3 [ 3 (m . r_hat) r_hat - m ],   m = (g_1^1, h_1^1, g_1^0)  (ECEF)

with r in the Earth-fixed frame (the ECI position turned about z by the Greenwich
sidereal angle) and the IGRF-14 2020.0 coefficients. Option ``field = "igrf"``: the full
IGRF model from the optional ``ppigrf`` package, evaluated at every ephemeris row
before the run (at the epoch's date) and interpolated linearly in time. The torque
on a residual dipole m_res (hub frame B) [A m^2] is tau = m_res x B_B.
"""

from __future__ import annotations

from datetime import datetime
from math import cos, sin, sqrt
from typing import Literal

import numpy as np
from numba import njit
from pydantic import Field

from flexsat.config.models import Vector3
from flexsat.environment.registry import (
    EPH_GMST,
    EPH_R,
    EPH_T,
    EnvironmentModelConfig,
    EnvironmentModelSpec,
    load_kernel,
)
from flexsat.errors import ConfigError

__all__ = ["IGRF_DIPOLE_NT", "MAGNETIC", "MagneticConfig", "field_at", "igrf_field",
           "magnetic_load"]  # fmt: skip

IGRF_DIPOLE_NT = (-1451.37, 4653.35, -29403.41)
"""IGRF-14 (DGRF) at 2020.0: (g_1^1, h_1^1, g_1^0) [nT], the dipole's ECEF components."""
REFERENCE_RADIUS = 6_371_200.0
"""IGRF's reference radius a [m]."""

_MODE, _A, _M, _RES, _TABLE = 0, 1, 2, 5, 8  # packed; then the field table if tabulated


class MagneticConfig(EnvironmentModelConfig):
    """Geomagnetic field and the residual dipole it torques (module docstring)."""

    kind: Literal["magnetic"] = Field("magnetic", description="the model")
    field: Literal["dipole", "igrf"] = Field(
        "dipole", description="tilted dipole (IGRF degree 1) or the full IGRF (ppigrf)"
    )
    residual_dipole_a_m2: Vector3 = Field(
        (0.0, 0.0, 0.0), description="residual magnetic dipole of the satellite, hub frame B "
        "[A m^2]"
    )  # fmt: skip

    def packed(self, context) -> np.ndarray:
        """mode (0 dipole, 1 tabulated), a [m], the dipole m (3) [T], m_res (3) [A m^2],
        then, tabulated: the step [s], its length and B (ECI) [T] at each row."""
        head = [0.0 if self.field == "dipole" else 1.0, REFERENCE_RADIUS,
                *(1e-9 * np.array(IGRF_DIPOLE_NT)), *self.residual_dipole_a_m2]  # fmt: skip
        if self.field == "dipole":
            return np.array(head)
        eph = context.ephemeris
        table = igrf_field(eph, context.epoch)
        step = float(eph[1, EPH_T] - eph[0, EPH_T])
        return np.concatenate([head, [step, eph.shape[0]], table.ravel()])


def igrf_field(eph: np.ndarray, epoch: str, max_degree: int = 13) -> np.ndarray:
    """The IGRF field (``ppigrf``) at every row of an ephemeris table, ECI.

    Parameters
    ----------
    eph : ndarray, shape (n, 13)
        The ephemeris (:data:`~flexsat.environment.registry.EPHEMERIS_COLUMNS`)
        [s, m, m/s, -, m, -, rad].
    epoch : str
        Its epoch, ISO 8601 UTC: the date of the coefficients.
    max_degree : int
        Highest degree of the expansion (1: the dipole).

    Returns
    -------
    ndarray, shape (n, 3)
        B, ECI [T].
    """
    try:
        import ppigrf
    except ImportError:
        raise ConfigError("environment.magnetic.field = 'igrf' needs the optional ppigrf "
                          "package: pip install 'flexsat[environment]'") from None  # fmt: skip
    date = datetime.fromisoformat(epoch.replace("Z", "+00:00")).replace(tzinfo=None)
    c, s = np.cos(eph[:, EPH_GMST]), np.sin(eph[:, EPH_GMST])
    x, y, z = eph[:, EPH_R], eph[:, EPH_R + 1], eph[:, EPH_R + 2]
    xe, ye = c * x + s * y, -s * x + c * y
    r = np.sqrt(x * x + y * y + z * z)
    theta, phi = np.arccos(z / r), np.arctan2(ye, xe)
    br, bt, bp = (np.ravel(b) for b in ppigrf.igrf_gc(r / 1e3, np.degrees(theta),
                                                         np.degrees(phi), date,
                                                         max_degree=max_degree))  # fmt: skip
    st, ct, sp, cp = np.sin(theta), np.cos(theta), np.sin(phi), np.cos(phi)
    bx = br * st * cp + bt * ct * cp - bp * sp
    by = br * st * sp + bt * ct * sp + bp * cp
    bz = br * ct - bt * st
    out = np.column_stack([c * bx - s * by, s * bx + c * by, bz])  # ECEF -> ECI
    return 1e-9 * np.ascontiguousarray(out)


@njit(cache=True)
def field_at(eph, params):
    """The geomagnetic field at an ephemeris row (module docstring).

    Parameters
    ----------
    eph : ndarray, shape (13,)
        The ephemeris row (``EPHEMERIS_COLUMNS``, ECI) [s, m, m/s, -, m, -, rad].
    params : ndarray
        The magnetic model's packed parameters (``MagneticConfig.packed``) [SI].

    Returns
    -------
    tuple of 3 float
        B, ECI [T]: the tilted dipole, or the tabulated IGRF interpolated in time.
    """
    if params[_MODE] != 0.0:
        step, n = params[_TABLE], int(params[_TABLE + 1])
        u = max(0.0, eph[EPH_T] / step)
        i = min(int(u), n - 2)
        w = min(1.0, u - i)
        b = _TABLE + 2 + 3 * i
        return ((1.0 - w) * params[b] + w * params[b + 3],
                (1.0 - w) * params[b + 1] + w * params[b + 4],
                (1.0 - w) * params[b + 2] + w * params[b + 5])  # fmt: skip
    c, s = cos(eph[EPH_GMST]), sin(eph[EPH_GMST])
    x, y, z = eph[EPH_R], eph[EPH_R + 1], eph[EPH_R + 2]
    xe, ye = c * x + s * y, -s * x + c * y  # ECEF
    r = sqrt(x * x + y * y + z * z)
    ux, uy, uz = xe / r, ye / r, z / r
    mx, my, mz = params[_M], params[_M + 1], params[_M + 2]
    ratio = params[_A] / r
    k = ratio * ratio * ratio
    along = 3.0 * (mx * ux + my * uy + mz * uz)
    bx, by, bz = k * (along * ux - mx), k * (along * uy - my), k * (along * uz - mz)
    return c * bx - s * by, s * bx + c * by, bz


@njit(cache=True)  # compiled with LOAD_SIGNATURE on first use
@load_kernel
def magnetic_load(eph, C_BN, points, surfaces, params, force, torque):
    """tau = m_res x B_B on the hub (module docstring).

    {contract}
    """
    bx, by, bz = field_at(eph, params)
    b0 = C_BN[0, 0] * bx + C_BN[0, 1] * by + C_BN[0, 2] * bz
    b1 = C_BN[1, 0] * bx + C_BN[1, 1] * by + C_BN[1, 2] * bz
    b2 = C_BN[2, 0] * bx + C_BN[2, 1] * by + C_BN[2, 2] * bz
    m0, m1, m2 = params[_RES], params[_RES + 1], params[_RES + 2]
    torque[0] += m1 * b2 - m2 * b1
    torque[1] += m2 * b0 - m0 * b2
    torque[2] += m0 * b1 - m1 * b0
    return 0


MAGNETIC = EnvironmentModelSpec(
    name="magnetic", config=MagneticConfig, load=magnetic_load,
    description="geomagnetic field (tilted dipole or IGRF) on the residual dipole",
)  # fmt: skip
