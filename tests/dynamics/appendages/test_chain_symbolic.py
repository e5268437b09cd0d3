"""The compiled chain against an independent SymPy Lagrangian (two segments, 2-DOF joints).

The reference is written here from first principles, sharing nothing with the engine:
positions and orientations of every body from the hub's ZYX angles and the joint
values (SymPy), their Jacobians by symbolic differentiation (the body rate from
[omega]x = R^T R_dot, not from an Euler-rate matrix), T = sum 1/2 m v.v + 1/2 w.J w =
1/2 qd^T M qd, and h = M_dot qd - dT/dq from Lagrange's equations at q_ddot = 0, the
derivatives of M taken by complex steps (exact to round-off).
"""

from __future__ import annotations

import numpy as np
import pytest
import sympy as sp
from scipy.spatial.transform import Rotation

from flexsat.config import validate_config
from flexsat.dynamics.plant import Plant

J0 = [[0.9, 0.05, -0.02], [0.05, 0.4, 0.03], [-0.02, 0.03, 1.1]]
J1 = [[0.5, -0.04, 0.01], [-0.04, 0.3, 0.02], [0.01, 0.02, 0.7]]
MOUNT_ZYX_DEG = (20.0, -35.0, 10.0)  # R_BM = Rz(a) Ry(b) Rx(c), given to the chain as its matrix
MOUNT_MATRIX = Rotation.from_euler("ZYX", MOUNT_ZYX_DEG, degrees=True).as_matrix()
CONFIG = {
    "name": "two-segment",
    "hub": {"mass_kg": 80.0, "inertia_kg_m2": [[30.0, 1.0, -0.5], [1.0, 25.0, 0.8],
                                               [-0.5, 0.8, 20.0]]},
    "appendages": [{
        "name": "arm", "model": "chain", "mount_point_m": [0.3, 0.7, -0.2],
        "mount_matrix": MOUNT_MATRIX.tolist(),
        "segment_list": [
            {"mass_kg": 3.0, "inertia_kg_m2": J0, "com_m": [0.05, 0.6, 0.02],
             "next_joint_m": [0.0, 1.2, 0.05],
             "joint": {"dofs": ["rx", "rz"], "stiffness": {"rx": 40.0, "rz": 60.0},
                       "damping": {"rx": 0.3, "rz": 0.2}}},
            {"mass_kg": 2.0, "inertia_kg_m2": J1, "com_m": [-0.03, 0.5, 0.01],
             "next_joint_m": [0.0, 1.0, 0.0],
             "joint": {"dofs": ["y", "ry"], "stiffness": {"y": 900.0, "ry": 25.0},
                       "damping": {"y": 1.0, "ry": 0.1}}},
        ],
    }],
}  # fmt: skip
SEGMENTS = CONFIG["appendages"][0]["segment_list"]

# Relative to each term's largest entry: both sides are exact formulas in float64 that
# round differently; 1e-9 is the acceptance bound, far above the observed round-off
# (measured 2.4e-15 over the 50 states).
RTOL = 1e-9


def _rx(a):
    return sp.Matrix([[1, 0, 0], [0, sp.cos(a), -sp.sin(a)], [0, sp.sin(a), sp.cos(a)]])


def _ry(a):
    return sp.Matrix([[sp.cos(a), 0, sp.sin(a)], [0, 1, 0], [-sp.sin(a), 0, sp.cos(a)]])


def _rz(a):
    return sp.Matrix([[sp.cos(a), -sp.sin(a), 0], [sp.sin(a), sp.cos(a), 0], [0, 0, 1]])


