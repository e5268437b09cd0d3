"""Validated parameters of the disturbance torques the actuator stages add."""

from __future__ import annotations

from typing import Annotated, Literal

import numpy as np
from pydantic import Field

from flexsat.config.models import Vector3, _Frozen

__all__ = ["DisturbanceConfig"]


class DisturbanceConfig(_Frozen):
    """Disturbance torques: "forced to maximum" (the nominal validation; docs/control.md,
    'Disturbances forced to maximum') or one random draw within the same bounds.

    In ``mode = "random"`` each run draws, from ``seed``: the actuator gain per axis
    uniformly within 1 +- ‖1 - G_act‖, the environment and residual torques per axis
    within +-‖value‖, and the sloshing ratio within [0, ratio]. The realised values
    are stored in the result's attributes so the run can be replayed.
    """

    mode: Literal["maximum", "random"] = Field(
        "maximum", description="every bound at its maximum, or one random draw"
    )
    seed: Annotated[int, Field(ge=0)] = Field(0, description="seed of the random draw")

    environment_nm: Vector3 = Field((0.005, 0.005, 0.005), description="constant [N m]")
    sloshing_ratio: Annotated[float, Field(ge=0.0, le=1.0)] = Field(
        0.02, description="sloshing amplitude / commanded torque [-]"
    )
    sloshing_hz: Annotated[float, Field(ge=0.0, le=100.0)] = Field(
        0.52, description="sloshing frequency [Hz]"
    )
    residual_nm: Vector3 = Field((0.0, 0.0, 0.0), description="unmodelled residual [N m]")

    def packed(self, actuator) -> np.ndarray:
        """Actuator gain, environment, sloshing ratio and frequency, residual, T_max.

        ``actuator`` gives ``t_max_nm`` and the gain ``G_act`` (3), 1 for an actuator
        without one (the wheels: their motors deliver the command through their own
        response). The draws of ``mode = "random"`` come in the same order whatever
        the actuator, so the external torques are the same for every actuator.
        """
        gain = np.array(getattr(actuator, "gain", (1.0, 1.0, 1.0)), dtype=float)
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
