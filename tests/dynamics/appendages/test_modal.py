"""The modal (hybrid-coordinate) appendage: its equations, its physics, its data format.

References: the plate model it is exported from (an independent formulation, exact
at linear order), the thesis's table 3.3 and section 3.3, the conservation laws, and
the Lagrangian M(q) and h(q, q_dot) of the same model against its articulated-body
accelerations (two formulations of one set of equations).
"""

from __future__ import annotations

import copy

import numpy as np
import pytest
from scipy.linalg import eigh

from flexsat import ConfigError, Plant, load_config
from flexsat.analysis.modal import modal_analysis
from flexsat.analysis.openloop import openloop_metrics
from flexsat.config import validate_config
from flexsat.config.modal_data import load_modal_data, save_modal_data
from flexsat.linear.export import modal_data, modal_satellite
from flexsat.simulate import OpenLoopScenario, run_openloop
from flexsat.study import thesis
from tests.conftest import nominal_dict


@pytest.fixture(scope="module")
def nominal() -> Plant:
    return Plant.from_config(load_config())


@pytest.fixture(scope="module")
def undamped(nominal) -> Plant:
    return nominal.with_joints(nominal.stiffness, np.zeros(nominal.n_dof - 6))


def _asymmetric() -> Plant:
    """Two unlike panels at odd mount angles, exported with their 3 lowest modes each
    (0.2-0.9 Hz): no symmetry left, every coupling term non-zero."""
    data = nominal_dict()
    first, second = data["appendages"]
    first.update(sadm_angle_deg=30.0, mount_yaw_deg=10.0)
    second.update(sadm_angle_deg=-55.0, mount_point_m=[0.1, -0.75, 0.2], damping_ratio=0.02,
                  length_m=3.2)  # fmt: skip
    return Plant.from_config(modal_satellite(Plant.from_config(validate_config(data)), n_modes=3))


@pytest.fixture(scope="module")
def asymmetric() -> Plant:
    return _asymmetric()


# -- the equations: articulated-body form == Lagrangian form -----------------------------


def test_accelerations_solve_the_lagrangian_equations(asymmetric):
    # q_ddot from pass 1 / hub solve / pass 2 against M(q)^-1 (Q - h - C q_dot - K q)
    # with M and h from the kinetic energy, at random states far from rest. Both are
    # exact; they differ by the round-off of a 12 x 12 solve (~1e-14 relative).
    rng = np.random.default_rng(7)
    for _ in range(5):
        q, qd = rng.normal(size=(2, asymmetric.n_dof)) * 0.4
        Q = rng.normal(size=asymmetric.n_dof)
        qdd = asymmetric.accelerations(q, qd, Q)
        M = asymmetric.mass_matrix(q)
        rhs = Q - asymmetric.bias_forces(q, qd) - asymmetric.damping_forces(qd)
        expected = np.linalg.solve(M, rhs - asymmetric.elastic_forces(q))
        np.testing.assert_allclose(qdd, expected, rtol=0, atol=1e-12 * np.abs(expected).max())
        # T = 1/2 q_dot^T M q_dot, the observer's kinetic energy (same round-off)
        assert asymmetric.kinetic_energy(q, qd) == pytest.approx(0.5 * qd @ M @ qd, rel=1e-13)


# -- exact round trip: the thesis plate exported with all its modes ----------------------


def test_round_trip_reproduces_the_coupled_frequencies(nominal):
    # Same M(0) and K_sys in modal coordinates: the coupled eigenvalues agree to the
    # round-off of two generalized eigenproblems (measured 9e-12; required 1e-9).
    modal = Plant.from_config(modal_satellite(nominal))
    f_plate = modal_analysis(nominal).frequencies_hz[6:]
    f_modal = modal_analysis(modal).frequencies_hz[6:]
    np.testing.assert_allclose(f_modal, f_plate, rtol=1e-9)


def test_round_trip_reproduces_the_mass_matrix(undamped):
    # phi^T M(0) phi of the plate coordinates is the modal appendage's M(0) exactly.
    modal = Plant.from_config(modal_satellite(undamped))
    M0, T = undamped.mass_matrix(), np.eye(undamped.n_dof)
    for block in undamped.layout.blocks:
        b = block.slice
        k = np.diag(undamped.stiffness[b.start - 6 : b.stop - 6])
        T[b, b] = eigh(k, M0[b, b])[1]
    np.testing.assert_allclose(T.T @ M0 @ T, modal.mass_matrix(), rtol=0, atol=1e-13 * 190.0)


