"""Quaternion PD with gyroscopic compensation: tau = w x Jw - J (kp q_v,e + kd w).

The linear baseline of the thesis's comparison (sec. 5.2); no sliding surface.
"""

from __future__ import annotations

from typing import Annotated, Literal, NamedTuple

import numpy as np
from numba import njit
from pydantic import Field

from flexsat.compiled.linalg3 import mv
from flexsat.config.models import Positive
from flexsat.control.laws._sliding import clip_and_store, law_terms
from flexsat.control.laws.registry import LawConfig, LawSpec
from flexsat.control.registry import Channel

__all__ = ["PD", "PDConfig", "PDGains"]


class PDGains(NamedTuple):
    """The packed gains, in order (SI).

    Attributes
    ----------
    t_max : float
        T_max per axis [N m].
    reduction_factor : float
        RF [-].
    kp : float
        Proportional gain kp [1/s^2].
    kd : float
        Rate gain kd [1/s].
    """

    t_max: float
    reduction_factor: float
    kp: float
    kd: float


G = PDGains(*range(len(PDGains._fields)))  # index of each gain in the packed array


class PDConfig(LawConfig):
    """Quaternion PD with gyroscopic compensation: tau = w x Jw - J (kp q_v,e + kd w)."""

    kind: Literal["pd"] = Field("pd", description="the law's registered name")
    natural_frequency_rad_s: Positive = Field(0.3, description="omega_n [rad/s]")
    damping_ratio: Annotated[float, Field(gt=0.0, le=5.0, description="zeta [-]")] = 0.9

    def gains(self, actuator) -> np.ndarray:
        wn = self.natural_frequency_rad_s
        # q_v,e ~ theta / 2 for small errors: kp = 2 wn^2 gives theta'' = -wn^2 theta.
        return np.array(PDGains(
            actuator.t_max_nm, actuator.reduction_factor, 2.0 * wn**2,
            2.0 * self.damping_ratio * wn,
        ), dtype=float)  # fmt: skip

    def linear_feedback(self, J: np.ndarray) -> np.ndarray:
        # With q_v,e ~ theta / 2: tau = -J (wn^2 theta + 2 zeta wn omega); the
        # gyroscopic term is quadratic in the rate.
        wn, zeta = self.natural_frequency_rad_s, self.damping_ratio
        return np.hstack([np.asarray(J) * wn**2, np.asarray(J) * 2.0 * zeta * wn])


@njit(cache=True)  # compiled with LAW_SIGNATURE on first use
def pd_step(q_d, omega_d, omega_dot_d, q, omega_B, J, gains, state, t, dt, tau_cmd, diag):
    """The PD command (law contract in :mod:`flexsat.control.laws.registry`); no state."""
    limit = gains[G.reduction_factor] * gains[G.t_max]
    qv, _, omega_e, _, J3, J_w_dot_d, tau_gyro = law_terms(q_d, omega_d, omega_dot_d, q, omega_B, J)
    kp, kd = gains[G.kp], gains[G.kd]
    u = (kp * qv[0] + kd * omega_e[0], kp * qv[1] + kd * omega_e[1],
         kp * qv[2] + kd * omega_e[2])  # fmt: skip
    Ju = mv(J3, u)
    tau_guide = (J_w_dot_d[0] - Ju[0], J_w_dot_d[1] - Ju[1], J_w_dot_d[2] - Ju[2])
    clip_and_store(limit, tau_gyro, tau_guide, (0.0, 0.0, 0.0), tau_cmd)
    diag[0], diag[1], diag[2] = tau_gyro
    diag[3], diag[4], diag[5] = tau_guide
    return 0


PD = LawSpec(
    name="pd", label="PD", config=PDConfig, step=pd_step, state_size=0,
    diagnostics=(
        Channel("tau_gyro", "N m", "w x J w", per_axis=True),
        Channel("tau_guide", "N m", "-J (kp q_v,e + kd w)", per_axis=True),
    ),
    description="quaternion PD with gyroscopic compensation",
)  # fmt: skip
