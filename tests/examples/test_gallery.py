"""Every gallery example runs, on a short horizon, and gives one physical number.

Each example is run as a script (``tests/examples/conftest.py``) and one number it
computed is checked against a reference that does not come from the same code: an
analytic result, a thesis value, or the same quantity by another path.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from flexsat.control.laws import LAWS

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"
TESTED = {
    "avionics", "compare_laws", "compiled_law", "higher_modes", "linear_design", "microvibration",
    "montecarlo_statistics", "nastran_wing", "openloop_validation", "own_satellite",
    "python_controller", "replay_case", "sensitivity_campaign", "slew_requirements",
    "spinning_beam", "three_panels",
}  # fmt: skip


def test_every_example_is_tested():
    assert {p.stem for p in EXAMPLES.glob("*.py")} == TESTED


def test_own_satellite(run_example):
    g = run_example("own_satellite")
    # Parallel-axis theorem by hand (independent of the plant's packing): hub
    # cylinder m R^2 / 2 plus each thin plate m (L^2 + W^2) / 12 + m (0.9 + L/2)^2
    # about Z; 1e-12 relative: the same closed form in another order.
    hub = 300.0 * 0.8**2 / 2.0
    plates = sum(
        (m := 1.2 * L) * (L**2 + 1.2**2) / 12.0 + m * (0.9 + L / 2.0) ** 2 for L in (6.0, 3.0)
    )
    assert g["J_tot"][2, 2] == pytest.approx(hub + plates, rel=1e-12)
    assert np.all(g["analysis"].frequencies_hz[:6] == 0.0)  # six rigid-body modes


def test_nastran_wing(run_example):
    pytest.importorskip("pyyeti")
    pytest.importorskip("skfem")
    g = run_example("nastran_wing", 1.0)
    # Newton: the roll torque's impulse, 1 N m for min(2, 0.5) s, is the satellite's
    # angular momentum about X when it ends (no other torque; RK4 conserves it to
    # ~1e-12 here, tolerance 1e-9). The wing's mass is rho L w t of the plate, exact
    # to round-off.
    assert g["momentum_x"] == pytest.approx(0.5, rel=1e-9)
    assert g["wing"].modal.mass_kg == pytest.approx(2700.0 * 0.8 * 0.3 * 0.006, rel=1e-12)
    assert g["mass_difference"] < 1e-12 * g["wing"].modal.mass_kg


def test_spinning_beam(run_example):
    pytest.importorskip("skfem")
    g = run_example("spinning_beam")
    # Southwell's coefficient of a cantilever spinning about its root, 1.193, within
    # 1e-3 (measured 1.1925 at Omega = omega_0 / 4, where the reference itself gives
    # 1.1924: the mode shape has barely changed); with the root at R, K against the
    # rotating-beam equation within 1e-3 at every offset and both spins (measured 6e-4
    # at most: 2 L, 2 omega_0).
    assert g["k_at_rest"] == pytest.approx(1.193, rel=1e-3)
    for s in g["spins"]:
        for R, k in zip(g["offsets"], g["measured"][s], strict=True):
            assert k == pytest.approx(g["reference_k"](s, R), rel=1e-3), (s, R)


def test_microvibration(run_example):
    g = run_example("microvibration")
    probe, plant = g["probe"], g["result"]["plant"]
    # Far above the loop's bandwidth (0.3 rad/s against 20 Hz) a torque line T at
    # Omega turns the hub by the structure's receptance: q = (K - Omega^2 M)^-1 [0; T; 0]
    # from the plant's mass and stiffness at rest, undamped and without the law. The
    # PD's torque adds (0.048 Hz / 20 Hz)^2 ~ 6e-6 and the modes' 0.5 % damping
    # 2 zeta (f_mode / f)^2 < 1e-4 off the modes; 1e-3 relative (measured 3e-4 at most).
    omega = probe["speed_rpm"] * np.pi / 30.0
    M, K = plant.mass_matrix(), plant.stiffness_matrix()
    force = np.zeros(M.shape[0], dtype=complex)
    force[3:6] = probe["torque"]
    hub = np.linalg.solve(K - omega**2 * M, force)[3:6]
    np.testing.assert_allclose(np.abs(probe["angles"]), np.abs(hub), rtol=1e-3)
    # the imbalance's torque U_d Omega^2 turns the hub by ~U_d / J whatever the speed:
    # the line is a jitter of the order of 1e-4 kg m^2 / 100 kg m^2 (not round-off)
    assert np.all(np.abs(hub) > 1e-6)
    # the default wheels at 2000 rpm: the sweep's worst is at least their jitter there
    assert g["sweep"].worst_rms[0] * g["ARCSEC"] >= np.linalg.norm(g["rms"])


def test_three_panels(run_example):
    g = run_example("three_panels")
    # Three-fold symmetry about Z: the inertia is isotropic in the X-Y plane and the
    # off-centre modes come in degenerate pairs; 1e-9 relative is round-off of the
    # rotated mount frames.
    J = g["J_tot"]
    assert J[0, 0] == pytest.approx(J[1, 1], rel=1e-9)
    f = g["analysis"].frequencies_hz[6:]
    assert f[1] == pytest.approx(f[2], rel=1e-9)


def test_higher_modes(run_example):
    g = run_example("higher_modes", duration_s=2.0)
    # The chain preset's panel clamped at its root, flapwise hinges only, N = 8 segments
    # with springs from EI, against the Euler-Bernoulli cantilever written out from the
    # preset's numbers (L = 4.5 m, rho A = 1.0 kg/m^2 * 1.5 m, EI = 123 N m^2):
    # f_1 = 1.875104^2 sqrt(EI / (rho A L^4)) / (2 pi) = 0.2502 Hz.
    length_m, mass_per_length_kg_m, ei_n_m2 = 4.5, 1.0 * 1.5, 123.0
    euler_bernoulli_hz = (
        1.875104**2 * np.sqrt(ei_n_m2 / (mass_per_length_kg_m * length_m**4)) / (2.0 * np.pi)
    )
    error = g["clamped_hz"][8][0] / euler_bernoulli_hz - 1.0
    # docs/model.md ('Chain appendages') gives the chain's error at N = 8 as -0.712 %
    # (second order in 1/N, always below the beam); measured -0.7122 %. 1e-4 on the
    # ratio covers the table's rounding and the panel's 2 cm thickness (rotary inertia
    # of the section, absent from Euler-Bernoulli: 4e-6), and still fails a wrong
    # segment count (N = 7 or 9: -0.93 % or -0.56 %) or root spring (EI/l instead of
    # 2 EI/l: -11 %).
    assert error == pytest.approx(-0.712e-2, abs=1e-4)


def test_openloop_validation(run_example):
    g = run_example("openloop_validation", duration_s=15.0)
    # The 10 s pulse of 1 N m gives H_z = 10 N m s exactly once it has ended
    # (thesis fig. 3.12); 1e-9 relative: conservation to RK4 round-off.
    assert g["metrics"]["final_angular_momentum_nms"][2] == pytest.approx(10.0, rel=1e-9)


def test_slew_requirements(run_example):
    g = run_example("slew_requirements", duration_s=10.0)
    # At the start of the slew the ASMC saturates: the commanded torque is clipped
    # at the software limit RF * T_max = 0.95 * 2 N m (thesis section 5.1.1) exactly.
    assert g["metrics"]["max_commanded_torque_nm"] == pytest.approx([1.9] * 3, rel=1e-12)
    assert g["metrics"]["r3_pass"]


def test_compare_laws(run_example):
    g = run_example("compare_laws", duration_s=10.0)
    # No law commands more than the software limit RF * T_max = 0.95 * 2 N m (thesis
    # section 5.1.1); the thesis's ASMC starts the slew saturated at it, exactly.
    assert set(g["metrics"]) == set(LAWS.names())
    for metrics in g["metrics"].values():
        assert max(metrics["max_commanded_torque_nm"]) <= 1.9 * (1.0 + 1e-12)
    assert g["metrics"]["asmc"]["max_commanded_torque_nm"] == pytest.approx([1.9] * 3, rel=1e-12)


ARCSEC_PER_RAD = 180.0 / np.pi * 3600.0  # [arcsec/rad]
ARCSEC_PER_DEG_RT_H = 3600.0 / 60.0  # [arcsec/sqrt(s) per deg/sqrt(h)]
SETTLED_S = 5.0  # [s] past the filter's start-up (steady state after ~2.6 s, below)


def test_avionics(run_example):
    g = run_example("avionics", duration_s=20.0)
    # Reference: the steady-state accuracy of a Kalman filter, from the configured
    # sensors. About each cross-boresight axis the MEKF is, to first order, the scalar
    # filter of an angle that random-walks by the gyro's angle random walk N between
    # star-tracker samples (variance q = N^2 T per sample period T) and is measured
    # with variance R = sigma_st^2 at each sample. Its steady-state variances before
    # and after an update are P- = (q + sqrt(q^2 + 4 q R)) / 2 and
    # P+ = P- R / (P- + R); the records, one per gyro sample, see the error between
    # the two: RMS sqrt((P- + P+) / 2) = 0.974 arcsec for N = 0.01 deg/sqrt(h),
    # T = 0.1 s and sigma_st = 5 arcsec (one tracker sample errs by 5 arcsec).
    arw = g["GYRO"]["arw_deg_rt_h"] * ARCSEC_PER_DEG_RT_H  # N [arcsec/sqrt(s)]
    period = g["STAR_TRACKER"]["sample_dt_s"]  # T [s]
    sigma_x, sigma_y, _ = g["STAR_TRACKER"]["noise_arcsec"]  # [arcsec]
    assert sigma_x == sigma_y  # the one scalar filter serves both axes
    q, r = arw**2 * period, sigma_x**2  # [arcsec^2]
    prior = 0.5 * (q + np.sqrt(q**2 + 4.0 * q * r))  # P- [arcsec^2]
    posterior = prior * r / (prior + r)  # P+ [arcsec^2]
    predicted = np.sqrt(0.5 * (prior + posterior))  # [arcsec]
    assert predicted == pytest.approx(0.974, abs=1e-3)

    # Measured: the estimate against the true attitude, x and y pooled, once settled
    # (the filter starts at one sample's error, R, and reaches P+ after about
    # R / P+ = 26 samples, 2.6 s).
    ds = g["avionics"].dataset
    settled = ds["time"].values >= SETTLED_S
    error = ds["estimation_error"].values[settled, :2] * ARCSEC_PER_RAD  # [arcsec]
    rms = np.sqrt(np.mean(error**2))  # [arcsec]; measured 0.908, with or without the
    # scenario's disturbances (they move the pointing, not the estimation error)

    # Tolerance 50 %: one realisation of this RMS scatters by about 21 %. The error
    # forgets over 1 / K = 27 tracker periods (gain K = P- / (P- + R) = 0.037), so
    # the 15 s on two axes hold about 11 independent squared errors (relative scatter
    # of the mean square sqrt(2 / 11), of the RMS half that); five other seed pairs,
    # (gyro, tracker) = (3, 4), (5, 6) ... (11, 12), gave 0.75 to 1.25 arcsec, mean
    # 1.00, within 28 % of the reference. Left out of the reference, both small: the
    # gyro bias's random walk (+1.6 % in the two-state steady state) and the coupling
    # of the axes by the slew's rotation. A filter that ignored the gyro (the
    # tracker's 5 arcsec) or the tracker (a drift) would be off by five times or more.
    assert rms == pytest.approx(predicted, rel=0.5)


def test_sensitivity_campaign(run_example):
    g = run_example("sensitivity_campaign", duration_s=5.0)
    from flexsat import Plant, nominal
    from flexsat.analysis import slew_metrics
    from flexsat.simulate import SlewScenario, run_slew

    # The campaign's nominal case is the nominal slew flown directly (the same
    # computation through the campaign machinery): equal to 1e-12 relative.
    row = g["table"].set_index("case_id").loc["nominal"]
    direct = run_slew(Plant.from_config(nominal()), SlewScenario(duration_s=5.0))
    direct = slew_metrics(direct.dataset)
    assert row["metrics.final_pointing_error_deg"] == pytest.approx(
        direct["final_pointing_error_deg"], rel=1e-12
    )
    assert g["summary"]["cases"] == 12  # 11 one-at-a-time cases + the nominal


def test_montecarlo_statistics(run_example):
    g = run_example("montecarlo_statistics", duration_s=5.0)
    # R3 (torque within the actuator limit) holds in all 61 cases (60 draws + the
    # nominal) from the start of the slew. With n passes out of n, the lower end of
    # the exact two-sided 95 % interval has a closed form, independent of the beta
    # quantile the example computes it with: the p at which n passes in a row have
    # probability (1 - 0.95) / 2, p = 0.025^(1/n) = 0.94132 for n = 61. 1e-12
    # relative allows for round-off in scipy's beta inversion (measured: 0 at n = 61,
    # at most 8.3e-16 for every n up to 20000).
    r3 = g["requirements"].set_index("requirement").loc["r3_pass"]
    n_cases = int(r3["cases"])
    assert n_cases == 61 and r3["passes"] == n_cases
    assert r3["ci_low"] == pytest.approx(0.025 ** (1.0 / n_cases), rel=1e-12)


def test_replay_case(run_example):
    g = run_example("replay_case", duration_s=5.0)
    # The replay flies the stored inputs again: the stored metric, to 1e-12 relative.
    assert g["metrics"]["final_pointing_error_deg"] == pytest.approx(
        g["worst"]["final_pointing_error_deg"], rel=1e-12
    )


def test_compiled_law(run_example):
    try:
        # 120 s: the integral removes the PD's standing error (~0.08 deg) under the
        # constant disturbances; measured 9.7e-5 deg, R1 is 0.05 deg.
        g = run_example("compiled_law", duration_s=120.0)
    finally:
        LAWS.unregister("qpid")
    metrics = g["metrics"]
    assert metrics["controller"] == "qpid"
    assert metrics["r1_pass"] and metrics["r2_pass"] and metrics["r3_pass"]
    assert metrics["final_pointing_error_deg"] < 1e-3


def test_python_controller(run_example):
    # 120 s at 10 ms control: the PID's integral removes the PD's standing error
    # under the constant disturbances, and the example meets what it says: R1, R2 and
    # R3 over the thesis's window from 90 s. Measured: inside R2 from 83.5 s, largest
    # residual rate over the window 7.6e-4 deg/s (band 1e-3), APE 0.019 deg (band
    # 0.05); the gains it names as failing (ki = 0.002, 0.3 rad/s) settle at 99.3 s.
    g = run_example("python_controller", duration_s=120.0)
    metrics = g["metrics"]
    assert metrics["controller"] == "python"
    assert metrics["r1_pass"] and metrics["r2_pass"] and metrics["r3_pass"]
    assert metrics["r2_settling_time_s"] < metrics["observation_window_s"][0]
    assert metrics["final_pointing_error_deg"] < 0.05
    # ... and what it says of the slower integral holds: R2 is lost, late to settle.
    from flexsat.analysis import slew_metrics
    from flexsat.simulate import run_slew

    slow = g["QuaternionPID"](g["scenario"].target_euler_deg, natural_frequency=0.3, ki=0.002)
    plant = g["Plant"].from_config(g["nominal"]())
    late = slew_metrics(run_slew(plant, g["scenario"], controller=slow,
                                 progress=False).dataset)  # fmt: skip
    assert not late["r2_pass"] and late["r2_settling_time_s"] > 90.0


def test_linear_design(run_example):
    summary = run_example("linear_design")["summary"]
    # Delay margin about Z set by the in-plane peak above 0 dB (docs/linear.md,
    # "Loop gains and margins"): 0.173 s at 1.48 Hz.
    assert summary["margins"]["z"]["delay_margin_s"] == pytest.approx(0.173, abs=1e-3)
    # Strongest appendage modes: the in-plane pair about Z (74.3 kg m^2 each).
    assert summary["strongest_modes"][0][1] == "z"
    assert summary["strongest_modes"][0][2] == pytest.approx(74.28, abs=0.01)
    assert summary["reduced_peak_error"] <= summary["reduced_error_bound"]


def test_python_controller_matches_compiled_pd(nominal_plant):
    # The same PD law written in Python and run through the Python path gives the
    # compiled PD's trajectory (both sample at 10 ms): equal to round-off.
    from flexsat.control import target_quaternion
    from flexsat.control.quaternion import quaternion_error
    from flexsat.simulate import SlewScenario, design_inertia, run_slew

    scenario = SlewScenario.model_validate(
        {"duration_s": 5.0, "control_dt_s": 0.01, "controller": {"kind": "pd"}}
    )
    kp, kd = scenario.controller.gains(scenario.actuator)[2:4]
    J = design_inertia()
    q_d = tuple(target_quaternion(scenario.target_euler_deg))

    def pd(t, q, omega):
        e = np.array(quaternion_error(q_d, tuple(q)))
        return np.cross(omega, J @ omega) - J @ (kp * e[1:] + kd * omega)

    compiled = run_slew(nominal_plant, scenario).dataset
    python = run_slew(nominal_plant, scenario, controller=pd).dataset
    np.testing.assert_allclose(python["q"].values, compiled["q"].values, rtol=0, atol=1e-12)
    np.testing.assert_allclose(
        python["pointing_error_deg"].values, compiled["pointing_error_deg"].values, atol=1e-9
    )
