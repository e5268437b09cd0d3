"""The thesis plate as a one-segment chain on a full 6-DOF joint gives the plate's results.

The chain's articulated-body recursion and the plate's Newton-Euler pass are two
formulations of the same mechanics (docs/model.md, 'Chain appendages'): at any
state they agree to round-off, and the thesis's open-loop run and slew reproduce the
histories stored before the chain existed (tests/data/reference_*.npz).
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from flexsat.dynamics.plant import Plant
from flexsat.simulate import run_openloop
from flexsat.simulate.closedloop import run_slew
from tests.dynamics.chain_satellites import thesis_chain_config
from tests.simulate.test_reference_histories import DATA, RTOL, _largest_difference

# Round-off: both sides evaluate O(100) flops per term in a different order, each
# rounding at 1.1e-16; 1e-13 relative to the term's largest entry is ~500 ulp.
STATE_RTOL = 1e-13


@pytest.fixture(scope="module")
def chain_plant() -> Plant:
    return Plant.from_config(thesis_chain_config())


def _rel(a: np.ndarray, b: np.ndarray) -> float:
    return float(np.max(np.abs(a - b)) / np.max(np.abs(b)))


def test_tuned_joints_equal_the_plates(nominal_plant, chain_plant):
    # Same diag M(0) entries, same eqs. 2.14-2.15: identical up to round-off.
    np.testing.assert_allclose(chain_plant.stiffness, nominal_plant.stiffness, rtol=1e-14)
    np.testing.assert_allclose(chain_plant.damping, nominal_plant.damping, rtol=1e-14)
    assert chain_plant.dof_names()[6:12] == [
        f"panel_1.eta_{d}_0" for d in ("x", "y", "z", "rx", "ry", "rz")
    ]


def test_terms_agree_with_the_plate_at_random_states(nominal_plant, chain_plant):
    rng = np.random.default_rng(20261201)
    for _ in range(20):
        q = 0.3 * rng.standard_normal(nominal_plant.n_dof)
        qd = 0.3 * rng.standard_normal(nominal_plant.n_dof)
        Q = rng.standard_normal(nominal_plant.n_dof)
        pairs = [
            (chain_plant.mass_matrix(q), nominal_plant.mass_matrix(q)),
            (chain_plant.bias_forces(q, qd), nominal_plant.bias_forces(q, qd)),
            (chain_plant.accelerations(q, qd, Q), nominal_plant.accelerations(q, qd, Q)),
            (chain_plant.angular_momentum(q, qd), nominal_plant.angular_momentum(q, qd)),
            (chain_plant.locked_inertia(q), nominal_plant.locked_inertia(q)),
            (np.concatenate(chain_plant.joint_wrench_on_hub(q, qd, Q)),
             np.concatenate(nominal_plant.joint_wrench_on_hub(q, qd, Q))),
            (chain_plant.tip_displacement(q), nominal_plant.tip_displacement(q)),
        ]  # fmt: skip
        for new, ref in pairs:
            assert _rel(new, ref) <= STATE_RTOL
        assert chain_plant.kinetic_energy(q, qd) == pytest.approx(
            nominal_plant.kinetic_energy(q, qd), rel=STATE_RTOL
        )
        assert chain_plant.elastic_energy(q) == pytest.approx(
            nominal_plant.elastic_energy(q), rel=STATE_RTOL
        )


@pytest.mark.parametrize(("kind", "run"), [("openloop", run_openloop), ("slew", run_slew)])
def test_thesis_runs_as_chains_reproduce_stored_histories(chain_plant, kind, run):
    # Same tolerance and argument as tests/simulate/test_reference_histories.py (measured:
    # 2.1e-15 open loop, 4.0e-14 slew).
    stored = np.load(DATA / f"reference_{kind}.npz")
    differences = _largest_difference(stored, run(chain_plant).dataset)
    worst = max(differences, key=differences.get)
    print(f"{kind} as chains: largest relative difference {differences[worst]:.3e} ({worst})")
    assert differences[worst] <= RTOL, differences


def test_a_chain_next_to_a_thesis_plate_is_the_thesis_satellite(nominal_plant):
    # panel_1 a plate, panel_2 a one-segment chain: two models, two groups, one hub.
    from flexsat.config import validate_config
    from tests.conftest import nominal_dict
    from tests.dynamics.chain_satellites import plate_as_chain

    data = nominal_dict()
    data["appendages"][1] = plate_as_chain(data["appendages"][1])
    mixed = Plant.from_config(validate_config(data))
    assert [m.name for m in mixed.models] == ["plate", "chain"]
    rng = np.random.default_rng(3)
    for _ in range(5):
        q, qd, Q = (0.3 * rng.standard_normal(mixed.n_dof) for _ in range(3))
        qdd = mixed.accelerations(q, qd, Q)
        assert _rel(qdd, nominal_plant.accelerations(q, qd, Q)) <= STATE_RTOL
        assert _rel(mixed.mass_matrix(q), nominal_plant.mass_matrix(q)) <= STATE_RTOL


def test_two_unlike_chains_in_one_group_satisfy_the_equations_of_motion():
    # Chains of 3 and 5 segments with unlike joints share one group (rows zero-padded,
    # scratch sized by the longer): q_ddot from the recursion must satisfy
    # M q_ddot + h + C qd + K q = Q with M and h from the other two algorithms.
    from flexsat.config import validate_config
    from tests.dynamics.chain_satellites import cantilever_chain

    SIX = ["x", "y", "z", "rx", "ry", "rz"]
    data = cantilever_chain(3, dofs=("rx", "rz"))
    other = dict(data["appendages"][0], name="other", segments=5, mount_point_m=[0.2, -0.5, 0.1],
                 mount_matrix=Rotation.from_euler("ZYX", [30.0, 10.0, -20.0], degrees=True
                                                  ).as_matrix().tolist(),
                 span_direction="-y", tip_mass_kg=0.3,
                 width_m=0.3, thickness_m=0.02, beam=None,
                 joint={"dofs": ["y", "rx", "ry"], "damping_ratio": 0.01,
                        "stiffness": {"y": 1e4, "rx": 300.0, "ry": 200.0}},
                 root_joint={"dofs": SIX, "stiffness": dict.fromkeys(SIX, 500.0)})  # fmt: skip
    data["appendages"].append(other)
    plant = Plant.from_config(validate_config(data))
    assert len(plant.packed.members) == 1 and plant.packed.params[0].shape[0] == 2
    rng = np.random.default_rng(11)
    for _ in range(10):
        q, qd, Q = (0.3 * rng.standard_normal(plant.n_dof) for _ in range(3))
        qdd = plant.accelerations(q, qd, Q)
        lhs = (plant.mass_matrix(q) @ qdd + plant.bias_forces(q, qd)
               + plant.damping_forces(qd) + plant.elastic_forces(q))  # fmt: skip
        # Residual relative to the largest term of the balance (|M| |q_ddot| included:
        # the thin bar's light DOFs accelerate fast): round-off of three algorithms on
        # sums of O(10^2) terms.
        M = plant.mass_matrix(q)
        scale = max(np.max(np.abs(M) @ np.abs(qdd)), np.max(np.abs(Q)),
                    np.max(np.abs(plant.elastic_forces(q))))  # fmt: skip
        assert np.max(np.abs(lhs - Q)) / scale <= 1e-12
