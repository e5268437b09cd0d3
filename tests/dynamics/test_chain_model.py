"""The chain model's Python side: campaign paths, drawing, root motion, initial states,
the docs' chain equation table."""

from __future__ import annotations

import re
import tomllib
from pathlib import Path

import numpy as np
import pytest

from flexsat.campaigns.modifiers import Modifier, apply_modifiers
from flexsat.config import load_config, preset_path, validate_config
from flexsat.dynamics.plant import Plant
from flexsat.plots.geometry import satellite_geometry
from flexsat.simulate import initial_state
from flexsat.simulate.scenario import OpenLoopScenario
from tests.test_docs import REFERENCE, _resolve

DOCS = Path(__file__).resolve().parents[2] / "docs"


@pytest.fixture(scope="module")
def plant() -> Plant:
    return Plant.from_config(load_config(preset_path("chain")))


def test_campaign_paths_reach_chain_parameters():
    data = tomllib.loads(preset_path("chain").read_text())
    realised: dict = {}
    modifiers = [
        Modifier(path="appendages[*].beam.EI_flap_N_m2", op="scale", value=1.1),
        Modifier(path="appendages[0].segments", value=4),
        Modifier(path="appendages[1].inertia", op="scale", value=2.0),
    ]
    out = apply_modifiers(data, modifiers, np.random.default_rng(0), realised)
    assert out["appendages"][0]["beam"]["EI_flap_N_m2"] == pytest.approx(1.1 * 123.0)
    assert out["appendages"][1]["surface_density_kg_m2"] == pytest.approx(2.0)
    plant = Plant.from_config(validate_config(out))
    assert [b.count for b in plant.layout.blocks] == [12, 24]  # 4 and 8 segments x 3 DOFs
    assert plant.models[1].rigid_body(plant.params[1]).mass == pytest.approx(13.5)


def test_each_segment_is_drawn_and_follows_the_deformation(plant):
    rest = satellite_geometry(plant)
    assert rest.panels.shape == (16, 4, 3) and rest.n_appendages == 2
    q = plant.zeros()
    block = plant.layout.block("panel_1")
    q[block.offset] = np.radians(5.0)  # eta_rx_0: the root joint flaps the whole panel
    moved = satellite_geometry(plant, q)
    # Rotation about X_M through the root (0, 0.8, 0): the free end at y = 5.3 m rises
    # by 4.5 sin 5 deg along Z (exact, to round-off).
    np.testing.assert_allclose(moved.tips[0] - rest.tips[0],
                               [0.0, 4.5 * (np.cos(np.radians(5.0)) - 1.0),
                                4.5 * np.sin(np.radians(5.0))], atol=1e-12)  # fmt: skip
    np.testing.assert_allclose(plant.tip_displacement(q)[0], moved.tips[0] - rest.tips[0],
                               atol=1e-12)  # fmt: skip


def test_initial_state_from_the_config_and_the_scenario(plant):
    data = tomllib.loads(preset_path("chain").read_text())
    data["appendages"][0]["root_joint"] = {"dofs": ["rx", "ry", "rz"], "damping_ratio": 0.005,
                                           "initial": {"rz": 2.0}}  # fmt: skip
    chained = Plant.from_config(validate_config(data))
    scenario = OpenLoopScenario.model_validate(
        {"initial": {"appendages": [{"name": "panel_2", "rho_deg": [1.0, 0.0, 0.0]}]}}
    )
    q, _ = initial_state(chained, scenario)
    names = chained.dof_names()
    assert q[names.index("panel_1.eta_rz_0")] == pytest.approx(np.radians(2.0))
    assert q[names.index("panel_2.eta_rx_0")] == pytest.approx(np.radians(1.0))
    bad = OpenLoopScenario.model_validate(
        {"initial": {"appendages": [{"name": "panel_2", "eta_m": [0.01, 0.0, 0.0]}]}}
    )
    with pytest.raises(Exception, match="root joint DOF 'x' is locked"):
        initial_state(chained, bad)


def test_root_motion_names_the_root_joint(plant):
    block = plant.layout.blocks[0]
    values = np.arange(block.count, dtype=float)[None, :]
    eta, rho = plant.models[0].root_motion(values, block.names)
    np.testing.assert_array_equal(eta, [[0.0, 0.0, 0.0]])
    np.testing.assert_array_equal(rho, [[0.0, 1.0, 2.0]])  # eta_rx_0, eta_ry_0, eta_rz_0


def test_the_chain_equation_table_resolves():
    text = (DOCS / "model.md").read_text(encoding="utf-8")
    section = text.split("\n## Chain appendages\n", 1)[1].split("\n## ", 1)[0]
    rows = [line for line in section.splitlines() if re.match(r"\| C\.\d+ \|", line)]
    assert len(rows) >= 10
    for row in rows:
        references = REFERENCE.findall(row)
        assert references, row
        for reference in references:
            _resolve(reference)
