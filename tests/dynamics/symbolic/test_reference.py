"""The compiled engine against the SymPy Lagrangian derivation ("two formulations, one truth").

The symbolic model is derived independently (Euler-Lagrange on T, U, D, thesis
eqs. 2.37-2.48); the engine uses Newton-Euler with the articulated solve. Both are
exact, so they agree to round-off at any state, configuration and SADM angle.
"""

from __future__ import annotations

import numpy as np
import pytest

from flexsat.config import SatelliteConfig
from flexsat.dynamics.plant import Plant
from flexsat.dynamics.symbolic import ReferenceParameters, reference_model
from tests.conftest import TOPOLOGIES

# 1e-9 relative (issue acceptance): both routes accumulate ~1e-15 relative
# round-off per operation; 1e-9 leaves room for cancellation in h without
# hiding a wrong term (a missing term is O(1) relative).
RTOL = 1e-9
CASES = ["nominal", "sadm_45", "two_different", "one_panel"]
STATES_PER_CASE = 30  # 4 cases x 30 = 120 random states


def _states(plant: Plant, rng: np.random.Generator):
    q = rng.uniform(-np.pi, np.pi, plant.n_dof)
    q[0:3] = rng.uniform(-5.0, 5.0, 3)
    for o in range(6, plant.n_dof, 6):
        q[o : o + 3] = rng.uniform(-0.05, 0.05, 3)  # root translations [m]
        q[o + 3 : o + 6] = rng.uniform(-0.5, 0.5, 3)  # root rotations [rad]
    q[4] = rng.uniform(-1.2, 1.2)  # hub pitch away from +-90 deg
    qd = rng.normal(scale=0.5, size=plant.n_dof)
    return q, qd


def _close(actual, expected, what):
    scale = max(np.abs(expected).max(), 1e-300)
    np.testing.assert_allclose(actual, expected, rtol=0, atol=RTOL * scale, err_msg=what)


@pytest.mark.parametrize("case", CASES)
def test_engine_matches_symbolic_derivation(case):
    config: SatelliteConfig = TOPOLOGIES[case]()
    plant = Plant.from_config(config)
    params = ReferenceParameters.from_config(
        config, plant.stiffness.reshape(-1, 6), plant.damping.reshape(-1, 6)
    )
    reference = reference_model(plant.n_appendages, "exact")
    rng = np.random.default_rng(20)
    for _ in range(STATES_PER_CASE):
        q, qd = _states(plant, rng)
        ref = reference.evaluate(params, q, qd)
        _close(plant.mass_matrix(q), ref["M"], f"M, {case}")
        _close(plant.bias_forces(q, qd), ref["h"], f"h, {case}")
        _close(plant.elastic_forces(q), ref["k_el"], f"k_el, {case}")
        _close(plant.damping_forces(qd), ref["C"] @ qd, f"C qd, {case}")
        Q = rng.normal(size=plant.n_dof)
        expected = np.linalg.solve(ref["M"], Q - ref["h"] - ref["C"] @ qd - ref["k_el"])
        _close(plant.accelerations(q, qd, Q), expected, f"q_ddot, {case}")
        _close(plant.kinetic_energy(q, qd), reference.kinetic_energy(params, q, qd), "T")
