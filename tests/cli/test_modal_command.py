"""``flexsat modal --json``: mode shapes, effective masses, damping; modal appendage files."""

from __future__ import annotations

import json

import numpy as np
import pytest

from flexsat import Plant, load_config
from flexsat.config.modal_data import _toml, save_modal_data
from flexsat.linear.export import modal_data
from tests.cli.harness import flexsat, to_toml
from tests.conftest import nominal_dict


@pytest.fixture(scope="module")
def panel_data():
    return modal_data(Plant.from_config(load_config()), "panel_1")


def test_modal_json_reports_shapes_effective_masses_and_damping(capsys):
    outcome = flexsat(["modal", "--json"], capsys)
    assert outcome.code == 0, outcome.stderr
    summary = json.loads(outcome.stdout)
    shapes = np.array(summary["mode_shapes"])  # one row per mode
    M0 = np.array(summary["mass_matrix"])
    np.testing.assert_allclose(shapes @ M0 @ shapes.T, np.eye(18), atol=1e-9)  # phi^T M phi = I
    # Joint damping tuned to zeta = 0.005 per DOF (nominal preset): the coupled modes'
    # damping ratios are of that order (between 0.1 zeta and 10 zeta: each mode mixes DOFs).
    zeta = np.array(summary["modal_damping_ratios"][6:])
    assert np.all((zeta > 5e-4) & (zeta < 5e-2))
    table = summary["effective_masses"]
    assert table["directions"] == ["x", "y", "z", "rx", "ry", "rz"]
    # Modes plus residual are M(0) at the hub: the total mass and the rigid design
    # inertia J_tot (appendix A.4, computed on an independent path), to round-off.
    mass = load_config().hub.mass_kg + 2 * 6.75  # hub + two 6.75 kg panels (table 3.1)
    np.testing.assert_allclose(table["total"][:3], [mass] * 3, rtol=1e-12)
    np.testing.assert_allclose(table["total"][3:], np.diag(summary["rigid_inertia"]), rtol=1e-12)
    cumulative = np.array(table["cumulative_fraction"])
    assert np.all(np.diff(cumulative, axis=0) >= 0.0) and np.all(cumulative <= 1.0 + 1e-12)


def _with_modal_file(tmp_path, table: dict) -> str:
    path = tmp_path / "wing.toml"
    path.write_text(_toml(table))
    data = nominal_dict()
    data["appendages"][0] = {"name": "wing", "model": "modal", "mount_point_m": [0.0, 0.8, 0.0],
                             "file": str(path)}  # fmt: skip
    config = tmp_path / "satellite.toml"
    config.write_text(to_toml(data))
    return str(config)


def test_a_modal_file_drives_the_modal_command(capsys, tmp_path, panel_data):
    # The exported plate replaces the plate: same coupled frequencies (exact round trip).
    outcome = flexsat(["modal", "--json", "--config",
                       _with_modal_file(tmp_path, panel_data.model_dump())], capsys)  # fmt: skip
    assert outcome.code == 0, outcome.stderr
    reference = json.loads(flexsat(["modal", "--json"], capsys).stdout)["frequencies_hz"]
    np.testing.assert_allclose(json.loads(outcome.stdout)["frequencies_hz"][6:], reference[6:],
                               rtol=1e-9)  # fmt: skip


@pytest.mark.parametrize(
    ("change", "field"),
    [
        (lambda d: d.__setitem__("frequencies_hz", [-0.2, *d["frequencies_hz"][1:]]),
         "frequencies_hz"),
        (lambda d: d["damping_ratios"].pop(), "damping_ratios"),
        (lambda d: d.__setitem__("participation",
                                 [[5.0 * x for x in r] for r in d["participation"]]),
         "participation"),
    ],
)  # fmt: skip
def test_a_bad_modal_file_exits_2_naming_the_field(capsys, tmp_path, panel_data, change, field):
    table = panel_data.model_dump()
    change(table)
    outcome = flexsat(["modal", "--config", _with_modal_file(tmp_path, table)], capsys)
    assert outcome.code == 2
    assert field in outcome.stderr and "Traceback" not in outcome.stderr


def test_npz_modal_file(capsys, tmp_path, panel_data):
    path = save_modal_data(panel_data, tmp_path / "wing.npz")
    data = nominal_dict()
    data["appendages"][0] = {"name": "wing", "model": "modal", "mount_point_m": [0.0, 0.8, 0.0],
                             "file": str(path)}  # fmt: skip
    config = tmp_path / "satellite.toml"
    config.write_text(to_toml(data))
    assert flexsat(["modal", "--json", "--config", str(config)], capsys).code == 0


def test_a_modal_file_is_found_beside_the_config_that_names_it(capsys, tmp_path, monkeypatch,
                                                                  panel_data):  # fmt: skip
    # docs/modal_format.md, "In a satellite TOML": `file` is relative to the TOML's
    # folder, so the command works from any folder (here the parent of fe/).
    folder = tmp_path / "fe"
    folder.mkdir()
    save_modal_data(panel_data, folder / "wing.npz")
    data = nominal_dict()
    data["appendages"][0] = {"name": "wing", "model": "modal", "mount_point_m": [0.0, 0.8, 0.0],
                             "file": "wing.npz"}  # fmt: skip
    (folder / "modal_sat.toml").write_text(to_toml(data))
    monkeypatch.chdir(tmp_path)
    outcome = flexsat(["modal", "--json", "--config", "fe/modal_sat.toml"], capsys)
    assert outcome.code == 0, outcome.stderr
    # The exported plate in place of panel_1: the coupled frequencies of the nominal
    # satellite (exact round trip; 1e-9 relative: the eigensolver's round-off).
    reference = json.loads(flexsat(["modal", "--json"], capsys).stdout)["frequencies_hz"]
    np.testing.assert_allclose(json.loads(outcome.stdout)["frequencies_hz"][6:], reference[6:],
                               rtol=1e-9)  # fmt: skip
    monkeypatch.chdir(folder)  # a file named from the working directory is not looked for
    (folder / "fe").mkdir()
    (folder / "fe" / "modal_sat.toml").write_text(to_toml(data))
    outcome = flexsat(["modal", "--config", "fe/modal_sat.toml"], capsys)
    assert outcome.code == 2
    assert "modal data file not found: fe/wing.npz" in outcome.stderr  # beside the TOML
