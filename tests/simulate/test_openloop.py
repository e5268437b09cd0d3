"""Open-loop validation (thesis section 3.3) and the integrator's physics."""

from __future__ import annotations

import numpy as np
import pytest

from flexsat.analysis.openloop import openloop_metrics
from flexsat.dynamics.plant import Plant
from flexsat.simulate import OpenLoopScenario, Result, run_openloop
from tests.conftest import config_from, variant


@pytest.fixture(scope="module")
def thesis_run(nominal_plant):
    return run_openloop(nominal_plant)


@pytest.fixture(scope="module")
def thesis_metrics(thesis_run):
    return openloop_metrics(thesis_run.dataset)


# -- the thesis's numbers (section 3.3) -----------------------------------------------


def test_angular_momentum_is_the_impulse(thesis_metrics):
    # 1 N m for 10 s: H_z = 10 N m s exactly (fig. 3.12); the RK4 sum of a
    # constant torque is exact, so only round-off remains.
    np.testing.assert_allclose(thesis_metrics["final_angular_momentum_nms"], [0, 0, 10], atol=1e-9)


def test_final_yaw_rate(thesis_metrics):
    # Thesis: ~3.22 deg/s (printed to 2 decimals; H_z / J_zz = 10/177.9 rad/s).
    rate = thesis_metrics["final_rate_deg_s"]
    assert rate[2] == pytest.approx(3.22, abs=0.005)
    assert rate[2] == pytest.approx(np.degrees(10 / 177.90), rel=1e-3)


def test_energies(thesis_metrics):
    # Section 3.3 prints E_tot ~0.28 J, peak U ~0.9 mJ, dissipated ~0.55 mJ, to the
    # last printed digit: tolerances of half that digit (0.005 J, 0.05 mJ).
    assert thesis_metrics["total_energy_j"] == pytest.approx(0.28, abs=0.005)
    assert thesis_metrics["peak_elastic_energy_j"] == pytest.approx(0.9e-3, abs=0.05e-3)
    assert thesis_metrics["dissipated_energy_j"] == pytest.approx(0.55e-3, abs=0.05e-3)


def test_flex_torque_and_deformation(thesis_run, thesis_metrics):
    # Fig. 3.11: tau_flex,z peaks "close to +-1.5 N m" (we get 1.58: within 0.1 of
    # the reading); roll and pitch stay zero. Section 3.3: root in-plane rotation
    # "almost 0.1 deg", tip displacement "just over 6 mm".
    peak = thesis_metrics["peak_flex_torque_nm"]
    assert peak[2] == pytest.approx(1.5, abs=0.1)
    assert thesis_metrics["peak_root_rotation_deg"] == pytest.approx(0.1, abs=0.025)
    assert 6e-3 <= thesis_metrics["peak_tip_displacement_m"] <= 6.5e-3
    # Fig. 3.8: the yaw acceleration oscillates with peaks near +-2 deg/s^2.
    peak_acc = np.degrees(np.abs(thesis_run.dataset["omega_dot"].values[:, 2]).max())
    assert peak_acc == pytest.approx(2.0, abs=0.3)


def test_ripple_at_the_yaw_coupled_mode(thesis_metrics):
    # Fig. 3.14: the free response rings at ~1.23 Hz (mode 12). Periodogram of
    # 110 s with interpolation: a few mHz.
    assert thesis_metrics["dominant_frequency_hz"] == pytest.approx(1.2313, abs=0.005)


def test_roll_and_pitch_stay_at_round_off(thesis_run):
    ds = thesis_run.dataset
    assert np.abs(ds["omega"].values[:, :2]).max() < 1e-12
    assert np.abs(ds["euler_deg"].values[:, :2]).max() < 1e-10


def test_energy_balance_at_round_off(thesis_metrics):
    # E - E0 - W_in + W_diss with damping and torque: W_in and W_diss ride on the
    # same RK4 stages, so only the truncation of the barely excited ~100 Hz modes
    # and round-off remain; the bound is 1e-8 J (total energy 0.28 J).
    assert thesis_metrics["energy_balance_error_j"] <= 1e-8


