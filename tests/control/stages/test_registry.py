"""Loop stages written outside the package: a biased sensor and a scaling actuator.

Each is defined, compiled and registered in this file with one line; the slew
scenario selects it by kind and the compiled loop runs it. Their effects are
checked against what they must do analytically.
"""

from __future__ import annotations

from typing import Literal

import numpy as np
import pytest
from numba import njit
from pydantic import Field, ValidationError
from scipy.integrate import trapezoid

from flexsat.compiled.linalg3 import euler_rate_matrix, load_seg, mv
from flexsat.control import Channel, StageConfig, StageSpec, register_stage
from flexsat.control.quaternion import euler_zyx_to_quaternion, target_quaternion
from flexsat.control.stages import (
    ACTUATOR_SIGNATURE,
    ACTUATORS,
    DERIVATIVE_SIGNATURE,
    SENSOR_SIGNATURE,
    SENSORS,
    ActuatorStageConfig,
    validate_stage,
)
from flexsat.simulate import SlewScenario, run_slew
from flexsat.simulate.closedloop import prepare_slew

BIAS_DEG = 0.2  # attitude bias of the sensor about body x


class BiasedSensorConfig(StageConfig):
    kind: Literal["biased"] = "biased"
    bias_x_deg: float = 0.0

    def packed(self, scenario) -> np.ndarray:
        half = np.radians(self.bias_x_deg) / 2.0
        return np.array([np.cos(half), np.sin(half), 0.0, 0.0])  # delta, scalar first


@njit(SENSOR_SIGNATURE, cache=True)
def biased_sensor_step(x, n_dof, t, params, state, q_meas, omega_meas, record):
    """q_meas = q (x) delta: the true attitude seen through a constant rotation."""
    q = euler_zyx_to_quaternion(x[3], x[4], x[5])
    d = params
    q_meas[0] = q[0] * d[0] - q[1] * d[1] - q[2] * d[2] - q[3] * d[3]
    q_meas[1] = q[0] * d[1] + q[1] * d[0] + q[2] * d[3] - q[3] * d[2]
    q_meas[2] = q[0] * d[2] - q[1] * d[3] + q[2] * d[0] + q[3] * d[1]
    q_meas[3] = q[0] * d[3] + q[1] * d[2] - q[2] * d[1] + q[3] * d[0]
    omega = mv(euler_rate_matrix(x[3], x[4]), load_seg(x, n_dof + 3))
    omega_meas[0], omega_meas[1], omega_meas[2] = omega
    return 0


class ScalingActuatorConfig(ActuatorStageConfig):
    kind: Literal["scaling"] = "scaling"
    scale: float = Field(0.5, gt=0.0)

    def packed(self, scenario) -> np.ndarray:
        return np.array([self.scale])


@njit(ACTUATOR_SIGNATURE, cache=True)
def scaling_actuator_step(tau_cmd, t, dt, params, state, tau_applied, record):
    for a in range(3):
        tau_applied[a] = params[0] * tau_cmd[a]
    record[0] = params[0]
    return 0


class PlainActuatorConfig(StageConfig):
    kind: Literal["plain"] = "plain"  # no limits: an actuation stage only


class RateIntegralConfig(StageConfig):
    kind: Literal["rate_integral"] = "rate_integral"

    def integrated_size(self) -> int:
        return 3  # the integral; the instant counter after it is discrete


@njit(ACTUATOR_SIGNATURE, cache=True)
def rate_integral_step(tau_cmd, t, dt, params, state, tau_applied, record):
    """Passes the torque on; records the integral of omega and counts the instants."""
    state[3] += 1.0
    for a in range(3):
        tau_applied[a] = tau_cmd[a]
        record[a] = state[a]
    record[3] = state[3]
    return 0


@njit(DERIVATIVE_SIGNATURE, cache=True)
def rate_integral_derivative(x, n_dof, t, omega, params, state, state_dot, wrench):
    """d/dt of the integral is the body rate the loop hands over; no torque on the hub."""
    for a in range(3):
        state_dot[a] = omega[a]
    return 0


BIASED = StageSpec(role="sensor", name="biased", config=BiasedSensorConfig,
                   step=biased_sensor_step)  # fmt: skip
SCALING = StageSpec(
    role="actuator", name="scaling", config=ScalingActuatorConfig, step=scaling_actuator_step,
    records=(Channel("actuator_scale", "1", "applied / commanded torque"),),
)  # fmt: skip

RATE_INTEGRAL = StageSpec(
    role="actuator", name="rate_integral", config=RateIntegralConfig, step=rate_integral_step,
    derivative=rate_integral_derivative, state_size=4,
    records=(Channel("rate_integral", "rad", "integral of omega, hub frame B", per_axis=True),
             Channel("instants", "1", "control instants seen")),
)  # fmt: skip


@pytest.fixture(scope="module")
def stages():
    register_stage(BIASED)  # the one line a user writes, per stage
    register_stage(SCALING)
    register_stage(RATE_INTEGRAL)
    yield
    SENSORS.unregister(BIASED.name)
    ACTUATORS.unregister(SCALING.name)
    ACTUATORS.unregister(RATE_INTEGRAL.name)


