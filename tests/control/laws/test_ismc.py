"""Integral SMC: no reaching phase, Lyapunov property, no chattering."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st

from flexsat.config import validate_config
from flexsat.control import ActuatorConfig
from flexsat.control.laws import CompiledLaw
from flexsat.control.laws.ismc import ISMCConfig
from flexsat.control.quaternion import quaternion_error
from flexsat.errors import ConfigError
from flexsat.simulate import SlewScenario, design_inertia, run_slew
from tests.control.rigid import fly_rigid

J = design_inertia()
LIMIT = 1.9  # RF * T_max [N m]
D_MAX = 0.85  # eq. 5.6: the disturbance bound JK = D_max + eta was sized for
Q_D = (0.8446231986207332, 0.1913417161825449, 0.46193976625564337, 0.1913417161825449)
CONFIG = ISMCConfig()

unit = st.floats(-1.0, 1.0, allow_nan=False)


def test_the_motion_starts_on_the_surface():
    # The thesis slew from rest at the identity: the first call sets z = -s0, so
    # s(0) = 0 exactly, where the SMC's surface starts at lambda q_v,e(0).
    law = CompiledLaw(CONFIG, ActuatorConfig(), J, Q_D, 1e-3)
    law(0.0, np.array([1.0, 0.0, 0.0, 0.0]), np.zeros(3))
    values = law.diagnostics()
    np.testing.assert_array_equal(values["sliding_variable"], 0.0)
    # z = -lambda q_v,e(0), and q_v,e(0) = -q_v,d from the identity
    np.testing.assert_allclose(values["surface_integral"], CONFIG.lambda_ * np.array(Q_D[1:]))


def test_no_reaching_phase_on_the_rigid_model_with_bounded_disturbances():
    # Rigid model, constant and sinusoidal disturbances within D_max: J s_dot =
    # -JK sat(s / Phi) + d keeps |s| <= Phi D_max / JK < Phi from s(0) = 0 on (the
    # command stays unclipped: the nominal demand J k_i |q_v,e(0)| is 1.64 N m).
    def disturbance(t):
        return np.array([0.005, 0.005, 0.005]) + 0.6 * np.sin(2 * np.pi * 0.52 * t)

    run = fly_rigid(CONFIG, J, Q_D, np.array([1.0, 0.0, 0.0, 0.0]), np.zeros(3), disturbance,
                    duration=30.0)  # fmt: skip
    assert np.all(np.abs(run["tau"]) < LIMIT)
    assert np.abs(run["sliding_variable"]).max() <= CONFIG.phi * 0.605 / CONFIG.jk_nm


small = st.floats(-0.1, 0.1, allow_nan=False)


@settings(max_examples=300, deadline=None)
@given(
    qv=st.tuples(small, small, small),
    omega=st.tuples(*[st.floats(-0.01, 0.01, allow_nan=False)] * 3),
    z=st.tuples(unit, unit, unit),
    d=st.tuples(unit, unit, unit),
)
def test_lyapunov_derivative_negative_outside_the_boundary_layer(qv, omega, z, d):
    # within ~11 deg of the target (q_d = identity): where the command is unclipped
    q = np.array([1.0, *qv]) / np.linalg.norm([1.0, *qv])
    q_d = (1.0, 0.0, 0.0, 0.0)
    omega = np.array(omega)
    law = CompiledLaw(CONFIG, ActuatorConfig(), J, q_d, 1e-3)
    law.state[:] = [*(0.05 * np.array(z)), 1.0]  # an integral already running
    tau = law(0.0, q, omega)
    values = law.diagnostics()
    s = values["sliding_variable"]
    unclipped = values["tau_gyro"] + values["tau_guide"] + values["tau_rob"]
    assume(np.all(np.abs(unclipped) <= LIMIT) and np.all(np.abs(s) > CONFIG.phi))
    disturbance = D_MAX * np.array(d)
    # rigid design model, eq. 4.7; s_dot = w_dot + lambda q_v,e_dot + k_i q_v,e
    omega_dot = np.linalg.solve(J, tau + disturbance - np.cross(omega, J @ omega))
    e = np.array(quaternion_error(q_d, q))
    qv_dot = 0.5 * (e[0] * omega + np.cross(e[1:], omega))
    s_dot = omega_dot + CONFIG.lambda_ * qv_dot + CONFIG.k_i * e[1:]
    # V_dot = s^T J s_dot = sum_i s_i (d_i - JK sgn s_i) <= -(JK - D_max) sum |s_i| < 0
    assert s @ J @ s_dot < -(CONFIG.jk_nm - D_MAX) * np.abs(s).sum() * (1 - 1e-9)


def test_no_chattering_and_no_reaching_phase_on_the_thesis_slew(nominal_plant):
    ds = run_slew(nominal_plant, SlewScenario.model_validate({"controller": {"kind": "ismc"}}))
    ds = ds.dataset
    s = ds["sliding_variable"].values
    # The flexible plant's coupling torques (< 1.6 N m peak) stay within JK's reach:
    # s never leaves the boundary layer (measured 0.0047 rad/s, Phi = 0.01).
    assert np.abs(s).max() < CONFIG.phi
    # Inside the layer the robust term is the continuous -JK s / Phi: over the last
    # 30 s the command's total variation is 2.2e-4 N m/s at most (measured); bound
    # 1e-3 N m/s, where a sgn(s) law would swing 2 JK per period, 1.8e3 N m/s.
    t = ds["time"].values
    tau = ds["tau_cmd"].values[t >= t[-1] - 30.0]
    assert np.all(np.abs(np.diff(tau, axis=0)).sum(axis=0) / 30.0 <= 1e-3)
    assert ds["surface_integral"].attrs["units"] == "rad/s"
    assert ds.attrs["boundary_layer_rad_s"] == CONFIG.phi


@pytest.mark.parametrize(
    ("table", "field"),
    [({"k_i": 0.0}, "controller.k_i"), ({"lambda": -1.0}, "controller.lambda"),
     ({"phi": "wide"}, "controller.phi"), ({"ki": 0.1}, "unknown key 'ki'")],
)  # fmt: skip
def test_bad_parameters_give_one_message_naming_the_field(table, field):
    with pytest.raises(ConfigError, match=r"^scenario\.toml: controller") as info:
        validate_config({"controller": {"kind": "ismc", **table}}, source="scenario.toml",
                        model=SlewScenario)  # fmt: skip
    assert field in str(info.value) and "\n" not in str(info.value)
