"""The wrench a chain's root joint transmits to the hub (tau_flex), constraint reactions included.

A joint that frees fewer than six DOFs carries the chain's inertial load through its
rigid directions (docs/model.md, 'Chain appendages', eq. C.9). Three independent
checks of ``chain_kernels.joint_wrench``:

1. a hinge chain against the same chain on a full 6-DOF root whose other five DOFs
   the engine locks (its constraint forces lambda come from the projection of q_ddot,
   docs/model.md, 'Locked coordinates');
2. the hub's own Newton-Euler equations: with no applied torque the hub's momentum
   rate is the appendage's wrench;
3. on a full 6-DOF root, the wrench of the joint's generalized forces (the
   free-direction formula the kernel used before the reactions were added).
"""

from __future__ import annotations

from typing import Literal

import numpy as np
import pytest
from pydantic import Field
from scipy.spatial.transform import Rotation

from flexsat.compiled.linalg3 import euler_rate_bias, euler_rate_matrix, rot_zyx
from flexsat.config import nominal, validate_config
from flexsat.dynamics.appendages import ChainModel, register_appendage_model
from flexsat.dynamics.appendages.chain_config import DOF_NAMES, ChainConfig
from flexsat.dynamics.appendages.sadm import with_sadm
from flexsat.dynamics.plant import Plant
from flexsat.simulate import run_openloop
from flexsat.simulate.scenario import OpenLoopScenario

# -- a chain whose coordinates the engine may lock ----------------------------------------


class LockableChainConfig(ChainConfig):
    """A chain with the plate's ``locked_dofs`` (coordinate names): the engine holds them."""

    model: Literal["lockable_chain"] = Field("lockable_chain")
    locked_dofs: list[str] = Field(default_factory=list)


class LockableChain(ChainModel):
    name = "lockable_chain"
    config_class = LockableChainConfig


register_appendage_model(LockableChain())

# -- the satellites -----------------------------------------------------------------------

HINGE = {"dofs": ["ry"], "stiffness": {"ry": 60.0}, "damping": {"ry": 0.3}}
ROOT_6DOF = {
    "dofs": list(DOF_NAMES),
    "stiffness": {"x": 4e4, "y": 5e4, "z": 6e4, "rx": 900.0, "ry": 60.0, "rz": 700.0},
    "damping": {"x": 20.0, "y": 25.0, "z": 30.0, "rx": 2.0, "ry": 0.3, "rz": 1.5},
}
LOCKED = ["eta_x_0", "eta_y_0", "eta_z_0", "eta_rx_0", "eta_rz_0"]  # all but the hinge


def _satellite(segments: int, root: dict, model: str = "chain", locked=None) -> dict:
    """A hub with one chain along its mount x axis; an off-axis, turned mount and a
    non-diagonal hub inertia so that every component of the wrench is exercised."""
    chain = {
        "name": "wing", "model": model, "mount_point_m": [0.6, 0.25, -0.15],
        "mount_matrix": Rotation.from_euler("ZYX", [20.0, 10.0, -5.0], degrees=True).as_matrix(
        ).tolist(), "span_direction": "+x", "segments": segments,
        "length_m": 2.4, "width_m": 0.8, "thickness_m": 0.02, "mass_kg": 14.0,
        "joint": HINGE, "root_joint": {**root, "initial": {"ry": 12.0}},
    }  # fmt: skip
    if locked is not None:
        chain["locked_dofs"] = locked
    return {
        "name": f"hinge-{segments}",
        "hub": {"mass_kg": 180.0,
                "inertia_kg_m2": [[110.0, 4.0, -3.0], [4.0, 80.0, 5.0], [-3.0, 5.0, 130.0]]},
        "appendages": [chain],
    }  # fmt: skip


def _plants(segments: int) -> tuple[Plant, Plant]:
    hinge = Plant.from_config(validate_config(_satellite(segments, HINGE)))
    locked = Plant.from_config(
        validate_config(_satellite(segments, ROOT_6DOF, "lockable_chain", LOCKED))
    )
    return hinge, locked


# Hub tumbling, hinge deflected 12 deg; a torque pulse on top in check 1.
TUMBLE = {"rate_deg_s": [4.0, -6.0, 5.0]}
DURATION_S, DT_S = 2.0, 1e-3


def _run(plant: Plant, torque: list) -> object:
    scenario = OpenLoopScenario.model_validate(
        {"torque": torque, "duration_s": DURATION_S, "dt_s": DT_S, "initial": TUMBLE}
    )
    return run_openloop(plant, scenario).dataset


