"""The switching attitude reference: a re-base changes the coordinates, never the motion."""

from __future__ import annotations

import numpy as np
import pytest

from flexsat.compiled.linalg3 import euler_rate_matrix, rot_zyx
from flexsat.dynamics.appendages.contract import OBS_KINETIC, OBS_MOMENTUM, OBS_SIZE
from flexsat.dynamics.attitude import (
    SWITCH_PITCH,
    euler_zyx,
    identity_frame,
    inertial_records,
    inertial_view,
    rebase,
)
from flexsat.dynamics.kernels import accelerations, observe

# Round-off: each quantity is formed by a few dozen floating-point operations on
# values of order one, in two frames; 1e-12 relative leaves a factor ~100 over eps.
RTOL = 1e-12


def _state(plant, pitch, seed=3):
    """A deformed, spinning, drifting state at the given hub pitch (fixed seed)."""
    rng = np.random.default_rng(seed)
    n = plant.n_dof
    x = np.zeros(2 * n + 2)
    x[0:3] = rng.normal(size=3)  # position [m]
    x[3:6] = rng.uniform(-1.0, 1.0), pitch, rng.uniform(-3.0, 3.0)
    x[6:n] = 1e-3 * rng.normal(size=n - 6)
    x[n : 2 * n] = 0.05 * rng.normal(size=n)
    x[2 * n :] = 0.3, 0.01  # work and dissipation: carried over unchanged
    return x


def _physics(plant, x, frame):
    """What must not depend on the frame: energy, H in N, body rate and acceleration,
    joint coordinates and their accelerations."""
    n = plant.n_dof
    q, qd = x[:n], x[n : 2 * n]
    qdd = np.empty(n)
    Q = np.zeros(n)
    assert accelerations(q, qd, Q, plant.packed, qdd) == 0
    obs = np.empty(OBS_SIZE)
    observe(q, qd, plant.packed, obs)
    R_NF = frame.reshape(3, 3)
    S = np.array(euler_rate_matrix(q[3], q[4]))
    omega = S @ qd[3:6]
    return {
        "kinetic": obs[OBS_KINETIC],
        "H_N": R_NF @ obs[OBS_MOMENTUM : OBS_MOMENTUM + 3],
        "R_NB": R_NF @ np.array(rot_zyx(q[3], q[4], q[5])),
        "omega_B": omega,
        "a_hub_N": R_NF @ qdd[0:3],
        "joints": q[6:n],
        "joint_acc": qdd[6:n],
        "energy_accumulators": x[2 * n :],
    }


@pytest.mark.parametrize("pitch_deg", [61.0, 75.0, 89.99, -80.0])
def test_rebase_moves_the_coordinates_not_the_motion(nominal_plant, pitch_deg):
    x = _state(nominal_plant, np.radians(pitch_deg))
    frame = np.array(rot_zyx(0.3, -0.2, 1.1)).ravel()  # a run that has switched before
    before = _physics(nominal_plant, x, frame)
    assert rebase(x, nominal_plant.n_dof, frame)
    assert np.all(x[3:6] == 0.0)
    after = _physics(nominal_plant, x, frame)
    for name, value in before.items():
        np.testing.assert_allclose(after[name], value, rtol=RTOL, atol=RTOL * np.abs(value).max(),
                                   err_msg=name)  # fmt: skip
    np.testing.assert_allclose(frame.reshape(3, 3) @ frame.reshape(3, 3).T, np.eye(3), atol=1e-15)


def test_no_rebase_inside_the_band(nominal_plant):
    # |pitch| <= SWITCH_PITCH: the state and the frame are left bit-for-bit.
    pitch = -SWITCH_PITCH
    x = _state(nominal_plant, pitch)
    frame = identity_frame()
    kept = x.copy()
    assert not rebase(x, nominal_plant.n_dof, frame)
    np.testing.assert_array_equal(x, kept)
    np.testing.assert_array_equal(frame, identity_frame())


def test_the_inertial_view_undoes_a_rebase(nominal_plant):
    # The view of a re-based state is the state before the re-base (frame N).
    n = nominal_plant.n_dof
    x = _state(nominal_plant, np.radians(70.0))
    original = x.copy()
    frame = identity_frame()
    assert rebase(x, n, frame)
    view = np.empty_like(x)
    inertial_view(x, n, frame, view)
    np.testing.assert_allclose(view, original, rtol=RTOL, atol=RTOL)
    # and the record conversion agrees with the compiled view
    omega = np.array(euler_rate_matrix(x[3], x[4])) @ x[n + 3 : n + 6]
    q_N, qd_N = inertial_records(x[None, :n], x[None, n : 2 * n], omega[None], frame[None])
    np.testing.assert_allclose(q_N[0], original[:n], rtol=RTOL, atol=RTOL)
    np.testing.assert_allclose(qd_N[0], original[n : 2 * n], rtol=RTOL, atol=RTOL)


def test_records_in_the_identity_frame_are_copied_bit_for_bit(nominal_plant):
    n = nominal_plant.n_dof
    x = _state(nominal_plant, 0.4)
    q, qd = x[None, :n], x[None, n : 2 * n]
    q_N, qd_N = inertial_records(q, qd, np.zeros((1, 3)), identity_frame()[None])
    np.testing.assert_array_equal(q_N, q)
    np.testing.assert_array_equal(qd_N, qd)


@pytest.mark.parametrize("angles", [(0.3, -1.2, 2.5), (-2.9, 0.7, -0.4), (1.0, np.pi / 2, 0.5)])
def test_euler_zyx_inverts_rot_zyx(angles):
    # Away from pitch +-90 deg the angles come back; at it, the rotation does.
    R = rot_zyx(*angles)
    back = euler_zyx(R)
    np.testing.assert_allclose(np.array(rot_zyx(*back)), np.array(R), atol=1e-15)
    if abs(np.cos(angles[1])) > 1e-6:
        np.testing.assert_allclose(back, angles, atol=1e-14)
