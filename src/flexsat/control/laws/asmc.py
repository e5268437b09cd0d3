"""Adaptive sliding-mode control with torque-budget allocation (thesis ch. 4, sec. 5.1).

s = omega_e + Lambda q_v,e (eq. 4.6); tau = omega x J omega - J Lambda q_v,e_dot
- JK sat(s / Phi) (eq. 4.14), the slope Lambda adapted to the pointing error and
to the torque budget (eqs. 4.27-4.29), the robust gain JK per axis (eq. 4.30).

``lambda_adaptation = "smooth"`` replaces the piecewise-linear target of eq. 4.27
by a C1 smoothstep in theta_err and passes it through a first-order filter of time
constant ``lambda_time_constant_s`` (exact discretization at the control period),
the budget cap of eqs. 4.28-4.29 still applied at once; Lambda_dot is then bounded
and its term -J Lambda_dot q_v,e of eq. 4.12 is flown (``docs/control.md``,
"A smoother Lambda adaptation").
"""

from __future__ import annotations

from math import exp
from typing import Literal, NamedTuple

import numpy as np
from numba import njit
from pydantic import Field, model_validator

from flexsat.compiled.linalg3 import mv
from flexsat.config.models import Positive
from flexsat.control.laws._sliding import (
    SLIDING_DIAGNOSTICS,
    clip_and_store,
    law_terms,
    linear_sliding_feedback,
    sat,
    surface,
    surface_attributes,
    surface_guide,
)
from flexsat.control.laws.registry import LawConfig, LawSpec

__all__ = ["ASMC", "ASMCConfig", "ASMCGains"]


class ASMCGains(NamedTuple):
    """The packed gains, in order (SI).

    Attributes
    ----------
    t_max : float
        T_max per axis [N m].
    reduction_factor : float
        RF [-].
    jk_min : float
        JK_min [N m].
    lambda_min : float
        Lower bound Lambda_min of the surface slope [rad/s].
    lambda_max : float
        Upper bound Lambda_max of the surface slope [rad/s].
    phi : float
        Boundary-layer width Phi [rad/s].
    theta_threshold : float
        theta_th, the error angle where the slope starts to adapt [rad].
    include_lambda_dot : float
        1.0: add -J Lambda_dot q_v,e; 0.0: leave it out [-].
    smooth : float
        1.0: smoothstep target, filtered (module docstring); 0.0: the thesis's slope [-].
    lambda_time_constant : float
        tau_Lambda of the filter [s].
    """

    t_max: float
    reduction_factor: float
    jk_min: float
    lambda_min: float
    lambda_max: float
    phi: float
    theta_threshold: float
    include_lambda_dot: float
    smooth: float
    lambda_time_constant: float


G = ASMCGains(*range(len(ASMCGains._fields)))  # index of each gain in the packed array


class ASMCConfig(LawConfig):
    """Adaptive sliding-mode control with torque-budget allocation (thesis ch. 4, sec. 5.1)."""

    kind: Literal["asmc"] = Field("asmc", description="the law's registered name")
    jk_min_nm: Positive = Field(0.8925, description="JK_min = D_max + eta [N m] (eq. 4.21)")
    lambda_min: Positive = Field(0.2, description="slope far from the target [rad/s]")
    lambda_max: Positive = Field(5.0, description="slope near the target [rad/s]")
    phi: Positive = Field(0.01, description="boundary-layer width Phi [rad/s]")
    theta_threshold_deg: Positive = Field(5.0, description="theta_th of eq. 4.27 [deg]")
    include_lambda_dot: bool = Field(False, description="add -J Lambda_dot q_v,e (eq. 4.12)")
    lambda_adaptation: Literal["thesis", "smooth"] = Field(
        "thesis", description="Lambda's adaptation: eq. 4.27 as published, or a smoothstep "
        "target through a first-order filter (adds -J Lambda_dot q_v,e)"
    )  # fmt: skip
    lambda_time_constant_s: Positive = Field(
        2.0, description="smooth adaptation: time constant of Lambda's filter [s]"
    )

    @model_validator(mode="after")
    def _ordered(self) -> ASMCConfig:
        if self.lambda_max < self.lambda_min:
            raise ValueError(f"lambda_max must be >= lambda_min ({self.lambda_min})")
        return self

    def gains(self, actuator) -> np.ndarray:
        return np.array(ASMCGains(
            actuator.t_max_nm, actuator.reduction_factor, self.jk_min_nm, self.lambda_min,
            self.lambda_max, self.phi, np.radians(self.theta_threshold_deg),
            float(self.include_lambda_dot),
            float(self.lambda_adaptation == "smooth"), self.lambda_time_constant_s,
        ), dtype=float)  # fmt: skip

    def plot_attributes(self) -> dict[str, float | str]:
        return {**surface_attributes(self.lambda_min, self.lambda_max, self.phi, self.jk_min_nm),
                "theta_threshold_deg": self.theta_threshold_deg}  # fmt: skip

    def linear_feedback(self, J: np.ndarray) -> np.ndarray:
        # At the target: Lambda_target = lambda_max (eq. 4.27 at theta = 0), never cut
        # by the budget (J q_v,e_dot -> 0, eq. 4.28), and JK = JK_min at s = 0 (eq. 4.30).
        return linear_sliding_feedback(J, self.lambda_max, self.jk_min_nm, self.phi)