def _pulse(amplitude: float) -> OpenLoopScenario:
    return OpenLoopScenario.model_validate({
        "duration_s": 5.0,
        "torque": [{"start_s": 0.0, "end_s": 1.0,
                    "torque_nm": [amplitude, -2.0 * amplitude, amplitude]}],
    })  # fmt: skip


def _history_error(plate: Plant, modal: Plant, amplitude: float,
                   compared=("omega", "tau_flex", "tip_displacement")) -> float:  # fmt: skip
    a = run_openloop(plate, _pulse(amplitude)).dataset
    b = run_openloop(modal, _pulse(amplitude)).dataset
    return max(float(np.abs(a[v].values - b[v].values).max() / np.abs(a[v].values).max())
               for v in compared)  # fmt: skip


def test_round_trip_reproduces_a_small_amplitude_history(undamped):
    # The plate's kinematics are exact (nonlinear), the modal appendage's linear: the
    # histories differ by the plate's quadratic terms, relative error proportional to
    # the amplitude (measured 1.3e-2 per N m of a 1 s pulse). At 1e-6 N m it is ~1e-8,
    # well inside 1e-6; that the error scales with the amplitude (x100 for x100, within
    # 5 %) shows no linear-order mismatch is left.
    modal = Plant.from_config(modal_satellite(undamped))
    small, large = _history_error(undamped, modal, 1e-6), _history_error(undamped, modal, 1e-4)
    assert small <= 1e-6
    assert large / small == pytest.approx(100.0, rel=0.05)


# -- the thesis: modal appendages fitted from its plates ---------------------------------


def test_fitted_modal_appendages_reproduce_table_3_3(nominal):
    modal = Plant.from_config(modal_satellite(nominal))
    modes = modal_analysis(modal).modes
    for index, frequency, *_ in thesis.TABLE_3_3:
        assert modes[index - 1].frequency_hz == pytest.approx(frequency, abs=thesis.PRINTED_2DP)


@pytest.fixture(scope="module")
def thesis_metrics(nominal) -> dict:
    return openloop_metrics(run_openloop(Plant.from_config(modal_satellite(nominal))).dataset)


def test_fitted_modal_appendages_reproduce_section_3_3(thesis_metrics):
    # Within the printed precision: H_z = 10 N m s (exact impulse, round-off only),
    # the 1.23 Hz ripple (2 decimals) and peak |tau_flex,z| 1.59 N m (2 decimals; the
    # plate model gives 1.583). Modal damping keeps the diagonal of phi^T C phi, which
    # changes the peak by far less than the printed half-unit.
    np.testing.assert_allclose(thesis_metrics["final_angular_momentum_nms"], [0, 0, 10], atol=1e-9)
    assert thesis_metrics["dominant_frequency_hz"] == pytest.approx(1.23, abs=thesis.PRINTED_2DP)
    assert thesis_metrics["peak_flex_torque_nm"][2] == pytest.approx(1.59, abs=0.01)


# -- physics -----------------------------------------------------------------------------

_SPINNING = {"attitude_deg": [10.0, -5.0, 30.0], "rate_deg_s": [0.5, -1.0, 2.0]}


def _free(plant: Plant, **settings):
    scenario = OpenLoopScenario.model_validate(
        {"torque": [], "initial": _SPINNING, "duration_s": 20.0, **settings}
    )
    return run_openloop(plant, scenario).dataset


def test_momentum_is_conserved_without_damping_or_torque(asymmetric):
    # A tumbling satellite excites the modes through the interface accelerations; the
    # total angular momentum is an exact invariant of the model. DOP853 at rtol 1e-12
    # keeps it to ~1e-12 relative over 20 s (required 1e-10).
    plant = asymmetric.with_joints(asymmetric.stiffness, np.zeros(asymmetric.n_dof - 6))
    ds = _free(plant, solver="dop853", rtol=1e-12, atol=1e-14)
    H = ds["angular_momentum"].values
    assert np.abs(H - H[0]).max() / np.linalg.norm(H[0]) <= 1e-10
    assert np.abs(ds["elastic_energy"].values).max() > 0.0  # the modes did move


