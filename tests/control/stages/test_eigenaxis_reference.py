"""Reference generators: the step (the thesis's regulation) and the shaped eigenaxis slew."""

from __future__ import annotations

import numpy as np
import pytest
from pydantic import ValidationError

from flexsat.control.quaternion import quaternion_product, target_quaternion
from flexsat.control.stages import REFERENCES
from flexsat.control.stages.eigenaxis_reference import EigenaxisReferenceConfig
from flexsat.simulate.scenario import SlewScenario

SCENARIO = SlewScenario(initial={"attitude_deg": (5.0, -10.0, 20.0)})


def _sample(config, t, plant=None):
    spec = REFERENCES.get(config.kind)
    params = np.ascontiguousarray(config.packed(SCENARIO, plant), dtype=float)
    q, w, dw = np.empty(4), np.empty(3), np.empty(3)
    record = np.empty(spec.record_size)
    assert spec.step(float(t), params, np.zeros(0), q, w, dw, record) == 0
    return q.copy(), w.copy(), dw.copy()


def test_step_reference_is_the_target_at_rest():
    q, w, dw = _sample(REFERENCES.get("step").config(), 3.0)
    np.testing.assert_array_equal(q, target_quaternion(SCENARIO.target_euler_deg))
    assert not w.any() and not dw.any()


@pytest.mark.parametrize("config", [
    EigenaxisReferenceConfig(),
    EigenaxisReferenceConfig(profile="polynomial", duration_s=30.0),
    EigenaxisReferenceConfig(profile="polynomial", duration_s=20.0,
                             shaper={"kind": "zvd", "frequencies_hz": [0.3, 0.8]}),
])  # fmt: skip
def test_eigenaxis_reference_goes_from_rest_to_rest_with_consistent_rates(config):
    end = config.duration(SCENARIO)
    q0, w0, _ = _sample(config, 0.0)
    qT, wT, dwT = _sample(config, end + 1.0)
    # The ends: the initial attitude and the target, at rest (1e-12: round-off of one
    # quaternion product of unit quaternions).
    np.testing.assert_allclose(q0, target_quaternion(SCENARIO.initial.attitude_deg), atol=1e-12)
    np.testing.assert_allclose(qT, target_quaternion(SCENARIO.target_euler_deg), atol=1e-12)
    assert np.abs(w0).max() == 0.0 and np.abs(wT).max() == 0.0 and np.abs(dwT).max() == 0.0
    # omega_d and omega_dot_d are the derivatives of q_d and omega_d: central
    # differences, h = 1e-4 s, error O(h^2 |d^3 q|) ~ 1e-9 (1e-7 allows the trapezoid's
    # acceleration steps, which a difference straddling one smears).
    h = 1e-4
    for t in np.linspace(0.37, end - 0.37, 23):
        q, w, dw = _sample(config, t)
        qp, wp, _ = _sample(config, t + h)
        qm, wm, _ = _sample(config, t - h)
        q_dot = (qp - qm) / (2 * h)
        # q_dot = 1/2 q (x) [0, omega]  ->  omega = 2 (q^-1 (x) q_dot)_v
        conj = (q[0], -q[1], -q[2], -q[3])
        omega_fd = 2.0 * np.array(quaternion_product(conj, q_dot))[1:]
        np.testing.assert_allclose(omega_fd, w, atol=1e-7)
        if not np.allclose(wp - wm, 2 * h * dw, atol=1e-7):
            assert config.profile == "trapezoid"  # a switching instant inside (t-h, t+h)


def test_trapezoid_honours_its_limits():
    config = EigenaxisReferenceConfig(rate_limit_deg_s=1.5, acceleration_limit_deg_s2=0.1)
    rates = np.array([np.linalg.norm(_sample(config, t)[1]) for t in np.linspace(0, 80, 801)])
    accs = np.array([np.linalg.norm(_sample(config, t)[2]) for t in np.linspace(0, 80, 801)])
    # the limits exactly (relative 1e-12), reached: the slew is long enough to coast
    assert rates.max() == pytest.approx(np.radians(1.5), rel=1e-12)
    assert accs.max() == pytest.approx(np.radians(0.1), rel=1e-12)


def test_bad_reference_parameters_name_the_field():
    with pytest.raises(ValidationError, match="duration_s"):
        SlewScenario.model_validate({"reference": {"kind": "eigenaxis", "profile": "polynomial"}})
    with pytest.raises(ValidationError, match="damping_ratios"):
        SlewScenario.model_validate({"reference": {"kind": "eigenaxis", "shaper": {
            "damping_ratios": [0.01]}}})  # fmt: skip
    with pytest.raises(ValidationError, match=r"unknown kind|eigenaxis"):
        SlewScenario.model_validate({"reference": {"kind": "ramp"}})
