"""Craig–Bampton reduction of a scikit-fem beam, against Euler–Bernoulli theory.

Two formulations of one uniform beam: the FE beam (Hermite cubics) reduced by
Craig–Bampton to k clamped modes and coupled to a hub by the modal appendage, and the
Euler–Bernoulli analytic solution of a hub carrying two cantilevers (a transcendental
frequency equation solved to 1e-13). The chain of rigid segments is held against the
same theory in ``tests/dynamics/appendages/test_chain_beam.py``.
"""

from __future__ import annotations

import numpy as np
import pytest

from flexsat import ConfigError, Plant
from flexsat.config import validate_config
from flexsat.fe import craig_bampton, euler_bernoulli_hub_frequencies, uniform_beam

pytest.importorskip("skfem")

L = 4.0  # [m] span
RHO_A = 2.0  # [kg/m]
EI_X = 400.0  # [N m^2] about X_M: out-of-plane deflection w_z
EI_Z = 50.0  # [N m^2] about Z_M: in-plane deflection w_x
GJ, RHO_IP = 80.0, 0.05  # [N m^2], [kg m]
EA = 1e6  # [N]
HUB_J = 30.0  # [kg m^2] hub inertia about Z
ROOT = 0.5  # [m] root radius
CANTILEVER = np.array([1.875104068711961, 4.694091132974175, 7.854757438237613])  # beta_n L


def _beam(n_elements: int):
    return uniform_beam(L, n_elements, mass_per_length_kg_m=RHO_A,
                        bending_stiffness_x_n_m2=EI_X, bending_stiffness_z_n_m2=EI_Z,
                        axial_stiffness_n=EA, torsional_stiffness_n_m2=GJ,
                        polar_inertia_per_length_kg_m=RHO_IP)  # fmt: skip


def _reduce(n_elements: int, n_modes: int):
    beam = _beam(n_elements)
    return craig_bampton(beam.M, beam.K, beam.interface_dofs, n_modes,
                         interface_map=beam.interface_map,
                         outputs={"tip": (beam.tip_dofs, beam.tip_position_m)})  # fmt: skip


def _cantilever_hz(ei: float) -> np.ndarray:
    return CANTILEVER**2 * np.sqrt(ei / (RHO_A * L**4)) / (2.0 * np.pi)


def test_clamped_modes_are_the_euler_bernoulli_cantilever():
    # 32 Hermite elements: the first two bending frequencies in each plane within 1e-6
    # (FE error ~ (h beta)^4: measured 3e-7 for the second mode); torsion with linear elements
    # within 1e-3 (error ~ (pi h / 2 L)^2 / 12 ~ 2e-4).
    data = _reduce(32, 8)
    f = np.array(data.frequencies_hz)
    for expected in (*_cantilever_hz(EI_Z)[:2], *_cantilever_hz(EI_X)[:2]):
        assert np.min(np.abs(f / expected - 1.0)) <= 1e-6
    torsion = np.sqrt(GJ / RHO_IP) / (4.0 * L)  # (2n - 1) pi / 2L sqrt(GJ / rho I_p) / 2 pi
    assert np.min(np.abs(f / torsion - 1.0)) <= 1e-3


def test_bending_frequencies_converge_at_fourth_order():
    # Cubic Hermite elements: eigenvalue error O(h^4); halving h divides the first
    # in-plane frequency's error by 16 (within 10 %).
    target = _cantilever_hz(EI_Z)[1]
    errors = []
    for n in (4, 8, 16):
        f = np.array(_reduce(n, 6).frequencies_hz)
        errors.append(np.min(np.abs(f - target)) / target)
    assert errors[0] / errors[1] == pytest.approx(16.0, rel=0.1)
    assert errors[1] / errors[2] == pytest.approx(16.0, rel=0.1)


