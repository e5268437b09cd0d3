"""Classical sliding-mode control: constant slope and robust gain on the ASMC's surface.

tau = omega x J omega - J lambda q_v,e_dot - JK sat(s / Phi), s = omega_e + lambda
q_v,e (thesis eqs. 4.6, 4.14 with Lambda and JK held constant), the baseline of the
thesis's comparison (sec. 5.2).
"""

from __future__ import annotations

from typing import Literal, NamedTuple

import numpy as np
from numba import njit
from pydantic import Field

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

__all__ = ["SMC", "SMCConfig", "SMCGains"]


class SMCGains(NamedTuple):
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
    phi : float
        Boundary-layer width [rad/s].
    """

    t_max: float
    reduction_factor: float
    jk: float
    lambda_: float
    phi: float


G = SMCGains(*range(len(SMCGains._fields)))  # index of each gain in the packed array


class SMCConfig(LawConfig):
    """Classical sliding-mode control: constant slope and robust gain, same surface."""

    kind: Literal["smc"] = Field("smc", description="the law's registered name")
    jk_nm: Positive = Field(0.8925, description="robust torque JK [N m]")
    lambda_: Positive = Field(1.0, alias="lambda", description="surface slope [rad/s]")
    phi: Positive = Field(0.01, description="boundary-layer width [rad/s]")

    def gains(self, actuator) -> np.ndarray:
        return np.array(
            SMCGains(actuator.t_max_nm, actuator.reduction_factor, self.jk_nm, self.lambda_,
                     self.phi), dtype=float,
        )  # fmt: skip

    def plot_attributes(self) -> dict[str, float | str]:
        return surface_attributes(self.lambda_, self.lambda_, self.phi, self.jk_nm)

    def linear_feedback(self, J: np.ndarray) -> np.ndarray:
        return linear_sliding_feedback(J, self.lambda_, self.jk_nm, self.phi)


@njit(cache=True)  # compiled with LAW_SIGNATURE on first use
def smc_step(q_d, omega_d, omega_dot_d, q, omega_B, J, gains, state, t, dt, tau_cmd, diag):
    """The SMC command (law contract in :mod:`flexsat.control.laws.registry`); no state."""
    limit = gains[G.reduction_factor] * gains[G.t_max]
    qv, qv_dot, omega_e, _, J3, J_w_dot_d, tau_gyro = law_terms(
        q_d, omega_d, omega_dot_d, q, omega_B, J
    )
    J_qv_dot = mv(J3, qv_dot)
    lam, jk, phi = gains[G.lambda_], gains[G.jk], gains[G.phi]
    s = surface(omega_e, lam, qv)
    tau_guide = surface_guide(J_w_dot_d, lam, J_qv_dot)  # J (omega_dot_d - lambda q_v,e_dot)
    tau_rob = (-jk * sat(s[0] / phi), -jk * sat(s[1] / phi), -jk * sat(s[2] / phi))
    clip_and_store(limit, tau_gyro, tau_guide, tau_rob, tau_cmd)
    diag[0], diag[1], diag[2] = s
    diag[3] = lam
    diag[4], diag[5], diag[6] = jk, jk, jk
    diag[7], diag[8], diag[9] = tau_gyro
    diag[10], diag[11], diag[12] = tau_guide
    diag[13], diag[14], diag[15] = tau_rob
    return 0


SMC = LawSpec(
    name="smc", label="SMC", config=SMCConfig, step=smc_step, state_size=0,
    diagnostics=SLIDING_DIAGNOSTICS,
    description="classical sliding-mode control (constant slope and robust gain)",
)  # fmt: skip
