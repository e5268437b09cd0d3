"""Three formulations of one uniform beam on a hub, one answer.

(1) a chain of N rigid segments on elastic joints (k = EI / l), (2) the scikit-fem beam
reduced by Craig–Bampton to k clamped modes in the modal appendage, (3) the
Euler–Bernoulli frequency equation of a hub with two cantilevers. The coupled yaw
frequencies converge to (3) as N, the elements and k grow (the table in
docs/performance.md, "Modal appendages"), and the open-loop response to a small yaw
torque pulse of (1) and (2) agree in the linear regime.
"""

from __future__ import annotations

import itertools

import numpy as np
import pytest

from flexsat import Plant
from flexsat.config import validate_config
from flexsat.simulate import OpenLoopScenario, run_openloop
from tests.fe.test_craig_bampton import (
    EI_Z,
    HUB_J,
    RHO_A,
    ROOT,
    L,
    _analytic_hub_frequencies,
    _satellite,
    coupled_yaw_frequencies,
)

pytest.importorskip("skfem")


def chain_satellite(segments: int) -> Plant:
    """The same hub with two uniform chains: in-plane bending only (joints free about
    Z_M), a narrow thin strip so that the segments' own section inertia is negligible."""
    wing = {"model": "chain", "span_direction": "+y", "segments": segments, "length_m": L,
            "width_m": 0.01, "thickness_m": 0.001, "mass_kg": RHO_A * L,
            "joint": {"dofs": ["rz"]}, "beam": {"EI_in_plane_N_m2": EI_Z}}  # fmt: skip
    return Plant.from_config(validate_config({
        "hub": {"mass_kg": 100.0, "inertia_kg_m2": [[40.0, 0, 0], [0, 35.0, 0], [0, 0, HUB_J]]},
        "appendages": [
            {**wing, "name": "wing_1", "mount_point_m": [0.0, ROOT, 0.0]},
            {**wing, "name": "wing_2", "mount_point_m": [0.0, -ROOT, 0.0],
             "mount_yaw_deg": 180.0},
        ],
    }))  # fmt: skip


@pytest.fixture(scope="module")
def analytic() -> np.ndarray:
    return _analytic_hub_frequencies(3)


def test_chain_frequencies_converge_to_euler_bernoulli(analytic):
    # Rigid segments on k = EI / l joints: second-order convergence in 1/N (the first yaw
    # frequency's error falls by 4 per doubling: measured 9.7e-3, 2.3e-3, 5.7e-4, 1.4e-4,
    # 3.7e-5 for N = 4 ... 64); with 64 segments the first two coupled yaw frequencies
    # are within 5e-4 of the analytic ones (measured 3.7e-5 and 3.8e-4).
    errors = []
    for n in (8, 16, 32, 64):
        f = coupled_yaw_frequencies(chain_satellite(n), 2)
        errors.append(np.abs(f / analytic[:2] - 1.0))
    assert np.all(errors[-1] <= 5e-4)
    first = [e[0] for e in errors]
    for coarse, fine in itertools.pairwise(first):
        assert coarse / fine == pytest.approx(4.0, rel=0.25)


def test_chain_and_craig_bampton_responses_agree(analytic):
    # A 1e-3 N m yaw torque for 1 s, then free for 9 s: the hub yaw rate of the chain
    # (32 segments) and of the Craig-Bampton beam (32 elements, 16 modes) agree within
    # 1e-2 of its peak (measured 5.3e-3; 1.4e-3 with 64 segments: the chain's
    # discretization error, 1.4e-4 on the first frequency, accumulated as phase over
    # ~3 periods). tau_flex, each model's whole interface load, is not asserted here: it
    # carries the higher modes, where a 32-segment chain and 16 clamped modes differ
    # most (measured 3.3e-2 of its peak); the exact round trip compares it
    # (tests/dynamics/appendages/test_modal.py).
    scenario = OpenLoopScenario.model_validate({
        "duration_s": 10.0, "dt_s": 4e-4, "record_dt_s": 0.01,
        "torque": [{"start_s": 0.0, "end_s": 1.0, "torque_nm": [0.0, 0.0, 1e-3]}],
    })  # fmt: skip
    chain = run_openloop(chain_satellite(32), scenario).dataset
    modal = run_openloop(_satellite(32, 16), scenario).dataset
    w_chain, w_modal = chain["omega"].values[:, 2], modal["omega"].values[:, 2]
    assert np.abs(w_chain - w_modal).max() <= 1e-2 * np.abs(w_modal).max()
