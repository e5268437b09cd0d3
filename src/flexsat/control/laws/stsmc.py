"""Super-twisting sliding-mode control on the thesis's quaternion surface.

The law of the thesis's reference [Nad+19] (Nadafi et al. 2019, super-twisting
sliding mode control for attitude tracking and vibration suppression of a flexible
spacecraft), on the surface s = omega_e + lambda q_v,e (eq. 4.6, lambda constant):

    tau = omega x J omega - J lambda q_v,e_dot + J u,
    u   = -k1 ‖s‖^(1/2) sgn(s) + v,     v_dot = -k2 sgn(s)     (per body axis)

On the rigid design model (eq. 4.7) with a disturbance torque d this gives exactly
s_dot = u + a, a = J^-1 d: the super-twisting algorithm in s, whose integral v
learns -a. The gains come from the disturbance bound D_max and a disturbance
frequency f_d: the torque rate is bounded by L = 2 pi f_d D_max [N m/s], on axis i
the perturbation rate by L_i = L sum_j ‖J^-1_ij‖ [rad/s^3], and

    k1_i = c1 sqrt(L_i),   k2_i = c2 L_i.

With the quadratic Lyapunov function of Moreno and Osorio (2008),
V = zeta^T P zeta, zeta = (‖s‖^(1/2) sgn(s), v + a), P = [[2 k2 + k1^2/2, -k1/2],
[-k1/2, 1]], V_dot = -zeta^T Q zeta / ‖s‖^(1/2) with Q positive definite for every
‖a_dot‖ <= L_i if and only if k1 > 0 and k2 > L_i + 2 L_i^2 / k1^2, that is
c2 > 1 + 2 / c1^2 (checked by the parameter model). Then s = s_dot = 0 in finite
time, T <= 2 V(0)^(1/2) / gamma, gamma = lambda_min(Q) lambda_min(P)^(1/2) /
lambda_max(P). The integral is held within the disturbance bound,
‖v_i‖ <= D_max sum_j ‖J^-1_ij‖ (anti-windup while the torque is clipped).
"""

from __future__ import annotations

from math import pi, sqrt
from typing import Literal, NamedTuple

import numpy as np
from numba import njit
from pydantic import Field, model_validator

from flexsat.compiled.linalg3 import mv
from flexsat.config.models import Positive
from flexsat.control.laws._sliding import (
    integral_diagnostics,
    law_terms,
    store_integral_breakdown,
    surface,
    surface_attributes,
    surface_guide,
)
from flexsat.control.laws.registry import LawConfig, LawSpec
from flexsat.control.registry import Channel

__all__ = [
    "STSMC",
    "STSMCConfig",
    "STSMCGains",
    "axis_gains",
    "lyapunov_matrices",
    "moreno_osorio_c2_min",
]


class STSMCGains(NamedTuple):
    """The packed gains, in order (SI).

    Attributes
    ----------
    t_max : float
        T_max per axis [N m].
    reduction_factor : float
        RF [-].
    lambda_ : float
        Surface slope [rad/s].
    d_max : float
        Disturbance bound D_max [N m].
    d_rate : float
        Disturbance rate bound L = 2 pi f_d D_max [N m/s].
    c1 : float
        K1 = c1 sqrt(L_i) [-].
    c2 : float
        K2 = c2 L_i [-].
    """

    t_max: float
    reduction_factor: float
    lambda_: float
    d_max: float
    d_rate: float
    c1: float
    c2: float


G = STSMCGains(*range(len(STSMCGains._fields)))  # index of each gain in the packed array


def moreno_osorio_c2_min(c1: float) -> float:
    """Smallest c2 of the Lyapunov condition k2 > L + 2 L^2 / k1^2 with k1 = c1 sqrt(L).

    Parameters
    ----------
    c1 : float
        k1 = c1 sqrt(L) [-].

    Returns
    -------
    float
        1 + 2 / c1^2 [-].
    """
    return 1.0 + 2.0 / c1**2


