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
from flexsat.config.models import HubConfig, SatelliteConfig

__all__ = [
    "PRESETS",
    "TEMPLATES",
    "HubConfig",
    "SatelliteConfig",
    "load_config",
    "nominal",
    "preset_path",
    "templates",
    "validate_config",
]