def _hinge_rows(plant: Plant) -> list[int]:
    """Indices in q of the coordinates the hinge chain has (every eta_ry_k)."""
    return [i for i, name in enumerate(plant.dof_names()) if i < 6 or "eta_ry_" in name]


# -- 1. against the engine's constraint forces ----------------------------------------------


@pytest.mark.parametrize("segments", [1, 4])
def test_hinge_wrench_equals_the_locked_6dof_joint(segments):
    # Same mechanics, two formulations: A's hinge reaction comes from its own
    # Newton-Euler sum, B's from the engine's projection and lambda (records add it).
    # The two runs agree to round-off of the 6 x 6 hub solve vs the projected M_ff solve,
    # grown over 2 000 RK4 steps; measured max |A - B| / max |B| 2.3e-15 (N = 1) and
    # 3.5e-14 (N = 4) for the recorded torque, 1.0e-15 and 2.1e-14 for the force at the
    # recorded states: 1e-9 leaves room for other CPUs' orderings and the growth of
    # round-off over a run, far below the reactions' share (next).
    hinge, locked = _plants(segments)
    torque = [{"start_s": 0.2, "end_s": 0.7, "torque_nm": [0.5, -1.0, 2.0]}]
    a, b = _run(hinge, torque), _run(locked, torque)
    rows = _hinge_rows(locked)
    np.testing.assert_allclose(a["q"].values, b["q"].values[:, rows], rtol=0,
                               atol=1e-9 * np.abs(b["q"].values).max())  # fmt: skip
    tau_a, tau_b = a["tau_flex"].values, b["tau_flex"].values
    peak = np.abs(tau_b).max()
    assert peak > 1.0  # [N m]: the hinge's reaction, not a vanishing signal
    assert np.abs(tau_a - tau_b).max() <= 1e-9 * peak
    # the force part, at every 10th recorded state of each run
    force_a, force_b = [], []
    for k in range(0, a.sizes["time"], 10):
        for plant, ds, out in ((hinge, a, force_a), (locked, b, force_b)):
            q, qd = ds["q"].values[k], ds["qd"].values[k]
            Q = plant.generalized_forces(q, ds["tau_applied"].values[k])
            out.append(plant.joint_wrench_on_hub(q, qd, Q)[0])
    force_a, force_b = np.array(force_a), np.array(force_b)
    force_error = np.abs(force_a - force_b).max() / np.abs(force_b).max()
    print(
        f"N = {segments}: torque {np.abs(tau_a - tau_b).max() / peak:.1e}, "
        f"force {force_error:.1e} of the peak"
    )
    assert force_error <= 1e-9
    # The hinge's own torque -tau_ry R_BM e_y (the free-direction wrench, S_r = e_y)
    # misses the reactions by a good part of the peak (measured 27 % for N = 1).
    tau_ry = -60.0 * a["q"].values[:, 6] - 0.3 * a["qd"].values[:, 6]
    R_BM = ChainModel.mount_rotation(hinge.params[0])
    free_direction = -np.outer(tau_ry, R_BM[:, 1])
    assert np.abs(tau_a - free_direction).max() > 0.1 * peak


# -- 2. the hub's own Newton-Euler equations ----------------------------------------------


@pytest.mark.parametrize("segments", [1, 4])
def test_hub_momentum_rate_is_the_chain_wrench(segments):
    # No applied torque: J_h omega_dot + omega x J_h omega (about the hub centre of mass,
    # from the recorded omega and omega_dot) is tau_flex at every record, and
    # m_h a_hub = the wrench's force at the recorded states. Both sides are one state's
    # q_ddot (6 x 6 hub solve vs the chain's Newton-Euler sum): round-off, 1e-12 of
    # the peak (measured at most 3.6e-15).
    hinge, _ = _plants(segments)
    ds = _run(hinge, [])
    J = hinge.hub_J
    w, w_dot = ds["omega"].values, ds["omega_dot"].values
    euler = w_dot @ J.T + np.cross(w, w @ J.T)
    tau_flex = ds["tau_flex"].values
    assert np.abs(tau_flex - euler).max() <= 1e-12 * np.abs(euler).max()
    for k in range(0, ds.sizes["time"], 50):
        q, qd = ds["q"].values[k], ds["qd"].values[k]
        qdd = hinge.accelerations(q, qd)
        force, torque = hinge.joint_wrench_on_hub(q, qd)
        newton = hinge.hub_mass * np.array(rot_zyx(q[3], q[4], q[5])).T @ qdd[0:3]
        assert np.abs(force - newton).max() <= 1e-12 * np.abs(newton).max()
        S = np.array(euler_rate_matrix(q[3], q[4]))
        omega, alpha = S @ qd[3:6], S @ qdd[3:6] + np.array(euler_rate_bias(*q[3:5], *qd[3:6]))
        expected = J @ alpha + np.cross(omega, J @ omega)
        assert np.abs(torque - expected).max() <= 1e-12 * np.abs(expected).max()


