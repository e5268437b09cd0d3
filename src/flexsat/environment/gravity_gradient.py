"""Gravity gradient: the tidal field of a central gravity field across the satellite.

About the hub centre of mass, with o_B the unit vector towards the Earth's centre in
hub frame B and r the orbit radius, the hub's own torque is (Wie, *Space Vehicle
Dynamics and Control*, sec. 6.3; docs/environment.md, 'Gravity gradient')::

    tau_gg = 3 mu / r^3  o_B x (J_hub o_B)

and each mass element m_k at rho_k (frame B, from the hub centre of mass) takes the
tidal force of the field linearized about the orbit (‖rho_k‖ << r)::

    f_k = m_k mu / r^3 (3 o_B (o_B . rho_k) - rho_k)

so the mass elements' torque about the hub centre of mass,
sum rho_k x f_k = 3 mu / r^3 o_B x (J o_B), has the hub's form with J their inertia
about the hub centre of mass (docs/environment.md, 'Gravity gradient').
"""

from __future__ import annotations

from math import sqrt
from typing import Literal

import numpy as np
from numba import njit
from pydantic import Field

from flexsat.environment.registry import (
    EPH_R,
    EnvironmentModelConfig,
    EnvironmentModelSpec,
    load_kernel,
)

__all__ = ["GRAVITY_GRADIENT", "MU_EARTH", "GravityGradientConfig", "gravity_gradient_load"]

MU_EARTH = 3.986004418e14
"""The Earth's gravitational parameter [m^3/s^2] (WGS 84, EGM 96)."""


class GravityGradientConfig(EnvironmentModelConfig):
    """Gravity-gradient torque on the hub and tidal loads on the mass elements."""

    kind: Literal["gravity_gradient"] = Field("gravity_gradient", description="the model")
    mu_m3_s2: float = Field(MU_EARTH, gt=0.0, description="gravitational parameter [m^3/s^2]")

    def packed(self, context) -> np.ndarray:
        """mu [m^3/s^2], then the hub's inertia about its centre of mass, frame B,
        row-major (9) [kg m^2]."""
        return np.concatenate([[self.mu_m3_s2], np.ravel(context.hub_inertia)])


@njit(cache=True)  # compiled with LOAD_SIGNATURE on first use
@load_kernel
def gravity_gradient_load(eph, C_BN, points, surfaces, params, force, torque):
    """Hub torque 3 mu/r^3 o x (J o) and the tidal force on each mass element (module
    docstring), frame B; surfaces take none.

    {contract}
    """
    rx, ry, rz = eph[EPH_R], eph[EPH_R + 1], eph[EPH_R + 2]
    r = sqrt(rx * rx + ry * ry + rz * rz)
    k = params[0] / (r * r * r)
    # o_B: towards the Earth's centre, hub frame B
    o0 = -(C_BN[0, 0] * rx + C_BN[0, 1] * ry + C_BN[0, 2] * rz) / r
    o1 = -(C_BN[1, 0] * rx + C_BN[1, 1] * ry + C_BN[1, 2] * rz) / r
    o2 = -(C_BN[2, 0] * rx + C_BN[2, 1] * ry + C_BN[2, 2] * rz) / r
    J = params[1:10]
    j0 = J[0] * o0 + J[1] * o1 + J[2] * o2
    j1 = J[3] * o0 + J[4] * o1 + J[5] * o2
    j2 = J[6] * o0 + J[7] * o1 + J[8] * o2
    torque[0] += 3.0 * k * (o1 * j2 - o2 * j1)
    torque[1] += 3.0 * k * (o2 * j0 - o0 * j2)
    torque[2] += 3.0 * k * (o0 * j1 - o1 * j0)
    for i in range(points.shape[0]):
        px, py, pz, m = points[i, 0], points[i, 1], points[i, 2], points[i, 3]
        along = 3.0 * (o0 * px + o1 * py + o2 * pz)
        force[i, 0] += m * k * (along * o0 - px)
        force[i, 1] += m * k * (along * o1 - py)
        force[i, 2] += m * k * (along * o2 - pz)
    return 0


GRAVITY_GRADIENT = EnvironmentModelSpec(
    name="gravity_gradient", config=GravityGradientConfig, load=gravity_gradient_load,
    description="gravity-gradient torque on the hub, tidal force on every mass element",
)  # fmt: skip
