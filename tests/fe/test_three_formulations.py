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


def _hub_row_in_root_loads(omega: float) -> float:
    """det of (M.12) with the hub row in the beams' root loads, J omega^2 Theta +
    2 EI beta^2 ((a - c) - R beta (b - d)) = 0 (docs/model.md, 'Hub and beam: the
    analytic reference'), scaled by 1 / cosh^2 (beta L)."""
    beta = (RHO_A * omega**2 / EI_Z) ** 0.25
    x, k = beta * L, 2.0 * EI_Z * beta**2
    A = np.array([
        [1.0, 0.0, 1.0, 0.0, -ROOT],
        [0.0, beta, 0.0, beta, -1.0],
        [np.cosh(x), np.sinh(x), -np.cos(x), -np.sin(x), 0.0],
        [np.sinh(x), np.cosh(x), np.sin(x), -np.cos(x), 0.0],
        [k, -k * ROOT * beta, -k, k * ROOT * beta, HUB_J * omega**2],
    ])  # fmt: skip
    return float(np.linalg.det(A) / np.cosh(x) ** 2)


def test_both_forms_of_the_hub_equation_have_the_same_roots(analytic):
    # The reference solves (M.12) with the hub row in angular momentum (a quadrature);
    # the root-load form is its integration by parts, closed form. Brent's method on
    # the second, bracketed 1 % around each root of the first, finds them within 1e-12
    # relative (both converged to 1e-14; the quadrature is exact to round-off).
    from scipy.optimize import brentq

    for f in analytic:
        w = 2.0 * np.pi * f
        root = brentq(_hub_row_in_root_loads, 0.99 * w, 1.01 * w, xtol=1e-14, rtol=1e-14)
        assert root / w == pytest.approx(1.0, abs=1e-12)


def test_three_formulations_agree_on_the_first_three_frequencies(analytic):
    # The chain's error is O(1/N^2) (the test above): Richardson's (4 f_64 - f_32) / 3
    # removes it, leaving the O(1/N^4) term (measured -1.6e-6, -8.4e-6, -2.1e-5 from the
    # analytic ones; from N = 16 and 32, -1.0e-6, -1.2e-5, -3.2e-5). The Craig-Bampton
    # beam (32 elements, 16 modes) is within 3.2e-6. Required: each pair within 1e-4.
    f32, f64 = (coupled_yaw_frequencies(chain_satellite(n), 3) for n in (32, 64))
    formulations = {
        "chain (Richardson, N = 32, 64)": (4.0 * f64 - f32) / 3.0,
        "Craig-Bampton (32 elements, 16 modes)": coupled_yaw_frequencies(_satellite(32, 16), 3),
        "analytic (M.12)": analytic,
    }
    for name, f in formulations.items():
        print(f"{name}: {np.array2string(f, precision=6)} Hz")
    for (a, fa), (b, fb) in itertools.combinations(formulations.items(), 2):
        assert np.all(np.abs(fa / fb - 1.0) <= 1e-4), (a, b)
