"""Attitude control: the law and loop-stage contracts and registries, disturbances.

Laws live in :mod:`flexsat.control.laws`, sensors and actuators in
:mod:`flexsat.control.stages`, one module each; each of those packages registers its
built-in members when imported. The names here are imported on first use (PEP 562):
a module that needs the disturbance model alone does not load every law and stage
(docs/performance.md, 'Start-up').
"""

import importlib

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


def __getattr__(name: str):
    """The control names, imported on first use (PEP 562)."""
    if name in _LAZY:
        value = getattr(importlib.import_module(f"{__name__}.{_LAZY[name]}"), name)
        globals()[name] = value
        return value
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def __dir__() -> list[str]:
    return sorted({*globals(), *__all__})