def test_a_drive_torque_and_the_panels_load_react_on_the_hub():
    # The thesis plates on solar-array drives (two-segment chains whose root frees ry
    # alone, k = c = 0): at a deformed, spinning state with a drive torque on each
    # drive and a hub torque, the wrench on the hub is what moves the hub alone: the
    # drive torque's reaction and the panels' load together, not the drive torque
    # alone. Round-off: 1e-12 of the largest term (measured 3.3e-15).
    plant = Plant.from_config(with_sadm(nominal(), 0.1, 2.0))
    rng = np.random.default_rng(5)
    q = 0.1 * rng.standard_normal(plant.n_dof)
    qd = 0.1 * rng.standard_normal(plant.n_dof)
    tau = np.array([0.4, -0.8, 1.1])  # [N m]
    Q = plant.generalized_forces(q, tau)
    drives = [i for i, name in enumerate(plant.dof_names()) if name.endswith(".eta_ry_0")]
    Q[drives] = [0.3, -0.5]  # [N m], motor torques
    qdd = plant.accelerations(q, qd, Q)
    force, torque = plant.joint_wrench_on_hub(q, qd, Q)
    newton = plant.hub_mass * np.array(rot_zyx(q[3], q[4], q[5])).T @ qdd[0:3]
    S = np.array(euler_rate_matrix(q[3], q[4]))
    omega, alpha = S @ qd[3:6], S @ qdd[3:6] + np.array(euler_rate_bias(*q[3:5], *qd[3:6]))
    J = plant.hub_J
    euler = J @ alpha + np.cross(omega, J @ omega) - tau
    scale_ = max(np.abs(newton).max(), np.abs(euler).max())
    print(f"drives: {max(np.abs(force - newton).max(), np.abs(torque - euler).max()) / scale_:.1e}")
    assert np.abs(force - newton).max() <= 1e-12 * scale_
    assert np.abs(torque - euler).max() <= 1e-12 * scale_


# -- 3. a full 6-DOF root: the joint's own generalized forces ---------------------------------


def _free_direction_wrench(plant: Plant, q: np.ndarray, qd: np.ndarray, Q: np.ndarray
                           ) -> np.ndarray:  # fmt: skip
    """The wrench of the 6-DOF root's generalized forces tau = Q - K q - C q_dot on the
    hub: force F_M = tau_t at the root (mount frame), moment N_P = S(rho)^-T tau_r on the
    segment (its frame), the opposite pair on the hub, about its centre of mass, B."""
    params = plant.params[0]
    block = plant.layout.blocks[0].slice
    tau = Q[block] - plant.stiffness[:6] * q[block] - plant.damping[:6] * qd[block]
    R_BM = ChainModel.mount_rotation(params)
    rho = q[block][3:6]
    R_JP = np.array(rot_zyx(*rho))
    S = np.array(euler_rate_matrix(rho[0], rho[1]))
    f_B = R_BM @ tau[:3]
    n_B = R_BM @ R_JP @ np.linalg.solve(S.T, tau[3:])
    r_O = ChainModel.mount_point(params) + R_BM @ q[block][:3]
    return -np.concatenate([f_B, n_B + np.cross(r_O, f_B)])


def test_a_full_6dof_root_keeps_the_free_direction_wrench():
    # Nothing is constrained: the Newton-Euler sum equals the generalized forces' wrench
    # (the joint's equation of motion S^T f_0 = tau with S invertible). Random states
    # and forces; round-off of q_ddot through stiff joint translations, measured 5.1e-15
    # of the largest component: 1e-12.
    plant = Plant.from_config(validate_config(_satellite(1, ROOT_6DOF)))
    rng = np.random.default_rng(20240611)
    worst = 0.0
    for _ in range(20):
        q = 0.2 * rng.standard_normal(plant.n_dof)
        qd = 0.2 * rng.standard_normal(plant.n_dof)
        Q = rng.standard_normal(plant.n_dof)
        got = np.concatenate(plant.joint_wrench_on_hub(q, qd, Q))
        expected = _free_direction_wrench(plant, q, qd, Q)
        worst = max(worst, np.abs(got - expected).max() / np.abs(expected).max())
    assert worst <= 1e-12, worst
