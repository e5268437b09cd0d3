"""The chain recursion's hinge step against its general step (docs/model.md, 'Chain appendages').

A joint that frees one rotation takes a specialized step in pass 1 and pass 2 (scalar
D, elementary rotations); every other joint the general one. The reference is the
same packed chain with every joint marked general (slot ``G_KIND``): the general step
handles a hinge as a 6 x 1 motion subspace, so both must give the same joint
accelerations and the same wrench and articulated inertia on the hub, up to the
round-off of their differently ordered arithmetic. Chains are random (masses,
inertias, geometry, hinge axes, states), drawn from a fixed, printed seed.
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from flexsat.config import validate_config
from flexsat.dynamics.appendages.chain import ChainModel
from flexsat.dynamics.appendages.chain_config import ChainConfig
from flexsat.dynamics.appendages.chain_kernels import (
    G_KIND,
    G_NF,
    H_N,
    HEADER,
    JOINT_GENERAL,
    JOINT_HINGE_X,
    SEG,
    WSEG,
    pass1,
    pass2,
)
from flexsat.dynamics.appendages.contract import (
    HUB_ACC,
    HUB_ALPHA,
    HUB_DISSIPATION,
    HUB_FORCE,
    HUB_INERTIA,
    HUB_OMEGA,
    HUB_SIZE,
    HUB_TORQUE,
)
from flexsat.dynamics.plant import Plant

SEED = 20261207
# Relative to the largest entry of each compared quantity. Both steps evaluate the same
# formulas in float64 in a different order (elementary rotations instead of 3 x 3
# products, a scalar 1 / D instead of a Gauss-Jordan inverse), so they differ by
# round-off amplified by the chain's conditioning. Measured (printed): at most 1.3e-13
# on the hinge chains N = 1 ... 32, 5.0e-13 on the mixed chain of N = 32, whose q_ddot
# the general step alone moves by 4e-13 when q changes by 1e-16 relative (the same
# order: conditioning, not an error of either step). 1e-12 is the acceptance bound.
RTOL = 1e-12
HINGES = (("rx",), ("ry",), ("rz",))
MIXED = (("x", "y", "z", "rx", "ry", "rz"), ("ry",), ("rx", "rz"), ("rz",), ("y",),
         ("rx",), ("x", "ry"), ("ry",), ("rx", "ry", "rz"), ("rz",))  # fmt: skip


def setup_module() -> None:
    print(f"test_chain_hinge: random seed {SEED}")


def _segment(rng: np.random.Generator, dofs: tuple[str, ...]) -> dict:
    """A random rigid segment (a box with its centre of mass off the span line)."""
    return {
        "mass_kg": float(rng.uniform(0.5, 5.0)),
        "box_m": rng.uniform(0.05, 1.0, 3).tolist(),
        "com_m": (np.array([0.0, 0.4, 0.0]) + rng.uniform(-0.1, 0.1, 3)).tolist(),
        "next_joint_m": (np.array([0.0, 0.8, 0.0]) + rng.uniform(-0.2, 0.2, 3)).tolist(),
        "joint": {"dofs": list(dofs),
                  "stiffness": {d: float(rng.uniform(10.0, 500.0)) for d in dofs},
                  "damping": {d: float(rng.uniform(0.0, 3.0)) for d in dofs}},
    }  # fmt: skip


def _chain(rng: np.random.Generator, joints: list[tuple[str, ...]]) -> dict:
    return {
        "name": "arm", "model": "chain", "mount_point_m": rng.uniform(-1.0, 1.0, 3).tolist(),
        "mount_matrix": Rotation.random(random_state=rng).as_matrix().tolist(),
        "segment_list": [_segment(rng, dofs) for dofs in joints],
    }  # fmt: skip


def _general(row: np.ndarray) -> np.ndarray:
    """The packed row with every joint marked general (the reference step)."""
    out = row.copy()
    for k in range(int(row[H_N])):
        out[HEADER + SEG * k + G_KIND] = JOINT_GENERAL
    return out


def _passes(row: np.ndarray, state: tuple[np.ndarray, ...]) -> tuple[np.ndarray, np.ndarray]:
    """pass 1 and pass 2 of one chain on its own coordinates (offset 6 after a hub's)."""
    q, qd, Q, hub_motion = state
    members = np.array([[0, 6]], dtype=np.int64)
    work = np.zeros((1, WSEG * int(row[H_N])))
    hub, qdd = np.zeros(HUB_SIZE), np.zeros(q.size)
    hub[HUB_OMEGA : HUB_OMEGA + 3] = hub_motion[0]
    assert pass1(q, qd, Q, members, row[None, :], work, hub, qdd) == 0
    hub[HUB_ALPHA : HUB_ALPHA + 3] = hub_motion[1]
    hub[HUB_ACC : HUB_ACC + 3] = hub_motion[2]
    assert pass2(q, qd, members, row[None, :], work, hub, qdd) == 0
    return qdd[6:], hub


def _random_state(rng: np.random.Generator, n: int) -> tuple[np.ndarray, ...]:
    q = np.concatenate([np.zeros(6), rng.uniform(-1.2, 1.2, n)])  # angles [rad], offsets [m]
    qd = np.concatenate([np.zeros(6), rng.uniform(-2.0, 2.0, n)])
    Q = np.concatenate([np.zeros(6), rng.uniform(-5.0, 5.0, n)])
    return q, qd, Q, rng.uniform(-0.5, 0.5, (3, 3))


def _relative(a: np.ndarray, b: np.ndarray) -> float:
    return float(np.max(np.abs(a - b)) / np.max(np.abs(b)))


def _compare(row: np.ndarray, rng: np.random.Generator, states: int = 3) -> float:
    """Largest relative difference hinge step - general step over random states."""
    n = int(sum(row[HEADER + SEG * k + G_NF] for k in range(int(row[H_N]))))
    worst = 0.0
    for _ in range(states):
        state = _random_state(rng, n)
        qdd, hub = _passes(row, state)
        qdd_ref, hub_ref = _passes(_general(row), state)
        for sl in (slice(HUB_FORCE, HUB_TORQUE + 3), slice(HUB_INERTIA, HUB_INERTIA + 36)):
            worst = max(worst, _relative(hub[sl], hub_ref[sl]))
        worst = max(worst, _relative(qdd, qdd_ref))
        assert hub[HUB_DISSIPATION] == pytest.approx(hub_ref[HUB_DISSIPATION], rel=RTOL)
    return worst


def test_each_single_rotation_joint_is_packed_as_a_hinge_about_its_axis():
    rng = np.random.default_rng(SEED)
    joints = [("rx",), ("ry",), ("rz",), ("x",), ("rx", "ry"), ("y", "rz"), MIXED[0]]
    row = ChainModel().pack(ChainConfig.model_validate(_chain(rng, joints)))
    kinds = [int(row[HEADER + SEG * k + G_KIND]) for k in range(len(joints))]
    assert kinds == [JOINT_HINGE_X, JOINT_HINGE_X + 1, JOINT_HINGE_X + 2] + [JOINT_GENERAL] * 4


@pytest.mark.parametrize("n", range(1, 33))
def test_hinge_step_equals_the_general_step_on_hinge_chains(n):
    rng = np.random.default_rng([SEED, n])
    joints = [HINGES[i] for i in rng.integers(0, 3, n)]
    row = ChainModel().pack(ChainConfig.model_validate(_chain(rng, joints)))
    worst = _compare(row, rng)
    print(f"N = {n}: hinge - general, largest relative difference {worst:.2e}")
    assert worst <= RTOL


@pytest.mark.parametrize("n", (1, 2, 3, 5, 10, 17, 32))
def test_hinge_step_equals_the_general_step_on_mixed_chains(n):
    rng = np.random.default_rng([SEED, 100 + n])
    joints = [MIXED[i] for i in rng.integers(0, len(MIXED), n)]
    row = ChainModel().pack(ChainConfig.model_validate(_chain(rng, joints)))
    worst = _compare(row, rng)
    print(f"mixed N = {n} {joints}: largest relative difference {worst:.2e}")
    assert worst <= RTOL


def test_whole_plant_accelerations_and_root_wrench_equal_the_general_steps():
    """Through the plant (hub coupling, two chains in one group): q_ddot and tau_flex."""
    rng = np.random.default_rng([SEED, 999])
    arm_1 = _chain(rng, [MIXED[i] for i in (0, 1, 3, 5, 1, 2)])
    arm_2 = {**_chain(rng, [HINGES[i] for i in rng.integers(0, 3, 8)]), "name": "arm_2"}
    plant = Plant.from_config(validate_config({
        "name": "mixed-chains",
        "hub": {"mass_kg": 300.0, "inertia_kg_m2": [[200.0, 3.0, -1.0], [3.0, 180.0, 2.0],
                                                    [-1.0, 2.0, 150.0]]},
        "appendages": [arm_1, arm_2],
    }))  # fmt: skip
    general = plant._with_params(tuple(_general(row) for row in plant.params))
    for _ in range(3):
        q = rng.uniform(-0.8, 0.8, plant.n_dof)
        qd = rng.uniform(-1.0, 1.0, plant.n_dof)
        Q = rng.uniform(-3.0, 3.0, plant.n_dof)
        a, a_ref = plant.accelerations(q, qd, Q), general.accelerations(q, qd, Q)
        assert _relative(a, a_ref) <= RTOL
        for part, ref in zip(plant.joint_wrench_on_hub(q, qd, Q),
                             general.joint_wrench_on_hub(q, qd, Q), strict=True):  # fmt: skip
            assert _relative(part, ref) <= RTOL