class STSMCConfig(LawConfig):
    """Super-twisting sliding mode on s = omega_e + lambda q_v,e ([Nad+19])."""

    kind: Literal["stsmc"] = Field("stsmc", description="the law's registered name")
    lambda_: Positive = Field(0.5, alias="lambda", description="surface slope [rad/s]")
    d_max_nm: Positive = Field(0.85, description="disturbance bound D_max [N m] (eq. 5.6)")
    disturbance_hz: Positive = Field(
        0.52, description="disturbance frequency f_d: |d_dot| <= 2 pi f_d D_max [Hz]"
    )
    c1: Positive = Field(1.5, description="k1 = c1 sqrt(L) [-]")
    c2: Positive = Field(2.5, description="k2 = c2 L [-], > 1 + 2 / c1^2 (Lyapunov)")

    @model_validator(mode="after")
    def _lyapunov(self) -> STSMCConfig:
        bound = moreno_osorio_c2_min(self.c1)
        if self.c2 <= bound:
            raise ValueError(
                f"c2 must be > 1 + 2 / c1^2 = {bound:.4g} for c1 = {self.c1:g} (the "
                f"Lyapunov condition k2 > L + 2 L^2 / k1^2), got {self.c2:g}"
            )
        return self

    def gains(self, actuator) -> np.ndarray:
        return np.array(STSMCGains(
            actuator.t_max_nm, actuator.reduction_factor, self.lambda_, self.d_max_nm,
            2.0 * pi * self.disturbance_hz * self.d_max_nm, self.c1, self.c2,
        ), dtype=float)  # fmt: skip

    def plot_attributes(self) -> dict[str, float | str]:
        return surface_attributes(self.lambda_, self.lambda_)


@njit(cache=True)
def _inverse_row_sums(J):
    """sum_j ‖J^-1_ij‖ for each row i of the (3, 3) inverse (adjugate / determinant)."""
    a, b, c = J[0, 0], J[0, 1], J[0, 2]
    d, e, f = J[1, 0], J[1, 1], J[1, 2]
    g, h, k = J[2, 0], J[2, 1], J[2, 2]
    c00, c01, c02 = e * k - f * h, c * h - b * k, b * f - c * e
    c10, c11, c12 = f * g - d * k, a * k - c * g, c * d - a * f
    c20, c21, c22 = d * h - e * g, b * g - a * h, a * e - b * d
    det = abs(a * c00 + b * c10 + c * c20)
    return (
        (abs(c00) + abs(c01) + abs(c02)) / det,
        (abs(c10) + abs(c11) + abs(c12)) / det,
        (abs(c20) + abs(c21) + abs(c22)) / det,
    )


def axis_gains(gains: np.ndarray, J: np.ndarray) -> dict[str, np.ndarray]:
    """Per-axis gains of the super-twisting law.

    Parameters
    ----------
    gains : ndarray, shape (7,)
        The packed :class:`STSMCGains` [SI, per gain].
    J : ndarray, shape (3, 3)
        Design inertia, hub frame B [kg m^2].

    Returns
    -------
    dict of str to ndarray, shape (3,)
        ``L`` [rad/s^3], ``k1`` [rad^(1/2)/s^(3/2)], ``k2`` [rad/s^3] and ``v_max``
        [rad/s^2] per axis.
    """
    rows = np.abs(np.linalg.inv(J)).sum(axis=1)
    rate = gains[G.d_rate] * rows
    return {"L": rate, "k1": gains[G.c1] * np.sqrt(rate), "k2": gains[G.c2] * rate,
            "v_max": gains[G.d_max] * rows}  # fmt: skip


