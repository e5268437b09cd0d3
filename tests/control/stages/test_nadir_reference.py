"""Nadir (LVLH) pointing: the frame, its rate and acceleration, and the loop flying it."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from flexsat.config import nominal
from flexsat.control.quaternion import quaternion_product, target_quaternion
from flexsat.control.stages.nadir_reference import NadirReferenceConfig, nadir_reference_step
from flexsat.dynamics.plant import Plant
from flexsat.orbit.config import EARTH_J2, EARTH_MU_M3_S2
from flexsat.orbit.sun import EARTH_RADIUS_M
from flexsat.simulate.closedloop import run_slew
from flexsat.simulate.scenario import SlewScenario

ORBIT = {"epoch": "2026-03-20T12:00:00Z", "altitude_m": 500e3, "inclination_deg": 51.6,
         "raan_deg": 30.0}  # fmt: skip


def _scenario(**changes) -> SlewScenario:
    fields = {"duration_s": 200.0, "reference": {"kind": "nadir"}, "orbit": ORBIT,
              "target_euler_deg": (0.0, 0.0, 0.0)} | changes  # fmt: skip
    return SlewScenario.model_validate(fields)


def _reference(scenario: SlewScenario, t: float):
    params = NadirReferenceConfig().packed(scenario)
    state, record = np.empty(13), np.empty(0)
    q_d, omega_d, omega_dot_d = np.empty(4), np.empty(3), np.empty(3)
    assert nadir_reference_step(t, params, state, q_d, omega_d, omega_dot_d, record) == 0
    return q_d, omega_d, omega_dot_d, state


def _rate_from_quaternions(q0: np.ndarray, q1: np.ndarray, dt: float) -> np.ndarray:
    """The body rate (frame of q) that turns q0 into q1 in dt [rad/s]."""
    r0, r1 = (Rotation.from_quat(q[[1, 2, 3, 0]]) for q in (q0, q1))
    return (r0.inv() * r1).as_rotvec() / dt


def test_body_z_points_at_nadir_and_y_against_the_orbit_normal():
    scenario = _scenario(orbit=ORBIT | {"j2": False})
    q_d, _, _, row = _reference(scenario, 123.4)
    axes = Rotation.from_quat(q_d[[1, 2, 3, 0]]).as_matrix()  # columns: body axes in ECI
    r, v = row[1:4], row[4:7]
    h = np.cross(r, v)
    # a rotation matrix from unit vectors: rounding only (1e-15 per entry)
    np.testing.assert_allclose(axes[:, 2], -r / np.linalg.norm(r), atol=1e-12)
    np.testing.assert_allclose(axes[:, 1], -h / np.linalg.norm(h), atol=1e-12)
    # an offset: q_d = q_NL (x) q_off
    offset = (10.0, -20.0, 30.0)
    q_off, _, _, _ = _reference(_scenario(orbit=ORBIT | {"j2": False},
                                          target_euler_deg=offset), 123.4)  # fmt: skip
    expected = np.array(quaternion_product(q_d, target_quaternion(offset)))
    np.testing.assert_allclose(q_off, expected * np.sign(expected[0] * q_off[0]), atol=1e-12)


def test_rate_and_acceleration_are_those_of_the_frame():
    # two-body: the frame turns about the orbit normal only, so omega_d and its rate
    # are exact; eccentric, so |h| / r^2 changes along the orbit
    scenario = _scenario(orbit=ORBIT | {"j2": False, "eccentricity": 0.05,
                                        "altitude_m": 1000e3})  # fmt: skip
    dt = 1e-2
    for t in (50.0, 97.3, 150.0):
        q0, w0, a0, _ = _reference(scenario, t - dt)
        q1, w1, a1, _ = _reference(scenario, t + dt)
        qm, wm, am, _ = _reference(scenario, t)
        # central differences over 2 dt = 0.02 s: truncation (omega dt)^2 / 6 of the
        # 1e-3 rad/s rate (2e-11 relative) and the interpolant's rounding (1e-12 rad
        # over 0.02 s); 1e-9 rad/s is both with margin, and 1e-3 of the rate
        np.testing.assert_allclose(_rate_from_quaternions(q0, q1, 2 * dt), wm, atol=1e-9)
        # the acceleration: 1e-8 rad/s^2 of a 1e-7 rad/s^2 signal differenced over 0.02 s
        # (the Hermite's second derivative jumps at grid nodes: the times avoid them)
        np.testing.assert_allclose((w1 - w0) / (2 * dt), am, atol=2e-10)


def test_pd_loop_keeps_nadir_within_the_bandwidth_bound():
    """The PD (omega_n = 0.3 rad/s, zeta = 0.9) flies nadir pointing for 100 s of a 500 km,
    51.6 deg orbit, starting on the target, without disturbances."""
    first, _, _, _ = _reference(_scenario(), 0.0)
    yaw, pitch, roll = Rotation.from_quat(first[[1, 2, 3, 0]]).as_euler("ZYX", degrees=True)
    _, omega_d, _, _ = _reference(_scenario(), 0.0)
    scenario = _scenario(
        duration_s=100.0, dt_s=2e-3, control_dt_s=2e-3, record_dt_s=0.1,
        controller={"kind": "pd"},
        initial={"attitude_deg": (roll, pitch, yaw), "rate_deg_s": tuple(np.degrees(omega_d))},
        disturbances={"environment_nm": (0.0, 0.0, 0.0), "sloshing_ratio": 0.0},
        requirements={"settling_deadline_s": 0.0},
    )  # fmt: skip
    result = run_slew(Plant.from_config(nominal()), scenario, progress=False)
    ds = result.dataset
    assert ds.attrs["status"] == "ok"
    assert "reference_quaternion" in ds
    pointing = ds["pointing_error_deg"].values
    # The bound: omega_d leaves out the orbit plane's turn under J2,
    # 3 mu J2 R_E^2 sin i cos i / (r^3 |h|) at most; a PD tracking a rate off by
    # that settles 2 zeta / omega_n times it away (docs/orbit.md, 'Pointing targets')
    r = EARTH_RADIUS_M + 500e3
    i = np.radians(51.6)
    rate_error = (3 * EARTH_MU_M3_S2 * EARTH_J2 * EARTH_RADIUS_M**2 * np.sin(i) * np.cos(i)
                  / (r**3 * np.sqrt(EARTH_MU_M3_S2 * r)))  # fmt: skip
    bound_deg = np.degrees(2 * 0.9 / 0.3 * rate_error)
    print(f"pointing error: max {pointing.max():.3g} deg, bound {bound_deg:.3g} deg")
    assert pointing.max() < bound_deg
    # against the fixed target of the scenario (the inertial frame) it would be the
    # orbit's turn: 100 s at 0.063 deg/s, 6 deg; the error is taken from the moving q_d
    assert pointing.max() < 1e-3 * np.degrees(100.0 * np.linalg.norm(omega_d))
    # and the residual rate is the rate error, not the orbit rate
    assert ds["rate_error_deg_s"].values.max() < 1e-3 * np.degrees(np.linalg.norm(omega_d))


def test_nadir_without_an_orbit_is_refused():
    with pytest.raises(ValueError, match=r"reference.kind = 'nadir'.*\[orbit\]"):
        SlewScenario.model_validate({"reference": {"kind": "nadir"}})
