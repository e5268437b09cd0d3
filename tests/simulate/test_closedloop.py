"""The thesis's closed-loop validation (section 5.1) and the closed loop's mechanics."""

from __future__ import annotations

import numpy as np
import pytest

from flexsat.analysis.requirements import settling_time, slew_metrics
from flexsat.dynamics.plant import Plant
from flexsat.simulate import SlewScenario, design_inertia, run_slew
from tests.conftest import config_from, variant


def _metrics(result):
    return slew_metrics(result.dataset)  # the stored scenario's requirements


@pytest.fixture(scope="module")
def thesis_slew(nominal_plant):
    return run_slew(nominal_plant)


@pytest.fixture(scope="module")
def thesis_metrics(thesis_slew):
    return _metrics(thesis_slew)


def test_requirements_are_met(thesis_metrics):
    # Section 5.1.3: R1 (< 0.05 deg), R2 (< 1e-3 deg/s), R3 (|tau| <= 2 N m) all met.
    assert thesis_metrics["r1_pass"] and thesis_metrics["r2_pass"] and thesis_metrics["r3_pass"]


def test_final_pointing_error(thesis_metrics):
    # Thesis: 2.50e-3 deg at the end. Our run: 2.3e-3 deg. The steady state is set
    # by the boundary layer and the disturbances (eq. 4.25); the thesis plots a
    # single value with no stated precision, so we accept the same order: within
    # 30 % of 2.5e-3 deg.
    assert thesis_metrics["final_pointing_error_deg"] == pytest.approx(2.5e-3, rel=0.3)
    np.testing.assert_allclose(thesis_metrics["final_euler_deg"], 45.0, atol=0.01)


def test_torque_never_exceeds_the_limits(thesis_slew):
    ds = thesis_slew.dataset
    # R3: commands within the software limit RF T_max = 1.9 N m; the applied torque
    # (gain 0.95, disturbances) within T_max = 2 N m on every axis and record.
    assert np.abs(ds["tau_cmd"].values).max() <= 1.9 + 1e-12
    assert np.abs(ds["tau_applied"].values).max() <= 2.0 + 1e-12


def test_adaptation_timeline(thesis_metrics):
    # Section 5.1.3: Lambda leaves its minimum "around 30 s" (the error crosses
    # theta_th = 5 deg) and the pointing error stays inside R1 "from t ~ 45 s".
    # Our run: 27.3 s and 37 s. The law as written is the spec (docs/control.md); the
    # thesis's plot timing is read off a figure, so the bounds are generous and the
    # gap on R1 is reported in docs/control.md.
    assert 20.0 < thesis_metrics["lambda_switch_time_s"] < 35.0
    assert 30.0 < thesis_metrics["settling_time_s"] < 50.0


def test_adaptive_gains_stay_in_their_bounds(thesis_slew):
    ds = thesis_slew.dataset
    lam = ds["lambda_act"].values
    assert lam.min() >= 0.2 - 1e-12 and lam.max() <= 5.0 + 1e-12
    assert ds["jk"].values.min() >= 0.8925 - 1e-12  # JK_min floor (eq. 4.30)
    assert lam[-1] == pytest.approx(5.0, abs=0.01)  # Lambda_max at convergence


def test_design_model_is_the_rigidized_satellite_of_the_config():
    # A heavier hub: the controller's design model is that satellite's J_tot (its
    # rigidized nominal configuration), not the thesis satellite's.
    heavy = variant()
    heavy["hub"]["mass_kg"] = 180.0
    config = config_from(heavy)
    plant = Plant.from_config(config)
    result = run_slew(plant, SlewScenario(duration_s=1.0))
    J = np.array(result.dataset.attrs["design_inertia"]).reshape(3, 3)
    np.testing.assert_array_equal(J, design_inertia(config))
    assert not np.allclose(J, design_inertia())  # the heavier hub changes J_tot


def test_explicit_design_inertia_of_the_scenario_is_used(nominal_plant):
    J = [[200.0, 1.0, 0.0], [1.0, 50.0, 0.0], [0.0, 0.0, 180.0]]
    scenario = SlewScenario.model_validate({"duration_s": 1.0, "design_inertia_kg_m2": J})
    result = run_slew(nominal_plant, scenario)
    np.testing.assert_array_equal(np.array(result.dataset.attrs["design_inertia"]), np.ravel(J))


@pytest.mark.parametrize("kind", ["smc", "pd"])
def test_baselines_fly_the_same_slew(nominal_plant, kind):
    scenario = SlewScenario.model_validate({"controller": {"kind": kind}})
    metrics = _metrics(run_slew(nominal_plant, scenario))
    assert metrics["r3_pass"]
    # Both converge near the target; the PD has no integral action, so the
    # constant disturbances leave it a standing error (~0.08 deg), which is the
    # point of the comparison.
    assert metrics["final_pointing_error_deg"] < 0.1


def test_lambda_dot_switch(nominal_plant):
    scenario = SlewScenario.model_validate({"controller": {"include_lambda_dot": True}})
    metrics = _metrics(run_slew(nominal_plant, scenario))
    assert metrics["r1_pass"] and metrics["r3_pass"]


def test_slews_are_deterministic(nominal_plant):
    scenario = SlewScenario(duration_s=5.0)
    a = run_slew(nominal_plant, scenario).dataset["q"].values
    b = run_slew(nominal_plant, scenario).dataset["q"].values
    np.testing.assert_array_equal(a, b)


