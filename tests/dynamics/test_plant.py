"""Physics of the compiled engine: structure, invariants and the thesis's numbers."""

from __future__ import annotations

import numpy as np
import pytest

from flexsat.dynamics.plant import Plant
from flexsat.dynamics.rigid import gyroscopic_torque, rigid_inertia
from flexsat.dynamics.symmetry import mirror_operator
from flexsat.errors import SimulationError
from flexsat.study.thesis import J_TOT_NOMINAL, PRINTED_2DP, appendix_b_mass_matrix
from tests.conftest import random_state

N_STATES = 25


def test_mass_matrix_matches_appendix_b(nominal_plant):
    # Appendix B prints every entry to 2 decimals: agreement within half a unit.
    np.testing.assert_allclose(
        nominal_plant.mass_matrix(), appendix_b_mass_matrix(), rtol=0, atol=PRINTED_2DP
    )


def test_rigid_inertia_matches_thesis(nominal_plant):
    # Section 3.1 prints J_tot(0) to 2 decimals; off-diagonals vanish by symmetry.
    np.testing.assert_allclose(rigid_inertia(nominal_plant), J_TOT_NOMINAL, atol=PRINTED_2DP)


def test_rigid_inertia_is_the_hub_rotation_block_of_M0(any_plant):
    # With q = 0 and S(0) = I the hub rotational block of M(0) is the rigidized
    # satellite's inertia about the hub centre of mass; only round-off differs.
    M0 = any_plant.mass_matrix()
    np.testing.assert_allclose(rigid_inertia(any_plant), M0[3:6, 3:6], rtol=1e-13, atol=1e-12)


def test_gyroscopic_torque():
    J = np.diag([1.0, 2.0, 3.0])
    omega = np.array([0.1, -0.2, 0.3])
    np.testing.assert_allclose(gyroscopic_torque(J, omega), np.cross(omega, J @ omega))


def test_accelerations_solve_the_lagrange_equations(any_plant):
    # The articulated (Schur-complement) solve must equal a dense solve of
    # M q_ddot = Q - h - C q_dot - k_el; both are exact, so only round-off
    # (condition number of M times eps ~ 1e-10 relative) separates them.
    rng = np.random.default_rng(1)
    for _ in range(N_STATES):
        q, qd = random_state(any_plant, rng)
        Q = rng.normal(size=any_plant.n_dof)
        M = any_plant.mass_matrix(q)
        rhs = Q - any_plant.bias_forces(q, qd) - any_plant.damping_forces(qd)
        rhs -= any_plant.elastic_forces(q)
        expected = np.linalg.solve(M, rhs)
        got = any_plant.accelerations(q, qd, Q)
        np.testing.assert_allclose(got, expected, rtol=0, atol=1e-9 * np.abs(expected).max())


def test_mass_matrix_is_symmetric_positive_definite(any_plant):
    rng = np.random.default_rng(2)
    for _ in range(N_STATES):
        q, _ = random_state(any_plant, rng)
        M = any_plant.mass_matrix(q)
        np.testing.assert_allclose(M, M.T, rtol=0, atol=1e-12 * np.abs(M).max())
        assert np.linalg.eigvalsh(M)[0] > 0.0


def test_kinetic_energy_is_the_mass_matrix_quadratic_form(any_plant):
    # T computed from the bodies' velocities and 1/2 q_dot^T M q_dot are two
    # routes to one number: equal to round-off.
    rng = np.random.default_rng(3)
    for _ in range(N_STATES):
        q, qd = random_state(any_plant, rng)
        expected = 0.5 * qd @ any_plant.mass_matrix(q) @ qd
        assert any_plant.kinetic_energy(q, qd) == pytest.approx(expected, rel=1e-12)


def _flow_derivative(plant: Plant, f, q, qd, Q, eps: float = 1e-6):
    """d f(q, q_dot)/dt along the flow for f at most quadratic in q_dot.

    Split as df/dq q_dot + df/dq_dot q_ddot: the first by a central difference in q
    (f is smooth in q: error ~eps^2), the second by a central difference in q_dot,
    exact for a quadratic. Stepping both at once would mix in the huge q_ddot of
    the ~100 Hz joint modes through cross terms.
    """
    qdd = plant.accelerations(q, qd, Q)
    along_q = (f(q + eps * qd, qd) - f(q - eps * qd, qd)) / (2 * eps)
    along_qd = (f(q, qd + eps * qdd) - f(q, qd - eps * qdd)) / (2 * eps)
    return along_q + along_qd


