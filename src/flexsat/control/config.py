"""Validated parameters of the control laws, the actuators and the disturbances."""

from __future__ import annotations

from typing import Annotated, Literal

import numpy as np
from pydantic import Discriminator, Field, Tag, model_validator

from flexsat.config.models import Positive, Vector3, _Frozen

__all__ = [
    "ASMCConfig",
    "ActuatorConfig",
    "ControllerConfig",
    "DisturbanceConfig",
    "PDConfig",
    "SMCConfig",
]


class ASMCConfig(_Frozen):
    """Adaptive sliding-mode control with torque-budget allocation (thesis ch. 4, sec. 5.1)."""

    kind: Literal["asmc"] = "asmc"
    jk_min_nm: Positive = Field(0.8925, description="JK_min = D_max + eta [N m] (eq. 4.21)")
    lambda_min: Positive = Field(0.2, description="slope far from the target [rad/s]")
    lambda_max: Positive = Field(5.0, description="slope near the target [rad/s]")
    phi: Positive = Field(0.01, description="boundary-layer width Phi [rad/s]")
    theta_threshold_deg: Positive = Field(5.0, description="theta_th of eq. 4.27 [deg]")
    include_lambda_dot: bool = Field(False, description="add -J Lambda_dot q_v,e (eq. 4.12)")

    @model_validator(mode="after")
    def _ordered(self) -> ASMCConfig:
        if self.lambda_max < self.lambda_min:
            raise ValueError(f"lambda_max must be >= lambda_min ({self.lambda_min})")
        return self

    def gains(self, actuator: ActuatorConfig) -> np.ndarray:
        return np.array([
            actuator.t_max_nm, actuator.reduction_factor, self.jk_min_nm, self.lambda_min,
            self.lambda_max, self.phi, np.radians(self.theta_threshold_deg),
            float(self.include_lambda_dot),
        ])  # fmt: skip


class SMCConfig(_Frozen):
    """Classical sliding-mode control: constant slope and robust gain, same surface."""

    kind: Literal["smc"] = "smc"
    jk_nm: Positive = Field(0.8925, description="robust torque JK [N m]")
    lambda_: Positive = Field(1.0, alias="lambda", description="surface slope [rad/s]")
    phi: Positive = Field(0.01, description="boundary-layer width [rad/s]")

    def gains(self, actuator: ActuatorConfig) -> np.ndarray:
        return np.array(
            [actuator.t_max_nm, actuator.reduction_factor, self.jk_nm, self.lambda_, self.phi]
        )


class PDConfig(_Frozen):
    """Quaternion PD with gyroscopic compensation: tau = w x Jw - J (kp q_v,e + kd w)."""

    kind: Literal["pd"] = "pd"
    natural_frequency_rad_s: Positive = Field(0.3, description="omega_n [rad/s]")
    damping_ratio: Annotated[float, Field(gt=0.0, le=5.0)] = 0.9

    def gains(self, actuator: ActuatorConfig) -> np.ndarray:
        wn = self.natural_frequency_rad_s
        # q_v,e ~ theta / 2 for small errors: kp = 2 wn^2 gives theta'' = -wn^2 theta.
        return np.array([
            actuator.t_max_nm, actuator.reduction_factor, 2.0 * wn**2,
            2.0 * self.damping_ratio * wn,
        ])  # fmt: skip


def _controller_kind(value: object) -> str | None:
    """The law a controller table names; a table without ``kind`` is the ASMC."""
    if isinstance(value, dict):
        return value.get("kind", "asmc")
    return getattr(value, "kind", None)


ControllerConfig = Annotated[
    Annotated[ASMCConfig, Tag("asmc")]
    | Annotated[SMCConfig, Tag("smc")]
    | Annotated[PDConfig, Tag("pd")],
    Discriminator(_controller_kind),
]


class ActuatorConfig(_Frozen):
    """Per-axis actuator limits and gain (thesis sec. 5.1.1, R3)."""

    t_max_nm: Positive = Field(2.0, description="hardware saturation per axis [N m]")
    reduction_factor: Annotated[float, Field(gt=0.0, le=1.0)] = Field(
        0.95, description="software limit RF * T_max [-]"
    )
    gain: tuple[
        Annotated[float, Field(gt=0.0, le=2.0)],
        Annotated[float, Field(gt=0.0, le=2.0)],
        Annotated[float, Field(gt=0.0, le=2.0)],
    ] = Field((0.95, 0.95, 0.95), description="G_act, delivered/commanded [-]")


class DisturbanceConfig(_Frozen):
    """Disturbance torques: "forced to maximum" (the nominal validation; docs/control.md,
    'Disturbances forced to maximum') or one random draw within the same bounds.

    In ``mode = "random"`` each run draws, from ``seed``: the actuator gain per axis
    uniformly within 1 +- |1 - G_act|, the environment and residual torques per axis
    within +-|value|, and the sloshing ratio within [0, ratio]. The realised values
    are stored in the result's attributes so the run can be replayed.
    """

    mode: Literal["maximum", "random"] = "maximum"
    seed: Annotated[int, Field(ge=0)] = 0

    environment_nm: Vector3 = Field((0.005, 0.005, 0.005), description="constant [N m]")
    sloshing_ratio: Annotated[float, Field(ge=0.0, le=1.0)] = Field(
        0.02, description="sloshing amplitude / commanded torque [-]"
    )
    sloshing_hz: Annotated[float, Field(ge=0.0, le=100.0)] = 0.52
    residual_nm: Vector3 = Field((0.0, 0.0, 0.0), description="unmodelled residual [N m]")

    def packed(self, actuator: ActuatorConfig) -> np.ndarray:
        """Actuator gain, environment, sloshing ratio and frequency, residual, T_max."""
        gain = np.array(actuator.gain, dtype=float)
        env = np.array(self.environment_nm, dtype=float)
        res = np.array(self.residual_nm, dtype=float)
        ratio = self.sloshing_ratio
        if self.mode == "random":
            rng = np.random.default_rng(np.random.SeedSequence(self.seed))
            spread = np.abs(1.0 - gain)
            gain = rng.uniform(1.0 - spread, 1.0 + spread)
            env = rng.uniform(-np.abs(env), np.abs(env))
            res = rng.uniform(-np.abs(res), np.abs(res))
            ratio = rng.uniform(0.0, ratio)
        return np.array([*gain, *env, ratio, self.sloshing_hz, *res, actuator.t_max_nm])