def test_rigid_mass_and_effective_masses():
    # Rigid mass about the root: m = rho A L, c = L/2 along Y, J_xx = J_zz = rho A L^3/3
    # (no section rotary inertia), J_yy = rho I_p L (to the round-off of K_ii^-1, 1e-10).
    # Effective masses: below the rigid mass with 4 modes; with all modes, the rigid mass
    # less what the interface node itself carries (its statically condensed mass).
    beam = _beam(8)
    data = craig_bampton(beam.M, beam.K, beam.interface_dofs, 4, interface_map=beam.interface_map)
    m = RHO_A * L
    assert data.mass_kg == pytest.approx(m, rel=1e-10)
    np.testing.assert_allclose(data.center_of_mass_m, [0, L / 2, 0], atol=1e-10)
    np.testing.assert_allclose(np.diag(data.inertia_interface_kg_m2),
                               [m * L**2 / 3, RHO_IP * L, m * L**2 / 3], rtol=1e-10)  # fmt: skip
    rigid = data.rigid_mass_matrix()
    assert np.linalg.eigvalsh(rigid - data.effective_mass()).min() >= -1e-10 * rigid.max()
    n_interior = beam.M.shape[0] - 6
    full = craig_bampton(beam.M, beam.K, beam.interface_dofs, n_interior,
                         interface_map=beam.interface_map)  # fmt: skip
    M, K = beam.M.toarray(), beam.K.toarray()
    b = beam.interface_dofs
    i = np.setdiff1d(np.arange(M.shape[0]), b)
    psi = np.zeros((M.shape[0], 6))
    psi[b] = beam.interface_map
    psi[i] = -np.linalg.solve(K[np.ix_(i, i)], K[np.ix_(i, b)] @ beam.interface_map)
    coupled = M[i] @ psi
    expected = coupled.T @ np.linalg.solve(M[np.ix_(i, i)], coupled)
    np.testing.assert_allclose(full.effective_mass(), expected, rtol=0, atol=1e-9 * rigid.max())


# -- the coupled satellite against Euler-Bernoulli ----------------------------------------


def _analytic_hub_frequencies(count: int) -> np.ndarray:
    return euler_bernoulli_hub_frequencies(HUB_J, ROOT, L, RHO_A, EI_Z, count)


def _satellite(n_elements: int, n_modes: int) -> Plant:
    data = _reduce(n_elements, n_modes).model_dump()
    wing = {"model": "modal", "data": data}
    return Plant.from_config(validate_config({
        "hub": {"mass_kg": 100.0, "inertia_kg_m2": [[40.0, 0, 0], [0, 35.0, 0], [0, 0, HUB_J]]},
        "appendages": [
            {**wing, "name": "wing_1", "mount_point_m": [0.0, ROOT, 0.0]},
            {**wing, "name": "wing_2", "mount_point_m": [0.0, -ROOT, 0.0], "mount_yaw_deg": 180.0},
        ],
    }))  # fmt: skip


def coupled_yaw_frequencies(plant: Plant, count: int) -> np.ndarray:
    """The coupled modes that move the hub about Z (yaw), lowest first [Hz]."""
    from scipy.linalg import eigh

    lam, phi = eigh(plant.stiffness_matrix(), plant.mass_matrix())
    yaw = np.abs(phi[5]) > 1e-8 * np.abs(phi).max(axis=0)
    f = np.sqrt(np.clip(lam[yaw], 0.0, None)) / (2.0 * np.pi)
    return f[f > 1e-6][:count]


@pytest.fixture(scope="module")
def analytic() -> np.ndarray:
    return _analytic_hub_frequencies(3)


def test_coupled_frequencies_converge_to_euler_bernoulli(analytic):
    # The error falls with the retained modes and with the elements (the table in
    # docs/performance.md, "Modal appendages"). With 32 elements and 16 modes per beam
    # the first three coupled yaw frequencies are within 5e-6 of the analytic ones
    # (measured 1.7e-7, 7.9e-7, 3.2e-6: the modal truncation of the third dominates).
    def first_errors(n_el, k):
        f = coupled_yaw_frequencies(_satellite(n_el, k), 3)
        return np.abs(f / analytic[: f.size] - 1.0)

    assert np.all(first_errors(32, 16) <= 5e-6)
    by_modes = [first_errors(32, k)[0] for k in (2, 4, 8, 16)]
    by_elements = [first_errors(n, 16)[0] for n in (4, 8, 16)]
    assert by_modes == sorted(by_modes, reverse=True)
    assert by_elements == sorted(by_elements, reverse=True)


def test_bad_interface_is_one_clear_message():
    beam = _beam(4)
    with pytest.raises(ConfigError, match="interface_dofs: DOF 999 is not in the model"):
        craig_bampton(beam.M, beam.K, [0, 1, 2, 3, 4, 999], 2)
    with pytest.raises(ConfigError, match="interface_map: expected shape"):
        craig_bampton(beam.M, beam.K, beam.interface_dofs, 2, interface_map=np.eye(5))
    with pytest.raises(ConfigError, match="n_modes: must be in"):
        craig_bampton(beam.M, beam.K, beam.interface_dofs, 0, interface_map=beam.interface_map)
    with pytest.raises(ConfigError, match="not rigid-body motions"):
        craig_bampton(beam.M, beam.K, beam.interface_dofs[:5], 2,
                      interface_map=beam.interface_map[:5])  # fmt: skip