def _reference():
    """M(q) of hub + two-segment chain (lambdified, complex-safe) and h(q, qd) from it."""
    q = sp.symbols("q0:10")
    r_N = sp.Matrix(q[0:3])
    R_NB = _rz(q[5]) * _ry(q[4]) * _rx(q[3])
    yaw, pitch, roll = (sp.rad(sp.Float(a)) for a in MOUNT_ZYX_DEG)
    R_BM = _rz(yaw) * _ry(pitch) * _rx(roll)
    mount = sp.Matrix(CONFIG["appendages"][0]["mount_point_m"])
    # Joint 0 frees rx, rz (R = Rz Rx), joint 1 frees y, ry (origin moved along y, R = Ry).
    R_B0 = R_BM * _rz(q[7]) * _rx(q[6])
    o_1 = mount + R_B0 * sp.Matrix(SEGMENTS[0]["next_joint_m"]) + R_B0 * sp.Matrix([0, q[8], 0])
    R_B1 = R_B0 * _ry(q[9])
    bodies = [
        (CONFIG["hub"]["mass_kg"], sp.zeros(3, 1), R_NB, CONFIG["hub"]["inertia_kg_m2"]),
        (SEGMENTS[0]["mass_kg"], mount + R_B0 * sp.Matrix(SEGMENTS[0]["com_m"]), R_NB * R_B0, J0),
        (SEGMENTS[1]["mass_kg"], o_1 + R_B1 * sp.Matrix(SEGMENTS[1]["com_m"]), R_NB * R_B1, J1),
    ]
    jacobians = []
    for _, r_B, R_NP, _ in bodies:
        Jv = (r_N + R_NB * r_B).jacobian(q)  # v = Jv qd
        # omega (body components) per unit rate of q_k: vee(R^T dR/dq_k).
        columns = [R_NP.T * sp.diff(R_NP, qk) for qk in q]
        Jw = sp.Matrix([[W[2, 1] for W in columns], [W[0, 2] for W in columns],
                        [W[1, 0] for W in columns]])  # fmt: skip
        jacobians.append(sp.lambdify(q, (Jv, Jw), cse=True, modules="numpy"))
    masses = [b[0] for b in bodies]
    inertias = [np.array(b[3], dtype=float) for b in bodies]

    def mass_matrix(qv):
        """M = sum m Jv^T Jv + Jw^T J Jw (T = 1/2 qd^T M qd)."""
        M = 0.0
        for jac, m, J in zip(jacobians, masses, inertias, strict=True):
            Jv, Jw = (np.array(a, dtype=complex) for a in jac(*qv))
            M = M + m * Jv.T @ Jv + Jw.T @ J @ Jw
        return M

    def bias(qv, qdv):
        """h = (dM/dt) qd - dT/dq (Lagrange's equations at q_ddot = 0); the derivatives of
        M by complex steps, exact to round-off (no subtraction)."""
        step = 1e-30
        M_dot = mass_matrix(qv + 1j * step * qdv).imag / step
        dT = [0.5 * qdv @ (mass_matrix(qv + 1j * step * e).imag / step) @ qdv
              for e in np.eye(len(qv))]  # fmt: skip
        return M_dot @ qdv - np.array(dT)

    return (lambda qv: mass_matrix(qv).real), bias


@pytest.fixture(scope="module")
def reference():
    return _reference()


@pytest.fixture(scope="module")
def plant():
    return Plant.from_config(validate_config(CONFIG))


def _rel(a, b):
    return float(np.max(np.abs(a - b)) / np.max(np.abs(b)))


def test_chain_matches_the_symbolic_lagrangian_at_random_states(plant, reference):
    M_ref, h_ref = reference
    assert plant.dof_names()[6:] == ["arm.eta_rx_0", "arm.eta_rz_0", "arm.eta_y_1", "arm.eta_ry_1"]
    rng = np.random.default_rng(7)
    worst = 0.0
    for _ in range(50):
        q = rng.uniform(-0.6, 0.6, plant.n_dof)
        q[8] *= 0.2  # the prismatic DOF [m]
        qd = rng.uniform(-0.8, 0.8, plant.n_dof)
        Q = rng.standard_normal(plant.n_dof)
        M = M_ref(q)
        h = h_ref(q, qd)
        rhs = Q - h - plant.elastic_forces(q) - plant.damping_forces(qd)
        errors = (_rel(plant.mass_matrix(q), M), _rel(plant.bias_forces(q, qd), h),
                  _rel(plant.accelerations(q, qd, Q), np.linalg.solve(M, rhs)))  # fmt: skip
        worst = max(worst, *errors)
    print(f"largest relative difference over 50 states: {worst:.2e}")
    assert worst <= RTOL
