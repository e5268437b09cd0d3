"""The compiled control laws, evaluated directly at chosen states."""

from __future__ import annotations

import numpy as np
import pytest

from flexsat.control import ActuatorConfig, target_quaternion
from flexsat.control.laws import CompiledLaw
from flexsat.control.laws.asmc import ASMCConfig
from flexsat.control.laws.pd import PDConfig
from flexsat.control.laws.smc import SMCConfig
from flexsat.control.quaternion import euler_zyx_to_quaternion, pointing_error, quaternion_error

J = np.diag([189.99, 44.16, 177.90])  # J_tot of the nominal case (section 3.1)
ACTUATOR = ActuatorConfig()
LIMIT = 0.95 * 2.0  # RF * T_max [N m]


Q_D = target_quaternion((45.0, 45.0, 45.0))


def _law(config, q, omega):
    """One call of the law's compiled step: the command and the diagnostics by name."""
    law = CompiledLaw(config, ACTUATOR, J, Q_D, 1e-3)
    tau = law(0.0, np.asarray(q, dtype=float), np.asarray(omega, dtype=float))
    return tau, law.diagnostics()


def test_target_quaternion_matches_the_thesis():
    # Section 5.1.1 prints q_d = [0.8446, 0.1913, 0.4619, 0.1913] to 4 decimals.
    np.testing.assert_allclose(
        target_quaternion((45.0, 45.0, 45.0)), [0.8446, 0.1913, 0.4619, 0.1913], atol=5e-5
    )


def test_quaternion_error_is_identity_at_the_target():
    q_d = tuple(target_quaternion((10.0, -20.0, 30.0)))
    q = euler_zyx_to_quaternion(*np.radians([10.0, -20.0, 30.0]))
    np.testing.assert_allclose(quaternion_error(q_d, q), [1, 0, 0, 0], atol=1e-15)
    # and picks the shorter rotation: -q is the same attitude
    np.testing.assert_allclose(quaternion_error(q_d, tuple(-np.array(q))), [1, 0, 0, 0], atol=1e-15)


def test_asmc_far_from_target_uses_lambda_min_and_the_whole_budget():
    tau, d = _law(ASMCConfig(), (1.0, 0.0, 0.0, 0.0), (0.0, 0.0, 0.0))
    # 45/45/45 deg away (theta_err ~ 65 deg >> 5 deg): Lambda = Lambda_min (eq. 4.27).
    assert d["lambda_act"] == pytest.approx(0.2)
    theta_err = pointing_error(Q_D, (1.0, 0.0, 0.0, 0.0))
    assert np.degrees(theta_err) == pytest.approx(64.7, abs=0.5)
    # At rest, s = Lambda q_v,e is far outside the boundary layer on every axis:
    # JK takes the whole budget RF T_max (no gyroscopic or guidance torque at rest)
    # and the command is at the software limit on each axis (R3, eq. 4.22).
    np.testing.assert_allclose(d["jk"], LIMIT)
    np.testing.assert_allclose(np.abs(tau), LIMIT)


def test_asmc_at_the_target_commands_only_the_gyroscopic_torque():
    q = target_quaternion((45.0, 45.0, 45.0))
    omega = np.array([0.0, 0.0, 0.0])
    tau, d = _law(ASMCConfig(), q, omega)
    assert d["lambda_act"] == pytest.approx(5.0)  # Lambda_max at zero error
    np.testing.assert_allclose(tau, 0.0, atol=1e-12)
    np.testing.assert_allclose(d["jk"], 0.8925)  # JK_min inside the layer


def test_asmc_lambda_is_limited_by_the_torque_budget():
    # Near the target but moving fast: the budget-feasible slope
    # B_free / |J q_v,e_dot| (eq. 4.28) caps Lambda below its target (eq. 4.29).
    q = euler_zyx_to_quaternion(*np.radians([44.0, 44.5, 44.0]))
    omega = (0.05, 0.05, 0.05)
    tau, d = _law(ASMCConfig(), q, omega)
    qv_dot_scale = 0.5 * np.abs(J @ np.array(omega)).max()
    assert d["lambda_act"] < 5.0
    assert d["lambda_act"] >= 0.2
    assert d["lambda_act"] == pytest.approx((LIMIT - 0.8925 - 0.0) / qv_dot_scale, rel=0.15)
    assert np.all(np.abs(tau) <= LIMIT + 1e-12)


def test_torque_breakdown_sums_to_the_command():
    rng = np.random.default_rng(3)
    for config in (ASMCConfig(), SMCConfig(), PDConfig()):
        for _ in range(20):
            q = rng.normal(size=4)
            q /= np.linalg.norm(q)
            omega = rng.normal(scale=0.01, size=3)
            tau, d = _law(config, q, omega)
            # the PD has no robust part
            total = d["tau_gyro"] + d["tau_guide"] + d.get("tau_rob", np.zeros(3))
            np.testing.assert_allclose(tau, np.clip(total, -LIMIT, LIMIT), atol=1e-12)
