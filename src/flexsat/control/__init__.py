"""Attitude control: laws (ASMC, SMC, PD), actuators and disturbances, their configs."""

from flexsat.control.config import (
    ActuatorConfig,
    ASMCConfig,
    DisturbanceConfig,
    PDConfig,
    SMCConfig,
)
from flexsat.control.quaternion import target_quaternion

__all__ = [
    "ASMCConfig",
    "ActuatorConfig",
    "DisturbanceConfig",
    "PDConfig",
    "SMCConfig",
    "target_quaternion",
]
