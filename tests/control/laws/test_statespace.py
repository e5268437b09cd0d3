"""The statespace law: any discrete controller from a file, in the compiled loop."""

from __future__ import annotations

import re

import numpy as np
import pytest

import control
from flexsat.control import ActuatorConfig
from flexsat.control.laws import CompiledLaw, get_law, law_names
from flexsat.control.laws.statespace import (
    CONTROLLER_INPUTS,
    DiscreteController,
    StateSpaceConfig,
    controller_input,
    load_controller,
    save_controller,
)
from flexsat.control.quaternion import quaternion_error
from flexsat.errors import ConfigError
from flexsat.simulate import SlewScenario, design_inertia, run_slew

SEED = 20261207
DT = 1e-3  # the loop's control period [s]
J = design_inertia()


def _pd_rolloff(wn=0.3, zeta=0.9, wf=5.0) -> control.StateSpace:
    """A PD through a first-order roll-off: x' = wf (-x + wn^2 theta + 2 zeta wn omega),
    tau = -J x (three states, continuous)."""
    I3 = np.eye(3)
    B = wf * np.hstack([wn**2 * I3, 2.0 * zeta * wn * I3])
    return control.ss(-wf * I3, B, -J, np.zeros((3, 6)))


def _order_20(seed: int = SEED) -> DiscreteController:
    """The PD with roll-off, in parallel with a random stable 17-state part of small gain
    (dense A, B, C, D: every entry of the packed matrices is read)."""
    print(f"seed {seed}")
    rng = np.random.default_rng(seed)
    pd = control.c2d(_pd_rolloff(), DT, method="tustin")
    Q, _ = np.linalg.qr(rng.standard_normal((17, 17)))
    A = Q @ np.diag(rng.uniform(0.5, 0.99, 17)) @ Q.T  # spectral radius 0.99 < 1
    extra = control.ss(A, rng.standard_normal((17, 6)), 1e-3 * rng.standard_normal((3, 17)),
                       1e-3 * rng.standard_normal((3, 6)), DT)  # fmt: skip
    both = control.parallel(pd, extra)
    return DiscreteController(both.A, both.B, both.C, both.D, DT)


@pytest.fixture(scope="module")
def controller_file(tmp_path_factory):
    return save_controller(_order_20(), tmp_path_factory.mktemp("k") / "k20.npz")


def test_the_loop_reproduces_python_controls_discrete_simulation(nominal_plant, controller_file):
    # A 2 s slew of the flexible satellite with the order-20 controller in the compiled
    # loop, every control instant recorded; the recorded inputs y (ideal sensor: the
    # plant's attitude and rate) fed to control.forced_response of the same controller
    # give the recorded C x + D y.
    scenario = SlewScenario(duration_s=2.0, record_dt_s=DT, controller={
        "kind": "statespace", "file": str(controller_file)})  # fmt: skip
    ds = run_slew(nominal_plant, scenario, progress=False).dataset
    assert ds.attrs["status"] == "ok"
    q_d = np.array(ds.attrs["target_quaternion"])
    q, omega = ds.quaternion.values, ds.omega.values
    zero = np.zeros(3)
    y = np.array([controller_input(q_d, zero, zero, q[k].copy(), omega[k].copy())
                  for k in range(len(q))])  # fmt: skip
    reference = control.forced_response(load_controller(controller_file).to_statespace(), U=y.T)
    tau = ds.tau_linear.values
    scale = np.abs(reference.outputs).max()
    assert scale > 1.0  # the command is large (clipped at 1.9 N m for part of the run)
    # Round-off: the same products summed in another order over 2000 steps of a
    # contraction (spectral radius 0.99); 1e-12 of the largest command is ~1e4 ulps.
    np.testing.assert_allclose(tau, reference.outputs.T, rtol=0.0, atol=1e-12 * scale)
    limit = ActuatorConfig().reduction_factor * ActuatorConfig().t_max_nm
    np.testing.assert_array_equal(ds.tau_cmd.values, np.clip(tau, -limit, limit))