def test_rk4_agrees_with_tight_dop853(nominal_plant, thesis_run):
    # The thesis scenario with scipy's DOP853 at rtol 1e-10. The slow motion agrees
    # to ~1e-8 (attitude, deformations, energy: measured 7e-9 deg, 2e-10 rad,
    # 8e-11 J). Rates, accelerations and tau_flex also carry the ~100 Hz joint
    # modes, which RK4 at 1 ms (omega dt ~ 0.6) integrates with a small phase and
    # amplitude error (docs/model.md, 'Integration'): measured 2e-7 rad/s,
    # 4e-5 rad/s^2 and 1.2e-3 N m (0.07 % of the 1.58 N m peak); bounds at about 5x those.
    # DOP853 flies the first 30 s (the 10 s pulse, the peaks of tau_flex and 20 s of
    # ringing): the differences over a part of the run are at most those over all of it,
    # so the bounds measured over 120 s hold; a quarter of the cost.
    reference = run_openloop(nominal_plant, OpenLoopScenario(solver="dop853", duration_s=30.0))
    b = reference.dataset
    a = thesis_run.dataset.isel(time=slice(0, b.sizes["time"]))
    np.testing.assert_allclose(a["time"], b["time"], rtol=0, atol=1e-12)  # the same instants
    np.testing.assert_allclose(a["euler_deg"], b["euler_deg"], rtol=0, atol=5e-8)
    np.testing.assert_allclose(a["rho"], b["rho"], rtol=0, atol=1e-9)
    np.testing.assert_allclose(a["total_energy"], b["total_energy"], rtol=0, atol=5e-10)
    np.testing.assert_allclose(a["omega"], b["omega"], rtol=0, atol=1e-6)
    np.testing.assert_allclose(a["omega_dot"], b["omega_dot"], rtol=0, atol=2e-4)
    np.testing.assert_allclose(a["tau_flex"], b["tau_flex"], rtol=0, atol=6e-3)


# -- conservation and convergence ------------------------------------------------------

_DEFORMED_SPINNING = {
    "attitude_deg": [10.0, -5.0, 30.0],
    "rate_deg_s": [0.5, -1.0, 2.0],
    "appendages": [
        {"name": "panel_1", "rho_deg": [0.5, -0.3, 0.8]},
        {"name": "panel_2", "rho_deg": [-0.2, 0.4, 0.1], "rho_rate_deg_s": [0.5, 0.0, 0.0]},
    ],
}


@pytest.fixture(scope="module")
def undamped_plant(nominal_plant):
    return nominal_plant.with_joints(nominal_plant.stiffness, np.zeros((2, 6)))


def _free_run(plant, **settings) -> Result:
    scenario = OpenLoopScenario.model_validate(
        {"torque": [], "initial": _DEFORMED_SPINNING, **settings}
    )
    return run_openloop(plant, scenario)


def _drifts(result: Result) -> tuple[float, float]:
    ds = result.dataset
    energy = ds["total_energy"].values
    H = ds["angular_momentum"].values
    return (
        float((energy[-1] - energy[0]) / energy[0]),
        float(np.abs(H - H[0]).max() / np.linalg.norm(H[0])),
    )


def test_conservation_at_small_step(undamped_plant):
    # zeta = 0, no torque, 120 s: energy within 1e-7 and momentum within 1e-8 of
    # their initial values at dt = 1e-4 s (the RK4 truncation of the ~100 Hz joint
    # modes is ~(omega dt)^6/144 per step there).
    energy, momentum = _drifts(_free_run(undamped_plant, dt_s=1e-4))
    assert abs(energy) <= 1e-7
    assert momentum <= 1e-8