def test_energy_balance_closes_with_damping(asymmetric):
    # E(t) - E(0) - W_in + W_diss, with the dissipation integrated with the motion:
    # zero to the integrator's tolerance (DOP853 rtol 1e-12: ~1e-13 of E0).
    ds = _free(asymmetric, solver="dop853", rtol=1e-12, atol=1e-14)
    assert ds["dissipated_energy"].values[-1] > 0.0
    E0 = float(ds["total_energy"].values[0])
    assert np.abs(ds["energy_balance_error"].values).max() <= 1e-10 * E0


def test_effective_masses_sum_to_the_rigid_mass_with_all_modes(nominal):
    # The plate's joint spans all its rigid motions relative to the hub: with all six
    # modes kept, sum_k L_k^T L_k is the rigid mass matrix about the root (round-off of
    # the eigenvectors, 1e-12 of the largest entry); with fewer it stays below it.
    full = modal_data(nominal, "panel_1")
    rigid = full.rigid_mass_matrix()
    np.testing.assert_allclose(full.effective_mass(), rigid, rtol=0, atol=1e-12 * rigid.max())
    for n in range(1, 6):
        partial = modal_data(nominal, "panel_1", n_modes=n)
        assert np.linalg.eigvalsh(rigid - partial.effective_mass()).min() >= -1e-12 * rigid.max()


# -- the data format ---------------------------------------------------------------------


@pytest.mark.parametrize("suffix", [".toml", ".npz"])
def test_files_round_trip_exactly(nominal, tmp_path, suffix):
    data = modal_data(nominal, "panel_1")
    assert load_modal_data(save_modal_data(data, tmp_path / f"panel{suffix}")) == data


def _table(nominal) -> dict:
    return modal_data(nominal, "panel_1").model_dump()


@pytest.mark.parametrize(
    ("change", "field", "says"),
    [
        (lambda d: d["participation"].pop(), "participation", "one entry per mode"),
        (lambda d: d.__setitem__("frequencies_hz", [-1.0, *d["frequencies_hz"][1:]]),
         "frequencies_hz", "> 0 Hz"),
        (lambda d: d["frequencies_hz"].reverse(), "frequencies_hz", "sorted ascending"),
        (lambda d: d.__setitem__("participation", [[3.0 * x for x in row]
                                                  for row in d["participation"]]),
         "participation", "effective masses exceed the rigid mass"),
        (lambda d: d.__setitem__("mass_kg", float("nan")), "mass_kg", "finite"),
        (lambda d: d["output_points"][0]["mode_shapes"].pop(), "mode_shapes", "one row per mode"),
        (lambda d: d.__setitem__("inertia_interface_kg_m2", [[1, 0, 0], [0, 1, 0], [0, 0, 1]]),
         "inertia_interface_kg_m2", "positive definite"),
    ],
)  # fmt: skip
def test_bad_modal_data_names_the_field(nominal, tmp_path, change, field, says):
    table = _table(nominal)
    change(table)
    path = tmp_path / "bad.toml"
    from flexsat.config.modal_data import _toml

    path.write_text(_toml(table))
    with pytest.raises(ConfigError, match=field) as caught:
        load_modal_data(path)
    assert says in str(caught.value)


def test_a_bad_file_in_a_satellite_config_is_one_clear_message(tmp_path):
    data = nominal_dict()
    data["appendages"][0] = {"name": "wing", "model": "modal", "mount_point_m": [0, 0.8, 0],
                             "file": str(tmp_path / "missing.npz")}  # fmt: skip
    with pytest.raises(ConfigError, match=r"appendages\[0\].*modal data file not found"):
        validate_config(data)


def test_campaign_scales_act_on_every_mode(nominal):
    table = copy.deepcopy(_table(nominal))
    base = {"name": "wing", "model": "modal", "mount_point_m": [0, 0.8, 0], "data": table}
    data = nominal_dict()
    data["appendages"] = [{**base, "frequency_scale": 1.1, "damping_scale": 2.0}]
    plant = Plant.from_config(validate_config(data))
    omega = 2 * np.pi * np.array(table["frequencies_hz"]) * 1.1
    np.testing.assert_allclose(plant.stiffness, omega**2, rtol=1e-14)
    np.testing.assert_allclose(plant.damping, 2 * 2.0 * np.array(table["damping_ratios"]) * omega,
                               rtol=1e-14)  # fmt: skip
    data["appendages"] = [{**base, "participation_scale": 2.0}]
    with pytest.raises(ConfigError, match="effective masses exceed the rigid mass"):
        validate_config(data)


