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

DOCS = Path(__file__).resolve().parents[3] / "docs"


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


# A corner of the thesis's Monte Carlo set: every appendage path its campaigns vary.
THESIS_DISPERSION = [
    Modifier(path="appendages[*].damping_ratio", value=0.01),
    Modifier(path="appendages[*].target_frequencies_hz.flapping", op="scale", value=1.2),
    Modifier(path="appendages[*].target_frequencies_hz.in_plane", op="scale", value=0.8),
    Modifier(path="appendages[*].target_frequencies_hz.torsion", op="scale", value=1.1),
    Modifier(path="appendages[*].sadm_angle_deg", value=30.0),
    Modifier(path="appendages[*].inertia", value=0.8),
]


def test_the_thesis_dispersions_change_a_chain_as_they_change_the_plate():
    # Independent formulation: the plate takes these paths in its own fields; its twin,
    # the one-segment chain on a 6-DOF joint tuned to the plate's targets, through the
    # chain's derived paths (joint damping ratio, per-DOF target frequencies of each
    # kind, the mount turned about the span, the mass). Before the change the two are
    # the same satellite to round-off (tests/dynamics/appendages/test_chain_plate.py); so must they
    # be after it: tuned stiffness and damping to 1e-14 (eqs. 2.14-2.15 from the same
    # M(0) entries), M(q) and q_ddot at random states to 1e-13 (about 500 ulp, the bound
    # of test_chain_plate.py for two orders of the same sums; measured 1.3e-15). The
    # mount turned about X instead of the span (Y) is off by 0.19, a wrong family or a
    # damping left per DOF by O(1).
    from tests.conftest import nominal_dict
    from tests.dynamics.chain_satellites import thesis_chain_dict

    plate, chain = (
        Plant.from_config(validate_config(
            apply_modifiers(data, THESIS_DISPERSION, np.random.default_rng(0), {})))
        for data in (nominal_dict(), thesis_chain_dict())
    )  # fmt: skip
    assert plate.config.appendages[0].sadm_angle_deg == 30.0
    np.testing.assert_allclose(chain.stiffness, plate.stiffness, rtol=1e-14)
    np.testing.assert_allclose(chain.damping, plate.damping, rtol=1e-14)
    rng = np.random.default_rng(20261204)
    for _ in range(10):
        q, qd = 0.3 * rng.standard_normal((2, plate.n_dof))
        for new, ref in ((chain.mass_matrix(q), plate.mass_matrix(q)),
                         (chain.accelerations(q, qd), plate.accelerations(q, qd))):  # fmt: skip
            assert np.abs(new - ref).max() <= 1e-13 * np.abs(ref).max()


def _clamped_modes(plant: Plant) -> tuple[np.ndarray, list[str]]:
    """Clamped-root frequencies [Hz] of the plant's appendage coordinates (the hub held)
    and the joint DOF (rx, ry, rz) that holds most of each mode's kinetic energy."""
    from scipy.linalg import eigh

    flex = plant.layout.flexible
    M = plant.mass_matrix()[flex, flex]
    w2, phi = eigh(plant.stiffness_matrix()[flex, flex], M)
    dofs = np.array([name.split(".")[-1].split("_")[1] for name in plant.dof_names()[flex]])
    energy = phi * (M @ phi)  # each coordinate's share of each mode's kinetic energy
    kinds = [max(("rx", "ry", "rz"), key=lambda d: energy[dofs == d, k].sum())
             for k in range(len(w2))]  # fmt: skip
    return np.sqrt(w2) / (2.0 * np.pi), kinds


@pytest.mark.parametrize(("kind", "dof"), [("flapping", "rx"), ("in_plane", "rz"),
                                           ("torsion", "ry")])  # fmt: skip
def test_a_frequency_factor_moves_every_clamped_mode_of_its_kind(kind, dof):
    # The chain preset: two 8-segment beam chains along +-Y (flapwise = rx, in-plane =
    # rz, torsion = ry). A factor s on target_frequencies_hz.<kind> multiplies that beam
    # stiffness by s^2. A straight chain's flapwise, in-plane and torsion motions do not
    # couple at q = 0, so K phi = w^2 M phi (hub held) gives every mode of that kind
    # times s and leaves the others: all 48 frequencies against that prediction to
    # 1e-10 relative (measured 4e-13 to 1e-12: eigh's round-off on a 48 x 48 problem
    # whose frequencies span three decades; any coupling between the kinds would move
    # them by 1e-3 or more). The plate has one mode per kind, and a factor on its
    # target moves that mode by s alike.
    data = tomllib.loads(preset_path("chain").read_text())
    before, kinds = _clamped_modes(Plant.from_config(validate_config(data)))
    scaled = apply_modifiers(
        data, [Modifier(path=f"appendages[*].target_frequencies_hz.{kind}", op="scale",
                        value=1.2)], np.random.default_rng(0), {})  # fmt: skip
    after, _ = _clamped_modes(Plant.from_config(validate_config(scaled)))
    expected = np.sort(np.where(np.array(kinds) == dof, 1.2, 1.0) * before)
    assert kinds.count(dof) == 16  # 8 segments x 2 panels
    np.testing.assert_allclose(after, expected, rtol=1e-10)