def test_energy_is_conserved_without_damping_and_torque(any_plant):
    # With zeta = 0 and Q = 0, d(T + U)/dt = 0. The central difference has
    # truncation error ~eps^2 |E'''| and round-off ~1e-16 |E| / eps; 1e-8 of
    # the energy scale bounds both at eps = 1e-6.
    plant = any_plant.with_joints(any_plant.stiffness, np.zeros_like(any_plant.damping))
    rng = np.random.default_rng(4)
    for _ in range(N_STATES):
        q, qd = random_state(plant, rng, scale=0.1)
        Q = plant.zeros()
        energy = lambda q_, qd_: plant.kinetic_energy(q_, qd_) + plant.elastic_energy(q_)  # noqa: E731
        rate = _flow_derivative(plant, energy, q, qd, Q)
        scale = energy(q, qd) * max(1.0, np.abs(qd).max())
        assert abs(rate) < 1e-8 * scale


def test_power_balance_with_damping_and_forces(any_plant):
    # dE/dt = q_dot^T Q - q_dot^T C q_dot: the work of the external generalized
    # forces minus the Rayleigh dissipation (eq. 2.36). Same tolerance argument.
    rng = np.random.default_rng(5)
    for _ in range(N_STATES):
        q, qd = random_state(any_plant, rng, scale=0.1)
        Q = rng.normal(size=any_plant.n_dof)
        energy = lambda q_, qd_: any_plant.kinetic_energy(q_, qd_) + any_plant.elastic_energy(q_)  # noqa: E731
        rate = _flow_derivative(any_plant, energy, q, qd, Q)
        expected = qd @ Q - any_plant.dissipation_power(qd)
        scale = max(energy(q, qd), abs(qd @ Q)) * max(1.0, np.abs(qd).max())
        assert abs(rate - expected) < 1e-8 * scale


def test_angular_momentum_rate_equals_external_torque(any_plant):
    # dH/dt about the inertial origin equals the external torque; for a pure
    # body torque tau_B that is R_NB tau_B. Central difference as above.
    from scipy.spatial.transform import Rotation

    rng = np.random.default_rng(6)
    for _ in range(N_STATES):
        q, qd = random_state(any_plant, rng, scale=0.1)
        torque_B = rng.normal(size=3)
        Q = any_plant.generalized_forces(q, torque_B)
        rate = _flow_derivative(any_plant, any_plant.angular_momentum, q, qd, Q)
        R_NB = Rotation.from_euler("ZYX", q[3:6][::-1]).as_matrix()
        H_scale = np.abs(any_plant.angular_momentum(q, qd)).max() + 1.0
        np.testing.assert_allclose(rate, R_NB @ torque_B, atol=1e-7 * H_scale)


def test_flex_torque_two_ways(any_plant):
    # tau_flex from the joint wrench equals J_hub w_dot + w x J_hub w - tau_applied
    # (the hub's own Euler equation; docs/model.md, 'Conventions'); both exact -> round-off.
    rng = np.random.default_rng(7)
    for _ in range(N_STATES):
        q, qd = random_state(any_plant, rng)
        torque_B = rng.normal(size=3)
        Q = any_plant.generalized_forces(q, torque_B)
        qdd = any_plant.accelerations(q, qd, Q)
        phi, theta = q[3], q[4]
        S = np.array(
            [
                [1, 0, -np.sin(theta)],
                [0, np.cos(phi), np.cos(theta) * np.sin(phi)],
                [0, -np.sin(phi), np.cos(theta) * np.cos(phi)],
            ]
        )
        omega = S @ qd[3:6]
        # w_dot = d/dt (S Theta_dot), S_dot by central difference along the flow.
        eps = 1e-7
        S_of = lambda t: np.array(  # noqa: E731
            [
                [1, 0, -np.sin(t[1])],
                [0, np.cos(t[0]), np.cos(t[1]) * np.sin(t[0])],
                [0, -np.sin(t[0]), np.cos(t[1]) * np.cos(t[0])],
            ]
        )
        S_dot = (S_of(q[3:5] + eps * qd[3:5]) - S_of(q[3:5] - eps * qd[3:5])) / (2 * eps)
        omega_dot = S @ qdd[3:6] + S_dot @ qd[3:6]
        J = any_plant.hub_J
        expected = J @ omega_dot + np.cross(omega, J @ omega) - torque_B
        _, tau_flex = any_plant.joint_wrench_on_hub(q, qd)
        np.testing.assert_allclose(tau_flex, expected, atol=1e-6 * (np.abs(expected).max() + 1))


