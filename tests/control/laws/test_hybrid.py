"""The hybrid law: ASMC slew, latched switch to a linear controller, bumpless transfer."""

from __future__ import annotations

import numpy as np
import pytest

pytest.importorskip("slycot")

from flexsat.analysis.requirements import slew_metrics
from flexsat.control.laws import get_law, law_names
from flexsat.control.laws.statespace import (
    controller_input,
    load_controller,
    save_controller,
)
from flexsat.linear import linearize
from flexsat.linear.hinf import synthesize
from flexsat.simulate import SlewScenario, run_slew

DT = 1e-3
SWITCH_DEG, SWITCH_RATE_DEG_S = 0.5, 0.05  # the law's defaults
# the root actuators of docs/control.md, "Hybrid active damping"
DAMPING = {"kind": "rate_feedback", "coordinates": ["eta_rx", "eta_ry", "eta_rz"],
           "gain": 10.0, "limit": 0.1, "bandwidth_hz": 20.0}  # fmt: skip


@pytest.fixture(scope="module")
def hinf_file(nominal_plant, tmp_path_factory):
    design = synthesize(linearize(nominal_plant), DT, order=16, n_modes=6)
    return save_controller(design.discrete, tmp_path_factory.mktemp("k") / "hinf.npz")


@pytest.fixture(scope="module")
def run(nominal_plant, hinf_file):
    # the thesis's 45/45/45 deg slew, the first 40 s (the ASMC reaches the switch
    # region at 36.1 s), every control instant recorded
    scenario = SlewScenario(duration_s=40.0, record_dt_s=DT,
                            controller={"kind": "hybrid", "file": str(hinf_file)})  # fmt: skip
    return run_slew(nominal_plant, scenario, progress=False).dataset


def test_the_switch_is_latched_at_the_first_instant_inside_the_region(run):
    mode = run.linear_mode.values
    k = int(np.argmax(mode > 0))
    assert 0 < k and np.all(mode[k:] == 1.0) and np.all(mode[:k] == 0.0)
    # the rule: pointing error < 0.5 deg and body-rate error < 0.05 deg/s, first time
    inside = (run.pointing_error_deg.values < SWITCH_DEG) & (
        run.rate_error_deg_s.values < SWITCH_RATE_DEG_S)  # fmt: skip
    assert inside[k] and not inside[:k].any()
    print(f"switch at t = {run.time.values[k]:.3f} s")


def test_the_transfer_is_bumpless(run, hinf_file):
    k = int(np.argmax(run.linear_mode.values > 0))
    tau, lin = run.tau_cmd.values, run.tau_linear.values
    # at the switch instant the linear controller's output is the ASMC's command
    np.testing.assert_allclose(lin[k], tau[k], rtol=0.0, atol=1e-12)  # pinv round-off [N m]
    jump = np.abs(tau[k + 1] - tau[k]).max()
    # Bound: 0.01 N m, 0.5 % of RF T_max = 1.9 N m (measured 7.9e-3 N m, the linear
    # controller's own first step; the ASMC changes by ~5e-5 N m per step there).
    assert jump < 0.01
    # a linear controller started from x = 0 would jump to D y: measured 0.078 N m,
    # ten times the bumpless jump (5 times asserted)
    q_d = np.array(run.attrs["target_quaternion"])
    y = controller_input(q_d, np.zeros(3), np.zeros(3), run.quaternion.values[k + 1].copy(),
                         run.omega.values[k + 1].copy())  # fmt: skip
    cold = np.abs(load_controller(hinf_file).D @ np.array(y) - tau[k]).max()
    print(f"jump {jump:.3g} N m, from x = 0: {cold:.3g} N m")
    assert cold > 5 * jump


def test_the_hybrid_needs_a_file_and_is_not_compared_by_default():
    assert get_law("hybrid").label == "ASMC+H-inf"
    assert "hybrid" not in law_names()


def _slew(plant, hinf_file, **fields):
    scenario = SlewScenario.model_validate(
        {"controller": {"kind": "hybrid", "file": str(hinf_file)}, **fields}
    )
    return run_slew(plant, scenario, progress=False).dataset


def test_the_thesis_slew_meets_r1_and_r2(nominal_plant, hinf_file):
    # 120 s, disturbances at maximum (docs/control.md, "The hybrid controller"):
    # measured APE 1.9e-3 deg (R1: 0.05), rate error up to 4.1e-4 deg/s (R2: 1e-3)
    metrics = slew_metrics(_slew(nominal_plant, hinf_file))
    assert metrics["r1_pass"] and metrics["r2_pass"] and metrics["r3_pass"]


def test_with_the_root_actuators_the_loop_rings_at_the_first_coupled_mode(nominal_plant, hinf_file):
    # The limit the docs state: the controller, designed against the open-loop modes,
    # and the root-rate loop settle into a 0.23 Hz oscillation that breaks R2
    # (measured 4.9e-3 deg/s over 90-120 s). The spectrum's resolution over the 30 s
    # window is 1/30 Hz: the peak is asserted within one bin of 0.23 Hz.
    ds = _slew(nominal_plant, hinf_file, joint_actuator=DAMPING)
    assert not slew_metrics(ds)["r2_pass"]
    t = ds.time.values
    w = ds.omega.values[t >= 90.0, 0]
    f = np.fft.rfftfreq(w.size, float(t[1] - t[0]))
    peak = f[np.abs(np.fft.rfft(w - w.mean())).argmax()]
    assert abs(peak - 0.233) <= 1.0 / 30.0


@pytest.fixture(scope="module")
def rigid_file(nominal_plant, tmp_path_factory):
    # the default design: the rigid attitude (no modes), reduced to 6 states
    design = synthesize(linearize(nominal_plant), DT)
    return save_controller(design.discrete, tmp_path_factory.mktemp("k") / "rigid.npz")


def test_the_rigid_design_with_the_root_actuators_meets_r2_after_the_shock(
    nominal_plant, rigid_file
):
    # Three of the deployment-shock cases (the first, and two the hub-only ASMC fails
    # R2 in): R1, R2, R3. Measured over all 32 (docs/control.md): R2 in 32, the rate
    # error over 90-120 s 5.0e-5 - 5.1e-5 deg/s (R2: 1e-3).
    from flexsat.campaigns.definition import load_campaign, resolve_cases
    from flexsat.config import nominal

    cases = {c.case_id: c for c in resolve_cases(load_campaign("deployment-shock"), nominal())}
    first = next(iter(cases))
    for case_id in (first, "w++++deform3", "w-+++deform2"):
        scenario = {**cases[case_id].scenario, "joint_actuator": DAMPING,
                    "controller": {"kind": "hybrid", "file": str(rigid_file)}}  # fmt: skip
        ds = run_slew(nominal_plant, SlewScenario.model_validate(scenario), progress=False)
        metrics = slew_metrics(ds.dataset)
        assert metrics["r1_pass"] and metrics["r2_pass"] and metrics["r3_pass"], case_id