def test_the_solvers_derivative_is_the_plants(nominal_plant):
    # DOP853 calls the derivative from Python with the packed plant in a typed list
    # (one pointer to unbox instead of every array and kernel): the same rates as
    # augmented_derivative, bit for bit (tolerance 0: the same compiled arithmetic on
    # the same arrays), at a deformed, spinning state under torque.
    from flexsat.compiled.typed_call import typed_list
    from flexsat.dynamics.integrators import augmented_derivative
    from flexsat.dynamics.kernels import hub_cs
    from flexsat.simulate.openloop import initial_state, listed_derivative

    scenario = OpenLoopScenario.model_validate({"initial": _DEFORMED_SPINNING})
    q0, qd0 = initial_state(nominal_plant, scenario)
    n = nominal_plant.n_dof
    x = np.concatenate([q0, qd0, [0.5, 0.1]])
    torque, Q = (1.0, -0.5, 0.25), np.linspace(0.0, 1.0, n)
    direct, listed = np.empty_like(x), np.empty_like(x)
    augmented_derivative(x, torque, n, Q, direct, nominal_plant.packed, hub_cs(x))
    listed_derivative(x, torque, n, Q, listed, typed_list(nominal_plant.packed))
    np.testing.assert_array_equal(listed, direct)
    assert np.abs(direct[n : 2 * n]).max() > 1e-3  # the state accelerates [SI]


def test_conservation_with_dop853(undamped_plant):
    # The same invariants by an independent integrator, over 30 s rather than 120 s
    # (a quarter of the cost): 3000 periods of the ~100 Hz joint modes, seven of the
    # slowest flapping mode (0.25 Hz) and about 70 deg of rotation, so an energy or
    # momentum error of the equations of motion shows many times over; DOP853's error
    # at rtol 1e-10 accumulates with time, so the bounds of the 120 s run are kept.
    energy, momentum = _drifts(_free_run(undamped_plant, solver="dop853", rtol=1e-10,
                                         atol=1e-12, duration_s=30.0))  # fmt: skip
    assert abs(energy) <= 1e-7
    assert momentum <= 1e-8


def test_rk4_at_1ms_shows_numerical_dissipation(undamped_plant):
    # At dt = 1 ms RK4 damps the ~100 Hz joint modes (omega dt ~ 0.6): with no
    # physical damping the energy can only fall, never grow, and the loss is the
    # integrator's. Measured: -1.1e-5 of E0 over 120 s for this state (the
    # momentum, a linear invariant of the exact flow, stays at 1e-11).
    energy, momentum = _drifts(_free_run(undamped_plant, dt_s=1e-3))
    assert -1e-4 < energy < -1e-7
    assert momentum <= 1e-8


def test_rk4_is_fourth_order(nominal_plant):
    # Smooth case (thesis torque, 0.5 s) at steps where omega dt << 1 for every
    # mode: halving dt divides the error by 2^4 = 16 (within 15 %).
    def final(dt):
        scenario = OpenLoopScenario(duration_s=0.5, dt_s=dt, record_dt_s=0.5)
        return run_openloop(nominal_plant, scenario).dataset["qd"].values[-1]

    reference = final(1e-5 / 4)
    errors = [np.abs(final(dt) - reference).max() for dt in (4e-4, 2e-4, 1e-4)]
    ratios = [errors[0] / errors[1], errors[1] / errors[2]]
    for ratio in ratios:
        assert ratio == pytest.approx(16.0, rel=0.15)


# -- faults -----------------------------------------------------------------------------


