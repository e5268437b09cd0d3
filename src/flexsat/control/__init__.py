"""Attitude control: the law and loop-stage contracts and registries, disturbances.

Laws live in :mod:`flexsat.control.laws`, sensors and actuators in
:mod:`flexsat.control.stages`, one module each; each of those packages registers its
built-in members when imported. The names here are imported on first use (PEP 562):
a module that needs the disturbance model alone does not load every law and stage
(docs/performance.md, 'Start-up').
"""

from flexsat._lazy import lazy_attributes

_LAZY = {
    "DisturbanceConfig": "disturbances",
    **dict.fromkeys(("LawConfig", "LawSpec", "get_law", "law_names", "register_law"), "laws"),
    "target_quaternion": "quaternion",
    "Channel": "registry",
    **dict.fromkeys(("StageConfig", "StageSpec", "register_stage"), "stages"),
    "ActuatorConfig": "stages.static_actuator",
}  # fmt: skip
"""The public names imported on first use, and the submodule each comes from."""

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


__getattr__, __dir__ = lazy_attributes(__name__, _LAZY)
