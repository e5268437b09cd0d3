"""The driven mount coordinate (SADM): a thesis plate on a drive is the plate plus one
coordinate; the drive's torque is internal (momentum conserved, its work booked in
the energy balance) and its reaction on the hub is the rigid-body momentum argument's.

The drive runs as in the closed loop: its step at every control instant (1 ms), its
torque held over the RK4 steps between (zero-order hold), no torque on the hub.
"""

from __future__ import annotations

import numpy as np
import pytest
from numba import njit

from flexsat.config import nominal
from flexsat.control.stages.sadm_drive import SADMDriveConfig, sadm_drive_step
from flexsat.dynamics.appendages.sadm import DRIVE_COORDINATE, driven_plate, with_sadm
from flexsat.dynamics.integrators import rk4_step
from flexsat.dynamics.plant import Plant
from flexsat.simulate.scenario import SlewScenario

ROTOR_INERTIA = 0.1  # kg m^2, drive rotor about its axis as seen at the array
ROTOR_MASS = 2.0  # kg
PANEL = nominal().appendages[0]
DRIVEN_INERTIA = ROTOR_INERTIA + PANEL.centroidal_inertia()[1, 1]  # about Y_M (eq. 2.10)
OMEGA_N = 2.0 * np.pi * 0.1  # drive loop natural frequency [rad/s], below the 0.25 Hz flapping