def test_control_sampling_slower_than_the_plant(nominal_plant):
    # A 10 ms controller (zero-order hold over 10 plant steps) still flies the slew.
    scenario = SlewScenario(control_dt_s=0.01)
    metrics = _metrics(run_slew(nominal_plant, scenario))
    assert metrics["r1_pass"] and metrics["r3_pass"]
    held = run_slew(nominal_plant, SlewScenario(control_dt_s=0.01, duration_s=0.1))
    tau = held.dataset["tau_cmd"].values  # records every 10 ms: a new value each
    assert np.unique(tau[:, 0]).size == tau.shape[0]


def test_settling_time():
    t = np.arange(6.0)
    assert settling_time(t, np.array([5, 4, 0.1, 2, 0.1, 0.1]), 1.0) == 4.0
    assert np.isnan(settling_time(t, np.array([5, 4, 0.1, 2, 0.1, 3]), 1.0))
    assert settling_time(t, np.zeros(6), 1.0) == 0.0


def test_random_disturbance_draws_are_seeded_and_bounded(nominal_plant):
    def draw(seed):
        scenario = SlewScenario.model_validate(
            {"duration_s": 1.0, "disturbances": {"mode": "random", "seed": seed}}
        )
        return np.array(run_slew(nominal_plant, scenario).dataset.attrs["realised_disturbances"])

    a, b, c = draw(1), draw(1), draw(2)
    np.testing.assert_array_equal(a, b)  # same seed, same draw
    assert not np.array_equal(a, c)
    assert np.all((a[0:3] >= 0.95) & (a[0:3] <= 1.05))  # gain within 1 +- 5 %
    assert np.all(np.abs(a[3:6]) <= 0.005) and 0.0 <= a[6] <= 0.02


def test_residual_disturbance_switch_still_meets_r1(nominal_plant):
    # docs/control.md, 'Disturbances forced to maximum': injecting the 0.005 N m
    # residual roughly doubles the steady-state error, still inside R1 (measured
    # 4.6e-3 deg against 2.3e-3 deg).
    scenario = SlewScenario.model_validate({"disturbances": {"residual_nm": [0.005] * 3}})
    metrics = _metrics(run_slew(nominal_plant, scenario))
    assert metrics["r1_pass"] and metrics["r3_pass"]
    assert 1.5e-3 < metrics["final_pointing_error_deg"] < 0.05


def test_python_callback_form_reproduces_the_compiled_asmc(nominal_plant):
    # The same compiled law called from Python at each control instant, through
    # the Python-callback path: identical arithmetic, identical trajectory.
    from flexsat.control.laws import CompiledLaw
    from flexsat.control.quaternion import target_quaternion

    scenario = SlewScenario(duration_s=20.0)
    law = CompiledLaw(
        scenario.controller, scenario.actuator, design_inertia(),
        target_quaternion(scenario.target_euler_deg), scenario.control_dt_s,
    )  # fmt: skip
    compiled = run_slew(nominal_plant, scenario).dataset
    python = run_slew(nominal_plant, scenario, controller=law).dataset
    np.testing.assert_allclose(python["q"].values, compiled["q"].values, rtol=0, atol=1e-12)
    np.testing.assert_allclose(
        python["tau_cmd"].values, compiled["tau_cmd"].values, rtol=0, atol=1e-12
    )


BAD_SCENARIOS = [
    ({"target_euler_deg": [45.0, float("nan"), 45.0]}, "target_euler_deg"),
    ({"actuator": {"t_max_nm": -2.0}}, "actuator.t_max_nm: Input should be greater than 0"),
    ({"actuator": {"reduction_factor": 1.2}}, "reduction_factor: Input should be less than or"),
    ({"actuator": {"reduction_factor": 0.0}}, "reduction_factor: Input should be greater than 0"),
    ({"controller": {"phi": 0.0}}, "controller.phi: Input should be greater than 0"),
    ({"controller": {"lambda_min": 6.0}}, "lambda_max must be >= lambda_min"),
    ({"controller": {"kind": "lqr"}}, "controller.kind: must be one of asmc, smc, pd"),
    ({"controller": {"jk_mn_nm": 1.0}}, "did you mean 'jk_min_nm'? (allowed here: include_"),
    ({"controller": {"kind": "smc", "lambda_": 1.0, "lamda": 1.0}}, "unknown key 'lamda'"),
    ({"sensor": {"kind": "sun_sensor"}}, "sensor.kind: must be one of ideal, gyro"),
    ({"actuator": {"kind": "cmg"}}, "actuator.kind: must be one of static, wheels"),
    ({"design_inertia_kg_m2": [[1, 2, 0], [0, 1, 0], [0, 0, 1]]}, "must be symmetric"),
    ({"design_inertia_kg_m2": [[1, 0, 0], [0, -1, 0], [0, 0, 1]]}, "positive definite"),
    ({"design_inertia_kg_m2": [[1e300, 0, 0], [0, 1, 0], [0, 0, 1]]}, "within +-1e+09 kg m^2"),
    ({"control_dt_s": 0.0015}, "control_dt_s must be a whole multiple of dt_s"),
    ({"disturbances": {"sloshing_ratio": -0.1}}, "sloshing_ratio"),
    ({"requirements": {"pointing_deg": 0.0}}, "requirements.pointing_deg"),
]


@pytest.mark.parametrize(("data", "fragment"), BAD_SCENARIOS, ids=[f for _, f in BAD_SCENARIOS])
def test_bad_slew_scenarios_are_refused(data, fragment):
    from flexsat.config import validate_config
    from flexsat.errors import ConfigError

    with pytest.raises(ConfigError) as caught:
        validate_config(data, model=SlewScenario)
    assert fragment in str(caught.value)
