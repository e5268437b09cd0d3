"""The thesis's static actuator and disturbance model between the command and the plant.

Order: tau_cmd is already clipped to the software limit RF * T_max by the law; the
applied torque is clip_Tmax(G_act tau_cmd + environment + sloshing + residual),
with sloshing_i = ratio * tau_cmd,i * sin(2 pi f t) (proportional to the effort,
so it vanishes at rest). The disturbances are the scenario's ``[disturbances]``
table (:class:`~flexsat.control.disturbances.DisturbanceConfig`), "forced to maximum" in
the nominal validation: gain 0.95, environment +0.005 N m, sloshing 2 % at 0.52 Hz
on every axis, residual off (``docs/control.md``).
"""

from __future__ import annotations

from math import pi, sin
from typing import Annotated, Literal

import numpy as np
from numba import njit
from pydantic import Field

from flexsat.control.stages.registry import ActuatorStageConfig, StageSpec

__all__ = ["PACKED", "STATIC_ACTUATOR", "ActuatorConfig"]

PACKED = {"gain": 0, "environment_nm": 3, "sloshing_ratio": 6, "sloshing_hz": 7,
          "residual_nm": 8, "t_max_nm": 11}  # fmt: skip
"""Offset of each packed parameter (three axes from there for the vectors)."""
_GAIN, _ENV, _RATIO, _HZ, _RES, _TMAX = PACKED.values()


class ActuatorConfig(ActuatorStageConfig):
    """Per-axis actuator limits and gain (thesis sec. 5.1.1, R3)."""

    applies_disturbances = True  # [disturbances] act with it

    kind: Literal["static"] = Field("static", description="an actuator with static limits")
    gain: tuple[
        Annotated[float, Field(gt=0.0, le=2.0)],
        Annotated[float, Field(gt=0.0, le=2.0)],
        Annotated[float, Field(gt=0.0, le=2.0)],
    ] = Field((0.95, 0.95, 0.95), description="G_act, delivered/commanded [-]")

    def packed(self, scenario) -> np.ndarray:
        """Gain (3), environment (3) [N m], sloshing ratio, sloshing [Hz], residual (3)
        [N m], T_max [N m] (:data:`PACKED`), disturbances realised from the scenario."""
        return scenario.disturbances.packed(self)


@njit(cache=True)
def _axis(tau_cmd, p, slosh, a):
    value = p[_GAIN + a] * tau_cmd[a] + p[_ENV + a] + slosh * tau_cmd[a] + p[_RES + a]
    return min(p[_TMAX], max(-p[_TMAX], value))


@njit(cache=True)  # compiled with ACTUATOR_SIGNATURE on first use
def static_actuator_step(tau_cmd, t, dt, params, state, tau_applied, record):
    """Applied torque, body frame [N m], per axis within T_max (module docstring)."""
    slosh = params[_RATIO] * sin(2.0 * pi * params[_HZ] * t)
    for a in range(3):
        tau_applied[a] = _axis(tau_cmd, params, slosh, a)
    return 0


STATIC_ACTUATOR = StageSpec(
    role="actuator", name="static", config=ActuatorConfig, step=static_actuator_step,
    description="gain, environment, sloshing and residual torques, clipped to T_max",
)  # fmt: skip
