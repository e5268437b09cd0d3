"""Integral sliding-mode control: the attitude error's integral in the surface.

    s = omega_e + lambda q_v,e + z,   z = k_i int_0^t q_v,e dt - (omega_e + lambda q_v,e)(0)

(Utkin and Shi 1996, on the thesis's quaternion surface of eq. 4.6), so s(0) = 0:
the motion starts on the surface and there is no reaching phase. The command

    tau = omega x J omega - J (lambda q_v,e_dot + k_i q_v,e) - JK sat(s / Phi)

gives on the rigid design model (eq. 4.7) with a disturbance d exactly
J s_dot = -JK sat(s / Phi) + d, so V = s^T J s / 2 has V_dot = s^T (d - JK sgn(s))
< 0 outside the boundary layer when JK > D_max (eqs. 4.15-4.21). On the surface,
omega_e = -lambda q_v,e - z with z_dot = k_i q_v,e: for small errors (omega_e ~
2 q_v,e_dot) 2 q_v,e_ddot + lambda q_v,e_dot + k_i q_v,e = 0, a second-order
response of natural frequency (k_i / 2)^(1/2) and damping lambda / (8 k_i)^(1/2).
"""

from __future__ import annotations

from typing import Literal, NamedTuple

import numpy as np
from numba import njit
from pydantic import Field

from flexsat.compiled.linalg3 import mv
from flexsat.config.models import Positive
from flexsat.control.laws._sliding import (
    integral_diagnostics,
    law_terms,
    sat,
    store_integral_breakdown,
    surface_attributes,
)
from flexsat.control.laws.registry import LawConfig, LawSpec
from flexsat.control.registry import Channel

__all__ = ["ISMC", "ISMCConfig", "ISMCGains"]


class ISMCGains(NamedTuple):
    """The packed gains, in order (SI).

    Attributes
    ----------
    t_max : float
        T_max per axis [N m].
    reduction_factor : float
        RF [-].
    jk : float
        Robust torque JK [N m].
    lambda_ : float
        Surface slope [rad/s].
    k_i : float
        Integral gain of the surface [1/s^2].
    phi : float
        Boundary-layer width [rad/s].
    """

    t_max: float
    reduction_factor: float
    jk: float
    lambda_: float
    k_i: float
    phi: float


G = ISMCGains(*range(len(ISMCGains._fields)))  # index of each gain in the packed array


class ISMCConfig(LawConfig):
    """Integral sliding mode: s = omega_e + lambda q_v,e + k_i int q_v,e - s(0)."""

    kind: Literal["ismc"] = Field("ismc", description="the law's registered name")
    jk_nm: Positive = Field(0.8925, description="robust torque JK = D_max + eta [N m]")
    lambda_: Positive = Field(0.6, alias="lambda", description="surface slope [rad/s]")
    k_i: Positive = Field(0.045, description="integral gain of the surface [1/s^2]")
    phi: Positive = Field(0.01, description="boundary-layer width Phi [rad/s]")

    def gains(self, actuator) -> np.ndarray:
        return np.array(ISMCGains(
            actuator.t_max_nm, actuator.reduction_factor, self.jk_nm, self.lambda_, self.k_i,
            self.phi,
        ), dtype=float)  # fmt: skip

    def plot_attributes(self) -> dict[str, float | str]:
        return surface_attributes(self.lambda_, self.lambda_, self.phi, self.jk_nm)


@njit(cache=True)  # compiled with LAW_SIGNATURE on first use
def ismc_step(q_d, omega_d, omega_dot_d, q, omega_B, J, gains, state, t, dt, tau_cmd, diag):
    """The ISMC command (law contract in :mod:`flexsat.control.laws.registry`).

    ``state``: the surface's integral term z per axis [rad/s], and 1.0 once a call
    has been made (the first call sets z so that s = 0).
    """
    limit = gains[G.reduction_factor] * gains[G.t_max]
    qv, qv_dot, omega_e, _, J3, J_w_dot_d, tau_gyro = law_terms(
        q_d, omega_d, omega_dot_d, q, omega_B, J
    )
    lam, k_i, jk, phi = gains[G.lambda_], gains[G.k_i], gains[G.jk], gains[G.phi]
    if state[3] == 0.0:  # s(0) = 0: no reaching phase
        for a in range(3):
            state[a] = -(omega_e[a] + lam * qv[a])
        state[3] = 1.0
    s = (omega_e[0] + lam * qv[0] + state[0], omega_e[1] + lam * qv[1] + state[1],
         omega_e[2] + lam * qv[2] + state[2])  # fmt: skip
    # the equivalent control: s_dot = 0 on the rigid design model without disturbance
    Jw = mv(J3, (lam * qv_dot[0] + k_i * qv[0], lam * qv_dot[1] + k_i * qv[1],
                 lam * qv_dot[2] + k_i * qv[2]))  # fmt: skip
    tau_guide = (J_w_dot_d[0] - Jw[0], J_w_dot_d[1] - Jw[1], J_w_dot_d[2] - Jw[2])
    tau_rob = (-jk * sat(s[0] / phi), -jk * sat(s[1] / phi), -jk * sat(s[2] / phi))
    z = (state[0], state[1], state[2])
    store_integral_breakdown(limit, s, z, tau_gyro, tau_guide, tau_rob, tau_cmd, diag)
    for a in range(3):  # z_dot = k_i q_v,e, explicit Euler over the control period
        state[a] += k_i * qv[a] * dt
    return 0


ISMC = LawSpec(
    name="ismc", label="ISMC", config=ISMCConfig, step=ismc_step, state_size=4,
    diagnostics=integral_diagnostics(
        "s = w_e + L q_v,e + z",
        Channel("surface_integral", "rad/s", "z = k_i int q_v,e dt - s0", per_axis=True),
        "-J (L q_v,e_dot + k_i q_v,e)", "-JK sat(s/Phi)",
    ),
    description="integral sliding-mode control (no reaching phase)",
)  # fmt: skip
