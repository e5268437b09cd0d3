"""The reaction-wheel cluster: conservation with internal torques only, momentum
saturation, far-limit wheels against the ideal actuator, refused configurations."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.integrate import cumulative_trapezoid
from scipy.spatial.transform import Rotation

from flexsat.analysis.requirements import slew_metrics
from flexsat.control.stages.wheels import WheelsConfig, _smooth_sign, wheel_axes
from flexsat.simulate import SlewScenario, run_slew
from flexsat.simulate.closedloop import prepare_slew


@pytest.fixture(scope="module")
def undamped(nominal_plant):
    return nominal_plant.with_joints(nominal_plant.stiffness, np.zeros_like(nominal_plant.damping))


QUIET = {"environment_nm": [0, 0, 0], "sloshing_ratio": 0.0}  # no external torque


def _slew(plant, duration_s=120.0, disturbances=QUIET, **wheels):
    scenario = SlewScenario.model_validate({
        "duration_s": duration_s, "controller": {"kind": "pd"},
        "actuator": {"kind": "wheels", **wheels}, "disturbances": disturbances,
    })  # fmt: skip
    return run_slew(plant, scenario).dataset


@pytest.fixture(scope="module")
def spun_up(undamped):
    # Four pyramid wheels biased at 1000 rpm, the PD slewing through them: only
    # internal torques (motors, friction, joints), no external torque, no damping.
    return _slew(undamped, initial_speed_rpm=1000.0)


def _total_momentum(plant, ds):
    """H_N of hub, appendages and wheels at each record [N m s], and R_NB."""
    q, qd = ds["q"].values, ds["qd"].values
    plant_H_N = np.array([plant.angular_momentum(a, b) for a, b in zip(q, qd, strict=True)])
    R_NB = Rotation.from_euler("ZYX", q[:, 5:2:-1]).as_matrix()
    return plant_H_N + np.einsum("kij,kj->ki", R_NB, ds["wheel_momentum_B"].values), R_NB


def test_total_momentum_of_hub_appendages_and_wheels_is_conserved(undamped, spun_up):
    ds = spun_up
    H_N = _total_momentum(undamped, ds)[0]
    # The wheels exchange ~24 N m s with the hub; the coupled RK4 step conserves the
    # total to its truncation error, measured 2.5e-14: acceptance 1e-10 relative.
    assert np.linalg.norm(H_N[0]) > 20.0
    assert np.abs(ds["wheel_momentum_B"].values - ds["wheel_momentum_B"].values[0]).max() > 5.0
    assert np.abs(H_N - H_N[0]).max() <= 1e-10 * np.linalg.norm(H_N[0])


def test_energy_balance_closes_with_motor_work_in_and_friction_out(undamped, spun_up):
    ds = spun_up
    q, qd = ds["q"].values, ds["qd"].values
    plant_E = [undamped.kinetic_energy(a, b) + undamped.elastic_energy(a)
               for a, b in zip(q, qd, strict=True)]  # fmt: skip
    E = np.array(plant_E) + ds["wheel_kinetic_energy"].values
    balance = E - E[0] - ds["wheel_motor_work"].values + ds["wheel_friction_loss"].values
    # Motor work and friction loss are integrated in the same RK4 stages as the
    # motion: the balance is the integrator's error, measured 7e-9 J against 2.2e3 J
    # of energy and 770 J of motor work (3e-12 relative): acceptance 1e-10 relative.
    assert ds["wheel_friction_loss"].values[-1] > 1.0
    assert np.abs(balance).max() <= 1e-10 * E[0]


def test_saturated_wheels_run_to_the_end_and_r3_says_when(nominal_plant):
    # 0.1 kg m^2 at 30 rpm holds 0.31 N m s per wheel; the slew needs several N m s.
    ds = _slew(nominal_plant, duration_s=60.0, max_speed_rpm=30.0)
    assert ds.attrs["status"] == "ok"
    assert ds["time"].values[-1] == pytest.approx(60.0)
    metrics = slew_metrics(ds)
    assert not metrics["r3_pass"]
    saturation = metrics["actuator_saturation_s"]
    assert set(saturation) <= {"1", "2", "3", "4"} and saturation
    assert all(0.0 < t < 60.0 for t in saturation.values())
    # The drive holds the limit; the cut acts within an RK4 step, so |h| may pass it
    # by at most one step of full motor torque: dt u_max / (I_s Omega_max) = 0.64 %.
    h_max = 0.1 * 30.0 * np.pi / 30.0
    assert ds["wheel_speed_ratio"].values.max() <= 1.0 + 1e-3 * 2.0 / h_max


def test_far_limit_wheels_fly_the_ideal_slew(nominal_plant):
    # Ideal reference: the static actuator without disturbances (gain 1, nothing
    # added). Wheels: limits far away, no friction, motor lag 1 ms (one step).
    ideal = run_slew(nominal_plant, SlewScenario.model_validate({
        "duration_s": 60.0, "controller": {"kind": "pd"},
        "actuator": {"kind": "static", "gain": [1.0, 1.0, 1.0]}, "disturbances": QUIET,
    })).dataset  # fmt: skip
    wheels = _slew(
        nominal_plant,
        duration_s=60.0,
        max_speed_rpm=1e5,
        max_torque_nm=100.0,
        viscous_nm_s_rad=0.0,
        coulomb_nm=0.0,
        motor_time_constant_s=1e-3,
    )
    # What differs physically: the wheels keep the slew's momentum inside the
    # satellite (omega x h_w, which the PD's omega x J omega does not compensate) and
    # lag the command by tau_m = 1 ms. Both are second order at slew rates
    # (|omega| < 0.02 rad/s): the pointing histories agree within 1 % of the initial
    # 65 deg error, the final errors within 0.05 deg.
    a, b = ideal["pointing_error_deg"].values, wheels["pointing_error_deg"].values
    assert np.abs(a - b).max() <= 0.01 * a[0]
    assert abs(a[-1] - b[-1]) <= 0.05


def test_external_torques_act_with_the_wheels(undamped):
    # The scenario's environment and residual torques are external: with the wheels
    # the total angular momentum of hub, appendages and wheels (conserved without
    # them, above) changes by their impulse, the integral of R_NB tau_d. The
    # trapezoidal rule over the 10 ms records errs at second order in their spacing:
    # measured 6.6e-9 N m s (3.4e-8 of the 0.19 N m s impulse; 6.6e-11 over 1 ms
    # records, 1.6e-11 over 0.5 ms): acceptance 1e-7 of the impulse. A torque missing,
    # or scaled by a gain such as G_act, would miss by 5 % or more.
    tau_d = np.array([0.006, -0.003, 0.002])  # environment + residual [N m]
    ds = _slew(undamped, duration_s=30.0, initial_speed_rpm=1000.0,
               disturbances={"environment_nm": [0.005, -0.003, 0.002],
                             "residual_nm": [0.001, 0.0, 0.0], "sloshing_ratio": 0.0})  # fmt: skip
    H_N, R_NB = _total_momentum(undamped, ds)
    impulse = cumulative_trapezoid(R_NB @ tau_d, ds["time"].values, axis=0, initial=0.0)
    assert np.linalg.norm(impulse[-1]) > 0.1
    assert np.abs(H_N - H_N[0] - impulse).max() <= 1e-7 * np.linalg.norm(impulse[-1])


def test_presets_are_unit_axes_with_equal_capability():
    pyramid = wheel_axes("pyramid4")
    np.testing.assert_allclose(np.linalg.norm(pyramid, axis=1), 1.0, rtol=1e-15)
    # At the 54.7356 deg half-angle A A^T = (4/3) I: the same torque on every axis.
    np.testing.assert_allclose(pyramid.T @ pyramid, 4.0 / 3.0 * np.eye(3), atol=1e-5)
    np.testing.assert_array_equal(wheel_axes("orthogonal3"), np.eye(3))


@pytest.mark.parametrize(("preset", "wheels"), [("pyramid4", 4), ("orthogonal3", 3)])
def test_the_coupled_step_carries_the_integrated_entries_only(nominal_plant, preset, wheels):
    # h, u and the held u_cmd of each wheel, motor work, friction loss: 3 N + 2 of the
    # stage's 20 entries (sized for six wheels) ride in the RK4 stages.
    scenario = SlewScenario.model_validate({"actuator": {"kind": "wheels", "preset": preset}})
    flow = prepare_slew(nominal_plant, scenario).data.flow
    assert flow.state.shape == flow.eval.shape == flow.rates.shape == (3 * wheels + 2,)
    assert WheelsConfig(preset=preset).integrated_size() == 3 * wheels + 2


def test_axes_that_do_not_span_3d_are_refused():
    with pytest.raises(ValueError, match="axes: the spin axes must span 3D"):
        WheelsConfig(axes=((1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (1.0, 1.0, 0.0)))


def test_a_python_controller_flies_the_wheels_like_the_compiled_loop(nominal_plant):
    # The Python-controller path steps the coupled RK4 in compiled blocks
    # (rk4_coupled_hold): a zero command leaves the wheels' momentum where the
    # initial speed put it and the satellite at rest, as the compiled path does.
    scenario = SlewScenario.model_validate(
        {"duration_s": 1.0, "actuator": {"kind": "wheels", "initial_speed_rpm": 100.0}}
    )
    ds = run_slew(nominal_plant, scenario, controller=lambda t, q, w: np.zeros(3)).dataset
    assert ds.attrs["status"] == "ok", ds.attrs.get("message")
    h0 = 0.1 * 100.0 * np.pi / 30.0 * 4.0 * np.cos(np.radians(54.7356))  # sum a_z h_i
    # Friction (1e-3 N m Coulomb + viscous) slows each wheel by ~1e-3 N m s in 1 s.
    np.testing.assert_allclose(ds["wheel_momentum_B"].values[0], [0.0, 0.0, h0], atol=1e-9)
    assert abs(ds["wheel_momentum_B"].values[-1, 2] - h0) < 5e-3


def test_the_friction_sign_is_the_c_librarys_tanh_within_two_ulp() -> None:
    """The fast forms agree with ``math.tanh`` to 2 ulp over 400 001 arguments across
    both switches (0.55 and 22). The exponential form: the exponential, the sum, the
    difference and the quotient each round once, damped by 1 +- e with e <= 1/3
    where it is used; near +-1 the ulp below 1 is half the one above, which is where
    the measured maximum, 2 ulp, lies. Cephes' rational form below 0.55: its minimax
    error is 2.5e-16 relative, measured at most 1 ulp from ``math.tanh`` over
    200 001 arguments. Exact at zero (with its sign), the infinities and where tanh is
    +-1; NaN stays NaN."""
    z = np.concatenate([np.linspace(-60.0, 60.0, 400_001), [0.55, -0.55, 0.549999999,
                        21.999999999, 22.0, -22.0, 0.0, -0.0, 1e-300]])  # fmt: skip
    fast = np.array([_smooth_sign(v) for v in z])
    exact = np.tanh(z)
    assert np.all(np.abs(fast - exact) <= 2.0 * np.spacing(np.abs(exact)))
    assert np.all(np.sign(fast) == np.sign(exact))
    assert np.array_equal(np.array([_smooth_sign(v) for v in (np.inf, -np.inf, 30.0, -0.0)]),
                          [1.0, -1.0, 1.0, -0.0])  # fmt: skip
    assert math.copysign(1.0, _smooth_sign(-0.0)) == -1.0
    assert math.isnan(_smooth_sign(math.nan))


def test_r3_counts_what_each_wheel_is_asked_not_the_gyroscopic_torque(nominal_plant):
    # Four pyramid wheels biased at 3000 rpm (72.5 N m s along +Z_B) with 2.5 N m
    # motors, the thesis's ASMC slewing through them (10 s: its acceleration). The
    # wheels' gyroscopic torque -omega x sum a_i h_i acts on the hub beside the
    # motors: the applied torque reaches 3.1 N m on X (measured), past T_max = 2 N m,
    # which a rule on |tau_applied| would fail; yet no motor is asked more than its
    # limit (measured 98.7 %) and no wheel nears its 6000 rpm (measured 4008 rpm): R3
    # holds.
    scenario = SlewScenario.model_validate({"duration_s": 10.0, "actuator": {
        "kind": "wheels", "initial_speed_rpm": 3000.0, "max_torque_nm": 2.5}})  # fmt: skip
    ds = run_slew(nominal_plant, scenario).dataset
    metrics = slew_metrics(ds)
    assert max(metrics["max_abs_torque_nm"]) > 2.0  # |tau_applied| <= T_max would fail
    assert metrics["actuator_saturation_s"] == {}
    assert ds["actuator_torque_ratio"].values.max() <= 1.0
    assert metrics["r3_pass"]
    # The excess is the gyroscopic torque: taken back out, what is left on the hub is
    # the motors' torque (the law's command, clipped to RF T_max = 1.9 N m per axis,
    # delivered in full as no motor was clipped) with the disturbances, inside T_max
    # (measured 1.94 N m), while -omega x h_B alone reaches 5.0 N m (measured).
    gyroscopic = -np.cross(ds["omega"].values, ds["wheel_momentum_B"].values)
    motors = ds["tau_applied"].values - gyroscopic
    assert np.abs(motors).max() <= 2.0 < np.abs(ds["tau_applied"].values).max()
    assert np.abs(gyroscopic).max() > 1.0


def test_wheel_speeds_are_recorded_per_wheel_in_rpm(nominal_plant):
    # wheel_speed is h_i / I_s [rpm], NaN beyond the cluster's four wheels: back in
    # momentum (x I_s = 0.1 kg m^2, x pi/30 rad/s per rpm) and along the axes it is
    # the recorded sum a_i h_i to rounding (1e-12 relative).
    ds = _slew(nominal_plant, duration_s=5.0, initial_speed_rpm=100.0)
    speed = ds["wheel_speed"].values
    assert ds["wheel_speed"].attrs["units"] == "rpm" and ds["wheel_speed"].dims == ("time", "unit")
    assert speed.shape[1] == 6 and np.isnan(speed[:, 4:]).all()
    assert speed[0, :4] == pytest.approx(100.0, rel=1e-12)  # at rest: h_i = I_s Omega_0
    momentum = 0.1 * speed[:, :4] * np.pi / 30.0
    np.testing.assert_allclose(momentum @ wheel_axes("pyramid4"), ds["wheel_momentum_B"].values,
                               rtol=1e-12, atol=1e-12)  # fmt: skip
    # the PD's slew torques the wheels: each leaves 100 rpm
    assert np.all(np.abs(speed[-1, :4] - 100.0) > 1.0)


def test_the_min_max_allocation_keeps_every_motor_inside_its_limit(nominal_plant):
    # The ASMC's 45/45/45 command starts clipped to RF T_max = 0.95 x 2 = 1.9 N m on
    # every axis; the pseudo-inverse of the pyramid (A A^T = 4/3 I, so A^+ = 3/4 A^T)
    # would ask the wheel on (1, 1, 1)/sqrt(3) for 3/4 x sqrt(3) x 1.9 = 2.468 N m,
    # 123.4 % of its 2 N m motor. Along the null direction (-1, 1, -1, 1)/2 the
    # min-max allocation asks every motor for sqrt(3) x 1.9 / 2 = 1.645 N m, 82.3 % of
    # its limit, at t = 0, and delivers the whole command. Later commands leave the
    # diagonal; the allocation engages whenever the pseudo-inverse would ask more than
    # the limit and keeps the demand at most at the limit (measured 99.6 %): R3 holds,
    # no wheel saturated. 1e-6: the preset's half-angle is the magic angle to 1.7e-7
    # rad (test_allocation.py).
    scenario = SlewScenario.model_validate({"duration_s": 2.0, "actuator": {"kind": "wheels"}})
    ds = run_slew(nominal_plant, scenario).dataset
    metrics = slew_metrics(ds)
    ratio = ds["actuator_torque_ratio"].values
    assert ratio[0] == pytest.approx(math.sqrt(3.0) * 0.95 * 2.0 / 2.0 / 2.0, rel=1e-6)
    assert ratio.max() <= 1.0
    assert metrics["actuator_saturation_s"] == {} and max(metrics["max_abs_torque_nm"]) < 2.0
    assert metrics["r3_pass"]