def test_sensor_bias_moves_the_true_attitude_by_the_bias(stages, nominal_plant):
    # No disturbances and a PD law: the loop drives the *measured* attitude onto the
    # target, so the true attitude ends the bias away from it: q = q_d (x) delta^-1.
    scenario = SlewScenario.model_validate({
        "duration_s": 60.0, "target_euler_deg": [1.0, 1.0, 1.0],
        "controller": {"kind": "pd"}, "sensor": {"kind": "biased", "bias_x_deg": BIAS_DEG},
        "actuator": {"gain": [1.0, 1.0, 1.0]},
        "disturbances": {"environment_nm": [0.0] * 3, "sloshing_ratio": 0.0},
    })  # fmt: skip
    ds = run_slew(nominal_plant, scenario).dataset
    assert ds.attrs["sensor"] == "biased"
    # The result's pointing error is the true attitude's: the bias, composed with the
    # measured error left after 60 s (~1.5e-5 deg: PD, zeta wn = 0.27 1/s, slowed by
    # the panels), within 1e-3 of the bias.
    assert ds["pointing_error_deg"].values[-1] == pytest.approx(BIAS_DEG, abs=1e-3 * BIAS_DEG)
    # the measured attitude q (x) delta is on the target
    q = ds["quaternion"].values[-1]
    half = np.radians(BIAS_DEG) / 2.0
    d = np.array([np.cos(half), np.sin(half), 0.0, 0.0])
    measured = np.array([
        q[0] * d[0] - q[1] * d[1], q[0] * d[1] + q[1] * d[0],
        q[2] * d[0] + q[3] * d[1], q[3] * d[0] - q[2] * d[1],
    ])  # fmt: skip
    q_d = target_quaternion(scenario.target_euler_deg)
    measured_error = 2.0 * np.degrees(np.arccos(min(1.0, abs(measured @ q_d))))
    assert measured_error < 1e-3 * BIAS_DEG


def test_actuator_stage_replaces_the_static_one(stages, nominal_plant):
    scenario = SlewScenario.model_validate(
        {"duration_s": 2.0, "actuator": {"kind": "scaling", "scale": 0.5}}
    )
    ds = run_slew(nominal_plant, scenario).dataset
    assert ds.attrs["actuator"] == "scaling"
    # exactly half of the command (a power of two: no rounding), no disturbance added
    np.testing.assert_array_equal(ds["tau_applied"].values, 0.5 * ds["tau_cmd"].values)
    np.testing.assert_array_equal(ds["actuator_scale"].values, 0.5)
    assert ds["actuator_scale"].attrs["units"] == "1"
    from flexsat.plots.slew import plot_disturbances

    fig = plot_disturbances(ds)  # a user's actuator that does not apply them: a note
    (note,) = fig.axes[0].texts
    assert "does not apply the scenario's disturbances" in note.get_text()


def test_a_continuous_stage_integrates_the_body_rate_the_loop_hands_it(stages, nominal_plant):
    # A stage's derivative receives omega = S(Theta) Theta_dot at every RK4 stage: its
    # integral over the first 2 s of the thesis slew is the integral of the recorded
    # body rate. Records every step (1 ms): the trapezoidal rule's error, dt^2 / 12 T
    # max|omega''| ~ 1e-6 / 12 * 2 * 0.05 ~ 1e-8 rad, against an integral of ~1e-3 rad:
    # 1e-4 relative bounds it with margin, while a wrong rate (a frame, a sign, a lag
    # of one step: ~|omega| dt = 1e-6 rad) would not pass.
    scenario = SlewScenario.model_validate({
        "duration_s": 2.0, "record_dt_s": 0.001,
        "actuator_stages": [{"kind": "rate_integral"}],
    })  # fmt: skip
    # only the integral rides in the coupled RK4 step, not the discrete counter
    assert prepare_slew(nominal_plant, scenario).data.flow.state.shape == (3,)
    ds = run_slew(nominal_plant, scenario).dataset
    expected = trapezoid(ds["omega"].values, ds["time"].values, axis=0)
    got = ds["rate_integral"].values[-1]
    assert np.abs(got).max() > 1e-4  # the slew has started turning
    np.testing.assert_allclose(got, expected, rtol=1e-4, atol=1e-10)
    assert ds["instants"].values[-1] == scenario.n_steps + 1  # held, never integrated


@pytest.mark.parametrize(
    ("role", "default"),
    [("sensor", "ideal"), ("actuator", "static"), ("reference", "step"),
     ("joint_actuator", "none")],
)  # fmt: skip
def test_one_validator_serves_every_role(role, default):
    # A table without kind selects the role's default stage; each field of the slew
    # scenario is validated by the role it is named after.
    assert validate_stage(role, {}).kind == default
    assert getattr(SlewScenario(), role).kind == default


def test_a_stage_without_limits_is_refused_as_the_final_actuator():
    with pytest.raises(ValidationError, match="actuator_stages, before the final"):
        SlewScenario(actuator={"kind": "notch"})
    # ...but is accepted in the chain before it
    chained = SlewScenario(actuator_stages=[{"kind": "notch"}])
    assert chained.actuator_stages[0].kind == "notch"


def test_registration_checks_the_config_the_role_needs():
    plain = StageSpec(role="actuator", name="plain", config=PlainActuatorConfig,
                      step=scaling_actuator_step)  # fmt: skip
    with pytest.raises(ValueError, match="must derive ActuatorStageConfig"):
        register_stage(plain, default=True)  # the default [actuator] needs limits
    joint = StageSpec(role="joint_actuator", name="plain", config=PlainActuatorConfig,
                      step=scaling_actuator_step)  # fmt: skip
    with pytest.raises(ValueError, match="must derive JointActuatorConfig"):
        register_stage(joint)
    assert ACTUATORS.default == "static" and "plain" not in ACTUATORS.names()
