"""The interface load tau_flex of every appendage model, on the thesis slew.

tau_flex is the whole wrench the appendages exert on the hub, its torque about the
hub's centre of mass (docs/model.md, 'Conventions'): for the plate, the chain (its
root joint's constraint reactions included, eq. C.9) and the modal appendage (its
residual mass's inertia included, eq. M.7). Two checks on the thesis's 45/45/45 deg
ASMC slew (the first seconds), for a satellite of each model:

(a) the wrench of the models' ``joint_wrench`` kernels (``Plant.joint_wrench_on_hub``)
    against the appendages' share of the hub rows of M(q) q_ddot + h(q, q_dot) (their
    generalized inertia forces on the hub's coordinates, assembled from the bodies'
    Jacobians: another route through other kernels), moved to a wrench by virtual
    work, Q_r = f_N and Q_Theta = S(Theta)^T tau_B;
(b) the recorded tau_flex against the hub's own Euler equation about its centre of
    mass, J_hub omega_dot + omega x J_hub omega - tau_applied (the hub translates; its
    Euler equation about its own centre of mass holds whatever its translation).
"""

from __future__ import annotations

import functools

import numpy as np
import pytest

from flexsat.compiled.linalg3 import euler_rate_bias, euler_rate_matrix, rot_zyx
from flexsat.config import load_config, nominal
from flexsat.config.load import preset_path
from flexsat.dynamics.appendages import modal as modal_kernels
from flexsat.dynamics.plant import Plant
from flexsat.linear.export import modal_satellite
from flexsat.simulate.closedloop import run_slew
from flexsat.simulate.scenario import SlewScenario

# The thesis slew (default scenario: 45/45/45 deg, ASMC, disturbances at maximum),
# reduced to its first 2 s, where the interface loads reach their peak (measured
# 2.5 N m for each model).
DURATION_S = 2.0
# Every 10th record (10 ms apart) for check (a), which assembles M(q) and h(q, q_dot).
STRIDE = 10
# Both sides of each check are one state's q_ddot summed two ways, so they differ by
# round-off: measured at most 1.7e-15 of the load's scale (below). 1e-12 leaves three
# orders for other summation orders and CPUs, and is ten orders below what a missing
# term costs (the modal appendage's former, mode-displacement load: 6.8e-2).
RTOL = 1e-12


def _plate() -> Plant:
    return Plant.from_config(nominal())


def _chain() -> Plant:
    # Two 8-segment chains whose joints free rx, ry, rz and lock x, y, z: the root's
    # translations carry the chain's load as constraint reactions.
    return Plant.from_config(load_config(preset_path("chain")))


def _modal() -> Plant:
    # The thesis plates exported with 3 of their 6 clamped modes: the kept modes
    # carry part of the mass beyond the interface, the residual mass the rest.
    return Plant.from_config(modal_satellite(_plate(), n_modes=3))


PLANTS = {"plate": _plate, "chain": _chain, "modal": _modal}


@functools.cache
def _slew(name: str):
    plant = PLANTS[name]()
    scenario = SlewScenario.model_validate({"duration_s": DURATION_S})
    return name, plant, run_slew(plant, scenario, progress=False).dataset


@pytest.fixture(params=list(PLANTS))
def slew(request):
    return _slew(request.param)


def _hub_kinematics(q, qd, qdd):
    """omega_B, omega_dot_B [rad/s, rad/s^2] and R_NB of the hub at one state."""
    S = np.array(euler_rate_matrix(q[3], q[4]))
    omega = S @ qd[3:6]
    alpha = S @ qdd[3:6] + np.array(euler_rate_bias(q[3], q[4], qd[3], qd[4], qd[5]))
    return S, omega, alpha, np.array(rot_zyx(q[3], q[4], q[5]))


