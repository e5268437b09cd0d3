"""An appendage model from an installed package reaches the config, the plant and the CLI
through the ``flexsat.appendages`` entry-point group."""

from __future__ import annotations

from importlib.metadata import EntryPoint

import pytest

import flexsat.config.models as models
from flexsat.config import validate_config
from flexsat.dynamics.plant import Plant
from tests.cli.harness import flexsat, to_toml
from tests.conftest import nominal_dict


@pytest.fixture
def plugin_installed(monkeypatch):
    point = EntryPoint("plugin_mass", "tests.dynamics.plugin_appendage", "flexsat.appendages")
    monkeypatch.setattr(models, "_PLUGINS_LOADED", False)
    monkeypatch.setattr(models, "entry_points",
                        lambda group: [point] if group == "flexsat.appendages" else [])  # fmt: skip


def _with_plugin() -> dict:
    data = nominal_dict()
    data["appendages"].append({"name": "box", "model": "plugin_mass", "mass_kg": 5.0,
                               "position_m": [0.0, 0.0, 0.9]})  # fmt: skip
    return data


def test_a_model_named_by_an_entry_point_is_loaded_on_demand(plugin_installed):
    plant = Plant.from_config(validate_config(_with_plugin()))
    assert [m.name for m in plant.models] == ["plate", "plate", "plugin_mass"]


def test_the_cli_accepts_the_plugin_model(plugin_installed, tmp_path, capsys):
    path = tmp_path / "c.toml"
    path.write_text(to_toml(_with_plugin()))
    outcome = flexsat(["config", "show", "--config", str(path)], capsys)
    assert outcome.code == 0, outcome.stderr
    assert "plugin_mass" in outcome.stdout