def test_diverging_run_stops_cleanly_and_keeps_its_history(tmp_path):
    # 2 kHz root translations integrated at dt = 10 ms: omega dt ~ 126, far outside
    # RK4's stability region.
    stiff = config_from(
        variant(
            target_frequencies_hz={
                "flapping": 0.25, "in_plane": 0.5, "torsion": 0.8,
                "translation_x": 2000.0, "translation_y": 2000.0, "translation_z": 2000.0,
            }
        )
    )  # fmt: skip
    plant = Plant.from_config(stiff)
    scenario = OpenLoopScenario(duration_s=60.0, dt_s=0.01, record_dt_s=0.01)
    result = run_openloop(plant, scenario)
    assert not result.ok
    failure_time = result.dataset.attrs["failure_time_s"]
    assert 0.0 < failure_time < 60.0
    assert f"t = {failure_time:.6g} s" in result.message
    assert result.time[-1] == pytest.approx(failure_time)
    assert np.all(np.isfinite(result.dataset["q"].values))
    path = result.to_netcdf(tmp_path / "failed.nc")
    again = Result.from_netcdf(path)
    assert again.dataset.attrs["status"] == "failed"
    assert again.time.size == result.time.size


def test_result_round_trips_through_netcdf(thesis_run, tmp_path):
    path = thesis_run.to_netcdf(tmp_path / "run.nc")
    again = Result.from_netcdf(path)
    assert again.dataset["omega"].attrs["units"] == "rad/s"
    np.testing.assert_array_equal(again.dataset["q"].values, thesis_run.dataset["q"].values)
    assert '"name": "nominal"' in again.dataset.attrs["config"]


def test_runs_are_deterministic(nominal_plant):
    scenario = OpenLoopScenario(duration_s=2.0)
    a = run_openloop(nominal_plant, scenario).dataset["q"].values
    b = run_openloop(nominal_plant, scenario).dataset["q"].values
    np.testing.assert_array_equal(a, b)


def test_unknown_appendage_in_initial_state_is_refused(nominal_plant):
    from flexsat.errors import ConfigError

    scenario = OpenLoopScenario.model_validate({"initial": {"appendages": [{"name": "wing"}]}})
    with pytest.raises(ConfigError, match="unknown appendage 'wing'"):
        run_openloop(nominal_plant, scenario)


def test_other_topologies_simulate(any_plant):
    # One panel, three panels, two different panels: no new code. The momentum law
    # holds for each: dH/dt = R_NB tau_B while the torque acts (each record's torque
    # is held to the next record; R_NB averaged over the interval: error
    # O(record_dt^2) ~ 1e-6 relative),
    # and H stays constant once it stops (RK4 round-off, 1e-9).
    from scipy.spatial.transform import Rotation

    result = run_openloop(any_plant, OpenLoopScenario(duration_s=12.0))
    assert result.ok
    ds = result.dataset
    t, H = ds["time"].values, ds["angular_momentum"].values
    R_NB = Rotation.from_euler("ZYX", ds["q"].values[:, 5:2:-1]).as_matrix()
    R_mid = 0.5 * (R_NB[:-1] + R_NB[1:])
    torque_N = np.einsum("kij,kj->ki", R_mid, ds["tau_applied"].values[:-1])
    impulse = np.vstack([np.zeros(3), np.cumsum(torque_N * np.diff(t)[:, None], axis=0)])
    pushing = t <= 10.0
    np.testing.assert_allclose(H[pushing], impulse[pushing], atol=1e-5 * 10.0)
    np.testing.assert_allclose(H[t > 10.0], np.broadcast_to(H[-1], H[t > 10.0].shape), atol=1e-8)


def test_recorded_flex_torque_two_ways(nominal_plant, thesis_run):
    # docs/model.md, 'Conventions': tau_flex from the joint wrench equals
    # J_hub w_dot + w x J_hub w - tau_applied (the hub's Euler equation), on every
    # record; round-off only.
    ds = thesis_run.dataset
    J = nominal_plant.hub_J
    w, w_dot = ds["omega"].values, ds["omega_dot"].values
    expected = w_dot @ J.T + np.cross(w, w @ J.T) - ds["tau_applied"].values
    np.testing.assert_allclose(ds["tau_flex"].values, expected, rtol=0, atol=1e-10)
    assert np.all(ds["tau_flex"].values[0] == 0.0)  # at rest and undeformed