def test_flex_torque_vanishes_at_rest(any_plant):
    force, torque = any_plant.joint_wrench_on_hub(any_plant.zeros(), any_plant.zeros())
    assert np.all(force == 0.0) and np.all(torque == 0.0)


def test_mirror_symmetry_of_the_nominal_plant(nominal_plant):
    # At alpha_sadm = 0 the two panels are mirror images through the hub XZ
    # plane: the model must commute with the reflection, exactly (round-off).
    P = mirror_operator(nominal_plant, "xz")
    assert P is not None
    np.testing.assert_allclose(P @ P, np.eye(nominal_plant.n_dof))
    rng = np.random.default_rng(8)
    for _ in range(N_STATES):
        q, qd = random_state(nominal_plant, rng)
        M = nominal_plant.mass_matrix(q)
        np.testing.assert_allclose(nominal_plant.mass_matrix(P @ q), P @ M @ P, atol=1e-11)
        h = nominal_plant.bias_forces(q, qd)
        np.testing.assert_allclose(nominal_plant.bias_forces(P @ q, P @ qd), P @ h, atol=1e-11)
        qdd = nominal_plant.accelerations(q, qd)
        np.testing.assert_allclose(
            nominal_plant.accelerations(P @ q, P @ qd), P @ qdd, atol=1e-9 * np.abs(qdd).max()
        )


def test_no_mirror_symmetry_when_panels_differ():
    from tests.conftest import two_different_panels

    assert mirror_operator(Plant.from_config(two_different_panels()), "xz") is None


def test_bias_forces_vanish_at_rest_and_are_quadratic_in_rates(any_plant):
    rng = np.random.default_rng(9)
    q, qd = random_state(any_plant, rng)
    assert np.all(any_plant.bias_forces(q, any_plant.zeros()) == 0.0)
    # h is a quadratic form in q_dot: h(q, 2 q_dot) = 4 h(q, q_dot) to round-off.
    np.testing.assert_allclose(
        any_plant.bias_forces(q, 2 * qd), 4 * any_plant.bias_forces(q, qd), rtol=1e-12, atol=1e-12
    )


def test_joint_tuning_reproduces_target_frequencies(nominal_plant):
    # Eq. 2.14: each joint DOF alone, with the hub clamped, oscillates at its
    # target: k_j / M0_jj = (2 pi f_j)^2 exactly (definition, round-off only).
    M0 = nominal_plant.mass_matrix()
    clamped = np.sqrt(nominal_plant.stiffness.ravel() / np.diag(M0)[6:]) / (2 * np.pi)
    targets = np.tile([50.0, 50.0, 50.0, 0.25, 0.80, 0.50], 2)
    np.testing.assert_allclose(clamped, targets, rtol=1e-14)
    # Eq. 2.15: c_j = 2 zeta omega_j J_eq,j with zeta = 0.005.
    expected_c = 2 * 0.005 * 2 * np.pi * targets * np.diag(M0)[6:]
    np.testing.assert_allclose(nominal_plant.damping.ravel(), expected_c, rtol=1e-14)


def test_tip_displacement_small_rotation(nominal_plant):
    # Thesis section 3.3: the in-plane tip displacement is L_p * eta_rz for small
    # angles (L_p = 4.5 m). For rho_z = 1e-3 rad the chord error is ~L rho^2/2.
    q = nominal_plant.zeros()
    q[11] = 1e-3  # panel 1 rho_z
    tip = nominal_plant.tip_displacement(q)
    assert tip[0, 0] == pytest.approx(-4.5e-3, rel=1e-6)  # tip at +Y moves to -X
    assert np.all(tip[1] == 0.0)


def test_hub_gimbal_lock_is_reported(nominal_plant):
    q = nominal_plant.zeros()
    q[4] = np.pi / 2
    with pytest.raises(SimulationError, match="90 deg"):
        nominal_plant.accelerations(q, nominal_plant.zeros())
