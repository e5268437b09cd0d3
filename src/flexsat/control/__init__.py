"""Attitude control: the law and loop-stage contracts and registries, disturbances.

Laws live in :mod:`flexsat.control.laws`, sensors and actuators in
:mod:`flexsat.control.stages`, one module each.
"""

from flexsat.control.disturbances import DisturbanceConfig
from flexsat.control.laws import LawConfig, LawSpec, get_law, law_names, register_law
from flexsat.control.quaternion import target_quaternion
from flexsat.control.registry import Channel
from flexsat.control.stages import StageConfig, StageSpec, register_stage
from flexsat.control.stages.static_actuator import ActuatorConfig

__all__ = [
    "ActuatorConfig",
    "Channel",
    "DisturbanceConfig",
    "LawConfig",
    "LawSpec",
    "StageConfig",
    "StageSpec",
    "get_law",
    "law_names",
    "register_law",
    "register_stage",
    "target_quaternion",
]
