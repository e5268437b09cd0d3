"""The wheels' microvibration: the compiled torque against the empirical model written
out, the default left untouched, and refused tables."""

from __future__ import annotations

import re

import numpy as np
import pytest
from pydantic import ValidationError

from flexsat.control.stages.wheels import (
    _SIZE,
    MicrovibrationConfig,
    WheelsConfig,
    radial_basis,
    wheels_derivative,
)
from flexsat.simulate import SlewScenario

SEED = 11
POSITIONS = [[0.4, 0.1, 0.3], [-0.2, 0.5, 0.1], [0.0, -0.6, 0.2], [0.3, 0.3, -0.4]]
TABLE = {
    "static_imbalance_kg_m": 3e-5, "dynamic_imbalance_kg_m2": 1e-5,
    "radial_force": [{"number": 2.0, "coefficient": 4e-6}, {"number": 3.7, "coefficient": 1e-6}],
    "axial_force": [{"number": 1.0, "coefficient": 2e-6}, {"number": 5.2, "coefficient": 5e-7}],
    "radial_torque": [{"number": 2.0, "coefficient": 2e-6}],
    "positions_m": POSITIONS, "seed": SEED,
}  # fmt: skip


def _scenario(**wheels) -> SlewScenario:
    return SlewScenario.model_validate({"actuator": {"kind": "wheels", **wheels}})


def _torque_by_hand(config: WheelsConfig, theta: np.ndarray, speed: np.ndarray) -> np.ndarray:
    """sum_i sum_k r_i x F_ik + T_ik, the wheels' docstring term by term."""
    vib = config.microvibration
    axes = config.spin_axes()
    e1, e2 = radial_basis(axes)
    phases = vib.phases(len(axes))
    total = np.zeros(3)
    for k, (kind, h, c) in enumerate(vib.terms()):
        for i in range(len(axes)):
            x = h * theta[i] + phases[k, i]
            size = c * speed[i] ** 2
            if kind == 1:
                total += np.cross(POSITIONS[i], size * np.sin(x) * axes[i])
            else:
                radial = size * (np.cos(x) * e1[i] + np.sin(x) * e2[i])
                total += radial if kind == 2 else np.cross(POSITIONS[i], radial)
    return total


def test_the_compiled_torque_is_the_empirical_model_and_the_angle_its_speed():
    print(f"phase seed {SEED}")
    scenario = _scenario(initial_speed_rpm=1500.0, microvibration=TABLE,
                         viscous_nm_s_rad=0.0, coulomb_nm=0.0)  # fmt: skip
    config = scenario.actuator
    params = config.packed(scenario)
    n = 4
    rng = np.random.default_rng(SEED)
    omega = rng.normal(scale=0.01, size=3)  # a rotating hub: Omega_i = h_i / I_s - a_i . omega
    for _ in range(5):
        state = np.zeros(4 * 6 + 2)
        state[:n] = rng.normal(scale=2.0, size=n)  # momenta away from I_s Omega_0
        state[3 * n + 2 : 4 * n + 2] = rng.uniform(0.0, 100.0, n)  # rotor angles [rad]
        state_dot, wrench = np.zeros_like(state), np.zeros(3)
        wheels_derivative(np.zeros(38), 18, 0.0, omega, params, state, state_dot, wrench)
        h = 0.1 * 1500.0 * np.pi / 30.0 + state[:n]
        speed = h / 0.1 - config.spin_axes() @ omega
        # frictionless and unpowered: the wrench is the microvibration and -omega x H
        gyro = -np.cross(omega, config.spin_axes().T @ h)
        expected = _torque_by_hand(config, state[3 * n + 2 : 4 * n + 2], speed) + gyro
        # the same sums in another order: round-off of 1e-15 of the ~0.1 N m terms
        np.testing.assert_allclose(wrench, expected, rtol=0, atol=1e-14)
        np.testing.assert_allclose(state_dot[3 * n + 2 : 4 * n + 2], speed, rtol=1e-15)


def test_without_microvibration_the_stage_packs_and_integrates_what_it_did():
    for vib in (None, {}, {"static_imbalance_kg_m": 0.0, "seed": 3}):
        scenario = _scenario(**({} if vib is None else {"microvibration": vib}))
        # no term: the packed parameters end where they did, the RK4 step carries the
        # 3 N + 2 states it did, so a run is the one without the table, bit for bit
        assert scenario.actuator.packed(scenario).size == _SIZE
        assert scenario.actuator.integrated_size() == 3 * 4 + 2
    scenario = _scenario(microvibration=TABLE)
    assert scenario.actuator.integrated_size() == 4 * 4 + 2


def test_the_phases_are_drawn_from_the_seed():
    a, b = MicrovibrationConfig(**TABLE), MicrovibrationConfig(**{**TABLE, "seed": SEED + 1})
    np.testing.assert_array_equal(a.phases(4), MicrovibrationConfig(**TABLE).phases(4))
    assert not np.allclose(a.phases(4), b.phases(4))
    assert a.phases(4).shape == (7, 4)  # the two imbalances and five harmonics


@pytest.mark.parametrize(
    ("edit", "fragment"),
    [
        ({"static_imbalance_kg_m": -1e-6}, "static_imbalance_kg_m"),
        ({"dynamic_imbalance_kg_m2": -1e-6}, "dynamic_imbalance_kg_m2"),
        ({"radial_force": [{"number": 0.0, "coefficient": 1e-6}]}, "number"),
        ({"axial_force": [{"number": -2.0, "coefficient": 1e-6}]}, "number"),
        ({"radial_torque": [{"number": 1.0, "coefficient": -1e-6}]}, "coefficient"),
        ({"positions_m": POSITIONS[:3]}, "one position per wheel (4), got 3"),
        ({"wheels": [5]}, "wheel numbers from 1 to 4, got 5"),
    ],
)
def test_bad_tables_are_refused_naming_the_field(edit, fragment):
    with pytest.raises(ValidationError, match=re.escape(fragment)):
        _scenario(microvibration={**TABLE, **edit})
