"""Validated satellite configuration: models, presets and TOML loading."""

from flexsat.config.load import (
    PRESETS,
    TEMPLATES,
    load_config,
    nominal,
    preset_path,
    templates,
    validate_config,
)
from flexsat.config.models import AppendageConfig, HubConfig, SatelliteConfig, TargetFrequencies

__all__ = [
    "PRESETS",
    "TEMPLATES",
    "AppendageConfig",
    "HubConfig",
    "SatelliteConfig",
    "TargetFrequencies",
    "load_config",
    "nominal",
    "preset_path",
    "templates",
    "validate_config",
]