# -- the mount: one vocabulary for every appendage model --------------------------------


def _rz_ry(yaw_deg: float, sadm_deg: float) -> np.ndarray:
    """Rz(yaw) Ry(sadm) written out (the plate's mount, docs/model.md)."""
    a, b = np.radians(yaw_deg), np.radians(sadm_deg)
    rz = np.array([[np.cos(a), -np.sin(a), 0.0], [np.sin(a), np.cos(a), 0.0], [0.0, 0.0, 1.0]])
    ry = np.array([[np.cos(b), 0.0, np.sin(b)], [0.0, 1.0, 0.0], [-np.sin(b), 0.0, np.cos(b)]])
    return rz @ ry


def test_every_appendage_model_names_its_mount_with_the_same_keys():
    # A plate, its twin as a chain and its modal export, each given mount_yaw_deg = 30
    # and sadm_angle_deg = 20: the same mount frame, Rz(30) Ry(20) written out, to
    # 1e-15 (round-off of one product of two rotations).
    from flexsat.dynamics.appendages.modal import ModalAppendageConfig
    from flexsat.linear.export import modal_satellite, mount_rotation
    from tests.conftest import nominal_dict
    from tests.dynamics.chain_satellites import plate_as_chain

    data = nominal_dict()
    data["appendages"][0].update(mount_yaw_deg=30.0, sadm_angle_deg=20.0)
    plate = validate_config(data)
    chain = plate_as_chain(data["appendages"][0])
    assert (chain["mount_yaw_deg"], chain["sadm_angle_deg"]) == (30.0, 20.0)
    modal = modal_satellite(Plant.from_config(plate), n_modes=2).appendages[0].model_dump()
    modal.pop("mount_matrix")  # the export states R_BM; given here by the two angles
    modal.update(mount_yaw_deg=30.0, sadm_angle_deg=20.0)
    expected = _rz_ry(30.0, 20.0)
    plant = Plant.from_config(plate)
    rotations = {
        "plate": mount_rotation(plant.models[0], plant.params[0]),
        "chain": validate_config({**data, "appendages": [chain, data["appendages"][1]]})
        .appendages[0].mount_rotation(),
        "modal": ModalAppendageConfig.model_validate(modal).mount_rotation(),
    }  # fmt: skip
    for model, rotation in rotations.items():
        np.testing.assert_allclose(rotation, expected, rtol=0, atol=1e-15, err_msg=model)


def test_the_chains_former_mount_key_is_read_with_one_warning(monkeypatch):
    # mount_zyx_deg = (a, b, 0) on a chain spanning Y is the yaw and SADM angles
    # exactly; (a, b, c) any other orientation, read as mount_matrix = Rz(a) Ry(b) Rx(c)
    # (written out, 1e-15). One FutureWarning in the process, naming the old key and
    # the new ones; a second config reads without another.
    import warnings

    from flexsat.config.load import ConfigError
    from flexsat.dynamics.appendages import chain_config
    from tests.conftest import nominal_dict
    from tests.dynamics.chain_satellites import plate_as_chain

    monkeypatch.setattr(chain_config, "_RENAMED_WARNED", set(), raising=False)
    data = nominal_dict()
    new = plate_as_chain(data["appendages"][0])
    new.update(mount_yaw_deg=30.0, sadm_angle_deg=20.0)
    old = {k: v for k, v in new.items() if k not in ("mount_yaw_deg", "sadm_angle_deg")}

    def mount(table: dict) -> np.ndarray:
        satellite = validate_config({**data, "appendages": [table, data["appendages"][1]]})
        return satellite.appendages[0].mount_rotation()

    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        first = mount({**old, "mount_zyx_deg": [30.0, 20.0, 0.0]})
        roll = np.radians(-10.0)
        rx = np.array([[1.0, 0.0, 0.0], [0.0, np.cos(roll), -np.sin(roll)],
                       [0.0, np.sin(roll), np.cos(roll)]])  # fmt: skip
        np.testing.assert_allclose(mount({**old, "mount_zyx_deg": [30.0, 20.0, -10.0]}),
                                   _rz_ry(30.0, 20.0) @ rx, rtol=0, atol=1e-15)  # fmt: skip
    np.testing.assert_array_equal(first, mount(new))
    messages = [str(w.message) for w in caught if issubclass(w.category, FutureWarning)]
    assert len(messages) == 1, messages
    assert "mount_zyx_deg is deprecated, read as mount_yaw_deg and sadm_angle_deg" in messages[0]
    with pytest.raises(ConfigError, match=r"give mount_zyx_deg \(deprecated\) or mount_yaw_deg"):
        mount({**new, "mount_zyx_deg": [30.0, 20.0, 0.0]})
