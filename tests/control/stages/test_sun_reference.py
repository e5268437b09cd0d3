"""Sun pointing: the frame on the Sun direction, and its rate."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from flexsat.control.stages.sun_reference import SunReferenceConfig, sun_reference_step
from flexsat.simulate.scenario import SlewScenario

ORBIT = {"epoch": "2026-06-21T00:00:00Z", "altitude_m": 600e3, "inclination_deg": 28.5,
         "raan_deg": 100.0}  # fmt: skip
SCENARIO = SlewScenario.model_validate(
    {"duration_s": 400.0, "reference": {"kind": "sun"}, "orbit": ORBIT,
     "target_euler_deg": (0.0, 0.0, 0.0)}
)  # fmt: skip
PARAMS = SunReferenceConfig().packed(SCENARIO)


def _reference(t: float):
    state, record = np.empty(39), np.empty(0)
    q_d, omega_d, omega_dot_d = np.empty(4), np.empty(3), np.empty(3)
    assert sun_reference_step(t, PARAMS, state, q_d, omega_d, omega_dot_d, record) == 0
    return q_d, omega_d, omega_dot_d, state[:13]


def test_body_z_points_at_the_sun_and_x_lies_in_the_equator():
    q_d, _, omega_dot_d, row = _reference(211.7)
    axes = Rotation.from_quat(q_d[[1, 2, 3, 0]]).as_matrix()
    # unit vectors into a rotation: rounding only
    np.testing.assert_allclose(axes[:, 2], row[7:10], atol=1e-12)
    assert abs(axes[2, 0]) < 1e-12  # x = Z x s / |Z x s| has no z component
    assert axes[:, 0] @ np.cross([0.0, 0.0, 1.0], row[7:10]) > 0.0
    np.testing.assert_array_equal(omega_dot_d, 0.0)


def test_rate_is_that_of_the_frame():
    # the frame turns at about 2e-7 rad/s (the year, and the orbit's parallax). Over
    # +-5 s inside one 10 s grid step s is linear: the central difference of q_d is
    # exact to the rotation's rounding (1e-16 / 10 s = 1e-17 rad/s) and the s' of the
    # stage is the grid's slope, the same line: 1e-12 rad/s is 1e-5 of the rate
    t, dt = 215.0, 4.0
    q0, _, _, _ = _reference(t - dt)
    q1, _, _, _ = _reference(t + dt)
    _, omega_d, _, _ = _reference(t)
    rate = (Rotation.from_quat(q0[[1, 2, 3, 0]]).inv()
            * Rotation.from_quat(q1[[1, 2, 3, 0]])).as_rotvec() / (2 * dt)  # fmt: skip
    assert 1e-8 < np.linalg.norm(omega_d) < 1e-6
    np.testing.assert_allclose(rate, omega_d, atol=1e-12)


def test_sun_without_an_orbit_is_refused():
    with pytest.raises(ValueError, match=r"reference.kind = 'sun'.*\[orbit\]"):
        SlewScenario.model_validate({"reference": {"kind": "sun"}})
