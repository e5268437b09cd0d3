"""The chain as a discretized continuous beam: Euler-Bernoulli cantilever frequencies and
the centrifugal stiffening of a spinning cantilever (docs/model.md, 'Chain appendages').

Clamped root: the cantilever frequencies are those of the joint block alone,
K_ff phi = omega^2 M_ff(0) phi (the hub held fixed, so its rows and columns drop).
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy.linalg import eigh

from flexsat.config import validate_config
from flexsat.dynamics.plant import Plant
from flexsat.linear import linearize
from tests.dynamics.chain_satellites import beam_frequency_hz, cantilever_chain


def clamped_frequencies_hz(plant: Plant, count: int = 3) -> np.ndarray:
    """Lowest clamped-root frequencies of the plant's appendage coordinates [Hz]."""
    flex = plant.layout.flexible
    M = plant.mass_matrix()[flex, flex]
    K = plant.stiffness_matrix()[flex, flex]
    return np.sqrt(eigh(K, M, eigvals_only=True)[:count]) / (2.0 * np.pi)


def _errors(segments: int) -> np.ndarray:
    plant = Plant.from_config(validate_config(cantilever_chain(segments)))
    reference = np.array([beam_frequency_hz(n) for n in (1, 2, 3)])
    return clamped_frequencies_hz(plant) / reference - 1.0


def test_first_bending_mode_within_one_percent_from_eight_segments():
    # Measured: -0.71 % at N = 8 (bench/bench_chain.py prints the table to N = 64).
    errors = _errors(8)
    assert abs(errors[0]) < 0.01
    assert np.all(errors < 0.0)  # a lumped chain is softer than the beam


def test_three_bending_modes_converge_at_second_order():
    # Springs at the joints, root spring 2 EI/l: the error falls as N^-2. Observed order
    # log2(e_N / e_2N) between N = 16 and 32 is 1.99-2.00 for modes 1-3; [1.9, 2.1]
    # leaves room for the next-order term, a first-order scheme (1.0) fails.
    e16, e32 = _errors(16), _errors(32)
    order = np.log2(e16 / e32)
    assert np.all((order > 1.9) & (order < 2.1)), order
    assert np.all(np.abs(e32) < 3e-3)


@pytest.mark.parametrize(("dof", "southwell", "tolerance"), [
    # Flapwise: K = 1.193, the classical Southwell coefficient of a uniform cantilever at
    # zero hub radius (tabulated e.g. by Wright et al. 1982), within 1 %. In-plane: 0.193,
    # within +-0.01 (the in-plane mode loses the Omega^2 of the rotating frame).
    ("rx", 1.193, 0.01 * 1.193),
    ("rz", 0.193, 0.01),
])  # fmt: skip
@pytest.mark.parametrize("ratio", [0.25, 0.5])
def test_southwell_coefficients_of_a_spinning_cantilever(dof, southwell, tolerance, ratio):
    # The root on the spin axis Z_B (zero hub radius), span along Y: flap is the rotation
    # about X, in-plane about Z. A hub 1e5 times heavier than the default keeps the
    # root clamped to the spin to ~1e-7 (the beam's share of the spin inertia).
    # Measured at N = 16: flap 1.1893 (0.25), 1.1865 (0.5); in-plane 0.1893, 0.1865.
    plant = Plant.from_config(validate_config(cantilever_chain(16, dofs=(dof,), hub_scale=1e5)))
    omega_0 = 2.0 * np.pi * clamped_frequencies_hz(plant, 1)[0]
    spin = ratio * omega_0
    model = linearize(plant, about=[0.0, 0.0, spin], outputs=("joint",))
    eigenvalues = np.linalg.eigvals(model.A)
    rates = np.abs(eigenvalues.imag)
    expected = omega_0 * np.sqrt(1.0 + southwell * ratio**2)
    omega = rates[np.argmin(np.abs(rates - expected))]
    measured = (omega**2 - omega_0**2) / spin**2
    print(f"{dof} Omega/omega_0 = {ratio}: K = {measured:.4f}")
    assert abs(measured - southwell) < tolerance
