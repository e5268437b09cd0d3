"""A spinning cantilever: centrifugal stiffening from the beam's large-motion invariants.

A uniform Euler–Bernoulli cantilever, radial on a hub spinning at Omega about Z_B
(flap: bending out of the plane of rotation; in-plane: in it, seen in the rotating
frame). The reference is the rotating-beam equation solved independently of the
finite elements: Galerkin on 12 analytic clamped-free modes, the centrifugal tension
N(s) = rho A Omega^2 (R (L - s) + (L^2 - s^2) / 2)
(:func:`flexsat.fe.beam.rotating_cantilever_frequencies`), which
reproduces the published table of Wright et al. (1982). Two formulations are held to
it: the scikit-fem beam reduced by Craig–Bampton with its large-motion invariants
(:func:`flexsat.fe.beam.beam_invariants`) in the modal appendage, and the chain of
rigid segments. Frequencies about the steady spin come from the plant linearized
about it (:func:`flexsat.linear.linearize`).
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy.linalg import eigh

from flexsat import Plant
from flexsat.config import validate_config
from flexsat.fe import craig_bampton, uniform_beam
from flexsat.fe.beam import rotating_cantilever_frequencies as rotating_cantilever
from flexsat.linear import linearize
from tests.dynamics.chain_satellites import cantilever_chain

pytest.importorskip("skfem")

L, MASS = 2.0, 4.0  # [m], [kg]: the cantilever of tests/dynamics/chain_satellites.py
EI_FLAP, EI_IN_PLANE = 500.0, 2000.0  # [N m^2]: unlike, so that the two modes stay apart
HUB_SCALE = 1e5  # a hub 1e5 times the default: the spin is held to ~1e-7 (as a prescribed spin)


def _scale(ei: float) -> float:
    """sqrt(EI / (rho A L^4)) [rad/s]."""
    return float(np.sqrt(ei / (MASS / L * L**4)))


def _modal_plant(offset_ratio: float = 0.0, large_motion: bool = True, n_modes: int = 10):
    beam = uniform_beam(L, 16, mass_per_length_kg_m=MASS / L,
                        bending_stiffness_x_n_m2=EI_FLAP, bending_stiffness_z_n_m2=EI_IN_PLANE,
                        axial_stiffness_n=1e8, torsional_stiffness_n_m2=400.0,
                        polar_inertia_per_length_kg_m=1e-4)  # fmt: skip
    data = craig_bampton(beam.M, beam.K, beam.interface_dofs, n_modes,
                         interface_map=beam.interface_map,
                         large_motion=beam.large_motion if large_motion else None)  # fmt: skip
    h = HUB_SCALE
    return Plant.from_config(validate_config({
        "name": "spinning-beam",
        "hub": {"mass_kg": 100.0 * h,
                "inertia_kg_m2": [[50.0 * h, 0, 0], [0, 50.0 * h, 0], [0, 0, 50.0 * h]]},
        "appendages": [{"name": "beam", "model": "modal",
                        "mount_point_m": [0.0, offset_ratio * L, 0.0],
                        "data": data.model_dump()}],
    }))  # fmt: skip


def _frequency_near(plant: Plant, spin: float, guess: float) -> float:
    """The frequency about the steady spin nearest ``guess`` [rad/s]."""
    rates = np.abs(np.linalg.eigvals(linearize(plant, about=[0.0, 0.0, spin],
                                               outputs=("rate",)).A).imag)  # fmt: skip
    return float(rates[np.argmin(np.abs(rates - guess))])


def test_the_reference_reproduces_the_published_table():
    # Wright et al. (1982), first flapwise frequency at Omega_bar = 0, 1, 2, 3, 4, 10,
    # printed to 4 decimals: within 6e-5 (half a unit of the last printed digit).
    published = {0: 3.5160, 1: 3.6816, 2: 4.1373, 3: 4.7973, 4: 5.5850, 10: 11.2024}
    for spin_bar, value in published.items():
        assert rotating_cantilever(spin_bar)[0] == pytest.approx(value, abs=6e-5)


@pytest.fixture(scope="module")
def modal() -> Plant:
    return _modal_plant()


@pytest.mark.parametrize("ratio", [0.25, 1.0, 2.0])
def test_spinning_modal_beam_stiffens_as_the_rotating_beam(modal, ratio):
    # K = (omega^2 - omega_0^2) / Omega^2 against the reference's at the same spin,
    # within 1 %: flap (Southwell's 1.193 as Omega -> 0, 1.154 at Omega = 2 omega_0,
    # where the mode shape has changed) and in-plane, whose rotating-frame equation is
    # the flap's less rho A Omega^2 w (K = K_flap(Omega_bar_in-plane) - 1, 0.193 -> 0.18).
    # Measured: flap within 1e-4, in-plane within 6e-4 (10 modes, 16 elements).
    for ei, flap in ((EI_FLAP, True), (EI_IN_PLANE, False)):
        unit = _scale(ei)
        omega_0 = 3.516015 * unit
        spin = ratio * 3.516015 * _scale(EI_FLAP)
        expected_bar = rotating_cantilever(spin / unit)[0]
        expected = np.sqrt((expected_bar * unit) ** 2 - (0.0 if flap else spin**2))
        measured = _frequency_near(modal, spin, expected)
        k_expected = (expected**2 - omega_0**2) / spin**2
        k_measured = (measured**2 - omega_0**2) / spin**2
        print(f"{'flap' if flap else 'in-plane'} Omega/omega_0 = {spin / omega_0:.2f}: "
              f"K = {k_measured:.4f} (reference {k_expected:.4f})")  # fmt: skip
        assert k_measured == pytest.approx(k_expected, rel=1e-2)
    if ratio == 0.25:
        assert (measured**2 - omega_0**2) / spin**2 == pytest.approx(0.193, rel=0.05)


def test_without_the_invariants_the_modal_beam_does_not_stiffen():
    # The first-order modal model (no large-motion keys): the flap frequency stays at
    # omega_0 when spinning at omega_0 (K below 1e-3; the stiffening is all in the keys).
    plant = _modal_plant(large_motion=False)
    omega_0 = 3.516015 * _scale(EI_FLAP)
    measured = _frequency_near(plant, omega_0, omega_0)
    assert abs(measured**2 - omega_0**2) / omega_0**2 < 1e-3


@pytest.mark.parametrize("offset_ratio", [0.5, 1.0, 2.0])
def test_root_offset_adds_its_stiffening(offset_ratio):
    # Flap at Omega = omega_0 / 4 with the root at R = offset_ratio L from the spin
    # axis: the tension R (L - s) enters through C_kl . a_I, the interface's
    # centripetal acceleration. K against the reference's within 1 % (measured 2e-4;
    # 7e-5 at R = 2 L, docs/model.md, 'Large motion', the table of K).
    plant = _modal_plant(offset_ratio)
    unit = _scale(EI_FLAP)
    omega_0 = 3.516015 * unit
    spin = 0.25 * omega_0
    expected = rotating_cantilever(spin / unit, offset_ratio)[0] * unit
    measured = _frequency_near(plant, spin, expected)
    k_expected = (expected**2 - omega_0**2) / spin**2
    k_measured = (measured**2 - omega_0**2) / spin**2
    print(f"R/L = {offset_ratio}: K = {k_measured:.4f} (reference {k_expected:.4f})")
    assert k_measured == pytest.approx(k_expected, rel=1e-2)


@pytest.mark.parametrize("ratio", [1.0, 2.0])
def test_spinning_chain_stiffens_as_the_rotating_beam(ratio):
    # The chain (16 segments, flap joints) against the same reference, within 1 %:
    # its discretization error (-0.2 % on omega_0 at N = 16) is the bulk of it
    # (measured 3.2e-3 at Omega = omega_0, 4.5e-3 at 2 omega_0).
    plant = Plant.from_config(validate_config(cantilever_chain(16, dofs=("rx",),
                                                               hub_scale=HUB_SCALE)))  # fmt: skip
    unit = float(np.sqrt(500.0 / (4.0 / 2.0 * 2.0**4)))  # the chain's EI, rho A and L
    flex = plant.layout.flexible
    omega_0 = float(
        np.sqrt(
            eigh(
                plant.stiffness_matrix()[flex, flex],
                plant.mass_matrix()[flex, flex],
                eigvals_only=True,
            )[0]
        )
    )
    spin = ratio * omega_0
    expected = rotating_cantilever(spin / unit)[0] * unit
    measured = _frequency_near(plant, spin, expected * omega_0 / (3.516015 * unit))
    k_expected = (expected**2 - (3.516015 * unit) ** 2) / spin**2
    k_measured = (measured**2 - omega_0**2) / spin**2
    print(f"chain Omega/omega_0 = {ratio}: K = {k_measured:.4f} (reference {k_expected:.4f})")
    assert k_measured == pytest.approx(k_expected, rel=1e-2)