def lyapunov_matrices(k1: float, k2: float, rho: float) -> tuple[np.ndarray, np.ndarray]:
    """P and Q(rho) of V = zeta^T P zeta, ‖s‖^(1/2) V_dot = -zeta^T Q zeta, rho = a_dot sgn(s).

    Parameters
    ----------
    k1 : float
        Gain of the square-root term [rad^(1/2)/s^(3/2)].
    k2 : float
        Gain of the integral term [rad/s^3].
    rho : float
        a_dot sgn(s), the disturbance rate seen by the surface [rad/s^3].

    Returns
    -------
    P, Q : ndarray, shape (2, 2)
        The Lyapunov matrices [SI].
    """
    P = np.array([[2.0 * k2 + 0.5 * k1**2, -0.5 * k1], [-0.5 * k1, 1.0]])
    Q = np.array([[k1 * k2 + 0.5 * k1**3 + rho * k1, -(0.5 * k1**2 + rho)],
                  [-(0.5 * k1**2 + rho), 0.5 * k1]])  # fmt: skip
    return P, Q


@njit(cache=True)
def _sgn(x):
    return 1.0 if x > 0.0 else (-1.0 if x < 0.0 else 0.0)


@njit(cache=True)
def _twist(k1, s):
    """-k1 ‖s‖^(1/2) sgn(s), the continuous term of the super-twisting algorithm."""
    return -k1 * sqrt(abs(s)) * _sgn(s)


@njit(cache=True)  # compiled with LAW_SIGNATURE on first use
def stsmc_step(q_d, omega_d, omega_dot_d, q, omega_B, J, gains, state, t, dt, tau_cmd, diag):
    """The STSMC command (law contract in :mod:`flexsat.control.laws.registry`).

    ``state``: the twisting integral v per axis [rad/s^2].
    """
    limit = gains[G.reduction_factor] * gains[G.t_max]
    qv, qv_dot, omega_e, _, J3, J_w_dot_d, tau_gyro = law_terms(
        q_d, omega_d, omega_dot_d, q, omega_B, J
    )
    J_qv_dot = mv(J3, qv_dot)
    lam = gains[G.lambda_]
    s = surface(omega_e, lam, qv)
    tau_guide = surface_guide(J_w_dot_d, lam, J_qv_dot)  # J (omega_dot_d - lambda q_v,e_dot)
    rows = _inverse_row_sums(J)
    c1_root_L = gains[G.c1] * sqrt(gains[G.d_rate])  # k1_i = c1 sqrt(L) sqrt(rows_i)
    v = (state[0], state[1], state[2])
    u = (_twist(c1_root_L * sqrt(rows[0]), s[0]) + v[0],
         _twist(c1_root_L * sqrt(rows[1]), s[1]) + v[1],
         _twist(c1_root_L * sqrt(rows[2]), s[2]) + v[2])  # fmt: skip
    tau_rob = mv(J3, u)
    tau_int = mv(J3, v)
    store_integral_breakdown(limit, s, v, tau_gyro, tau_guide, tau_rob, tau_cmd, diag)
    diag[15], diag[16], diag[17] = tau_int
    for a in range(3):  # v_dot = -k2 sgn(s), explicit Euler over the control period
        v_max = gains[G.d_max] * rows[a]
        v_next = v[a] - gains[G.c2] * gains[G.d_rate] * rows[a] * _sgn(s[a]) * dt
        state[a] = min(v_max, max(-v_max, v_next))
    return 0


STSMC = LawSpec(
    name="stsmc", label="STSMC", config=STSMCConfig, step=stsmc_step, state_size=3,
    diagnostics=(
        *integral_diagnostics(
            "s = w_e + L q_v,e",
            Channel("twisting_integral", "rad/s^2", "v, v_dot = -k2 sgn(s)", per_axis=True),
            "-J L q_v,e_dot", "J (-k1 |s|^1/2 sgn(s) + v)",
        ),
        Channel("tau_integral", "N m", "J v, the integral part of tau_rob", per_axis=True),
    ),
    description="super-twisting sliding-mode control (Nadafi et al. 2019)",
)  # fmt: skip
