"""A plate's ``drive`` key: a TOML satellite puts its plates on a solar-array drive.

The plant builds a plate with ``drive`` as the driven two-segment chain, its joints
tuned as the undriven plate's: the same plant, bit for bit, as the chain written out
by hand from the tuned plant (then the plant of that chain).
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from flexsat.analysis.modal import modal_analysis
from flexsat.config import load_config, nominal, preset_path, validate_config
from flexsat.dynamics.appendages.sadm import DRIVE_COORDINATE, driven_plate, with_sadm
from flexsat.dynamics.plant import Plant
from flexsat.errors import ConfigError
from flexsat.simulate import run_slew
from flexsat.simulate.scenario import SlewScenario
from tests.cli.harness import flexsat
from tests.conftest import nominal_dict

ROTOR = {"rotor_inertia_kg_m2": 0.1, "rotor_mass_kg": 2.0}
_TABLE = "[appendages.drive]\nrotor_inertia_kg_m2 = 0.1\nrotor_mass_kg = 2.0\n"


def _driven_toml(tmp_path) -> str:
    """The nominal preset with a ``[appendages.drive]`` table after each plate's targets."""
    text = preset_path("nominal").read_text()
    blocks = text.split("[[appendages]]")
    path = tmp_path / "driven.toml"
    path.write_text("[[appendages]]".join([blocks[0]] + [b + "\n" + _TABLE for b in blocks[1:]]))
    return str(path)


def _hand_written_chains(config):
    """The driven chains written out from the tuned plant, each plate's joints tuned as its own."""
    plant = Plant.from_config(config)
    chains = [driven_plate(app, model.stiffness(row), model.damping(row), **ROTOR)
              for app, model, row in zip(config.appendages, plant.models, plant.params,
                                         strict=True)]  # fmt: skip
    return config.model_copy(update={"appendages": chains})


def _same_plant(a: Plant, b: Plant) -> None:
    assert a.config == b.config
    assert a.layout.dof_names() == b.layout.dof_names()
    for row_a, row_b in zip(a.params, b.params, strict=True):
        assert np.array_equal(row_a, row_b)
    assert np.array_equal(a.mass_matrix(), b.mass_matrix())


@pytest.fixture(scope="module")
def hand_written() -> Plant:
    return Plant.from_config(_hand_written_chains(nominal()))


def test_a_toml_drive_builds_the_plant_with_sadm_built(tmp_path, hand_written):
    config = load_config(_driven_toml(tmp_path))
    assert [app.drive.model_dump() for app in config.appendages] == [ROTOR, ROTOR]
    assert with_sadm(nominal(), **ROTOR) == config  # with_sadm just sets the key
    plant = Plant.from_config(config)
    _same_plant(plant, hand_written)
    assert f"panel_2.{DRIVE_COORDINATE}" in plant.layout.dof_names()


def test_a_driven_slew_is_bit_identical_to_the_hand_written_chains(tmp_path, hand_written):
    # A short slew with the drive turning: every recorded value equal, bit for bit.
    drive = {"kind": "sadm_drive", "coordinates": [DRIVE_COORDINATE], "stiffness_nm_rad": 4.0,
             "damping_nms_rad": 1.0, "rate_deg_s": 0.5}  # fmt: skip
    scenario = SlewScenario.model_validate({"duration_s": 0.2, "joint_actuator": drive})
    new = run_slew(Plant.from_config(load_config(_driven_toml(tmp_path))), scenario,
                   progress=False).dataset  # fmt: skip
    old = run_slew(hand_written, scenario, progress=False).dataset
    for name in ("q", "qd", "tau_applied", "sadm_torque", "pointing_error_deg"):
        assert np.array_equal(new[name].values, old[name].values), name


def test_the_modal_analysis_counts_each_drive_as_a_rigid_mode(hand_written):
    # Each drive angle is a mechanism (no stiffness): 6 + 2 modes at exactly 0 Hz,
    # then the flexible modes, the first the symmetric flapping near 0.25 Hz.
    analysis = modal_analysis(hand_written)
    assert [m.kind for m in analysis.modes[:8]] == ["rigid"] * 8
    assert np.all(analysis.frequencies_hz[:8] == 0.0)
    assert analysis.modes[8].kind == "flapping"
    assert analysis.frequencies_hz[8] == pytest.approx(0.25, rel=0.1)


def _with_drive(**edits) -> dict:
    data = nominal_dict()
    plate = data["appendages"][0]
    drive = {**ROTOR, **{k: v for k, v in edits.items() if k in ROTOR or k == "colour"}}
    plate.update({k: v for k, v in edits.items() if k not in drive})
    plate["drive"] = drive
    return data


@pytest.mark.parametrize(("edits", "fragment"), [
    ({"rotor_inertia_kg_m2": 0.0}, "appendages[0].drive.rotor_inertia_kg_m2: Input should be "
     "greater than 0"),
    ({"rotor_inertia_kg_m2": -1.0}, "appendages[0].drive.rotor_inertia_kg_m2: Input should be "
     "greater than 0"),
    ({"rotor_inertia_kg_m2": math.inf}, "appendages[0].drive.rotor_inertia_kg_m2: Input should "
     "be a finite number"),
    ({"rotor_inertia_kg_m2": 1e13}, "appendages[0].drive.rotor_inertia_kg_m2: Input should be "
     "less than or equal to 1000000000000"),
    ({"rotor_mass_kg": 0.0}, "appendages[0].drive.rotor_mass_kg: Input should be greater than "
     "or equal to 0.0001"),
    ({"rotor_mass_kg": math.nan}, "appendages[0].drive.rotor_mass_kg: Input should be a finite "
     "number"),
    ({"colour": 1.0}, "unknown key 'appendages[0].drive.colour'"),
    ({"locked_dofs": ["eta_x"]}, "drive: a plate on a drive takes no locked_dofs"),
    ({"sadm_angle_deg": 60.0}, "sadm_angle_deg: a plate on a drive starts its drive angle "
     "within -45 < alpha < 45 deg (got 60)"),
])  # fmt: skip
def test_bad_drives_give_one_message(edits, fragment):
    with pytest.raises(ConfigError) as caught:
        validate_config(_with_drive(**edits))
    assert fragment in str(caught.value)
    assert "\n" not in str(caught.value)


def test_a_bad_drive_is_exit_code_2(tmp_path, capsys):
    path = tmp_path / "bad.toml"
    path.write_text(preset_path("nominal").read_text().replace(
        "\n[[appendages]]\nname = \"panel_2\"",
        "\n[appendages.drive]\nrotor_inertia_kg_m2 = -0.1\nrotor_mass_kg = 2.0\n"
        "\n[[appendages]]\nname = \"panel_2\""))  # fmt: skip
    outcome = flexsat(["config", "show", "--config", str(path)], capsys)
    assert outcome.code == 2, outcome.stderr
    assert "appendages[0].drive.rotor_inertia_kg_m2" in outcome.stderr
    assert "Traceback" not in outcome.stderr
