"""The solar-array drive stage: its commanded profiles, its torque law and its bad
settings (one message naming the field, exit code 2)."""

from __future__ import annotations

import numpy as np
import pytest

from flexsat.config import nominal
from flexsat.control.stages import JOINT_ACTUATORS
from flexsat.control.stages.sadm_drive import SADMDriveConfig, commanded_angle
from flexsat.dynamics.appendages.sadm import DRIVE_COORDINATE, with_sadm
from flexsat.dynamics.plant import Plant
from flexsat.simulate import run_slew
from flexsat.simulate.scenario import SlewScenario
from tests.cli.harness import flexsat

STEP = JOINT_ACTUATORS.get("sadm_drive").step
_DRIVE = {"coordinates": [DRIVE_COORDINATE], "stiffness_nm_rad": 4.0, "damping_nms_rad": 1.0,
          "rate_deg_s": 0.06}  # fmt: skip


@pytest.fixture(scope="module")
def driven() -> Plant:
    return Plant.from_config(with_sadm(nominal(), 0.1, 2.0))


def test_profiles():
    # Constant rate: beta_0 + r t exactly; to_target: at the rate limit until the
    # target, then held (1e-15: round-off of the products).
    assert commanded_angle(10.0, 0.1, 0.0, 0.002, False) == pytest.approx((0.12, 0.002),
                                                                            rel=1e-15)  # fmt: skip
    assert commanded_angle(10.0, 0.1, 0.0, 0.002, True) == pytest.approx((0.08, -0.002),
                                                                           rel=1e-15)  # fmt: skip
    assert commanded_angle(60.0, 0.1, 0.0, 0.002, True) == (0.0, 0.0)
    assert commanded_angle(60.0, 0.1, 0.5, 0.002, True) == pytest.approx((0.22, 0.002),
                                                                           rel=1e-15)  # fmt: skip


def test_torque_is_the_pd_law_on_the_driven_coordinates_only(driven):
    # Q = k_d (beta_cmd - beta) + c_d (beta_dot_cmd - beta_dot), clipped to Q_max,
    # written on the drive coordinates of both plates and nowhere else.
    n = driven.n_dof
    config = SADMDriveConfig(**_DRIVE, max_torque_nm=0.005)
    params = np.ascontiguousarray(config.packed(SlewScenario(), driven))
    drive = [driven.layout.dof_names().index(f"panel_{k}.{DRIVE_COORDINATE}") for k in (1, 2)]
    x = np.zeros(2 * n + 2)
    x[drive[0]], x[n + drive[0]] = 0.001, 0.0005  # ahead of the command, faster
    Q, record, J = np.zeros(n), np.zeros(4), np.eye(3)
    assert STEP(x, n, 2.0, 1e-3, np.array([1.0, 0, 0, 0]), J, params, np.zeros(10), Q, record) == 0
    assert np.array_equal(J, np.eye(3))  # design_model "initial": left as it is
    r = np.radians(0.06)
    expected = 4.0 * (2.0 * r - 0.001) + 1.0 * (r - 0.0005)
    assert Q[drive[0]] == pytest.approx(expected, rel=1e-14)  # 4.9e-3 N m, within the limit
    assert Q[drive[1]] == 0.005  # at rest: 4 (2 r) + r = 9.4e-3 N m, clipped
    assert np.count_nonzero(Q) == 2
    assert record[2] == pytest.approx(2.0 * r, rel=1e-14)  # the largest tracking error


@pytest.mark.parametrize(("fields", "fragment"), [
    ({"stiffness_nm_rad": -1.0}, "joint_actuator.stiffness_nm_rad"),
    ({"damping_nms_rad": -0.1}, "joint_actuator.damping_nms_rad"),
    ({"profile": "to_target", "target_deg": 10.0, "rate_deg_s": 0.0}, "rate_deg_s: the to_target "
     "rate limit must be > 0"),
    ({"profile": "to_target"}, "target_deg: the to_target profile needs a target"),
    ({"max_torque_nm": 0.0}, "joint_actuator.max_torque_nm"),
    ({"coordinates": ["beta"]}, "joint_actuator.coordinates: unknown coordinate 'beta'"),
    ({"design_model": "encoder"}, "joint_actuator.design_model: Input should be 'initial' or "
     "'measured'"),
])  # fmt: skip
def test_bad_settings_give_one_message_and_exit_code_2(fields, fragment, tmp_path, capsys):
    table = {**_DRIVE, **fields}

    def toml(value):
        if isinstance(value, str):
            return f'"{value}"'
        if isinstance(value, list):
            return "[" + ", ".join(toml(v) for v in value) + "]"
        return repr(value)

    # a 10 ms run that holds its observation window (a run must, test_bad_inputs.py)
    body = ("duration_s = 0.01\n[requirements]\nsettling_deadline_s = 0.005\n"
            "[joint_actuator]\nkind = \"sadm_drive\"\n") + "".join(
        f"{key} = {toml(value)}\n" for key, value in table.items())  # fmt: skip
    (tmp_path / "s.toml").write_text(body)
    outcome = flexsat(["slew", "--scenario", str(tmp_path / "s.toml"), "--out",
                       str(tmp_path / "out")], capsys)  # fmt: skip
    assert outcome.code == 2, outcome.stderr
    assert fragment in outcome.stderr, outcome.stderr
    assert "Traceback" not in outcome.stderr


def test_a_slew_moves_the_arrays_to_the_target_angle(driven):
    # The closed loop, hub held at its initial attitude by the law, arrays moved
    # 1 deg at 0.5 deg/s (the command arrives at 2 s): the drive loop, critically
    # damped at omega_n = 2 pi x 0.5 Hz (J = rotor + array about the axis, 1.37 kg m^2),
    # settles as exp(-omega_n t): 8 s later (25 time constants) the error is below
    # 1e-3 deg (measured 3.3e-6 deg).
    inertia = 0.1 + nominal().appendages[0].centroidal_inertia()[1, 1]
    omega_n = 2.0 * np.pi * 0.5
    drive = {**_DRIVE, "kind": "sadm_drive", "profile": "to_target", "target_deg": 1.0,
             "rate_deg_s": 0.5, "stiffness_nm_rad": inertia * omega_n**2,
             "damping_nms_rad": 2.0 * omega_n * inertia}  # fmt: skip
    scenario = SlewScenario.model_validate({"duration_s": 10.0, "target_euler_deg": [0.0] * 3,
                                            "joint_actuator": drive})  # fmt: skip
    ds = run_slew(driven, scenario, progress=False).dataset
    final = [float(ds["q"].sel(dof=f"panel_{k}.{DRIVE_COORDINATE}").values[-1]) for k in (1, 2)]
    assert np.degrees(final) == pytest.approx([1.0, 1.0], abs=1e-3)
    assert float(np.degrees(ds["sadm_tracking_error"].values[-1])) < 1e-3
