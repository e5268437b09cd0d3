"""A third-party appendage model as an installed package would ship it: importing this
module registers it (the ``flexsat.appendages`` entry point names this module)."""

from __future__ import annotations

from typing import Literal

from pydantic import Field

from flexsat.dynamics.appendages import register_appendage_model
from tests.dynamics.appendages.test_contract import PointMass, PointMassConfig


class PluginMassConfig(PointMassConfig):
    model: Literal["plugin_mass"] = Field("plugin_mass")


class PluginMass(PointMass):
    name = "plugin_mass"
    config_class = PluginMassConfig


register_appendage_model(PluginMass())
