"""Solar radiation pressure on every surface: specular, diffuse and absorbed photons.

A flat surface of area A and outward normal n, lit by the Sun in direction s (unit,
satellite to Sun) at cos(theta) = n . s > 0, takes (Montenbruck & Gill, *Satellite
Orbits*, sec. 3.4.2; Vallado, *Fundamentals of Astrodynamics and Applications*,
sec. 8.6.4; docs/environment.md, 'Solar radiation pressure')::

    F = -P A cos(theta) [ (1 - c_s) s + 2 (c_s cos(theta) + c_d / 3) n ]

with c_s, c_d and c_a = 1 - c_s - c_d the specular, diffuse and absorbed fractions
and P = nu (Phi / c) (AU / d)^2 the pressure at the satellite-Sun distance d,
nu the lit fraction of the solar disc (0 in umbra). A surface facing away from the
Sun (cos(theta) <= 0) takes none; a panel is two surfaces, front and back. Shadows
one part of the satellite casts on another are not modelled.
"""

from __future__ import annotations

from typing import Literal

import numpy as np
from numba import njit
from pydantic import Field

from flexsat.environment.registry import (
    EPH_LIT,
    EPH_S,
    EPH_SUN_DISTANCE,
    SURF_AREA,
    SURF_DIFFUSE,
    SURF_NORMAL,
    SURF_SPECULAR,
    EnvironmentModelConfig,
    EnvironmentModelSpec,
    load_kernel,
)

__all__ = ["ASTRONOMICAL_UNIT", "SOLAR_PRESSURE", "SRP", "SrpConfig", "srp_load"]

ASTRONOMICAL_UNIT = 149_597_870_700.0
"""The astronomical unit [m] (IAU 2012)."""
SOLAR_PRESSURE = 1361.0 / 299_792_458.0
"""Phi / c at 1 AU: the total solar irradiance 1361 W/m^2 (IAU 2015 B3) over the
speed of light [N/m^2]."""


class SrpConfig(EnvironmentModelConfig):
    """Solar radiation pressure on the hub faces and the panels' two sides."""

    kind: Literal["srp"] = Field("srp", description="the model")
    pressure_n_m2: float = Field(
        SOLAR_PRESSURE, gt=0.0, le=1e-3, description="Phi / c at 1 AU [N/m^2]"
    )

    def packed(self, context) -> np.ndarray:
        """P at 1 AU [N/m^2], the astronomical unit [m]."""
        return np.array([self.pressure_n_m2, ASTRONOMICAL_UNIT])


@njit(cache=True)  # compiled with LOAD_SIGNATURE on first use
@load_kernel
def srp_load(eph, C_BN, points, surfaces, params, force, torque):
    """The pressure force on each lit surface's centre, frame B (module docstring).

    {contract}
    """
    lit = eph[EPH_LIT]
    if lit <= 0.0:
        return 0
    ratio = params[1] / eph[EPH_SUN_DISTANCE]
    pressure = lit * params[0] * ratio * ratio
    sx, sy, sz = eph[EPH_S], eph[EPH_S + 1], eph[EPH_S + 2]
    s0 = C_BN[0, 0] * sx + C_BN[0, 1] * sy + C_BN[0, 2] * sz
    s1 = C_BN[1, 0] * sx + C_BN[1, 1] * sy + C_BN[1, 2] * sz
    s2 = C_BN[2, 0] * sx + C_BN[2, 1] * sy + C_BN[2, 2] * sz
    k = points.shape[0]
    for j in range(surfaces.shape[0]):
        row = surfaces[j]
        n0, n1, n2 = row[SURF_NORMAL], row[SURF_NORMAL + 1], row[SURF_NORMAL + 2]
        c = n0 * s0 + n1 * s1 + n2 * s2
        if c <= 0.0:
            continue
        spec, diff = row[SURF_SPECULAR], row[SURF_DIFFUSE]
        a = -pressure * row[SURF_AREA] * c
        along_s = a * (1.0 - spec)
        along_n = a * 2.0 * (spec * c + diff / 3.0)
        force[k + j, 0] += along_s * s0 + along_n * n0
        force[k + j, 1] += along_s * s1 + along_n * n1
        force[k + j, 2] += along_s * s2 + along_n * n2
    return 0


SRP = EnvironmentModelSpec(
    name="srp", config=SrpConfig, load=srp_load,
    description="solar radiation pressure on every surface, scaled by the lit fraction",
)  # fmt: skip