def test_the_attitude_input_is_the_rotation_vector():
    # q = q_d (x) (cos a/2, sin a/2 e): the input is a e exactly, the rate error omega
    rng = np.random.default_rng(SEED)
    print(f"seed {SEED}")
    for _ in range(50):
        q_d = rng.standard_normal(4)
        q_d /= np.linalg.norm(q_d)
        e = rng.standard_normal(3)
        e /= np.linalg.norm(e)
        a = rng.uniform(1e-6, 3.0)
        r = np.array([np.cos(a / 2), *(np.sin(a / 2) * e)])
        w0, v0, w1, v1 = q_d[0], q_d[1:], r[0], r[1:]
        q = np.array([w0 * w1 - v0 @ v1, *(w0 * v1 + w1 * v0 + np.cross(v0, v1))])
        omega = rng.standard_normal(3) * 0.01
        y = controller_input(q_d, np.zeros(3), np.zeros(3), q, omega)
        np.testing.assert_allclose(y[:3], a * e, atol=1e-12)  # round-off of atan2/acos [rad]
        np.testing.assert_allclose(y[3:], omega, atol=1e-17)
        np.testing.assert_allclose(np.array(quaternion_error(q_d, q))[1:], r[1:], atol=1e-15)


def test_small_errors_are_the_zyx_angles_of_the_linear_model():
    # phi, theta, psi of 1e-3 rad: the rotation vector agrees to second order (~1e-6 rad)
    from scipy.spatial.transform import Rotation

    angles = np.array([1e-3, -2e-3, 1.5e-3])  # roll, pitch, yaw [rad]
    xyzw = Rotation.from_euler("ZYX", angles[::-1]).as_quat()
    q = np.array([xyzw[3], *xyzw[:3]])
    y = controller_input(np.array([1.0, 0, 0, 0]), np.zeros(3), np.zeros(3), q, np.zeros(3))
    np.testing.assert_allclose(y[:3], angles, atol=5e-6)  # |angles|^2 ~ 7e-6


@pytest.mark.parametrize("suffix", [".npz", ".mat"])
def test_files_round_trip_exactly(tmp_path, suffix):
    k = _order_20()
    back = load_controller(save_controller(k, tmp_path / f"k{suffix}"))
    for name in "ABCD":
        np.testing.assert_array_equal(getattr(back, name), getattr(k, name))
    assert back.dt == k.dt and back.order == 20


def test_the_compiled_step_is_the_difference_equation(controller_file):
    # CompiledLaw: three calls of x+ = A x + B y, tau = C x + D y by hand
    k = load_controller(controller_file)
    config = StateSpaceConfig(file=str(controller_file))
    law = CompiledLaw(config, ActuatorConfig(), J, (1.0, 0.0, 0.0, 0.0), DT)
    x = np.zeros(20)
    for n, angle in enumerate((1e-3, 2e-3, -1e-3)):
        q = np.array([np.cos(angle / 2), np.sin(angle / 2), 0.0, 0.0])
        omega = np.array([1e-4, -2e-4, 3e-4]) * n
        law(n * DT, q, omega)
        y = np.array([angle, 0.0, 0.0, *omega])
        np.testing.assert_allclose(law.diagnostics()["tau_linear"], k.C @ x + k.D @ y,
                                   rtol=0.0, atol=1e-15)  # fmt: skip
        x = k.A @ x + k.B @ y
        np.testing.assert_allclose(law.state[:20], x, rtol=0.0, atol=1e-15)


def test_a_controller_of_another_period_is_refused(controller_file):
    message = ("controller.file: the controller was discretized at dt = 0.001 s, the loop "
               "runs at control_dt_s = 0.002 s")  # fmt: skip
    with pytest.raises(ValueError, match=re.escape(message)):
        SlewScenario(control_dt_s=2e-3, controller={"kind": "statespace",
                                                    "file": str(controller_file)})  # fmt: skip


def test_unreadable_files_name_the_file(tmp_path):
    path = tmp_path / "k.npz"
    path.write_bytes(b"not a zip")
    with pytest.raises(ConfigError, match=re.escape(f"controller file {path}: not a readable")):
        load_controller(path)


def test_the_law_is_registered_but_not_among_the_compared_laws():
    # it needs a file: a [controller] table selects it, "every law" does not run it
    assert get_law("statespace").label == "SS"
    assert "statespace" not in law_names()
    assert len(CONTROLLER_INPUTS) == 6