def test_tau_flex_is_the_hubs_euler_equation(slew):
    # (b) at every record: J_hub omega_dot + omega x J_hub omega - tau_applied.
    name, plant, ds = slew
    J = plant.hub_J
    w, w_dot = ds["omega"].values, ds["omega_dot"].values
    euler = w_dot @ J.T + np.cross(w, w @ J.T) - ds["tau_applied"].values
    peak = np.abs(euler).max()
    assert peak > 0.5  # [N m]: the slew's interface load, not a vanishing signal
    error = np.abs(ds["tau_flex"].values - euler).max() / peak
    print(f"{name}: (b) max |tau_flex - hub Euler| = {error:.1e} of {peak:.2f} N m")
    assert error <= RTOL


def test_joint_wrench_is_the_appendages_inertia_forces(slew):
    # (a) at every 10th record: the kernels' wrench [f_B; tau_B] against
    # -(appendages' share of the hub rows of M q_ddot + h), the bare hub's share being
    # m_hub r_ddot_N and S^T (J_hub alpha + omega x J_hub omega). The load's scale is
    # the larger of the peak force [N] and torque [N m] (lever arms of order 1 m): the
    # symmetric satellites' net force vanishes by symmetry (to 1e-12 N), so it sets no
    # scale of its own.
    name, plant, ds = slew
    J, m_hub = plant.hub_J, plant.hub_mass
    got, expected = [], []
    for k in range(0, ds.sizes["time"], STRIDE):
        q, qd = ds["q"].values[k], ds["qd"].values[k]
        Q = plant.generalized_forces(q, ds["tau_applied"].values[k])
        qdd = plant.accelerations(q, qd, Q)
        S, omega, alpha, R_NB = _hub_kinematics(q, qd, qdd)
        hub_rows = plant.mass_matrix(q)[:6] @ qdd + plant.bias_forces(q, qd)[:6]
        appendages = hub_rows - np.concatenate(
            [m_hub * qdd[0:3], S.T @ (J @ alpha + np.cross(omega, J @ omega))]
        )
        expected.append(np.concatenate(
            [-R_NB.T @ appendages[0:3], -np.linalg.solve(S.T, appendages[3:6])]
        ))  # fmt: skip
        got.append(np.concatenate(plant.joint_wrench_on_hub(q, qd, Q)))
    got, expected = np.array(got), np.array(expected)
    scale = np.abs(expected).max()
    assert scale > 0.5
    error = np.abs(got - expected).max() / scale
    print(f"{name}: (a) max |joint wrench - M q_ddot + h| = {error:.1e} of {scale:.2f}")
    assert error <= RTOL


def test_the_mode_displacement_load_misses_the_residual_mass():
    # The modes' elastic and damping load at the modal appendage's interface,
    # interface, sum_k l_k (omega_k^2 eta_k + 2 zeta_k omega_k eta_dot_k) moved to the
    # hub centre of mass, leaves out the inertia of the residual mass (M_rr - L^T L)
    # and of the interface's rigid motion: on the slew it misses a good part of the
    # whole load (measured 6.8e-2 of its peak with 3 of 6 modes kept).
    _, plant, ds = _slew("modal")
    q, qd = ds["q"].values, ds["qd"].values
    elastic = np.zeros((q.shape[0], 3))
    offset = 6
    for p in plant.params:
        n = int(p[modal_kernels.P_N])
        F, N = np.zeros((q.shape[0], 3)), np.zeros((q.shape[0], 3))
        for k in range(n):
            b = modal_kernels.P_MODES + modal_kernels.MODE_SIZE * k
            e = (
                p[b + modal_kernels.MODE_K] * q[:, offset + k]
                + p[b + modal_kernels.MODE_C] * qd[:, offset + k]
            )
            F += np.outer(e, p[b + modal_kernels.MODE_LT : b + modal_kernels.MODE_LT + 3])
            N += np.outer(e, p[b + modal_kernels.MODE_LR : b + modal_kernels.MODE_LR + 3])
        r = p[modal_kernels.P_MOUNT : modal_kernels.P_MOUNT + 3]
        elastic += N + np.cross(r, F)
        offset += n
    whole = ds["tau_flex"].values
    share = np.abs(whole - elastic).max() / np.abs(whole).max()
    print(f"mode-displacement load alone: off by {share:.1e} of the peak")
    assert share > 1e-2