@njit(cache=True)
def _jk(jk_min, limit, tau_gyro, tau_guide, s, phi):
    """Eq. 4.30 on one axis: JK_min + (JK_avail - JK_min) min(|s| / Phi, 1)."""
    avail = max(jk_min, limit - abs(tau_gyro) - abs(tau_guide))
    return jk_min + (avail - jk_min) * min(abs(s) / phi, 1.0)


@njit(cache=True)  # compiled with LAW_SIGNATURE on first use
def asmc_step(q_d, omega_d, omega_dot_d, q, omega_B, J, gains, state, t, dt, tau_cmd, diag):
    """The ASMC command (law contract in :mod:`flexsat.control.laws.registry`).

    ``state``: Lambda of the previous call, and 1.0 once a call has been made.
    """
    limit = gains[G.reduction_factor] * gains[G.t_max]
    qv, qv_dot, omega_e, theta_err, J3, J_w_dot_d, tau_gyro = law_terms(
        q_d, omega_d, omega_dot_d, q, omega_B, J
    )
    J_qv_dot = mv(J3, qv_dot)
    jk_min, lam_min, lam_max = gains[G.jk_min], gains[G.lambda_min], gains[G.lambda_max]
    phi = gains[G.phi]
    # eq. 4.27: target slope from the pointing error
    u = min(1.0, theta_err / gains[G.theta_threshold])
    smooth = gains[G.smooth] > 0.0
    if smooth:  # C1 smoothstep, then a first-order filter from the previous slope
        lam_target = lam_max - (lam_max - lam_min) * u * u * (3.0 - 2.0 * u)
        if state[1] > 0.0:
            lam_target = state[0] + (1.0 - exp(-dt / gains[G.lambda_time_constant])) * (
                lam_target - state[0])  # fmt: skip
    else:
        lam_target = lam_max - (lam_max - lam_min) * u
    # eqs. 4.23, 4.28: budget-feasible slope; the most restrictive axis decides
    lam_feasible = 1e300
    for a in range(3):
        budget = limit - abs(tau_gyro[a]) - abs(J_w_dot_d[a]) - jk_min  # eq. 4.23
        if abs(J_qv_dot[a]) > 0.0:
            lam_feasible = min(lam_feasible, max(0.0, budget) / abs(J_qv_dot[a]))
    lam = max(lam_min, min(lam_target, lam_feasible))  # eq. 4.29
    s = surface(omega_e, lam, qv)
    tau_guide = surface_guide(J_w_dot_d, lam, J_qv_dot)  # J (omega_dot_d - Lambda q_v,e_dot)
    # eq. 4.30, per axis: all the residual budget outside the boundary layer, scaled
    # down towards JK_min inside it.
    jk = (
        _jk(jk_min, limit, tau_gyro[0], tau_guide[0], s[0], phi),
        _jk(jk_min, limit, tau_gyro[1], tau_guide[1], s[1], phi),
        _jk(jk_min, limit, tau_gyro[2], tau_guide[2], s[2], phi),
    )
    if gains[G.include_lambda_dot] > 0.0 and state[1] > 0.0:
        # -J Lambda_dot q_v,e (eq. 4.12), omitted by default as in eq. 4.14
        lam_dot = (lam - state[0]) / dt
        Jq = mv(J3, qv)
        tau_guide = (tau_guide[0] - lam_dot * Jq[0], tau_guide[1] - lam_dot * Jq[1],
                     tau_guide[2] - lam_dot * Jq[2])  # fmt: skip
    state[0] = lam
    state[1] = 1.0
    tau_rob = (-jk[0] * sat(s[0] / phi), -jk[1] * sat(s[1] / phi), -jk[2] * sat(s[2] / phi))
    clip_and_store(limit, tau_gyro, tau_guide, tau_rob, tau_cmd)
    diag[0], diag[1], diag[2] = s
    diag[3] = lam
    diag[4], diag[5], diag[6] = jk
    diag[7], diag[8], diag[9] = tau_gyro
    diag[10], diag[11], diag[12] = tau_guide
    diag[13], diag[14], diag[15] = tau_rob
    return 0


ASMC = LawSpec(
    name="asmc", label="ASMC", config=ASMCConfig, step=asmc_step, state_size=2,
    diagnostics=SLIDING_DIAGNOSTICS,
    description="adaptive sliding-mode control with torque-budget allocation (the thesis's)",
)  # fmt: skip
