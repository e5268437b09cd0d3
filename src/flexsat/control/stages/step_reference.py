"""The thesis's step reference: the target attitude from t = 0, at rest (regulation).

q_d is the target quaternion of ``target_euler_deg`` and omega_d = omega_dot_d = 0
at every instant (eq. 4.14 with the desired-motion terms zero, thesis sec. 4.2.3).
"""

from __future__ import annotations

from typing import Literal

import numpy as np
from numba import njit

from flexsat.control.quaternion import target_quaternion
from flexsat.control.stages.registry import PlantStageConfig, StageSpec

__all__ = ["STEP_REFERENCE", "StepReferenceConfig"]


class StepReferenceConfig(PlantStageConfig):
    """The step reference has no parameters: the scenario's target, at rest.

    Parameters
    ----------
    kind : str
        The stage's registered name, ``"step"``.
    """

    kind: Literal["step"] = "step"

    def packed(self, scenario, plant=None) -> np.ndarray:
        """The target quaternion (4,), scalar first."""
        return target_quaternion(scenario.target_euler_deg)


@njit(cache=True)  # compiled with REFERENCE_SIGNATURE on first use
def step_reference_step(t, params, state, q_d, omega_d, omega_dot_d, record):
    """Target attitude, zero rate and acceleration (contract in ``stages.registry``)."""
    for i in range(4):
        q_d[i] = params[i]
    for i in range(3):
        omega_d[i] = 0.0
        omega_dot_d[i] = 0.0
    return 0


STEP_REFERENCE = StageSpec(
    role="reference", name="step", config=StepReferenceConfig, step=step_reference_step,
    description="the target attitude at rest from t = 0 (the thesis's regulation)",
)  # fmt: skip
