"""Root actuators on joint coordinates: the lag's discretization, the authority, the
coordinates by name, and their reaction on the hub through the joint equations."""

from __future__ import annotations

import numpy as np
import pytest

from flexsat.control.stages import JOINT_ACTUATORS
from flexsat.control.stages.joint_rate_feedback import JointRateFeedbackConfig
from flexsat.dynamics.integrators import rk4_step
from flexsat.errors import ConfigError
from flexsat.simulate.scenario import SlewScenario

STEP = JOINT_ACTUATORS.get("rate_feedback").step


def _params(plant, **fields):
    config = JointRateFeedbackConfig(**{"coordinates": ["eta_ry"], "gain": 10.0, "limit": 0.1,
                                        **fields})  # fmt: skip
    return config, np.ascontiguousarray(config.packed(SlewScenario(), plant))


def test_coordinates_by_name_in_the_plant_layout(nominal_plant):
    names = nominal_plant.layout.dof_names()
    config, params = _params(nominal_plant, coordinates=["eta_rz", "panel_2.eta_rx"])
    idx = [int(i) for i in params[5:]]
    assert [names[i] for i in idx] == ["panel_1.eta_rz", "panel_2.eta_rz", "panel_2.eta_rx"]
    with pytest.raises(ConfigError, match=r"joint_actuator\.coordinates: unknown coordinate "
                       r"'rho_y'.*panel_1\.eta_ry"):  # fmt: skip
        _params(nominal_plant, coordinates=["rho_y"])


def test_lag_is_the_exact_discretization_and_the_authority_holds(nominal_plant):
    # A constant joint rate: the lag's output at the control instants is the
    # continuous first-order step response Q_cmd (1 - exp(-2 pi f_b t)) exactly
    # (zero-order-hold discretization; 1e-15 relative: round-off of the recursion).
    n = nominal_plant.n_dof
    _, params = _params(nominal_plant, gain=10.0, limit=1.0, bandwidth_hz=5.0)
    j = int(params[5])
    x = np.zeros(2 * n + 2)
    x[n + j] = 0.02  # rad/s: command -10 * 0.02 = -0.2 N m, within the authority
    Q, record, dt = np.zeros(n), np.zeros(2), 1e-3
    q_d = np.array([1.0, 0.0, 0.0, 0.0])
    for k in range(1, 301):
        assert STEP(x, n, k * dt, dt, q_d, np.eye(3), params, np.zeros(0), Q, record) == 0
        expected = -0.2 * (1.0 - np.exp(-2.0 * np.pi * 5.0 * k * dt))
        assert Q[j] == pytest.approx(expected, rel=1e-12)
    assert np.count_nonzero(Q) == 1  # only the actuated coordinate
    assert record[0] == pytest.approx(Q[j] * 0.02, rel=1e-15) and record[0] < 0.0  # dissipates
    x[n + j] = 5.0  # saturating: the output converges to the authority, never beyond
    for k in range(2000):
        STEP(x, n, k * dt, dt, q_d, np.eye(3), params, np.zeros(0), Q, record)
        assert abs(Q[j]) <= 1.0
    assert Q[j] == pytest.approx(-1.0, rel=1e-12)


def test_engages_only_near_the_target(nominal_plant):
    n = nominal_plant.n_dof
    _, params = _params(nominal_plant, engage_below_deg=1.0)
    j = int(params[5])
    x = np.zeros(2 * n + 2)
    x[n + j] = 0.01
    x[5] = np.radians(2.0)  # 2 deg of yaw from the reference: off
    Q, q_d = np.zeros(n), np.array([1.0, 0.0, 0.0, 0.0])
    STEP(x, n, 0.0, 1e-3, q_d, np.eye(3), params, np.zeros(0), Q, np.zeros(2))
    assert Q[j] == 0.0
    x[5] = np.radians(0.5)  # inside: on
    STEP(x, n, 0.0, 1e-3, q_d, np.eye(3), params, np.zeros(0), Q, np.zeros(2))
    assert Q[j] < 0.0


def test_joint_forces_react_on_the_hub_through_the_joint_equations(nominal_plant):
    # Forces on the joint coordinates are internal to the satellite: with no torque on
    # the hub the total angular momentum is an exact invariant (RK4 at 1e-4 s over 5 s:
    # 1e-9 relative, the bound of the torque-free open-loop test), and the energy
    # balance E - E0 = W_in - W_diss closes with W_in the actuators' work (1e-7 of the
    # energy exchanged, the open-loop test's bound).
    plant = nominal_plant
    n = plant.n_dof
    x = np.zeros(2 * n + 2)
    x[n + 3 : n + 6] = np.radians([0.5, -1.0, 2.0])  # spinning hub
    Q = np.zeros(n)
    names = plant.layout.dof_names()
    for name, value in (("panel_1.eta_ry", 0.3), ("panel_2.eta_rz", -0.2), ("panel_1.eta_z", 2.0)):
        Q[names.index(name)] = value
    scratch = np.empty((5, x.size))
    energy = lambda q, qd: plant.kinetic_energy(q, qd) + plant.elastic_energy(q)  # noqa: E731
    H0, E0 = plant.angular_momentum(x[:n], x[n : 2 * n]), energy(x[:n], x[n : 2 * n])
    for _ in range(50_000):
        assert rk4_step(x, 1e-4, (0.0, 0.0, 0.0), n, Q, scratch, plant.packed) == 0
    q, qd = x[:n], x[n : 2 * n]
    H = plant.angular_momentum(q, qd)
    assert np.abs(H - H0).max() <= 1e-9 * np.linalg.norm(H0)
    work_in, dissipated = x[2 * n], x[2 * n + 1]
    assert abs(work_in) > 1e-4  # the actuators did work, and it is booked
    assert abs(energy(q, qd) - E0 - work_in + dissipated) <= 1e-7 * (abs(work_in) + E0)