def test_the_thesis_damping_path_sets_every_modes_ratio(nominal):
    # The thesis's campaigns set appendages[*].damping_ratio (zeta = 0 is their critical
    # case); on a modal appendage it sets every mode's ratio, any damping_scale undone:
    # the plant's modal damping is then 2 zeta omega_k (eq. 2.15 per mode), to round-off.
    # Its frequency paths have no meaning for modes from a file: refused, naming the
    # modal paths instead.
    from flexsat.campaigns.modifiers import Modifier, apply_modifiers

    table = copy.deepcopy(_table(nominal))
    data = nominal_dict()
    data["appendages"] = [{"name": "wing", "model": "modal", "mount_point_m": [0, 0.8, 0],
                           "data": table, "damping_scale": 2.0}]  # fmt: skip
    base = validate_config(data).model_dump()
    rng = np.random.default_rng(0)
    realised: dict = {}
    out = apply_modifiers(base, [Modifier(path="appendages[*].damping_ratio", value=0.02)],
                          rng, realised)  # fmt: skip
    plant = Plant.from_config(validate_config(out))
    omega = 2 * np.pi * np.array(table["frequencies_hz"])
    np.testing.assert_allclose(plant.damping, 2 * 0.02 * omega, rtol=1e-14)
    assert realised == {"appendages[0].damping_ratio": 0.02}
    with pytest.raises(KeyError, match=r"a 'modal' appendage.*frequency_scale"):
        apply_modifiers(base, [Modifier(path="appendages[*].target_frequencies_hz.flapping",
                                        op="scale", value=1.2)], rng, {})  # fmt: skip


# -- exact round trip: a chain exported with all its modes -------------------------------


@pytest.fixture(scope="module")
def beam_chains():
    from tests.fe.test_three_formulations import chain_satellite

    chain = chain_satellite(8)
    return chain, Plant.from_config(modal_satellite(chain))


def test_chain_round_trip_frequencies_and_history(beam_chains):
    # Two 8-segment chains (in-plane joints): all 8 modes each kept, the coupled
    # frequencies agree to round-off (required 1e-9) and a small pulse's history within
    # 1e-6 (measured 1.6e-13 at 1e-6 N m: with the exported inertia derivatives the
    # planar chain's leading terms are all in the modal model; 7.9e-7 at 1e-4 N m,
    # 7.9e-5 at 1e-2 N m). tau_flex is each model's whole interface load (the chain's
    # root reactions, the modal appendage's interface wrench, docs/model.md eqs. C.9
    # and M.7): measured 2.8e-13 at 1e-6 N m and 1.1e-10 at 1e-4 N m.
    chain, modal = beam_chains
    np.testing.assert_allclose(modal_analysis(modal).frequencies_hz[6:],
                               modal_analysis(chain).frequencies_hz[6:], rtol=1e-9)  # fmt: skip
    compared = ("omega", "tip_displacement", "tau_flex")
    assert _history_error(chain, modal, 1e-6, compared) <= 1e-6
    assert _history_error(chain, modal, 1e-4, compared) <= 1e-5


def test_the_modal_equation_table_resolves():
    # docs/model.md, "Modal appendages": every function its table names imports.
    from tests.test_docs import DOCS, REFERENCE, _resolve

    text = (DOCS / "model.md").read_text(encoding="utf-8")
    section = text.split("\n## Modal appendages\n", 1)[1].split("\n## ", 1)[0]
    references = set(REFERENCE.findall(section))
    assert len(references) >= 10
    for reference in sorted(references):
        _resolve(reference)


def test_design_model_and_drawing_of_the_fitted_thesis_plates(nominal):
    # The rigid design inertia J_tot of the modal satellite is the thesis's (appendix
    # A.4, printed to 2 decimals); the drawn tip moves by the tip mode-shape rows.
    from flexsat.dynamics.rigid import rigid_inertia

    modal = Plant.from_config(modal_satellite(nominal))
    np.testing.assert_allclose(rigid_inertia(modal), thesis.J_TOT_NOMINAL, atol=thesis.PRINTED_2DP)
    model, config, params = modal.models[0], modal.config.appendages[0], modal.params[0]
    q = np.zeros(6)
    q[0] = 1e-3
    moved = model.shape_points(config, params, q)[5] - model.shape_points(config, params, 0 * q)[5]
    tip = np.zeros(modal.n_dof)
    tip[modal.layout.blocks[0].slice] = q
    np.testing.assert_allclose(moved, modal.tip_displacement(tip)[0], atol=1e-15)
