"""Inputs on actuated appendage coordinates: analytic against differences and against
the nonlinear plant driven by the same generalized force."""

import numpy as np
import pytest
from scipy.integrate import solve_ivp
from scipy.linalg import expm

from flexsat.errors import ConfigError
from flexsat.linear import linearize, signal_names

ACTUATED = ("panel_1.eta_rz", "eta_x")  # one full name, one short name (both panels)


@pytest.fixture(scope="module")
def actuated_model(plant):
    return linearize(plant, actuated=ACTUATED)


def test_inputs_are_named_with_the_layout_units(plant, actuated_model):
    expected = ("tau_x", "tau_y", "tau_z", "Q_panel_1.eta_rz", "Q_panel_1.eta_x", "Q_panel_2.eta_x")
    assert actuated_model.input_names == expected
    assert actuated_model.input_units == ("N m",) * 4 + ("N",) * 2
    assert signal_names(plant, ACTUATED)["inputs"][0] == expected


def test_body_torque_columns_are_unchanged(rest_model, actuated_model):
    # The torque-only model is the first three columns, bit for bit.
    np.testing.assert_array_equal(actuated_model.A, rest_model.A)
    np.testing.assert_array_equal(actuated_model.B[:, :3], rest_model.B)
    np.testing.assert_array_equal(actuated_model.C, rest_model.C)
    np.testing.assert_array_equal(actuated_model.D[:, :3], rest_model.D)


def test_analytic_actuator_columns_equal_the_richardson_ones(plant, actuated_model):
    fd = linearize(plant, actuated=ACTUATED, jacobian="richardson")
    # B is linear in u (Q enters eq. 2.50 linearly through M^-1): the differences have
    # no truncation error, only round-off ~eps/h = 2e-12 of the column (h = 1e-4 N);
    # measured 2e-16. 1e-9 as for the state Jacobian.
    for j in range(3, 6):
        col = actuated_model.B[:, j]
        assert np.max(np.abs(fd.B[:, j] - col)) <= 1e-9 * np.max(np.abs(col))


def test_an_unknown_coordinate_is_refused_with_the_allowed_names(plant):
    allowed = r"panel_1\.eta_x, .*, panel_2\.eta_rz"
    with pytest.raises(ConfigError, match=rf"actuated: unknown coordinate 'rho_q' .*{allowed}"):
        linearize(plant, actuated=["rho_q"])


def test_about_a_spin_the_actuator_is_an_extra_input(plant):
    spin = linearize(plant, about=[0.5, 0.0, 0.0], actuated=["panel_1.eta_rz"])
    assert spin.B.shape == (36, 4) and spin.u0[3] == 0.0
    # At rest and about a spin the force enters q_ddot through the same M^-1 (the
    # centrifugal deformation changes M(q) at first order in it; measured 1.9e-6 of the
    # column): 1e-3 bounds a deformation-sized change, not a different input.
    rest = linearize(plant, actuated=["panel_1.eta_rz"])
    np.testing.assert_allclose(spin.B[:, 3], rest.B[:, 3], atol=1e-3 * np.abs(rest.B[:, 3]).max())


def test_step_force_response_matches_the_nonlinear_plant(plant):
    name = "panel_1.eta_rz"
    j = plant.layout.dof_names().index(name)
    model = linearize(plant, outputs=["rate", "joint"], actuated=[name])
    n = plant.n_dof
    force = 1e-4 * plant.stiffness[j - 6]  # [N m] static deflection 1e-4 rad
    Q = np.zeros(n)
    Q[j] = force

    def rhs(t, y):
        return np.concatenate([y[n:], plant.accelerations(y[:n], y[n:], Q)])

    t = np.linspace(0.0, 8.0, 161)  # [s] two periods of the slowest mode (0.26 Hz)
    sol = solve_ivp(rhs, (0.0, t[-1]), np.zeros(2 * n), method="DOP853", t_eval=t,
                    rtol=1e-10, atol=1e-14)  # fmt: skip
    assert sol.success
    # Linear: x(t) from the exact zero-order-hold step, expm of [[A, B u], [0, 0]].
    aug = np.zeros((2 * n + 1, 2 * n + 1))
    aug[: 2 * n, : 2 * n] = model.A
    aug[: 2 * n, -1] = model.B[:, 3] * force
    x_lin = np.array([expm(aug * tk)[: 2 * n, -1] for tk in t])
    y_lin = x_lin @ model.C.T
    eta_nl = sol.y[j]
    phi, theta = sol.y[3], sol.y[4]
    omega_z_nl = -np.sin(phi) * sol.y[n + 3] + np.cos(theta) * np.cos(phi) * sol.y[n + 5]
    rows = list(model.output_names)
    eta_lin = y_lin[:, rows.index(name)]
    omega_z_lin = y_lin[:, rows.index("omega_z")]
    # Deflections ~1e-4 rad: the neglected terms are O(amplitude) relative, ~1e-4; the
    # integrator at rtol 1e-10 adds nothing visible (measured 1e-8 on eta, 5e-8 on
    # omega_z). Acceptance 1 % of the peak, the linear regime's figure.
    for nl, lin in ((eta_nl, eta_lin), (omega_z_nl, omega_z_lin)):
        assert np.max(np.abs(lin)) > 0.0
        assert np.max(np.abs(nl - lin)) <= 0.01 * np.max(np.abs(lin))