@njit(cache=True)
def _fly(x, dt, steps, record_every, n, params, Q, scratch, packed, log):
    """Drive step every RK4 step (control period = dt), no hub torque; x logged."""
    record = np.zeros(4)
    q_d = np.array([1.0, 0.0, 0.0, 0.0])
    state = np.zeros(10)
    J_design = np.eye(3)  # the law's, not read here
    for s in range(steps):
        if s % record_every == 0:
            log[s // record_every, :] = x
        sadm_drive_step(x, n, s * dt, dt, q_d, J_design, params, state, Q, record)
        status = rk4_step(x, dt, (0.0, 0.0, 0.0), n, Q, scratch, packed)
        if status != 0:
            return status
    log[-1, :] = x
    return 0


def _drive(plant, **fields):
    config = SADMDriveConfig(**{
        "coordinates": [DRIVE_COORDINATE], "stiffness_nm_rad": DRIVEN_INERTIA * OMEGA_N**2,
        "damping_nms_rad": 2.0 * OMEGA_N * DRIVEN_INERTIA, "rate_deg_s": 0.5, **fields,
    })  # fmt: skip
    return np.ascontiguousarray(config.packed(SlewScenario(), plant))


def _run(plant, params, hub_rate_deg_s=(0.0, 0.0, 0.0), duration=120.0, dt=1e-3):
    n = plant.n_dof
    x = np.zeros(2 * n + 2)
    x[n + 3 : n + 6] = np.radians(hub_rate_deg_s)
    every = round(0.1 / dt)
    steps = round(duration / dt)
    log = np.zeros((steps // every + 1, x.size))
    status = _fly(x, dt, steps, every, n, params, np.zeros(n), np.empty((5, x.size)),
                  plant.packed, log)  # fmt: skip
    assert status == 0
    return log


@pytest.fixture(scope="module")
def driven() -> Plant:
    """The nominal satellite with both panels on a drive, joints undamped."""
    plant = Plant.from_config(with_sadm(nominal(), ROTOR_INERTIA, ROTOR_MASS))
    return plant.with_joints(plant.stiffness, np.zeros_like(plant.damping))


def test_a_driven_plate_is_the_plate_plus_its_drive_coordinate():
    # With a vanishing rotor (1e-4 kg, 1e-9 kg m^2) the driven plate's M(q), drive row
    # and column removed, is the plate's: its kinematics are the plate's exactly with
    # the drive angle held (sadm module docstring). What remains is the two rotors'
    # share: 2 m_r on the hub translation block, 2 (m_r |r_m|^2 + J_r) on its rotation
    # block (|r_m| = 0.8 m); 1e-12 is the round-off of entries up to 200.
    config = nominal()
    plate = Plant.from_config(config)
    tiny = Plant.from_config(with_sadm(config, 1e-9, 1e-4))
    assert tiny.n_dof == plate.n_dof + 2
    names = tiny.layout.dof_names()
    assert names[6] == f"panel_1.{DRIVE_COORDINATE}"
    rng = np.random.default_rng(7)
    q_plate = np.concatenate([rng.normal(0.0, 0.2, 6), rng.normal(0.0, 0.02, plate.n_dof - 6)])
    keep = [i for i, name in enumerate(names) if not name.endswith(DRIVE_COORDINATE)]
    q = np.zeros(tiny.n_dof)
    q[keep] = q_plate
    M = tiny.mass_matrix(q)[np.ix_(keep, keep)]
    M_plate = plate.mass_matrix(q_plate)
    assert np.abs(M - M_plate).max() <= 2e-4 + 1e-12
    np.testing.assert_allclose(tiny.stiffness[[k - 6 for k in keep[6:]]], plate.stiffness,
                               rtol=1e-15)  # fmt: skip


def test_locked_dofs_are_refused():
    locked = nominal().appendages[0].model_copy(update={"locked_dofs": ["eta_x"]})
    with pytest.raises(ValueError, match=r"panel_1.*locks.*no locked DOFs"):
        driven_plate(locked, np.ones(6), np.zeros(6), ROTOR_INERTIA, ROTOR_MASS)


def test_drive_torque_is_internal_momentum_and_energy(driven):
    # Both arrays driven at 0.5 deg/s for 120 s (60 deg) on a tumbling hub, no torque on
    # the hub, no damping. The drive torque is internal: H about the inertial origin is
    # an exact invariant, RK4 keeps it to round-off (measured 3e-14 relative; bound
    # 1e-10). Energy: E - E0 = W_drive (booked by the integrator as int Q qd dt); what
    # remains is RK4 truncation at 1 ms of the 50 Hz root translations, measured 8e-7 of
    # the drive work (7e-9 of E0) and 16x smaller at half the step (4th order), bound
    # 1e-5 of the work.
    n = driven.n_dof
    log = _run(driven, _drive(driven), hub_rate_deg_s=(0.5, -1.0, 2.0))
    q, qd = log[:, :n], log[:, n : 2 * n]
    H = np.array([driven.angular_momentum(a, b) for a, b in zip(q, qd, strict=True)])
    drift = np.abs(H - H[0]).max() / np.linalg.norm(H[0])
    energy = np.array([driven.kinetic_energy(a, b) + driven.elastic_energy(a)
                       for a, b in zip(q, qd, strict=True)])  # fmt: skip
    work = log[:, 2 * n]
    balance = np.abs(energy - energy[0] - work).max() / np.abs(work).max()
    drive = [driven.layout.dof_names().index(f"panel_{k}.{DRIVE_COORDINATE}") for k in (1, 2)]
    print(
        f"momentum drift {drift:.1e}, energy balance {balance:.1e} of the drive work "
        f"{np.abs(work).max():.2e} J"
    )
    assert np.degrees(q[-1, drive]) == pytest.approx([60.0, 60.0], abs=0.01)
    assert drift <= 1e-10
    assert np.abs(work).max() > 1e-4  # the drive did work, and it is booked
    assert balance <= 1e-5


def test_drive_energy_balance_closes_to_round_off_as_the_step_shrinks(driven):
    # The drive work is booked by the integrator (int Q qd dt, in the same RK4 stages
    # as the motion), so E - E0 - W_drive is RK4's truncation alone: it falls faster
    # than the 4th power of the step (measured 2.6e-9 then 5.4e-11 of the work at
    # 0.25 and 0.125 ms over 20 s, a factor 48) down to round-off of E0 (5e-14 of
    # E0 at 0.125 ms). A bookkeeping error (a term of the work missed) would not shrink
    # with the step. Bounds: a factor >= 8 per halving (at least 3rd order, margin for
    # the round-off floor near which the finer run lies), and 1e-12 of E0 at 0.125 ms.
    n = driven.n_dof
    residual = {}
    for dt in (2.5e-4, 1.25e-4):
        log = _run(driven, _drive(driven), hub_rate_deg_s=(0.5, -1.0, 2.0), duration=20.0,
                   dt=dt)  # fmt: skip
        q, qd = log[:, :n], log[:, n : 2 * n]
        energy = np.array([driven.kinetic_energy(a, b) + driven.elastic_energy(a)
                           for a, b in zip(q, qd, strict=True)])  # fmt: skip
        residual[dt] = np.abs(energy - energy[0] - log[:, 2 * n]).max()
        e0 = energy[0]
    print(f"energy balance {residual[2.5e-4]:.1e} J, {residual[1.25e-4]:.1e} J; E0 {e0:.3f} J")
    assert residual[2.5e-4] >= 16.0 * residual[1.25e-4]
    assert residual[1.25e-4] <= 1e-12 * e0


def test_hub_reaction_is_the_rigid_body_momentum_argument(driven):
    # Hub at rest, both arrays driven about Y_B: each array's centre of mass and its
    # rotor are on the hub's Y axis through its centre of mass, so the motion stays a
    # rotation about Y_B and H_y = 0 reads
    # (J_hub,yy + 2 J_r + 2 J_py) omega_y + sum_i [J_r beta_dot_i + J_py (beta_dot_i +
    # rho_dot_y,i)] = 0 (rho_y the panel's torsion about the same axis), an
    # independent statement of the drive's reaction: omega_y from it agrees with the
    # integrated hub rate to round-off (measured 1e-15 rad/s; bound 1e-12 rad/s, 1e-9
    # of the 1e-3 rad/s reached), and the other rates stay zero.
    n = driven.n_dof
    names = driven.layout.dof_names()
    log = _run(driven, _drive(driven), duration=30.0)
    qd = log[:, n : 2 * n]
    J_py = PANEL.centroidal_inertia()[1, 1]
    beta = sum(qd[:, names.index(f"panel_{k}.{DRIVE_COORDINATE}")] for k in (1, 2))
    torsion = sum(qd[:, names.index(f"panel_{k}.eta_ry_1")] for k in (1, 2))
    J_total = driven.hub_J[1, 1] + 2.0 * ROTOR_INERTIA + 2.0 * J_py
    expected = -((ROTOR_INERTIA + J_py) * beta + J_py * torsion) / J_total
    omega = qd[:, 3:6]  # at zero roll and yaw the pitch rate is omega_y
    assert np.abs(log[:, [3, 5]]).max() <= 1e-12
    assert np.abs(omega[:, 1] - expected).max() <= 1e-12
    assert np.abs(omega[:, [0, 2]]).max() <= 1e-12
    assert np.abs(omega[:, 1]).max() > 1e-4


def test_drive_angle_tracks_a_constant_rate(driven):
    # The PD loop about a constant-rate command: J e'' + c_d e' + k_d e = 0 for the
    # error e, started at rest, critically damped (sadm_drive docstring): the error
    # peaks at r / (e omega_n) (5.1e-3 rad at 0.5 deg/s, omega_n = 0.63 rad/s; J the
    # rotor and array about the axis; the free hub only lowers the effective inertia,
    # raising omega_n) and decays as exp(-omega_n t): below 1 % of the peak after 20 s
    # (0.63 * 20 = 12.6 time constants would give 1e-4; the 0.8 Hz torsion in series
    # rings at a few 1e-5 rad, measured).
    n = driven.n_dof
    names = driven.layout.dof_names()
    rate = np.radians(0.5)
    log = _run(driven, _drive(driven), duration=40.0)
    t = np.arange(log.shape[0]) * 0.1
    beta = log[:, names.index(f"panel_1.{DRIVE_COORDINATE}")]
    error = np.abs(beta - rate * t)
    peak = rate / (np.e * OMEGA_N)
    print(
        f"peak error {error.max():.2e} rad (bound {peak:.2e}), after 20 s "
        f"{error[t >= 20.0].max():.2e}"
    )
    assert error.max() <= peak
    assert error[t >= 20.0].max() <= 0.01 * peak
    assert n == Plant.from_config(nominal()).n_dof + 2


def test_the_plates_six_dof_joint_behind_the_drive_satisfies_the_equations_of_motion(driven):
    # The plate segment's joint frees all six directions, so pass 1 hands the drive
    # segment no articulated inertia (I^a = 0 analytically) and skips computing it.
    # q_ddot from the recursion must still satisfy M q_ddot + h + C q_dot + K q = Q
    # with M (composite inertias) and h (inverse dynamics) from the other algorithms:
    # round-off of sums of O(10^2) terms, 1e-12 of the largest term of the balance.
    plant = driven
    rng = np.random.default_rng(23)
    for _ in range(10):
        q, qd, Q = (0.2 * rng.standard_normal(plant.n_dof) for _ in range(3))
        qdd = plant.accelerations(q, qd, Q)
        M = plant.mass_matrix(q)
        lhs = (M @ qdd + plant.bias_forces(q, qd) + plant.damping_forces(qd)
               + plant.elastic_forces(q))  # fmt: skip
        scale = max(np.max(np.abs(M) @ np.abs(qdd)), np.max(np.abs(Q)),
                    np.max(np.abs(plant.elastic_forces(q))))  # fmt: skip
        assert np.max(np.abs(lhs - Q)) / scale <= 1e-12


def _chains(segments: int = 3):
    """The chain preset with each panel as ``segments`` segments (bending and torsion)."""
    from flexsat.config import load_config, preset_path, validate_config

    data = load_config(preset_path("chain")).model_dump(exclude_none=True)
    for app in data["appendages"]:
        app["segments"] = segments
    return validate_config(data)


def test_a_driven_chain_is_the_chain_plus_its_drive_coordinate():
    # As for the plate: with a vanishing rotor (1e-4 kg, 1e-9 kg m^2) the driven chain's
    # M(q), drive rows removed, is the chain's up to the two rotors' share, 2 m_r on the
    # hub translation block and 2 (m_r |r_m|^2 + J_r) on its rotation block (2e-4 with
    # |r_m| = 0.8 m); the tuned joint stiffness is carried over exactly (the chain's
    # segments become segments 1..N of the driven chain).
    config = _chains()
    chain = Plant.from_config(config)
    tiny = Plant.from_config(with_sadm(config, 1e-9, 1e-4))
    assert tiny.n_dof == chain.n_dof + 2
    names = tiny.layout.dof_names()
    assert names[6] == f"panel_1.{DRIVE_COORDINATE}"
    assert names[7] == "panel_1.eta_rx_1"
    rng = np.random.default_rng(11)
    q_chain = np.concatenate([rng.normal(0.0, 0.2, 6), rng.normal(0.0, 0.02, chain.n_dof - 6)])
    keep = [i for i, name in enumerate(names) if not name.endswith(DRIVE_COORDINATE)]
    q = np.zeros(tiny.n_dof)
    q[keep] = q_chain
    M = tiny.mass_matrix(q)[np.ix_(keep, keep)]
    assert np.abs(M - chain.mass_matrix(q_chain)).max() <= 2e-4 + 1e-12
    np.testing.assert_allclose(tiny.stiffness[[k - 6 for k in keep[6:]]], chain.stiffness,
                               rtol=1e-15)  # fmt: skip


def test_a_drive_turning_a_chain_conserves_momentum_and_books_its_work():
    # Both chains driven at 0.5 deg/s for 20 s (10 deg) on a tumbling hub, no hub
    # torque, joints undamped: the drive torque is internal, so H is an exact
    # invariant (bound 1e-10 relative, RK4 round-off measured below it), and
    # E - E0 = W_drive up to RK4's truncation at 1 ms (bound 1e-5 of the work, as
    # for the plate).
    plant = Plant.from_config(with_sadm(_chains(), ROTOR_INERTIA, ROTOR_MASS))
    plant = plant.with_joints(plant.stiffness, np.zeros_like(plant.damping))
    n = plant.n_dof
    log = _run(plant, _drive(plant), hub_rate_deg_s=(0.5, -1.0, 2.0), duration=20.0)
    q, qd = log[:, :n], log[:, n : 2 * n]
    H = np.array([plant.angular_momentum(a, b) for a, b in zip(q, qd, strict=True)])
    drift = np.abs(H - H[0]).max() / np.linalg.norm(H[0])
    energy = np.array([plant.kinetic_energy(a, b) + plant.elastic_energy(a)
                       for a, b in zip(q, qd, strict=True)])  # fmt: skip
    work = log[:, 2 * n]
    balance = np.abs(energy - energy[0] - work).max() / np.abs(work).max()
    drive = [plant.layout.dof_names().index(f"panel_{k}.{DRIVE_COORDINATE}") for k in (1, 2)]
    print(f"chain: momentum drift {drift:.1e}, energy balance {balance:.1e} of the work "
          f"{np.abs(work).max():.2e} J")  # fmt: skip
    # The drive turned as commanded (10 deg at 20 s); 0.1 deg leaves room for the 0.1 Hz
    # drive loop's transient after 20 s (measured 0.073 deg).
    assert np.degrees(q[-1, drive]) == pytest.approx([10.0, 10.0], abs=0.1)
    assert drift <= 1e-10
    assert np.abs(work).max() > 1e-6
    assert balance <= 1e-5
