"""A modal appendage on a solar-array drive (docs/model.md, 'Modal appendage on a drive').

The drive angle is a coordinate of the modal model itself (eqs. D.1-D.8). Checks:
the articulated-body accelerations against M(q)^-1 (Q - h - C q_dot - K q) of the
kinetic energy (D.7); the drive held against the same appendage rigidly mounted at
that angle; the drive torque internal on a free-floating satellite (momentum and the
energy balance, with the large-motion terms and the full modal damping), and the
chain's drive likewise with its joint damping; against a chain of beam segments on
its own drive, exported to modal data: the accelerations' expansion in the modes, and
the drive-angle and hub-rate histories; the named coordinate, the recorded channels,
the modal analysis and the linearization; bad input.
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy.linalg import eigh
from scipy.spatial.transform import Rotation

from flexsat import ConfigError, Plant, load_config
from flexsat.analysis.modal import modal_analysis
from flexsat.config import validate_config
from flexsat.config.load import preset_path
from flexsat.control.stages.sadm_drive import SADMDriveConfig
from flexsat.dynamics.appendages.modal import DRIVE_COORDINATE
from flexsat.dynamics.appendages.sadm import DRIVE_COORDINATE as CHAIN_DRIVE
from flexsat.dynamics.appendages.sadm import with_sadm
from flexsat.linear import linearize
from flexsat.linear.export import modal_satellite
from flexsat.simulate import run_slew
from flexsat.simulate.scenario import SlewScenario
from tests.dynamics.appendages.test_modal_large_motion import beam_panels
from tests.dynamics.appendages.test_sadm import _run

SEED = 23
ROTOR = {"rotor_inertia_kg_m2": 0.1, "rotor_mass_kg": 2.0}  # [kg m^2], [kg]
SPAN = [0.0, 1.0, 0.0]  # the chain preset's span axis, frame M [-]
TUMBLE = (0.5, -1.0, 2.0)  # initial Euler rates of the hub [deg/s]
SPIN = (5.0, -10.0, 20.0)  # a faster tumble, loading the modes centrifugally [deg/s]


@pytest.fixture(scope="module")
def chain() -> Plant:
    # The chain preset: two 8-segment panels on rx, ry, rz joints (24 clamped modes
    # each), damped.
    return Plant.from_config(load_config(preset_path("chain")))


def _driven(chain: Plant, n_modes: int | None = 6, large_motion: bool = True,
            axis=SPAN, **edits) -> dict:  # fmt: skip
    """The chain's modal export as a plain dict, each appendage on a drive about ``axis``."""
    data = modal_satellite(chain, n_modes, large_motion).model_dump(exclude_none=True)
    for app in data["appendages"]:
        app.update({"drive": dict(ROTOR), "drive_axis": list(axis), **edits})
    return data


@pytest.fixture(scope="module")
def driven(chain) -> Plant:
    return Plant.from_config(validate_config(_driven(chain)))


@pytest.mark.parametrize("large_motion", [True, False])
def test_accelerations_solve_the_lagrangian_equations(chain, large_motion):
    # Articulated form (pass 1 with the drive eliminated, hub solve, pass 2: eqs.
    # D.3-D.6) against M(q)^-1 (Q - h - C q_dot - K q), M built column by column from
    # T (D.7) and h the body's wrench at q_ddot = 0, at random states far from rest
    # (seeded), drive torque included: both exact, they differ by the round-off of a
    # 20 x 20 solve (measured 1e-15); T = 1/2 q_dot^T M q_dot likewise.
    print(f"seed {SEED}")
    rng = np.random.default_rng(SEED)
    plant = Plant.from_config(validate_config(_driven(chain, 6, large_motion,
                                                      axis=[0.3, 1.0, -0.2])))  # fmt: skip
    for _ in range(4):
        q, qd = rng.normal(size=(2, plant.n_dof)) * 0.3
        Q = rng.normal(size=plant.n_dof)
        qdd = plant.accelerations(q, qd, Q)
        M = plant.mass_matrix(q)
        rhs = Q - plant.bias_forces(q, qd) - plant.damping_forces(qd) - plant.elastic_forces(q)
        expected = np.linalg.solve(M, rhs)
        np.testing.assert_allclose(qdd, expected, rtol=0, atol=1e-12 * np.abs(expected).max())
        assert plant.kinetic_energy(q, qd) == pytest.approx(0.5 * qd @ M @ qd, rel=1e-13)


def _rigidly_mounted(chain: Plant, alpha: float, axis) -> Plant:
    """The driven satellite's appendages mounted at drive angle ``alpha`` [rad]: mount
    R_BM0 Rot(u, alpha), the rotor (mass on the axis at the interface, inertia J_r in
    every direction) added to the data's rigid body."""
    data = modal_satellite(chain, 6).model_dump(exclude_none=True)
    u = np.asarray(axis) / np.linalg.norm(axis)
    m_r, J_r = ROTOR["rotor_mass_kg"], ROTOR["rotor_inertia_kg_m2"]
    for app in data["appendages"]:
        R0 = np.asarray(app["mount_matrix"])
        app["mount_matrix"] = (R0 @ Rotation.from_rotvec(alpha * u).as_matrix()).tolist()
        modes = app["data"]
        m = modes["mass_kg"]
        modes["center_of_mass_m"] = (np.asarray(modes["center_of_mass_m"]) * m
                                     / (m + m_r)).tolist()  # fmt: skip
        modes["mass_kg"] = m + m_r
        modes["inertia_interface_kg_m2"] = (np.asarray(modes["inertia_interface_kg_m2"])
                                            + J_r * np.eye(3)).tolist()  # fmt: skip
    return Plant.from_config(validate_config(data))


@pytest.mark.parametrize("alpha", [0.7, -2.4])
def test_a_held_drive_is_the_appendage_mounted_at_that_angle(chain, alpha):
    # Drive angle alpha held (alpha_dot = 0 and the motor torque that makes
    # alpha_ddot = 0), about an oblique axis, large-motion terms on: every other row
    # of M(q), h(q, q_dot) and q_ddot, T, U and H equal the appendage mounted at R_BM0
    # Rot(u, alpha) with the rotor in its data. Both are exact, the same equations in
    # another frame: equal to round-off (measured 1e-15; bound 1e-12 of each array).
    axis = [0.3, 1.0, -0.2]
    print(f"seed {SEED}")
    rng = np.random.default_rng(SEED)
    plant = Plant.from_config(validate_config(_driven(chain, axis=axis)))
    fixed = _rigidly_mounted(chain, alpha, axis)
    names = plant.layout.dof_names()
    drives = [names.index(f"panel_{k}.{DRIVE_COORDINATE}") for k in (1, 2)]
    keep = [i for i in range(plant.n_dof) if i not in drives]
    assert [names[i] for i in keep] == fixed.layout.dof_names()

    def close(a, b):
        np.testing.assert_allclose(a, b, rtol=0, atol=1e-12 * np.abs(b).max())

    for _ in range(3):
        q_f, qd_f = rng.normal(size=(2, fixed.n_dof)) * 0.3
        Q_f = rng.normal(size=fixed.n_dof)
        q, qd, Q = np.full(plant.n_dof, alpha), np.zeros(plant.n_dof), np.zeros(plant.n_dof)
        q[keep], qd[keep], Q[keep] = q_f, qd_f, Q_f
        close(plant.mass_matrix(q)[np.ix_(keep, keep)], fixed.mass_matrix(q_f))
        close(plant.bias_forces(q, qd)[keep], fixed.bias_forces(q_f, qd_f))
        # q_ddot is affine in the drive torques: the pair that holds both drives.
        base = plant.accelerations(q, qd, Q)
        columns = []
        for d in drives:
            unit = Q.copy()
            unit[d] += 1.0
            columns.append(plant.accelerations(q, qd, unit) - base)
        columns = np.array(columns).T
        torques = np.linalg.solve(columns[drives], -base[drives])
        held = base + columns @ torques
        assert np.abs(held[drives]).max() <= 1e-12 * np.abs(held).max()
        close(held[keep], fixed.accelerations(q_f, qd_f, Q_f))
        assert plant.kinetic_energy(q, qd) == pytest.approx(fixed.kinetic_energy(q_f, qd_f),
                                                            rel=1e-12)  # fmt: skip
        assert plant.elastic_energy(q) == pytest.approx(fixed.elastic_energy(q_f), rel=1e-12)
        close(plant.angular_momentum(q, qd), fixed.angular_momentum(q_f, qd_f))
        close(plant.locked_inertia(q), fixed.locked_inertia(q_f))


def _drive_params(plant: Plant, coordinate: str, rate_deg_s: float = 2.0) -> np.ndarray:
    """The sadm_drive stage on ``coordinate`` of every appendage: a 0.1 Hz loop on
    3.1 kg m^2 (rotor and a panel about its span), critically damped."""
    inertia, omega_n = 3.1, 2.0 * np.pi * 0.1  # [kg m^2], [rad/s]
    config = SADMDriveConfig(
        coordinates=[coordinate],
        stiffness_nm_rad=inertia * omega_n**2,
        damping_nms_rad=2.0 * omega_n * inertia,
        rate_deg_s=rate_deg_s,
    )
    return np.ascontiguousarray(config.packed(SlewScenario(), plant))  # fmt: skip


def _no_drive(plant: Plant) -> np.ndarray:
    """The sadm_drive stage's packed parameters with no driven coordinate (no torque)."""
    return np.array([1.0, 0.0, -1.0, 0.0, 0.0, 0.0, 0.0])


def _balance(plant: Plant, log: np.ndarray):
    """Momentum drift (relative) and max |E - E0 - W_in + W_diss| [J], E = T + U."""
    n = plant.n_dof
    q, qd = log[:, :n], log[:, n : 2 * n]
    H = np.array([plant.angular_momentum(a, b) for a, b in zip(q, qd, strict=True)])
    energy = np.array([plant.kinetic_energy(a, b) + plant.elastic_energy(a)
                       for a, b in zip(q, qd, strict=True)])  # fmt: skip
    residual = energy - energy[0] - log[:, 2 * n] + log[:, 2 * n + 1]
    return np.abs(H - H[0]).max() / np.linalg.norm(H[0]), np.abs(residual).max()


def test_drive_torque_is_internal_momentum_and_energy(driven):
    # Both modal arrays (6 modes, large-motion invariants: centrifugal stiffening and
    # gyroscopic coupling; the full modal damping) driven at 2 deg/s for 10 s on a hub
    # tumbling at up to 20 deg/s, no hub torque, RK4 with the drive's torque held over
    # each step. H is an exact invariant of the equations: bound 1e-10 relative (RK4's
    # drift measured 1.5e-11 at 1 ms, 9.4e-13 at 0.5 ms). Energy: d(T + U)/dt =
    # tau alpha_dot - eta_dot^T D eta_dot (eq. D.8), both integrated by the RK4 stages
    # (W_in, W_diss), so the residual is RK4's truncation alone: measured 2.1e-10 J then
    # 1.3e-11 J (a factor 16.6, 4th order) of a 0.054 J drive work and E0 = 12.4 J.
    # Bounds: at least 8x smaller at half the step, and 1e-9 of the work at 0.5 ms.
    assert driven.params[0][63] > 0.0  # the large-motion invariants are packed
    residual = {}
    for dt in (1e-3, 5e-4):
        log = _run(driven, _drive_params(driven, DRIVE_COORDINATE), SPIN, 10.0, dt)
        drift, residual[dt] = _balance(driven, log)
        n = driven.n_dof
        work, dissipated = np.abs(log[:, 2 * n]).max(), log[-1, 2 * n + 1]
        print(f"dt {dt}: momentum drift {drift:.1e}, energy residual {residual[dt]:.1e} J "
              f"of the work {work:.2e} J (dissipated {dissipated:.2e} J)")  # fmt: skip
        assert drift <= 1e-10
        assert work > 1e-4 and dissipated > 0.0
        elastic = np.array([driven.elastic_energy(q) for q in log[:, :n]])
        assert elastic.max() > 0.0
    assert residual[1e-3] >= 8.0 * residual[5e-4]
    assert residual[5e-4] <= 1e-9 * work


def test_a_damped_chain_on_a_drive_closes_its_energy_balance(chain):
    # The chain's own drive (tests/dynamics/appendages/test_sadm.py holds it undamped):
    # with the preset's joint damping, the same run as the modal arrays', E - E0 - W_in
    # + W_diss is RK4's truncation (measured 2.1e-10 J then 1.3e-11 J, 4th order):
    # >= 8x smaller at half the step and 1e-9 of the work; H conserved to 1e-10.
    plant = Plant.from_config(with_sadm(chain.config, **ROTOR))
    residual = {}
    for dt in (1e-3, 5e-4):
        log = _run(plant, _drive_params(plant, CHAIN_DRIVE), SPIN, 10.0, dt)
        drift, residual[dt] = _balance(plant, log)
        print(f"chain, dt {dt}: momentum drift {drift:.1e}, energy residual "
              f"{residual[dt]:.1e} J, dissipated {log[-1, -1]:.2e} J")  # fmt: skip
        assert drift <= 1e-10
        assert log[-1, -1] > 0.0
    assert residual[1e-3] >= 8.0 * residual[5e-4]
    assert residual[5e-4] <= 1e-9 * np.abs(log[:, 2 * plant.n_dof]).max()


@pytest.fixture(scope="module")
def beams() -> tuple[Plant, Plant]:
    """A satellite whose panels are 8-segment beams (the chain comparison of
    test_modal_large_motion.py) and the same on drives about the span axis."""
    chain = beam_panels()
    return chain, Plant.from_config(with_sadm(chain.config, **ROTOR))


def test_the_driven_export_is_the_driven_chains_second_order_expansion(beams):
    # Along eta = e eta_1 (three modes of each panel, all 16 kept, undamped) at drive
    # angle 0.4 rad, hub attitude (0.2, -0.1, 0.3) rad: every acceleration and its
    # first and second derivatives in e (central differences, step 5e-3) against the
    # driven chain's mapped to modal coordinates (the drive angle is the rotor joint's
    # angle). The modal model is the chain's expansion to second order in the modes,
    # the drive's rotation exact: at e = 0 they agree to round-off (measured 2.9e-12
    # and 1.1e-11 of the largest; bound 1e-10); the first derivatives to the
    # differences' error (6.1e-6, 1.5e-6, 3.8e-7 at steps 5e-3, 2.5e-3, 1.25e-3; bound
    # 1e-4); the second derivatives differ by 2.9e-3 with the drive at rest and 3.9e-3
    # turning (the frame's rate is then larger), at every step: the export's own
    # second-order error on these beams, whose segments keep a small rotational
    # inertia (bound 1e-2). A drive turning at 0.3 rad/s adds no error of its own: its
    # case within 2x the case of the drive at rest, plus 1e-5.
    chain, driven_chain = beams
    chain = chain.with_joints(chain.stiffness, np.zeros(chain.n_dof - 6))
    driven_chain = driven_chain.with_joints(driven_chain.stiffness,
                                            np.zeros(driven_chain.n_dof - 6))  # fmt: skip
    plant = Plant.from_config(validate_config(_driven(chain, None)))
    plant = plant.with_joints(plant.stiffness, np.zeros(plant.n_dof - 6))
    T = np.zeros((driven_chain.n_dof, plant.n_dof))
    T[:6, :6] = np.eye(6)
    M0, K = chain.mass_matrix(), chain.stiffness_matrix()
    eta_1, base = np.zeros(plant.n_dof), np.zeros(plant.n_dof)
    base[3:6] = [0.2, -0.1, 0.3]
    drives = []
    for name in ("panel_1", "panel_2"):
        b, c, m = (p.layout.block(name).slice for p in (chain, driven_chain, plant))
        T[c.start, m.start] = 1.0
        T[c.start + 1 : c.stop, m.start + 1 : m.stop] = eigh(K[b, b], M0[b, b])[1]
        eta_1[m.start + 1 : m.start + 4] = [1.0, 0.5, -0.7]
        base[m.start] = 0.4
        drives.append(m.start)
    T_inv = np.linalg.inv(T)
    zero = np.zeros(plant.n_dof)

    def derivatives(f, step=5e-3):
        plus, at, minus = f(step), f(0.0), f(-step)
        return at, (plus - minus) / (2 * step), (plus - 2 * at + minus) / step**2

    errors = {}
    for drive_rate in (0.0, 0.3):
        rates = np.zeros(plant.n_dof)
        rates[3:6] = [0.3, -0.15, 0.21]
        rates[drives] = drive_rate
        chain_d = derivatives(lambda e, r=rates: T_inv @ driven_chain.accelerations(
            T @ (base + e * eta_1), T @ r, T @ zero))  # fmt: skip
        modal_d = derivatives(lambda e, r=rates: plant.accelerations(base + e * eta_1, r, zero))
        errors[drive_rate] = [np.abs(a - b).max() / np.abs(a).max()
                              for a, b in zip(chain_d, modal_d, strict=True)]  # fmt: skip
        print(f"drive rate {drive_rate}: " + ", ".join(f"{e:.1e}" for e in errors[drive_rate]))
        assert errors[drive_rate][0] <= 1e-10
        assert errors[drive_rate][1] <= 1e-4
        assert errors[drive_rate][2] <= 1e-2
    assert errors[0.3][1] <= 2.0 * errors[0.0][1] + 1e-5
    assert errors[0.3][2] <= 2.0 * errors[0.0][2] + 1e-5


def test_the_driven_export_follows_the_driven_chain(beams):
    # The beam satellite on its own drives (rotor segment 0) against its modal export
    # on drives with the same rotors, both turned at 2 deg/s for 20 s (40 deg) on a
    # tumbling hub (RK4, 1 ms). The modal model's own error (its truncation to n modes,
    # its second-order expansion) is what the same run shows with the drives idle (no
    # torque). Measured, hub rate against its peak, driven (idle): all 16 modes 1.3e-7
    # (9.0e-8), 6 modes 4.5e-6 (7.8e-6), 3 modes 1.5e-4 (2.6e-4); the drive angles to
    # 4e-9 rad at most. Bounds: the driven error within 2x the idle error of the same
    # model plus 1e-7 of the peak (the drive adds no error of its own), the drive angle
    # within 1e-6 of its 0.7 rad.
    chain, driven_chain = beams
    log = _run(driven_chain, _drive_params(driven_chain, CHAIN_DRIVE), TUMBLE, 20.0)
    idle = _run(chain, _no_drive(chain), TUMBLE, 20.0)
    n_c, n_chain = driven_chain.n_dof, chain.n_dof
    angle_c = log[:, [driven_chain.layout.dof_names().index(f"panel_{k}.{CHAIN_DRIVE}")
                      for k in (1, 2)]]  # fmt: skip
    rate_c, idle_rate_c = log[:, n_c + 3 : n_c + 6], idle[:, n_chain + 3 : n_chain + 6]
    assert np.degrees(angle_c[-1]) == pytest.approx([40.0, 40.0], abs=0.5)
    errors = {}
    for n_modes in (None, 6, 3):
        plant = Plant.from_config(validate_config(_driven(chain, n_modes)))
        fixed = Plant.from_config(modal_satellite(chain, n_modes))
        n = plant.n_dof
        log_m = _run(plant, _drive_params(plant, DRIVE_COORDINATE), TUMBLE, 20.0)
        angle = log_m[:, [plant.layout.dof_names().index(f"panel_{k}.{DRIVE_COORDINATE}")
                          for k in (1, 2)]]  # fmt: skip
        idle_m = _run(fixed, _no_drive(fixed), TUMBLE, 20.0)
        rate_error = np.abs(log_m[:, n + 3 : n + 6] - rate_c).max() / np.abs(rate_c).max()
        idle_error = np.abs(idle_m[:, fixed.n_dof + 3 : fixed.n_dof + 6]
                            - idle_rate_c).max() / np.abs(idle_rate_c).max()  # fmt: skip
        angle_error = np.abs(angle - angle_c).max()
        errors[n_modes] = rate_error
        print(f"{n_modes or 'all'} modes: hub rate {rate_error:.1e} of its peak (idle "
              f"{idle_error:.1e}), drive angle {angle_error:.1e} rad")  # fmt: skip
        assert rate_error <= 2.0 * idle_error + 1e-7
        assert angle_error <= 1e-6 * np.abs(angle_c).max()
    assert errors[None] < errors[6] < errors[3]  # the truncation's error, mode by mode


def test_the_drive_is_a_named_coordinate_the_stage_drives_and_records(driven):
    # The closed loop with the sadm_drive stage on 'drive_angle': the coordinate is in
    # the records, the motor's torque and power are recorded, the angle follows the
    # command (0.5 deg/s for 2 s: 1 deg, within the 1 Hz loop's lag r / omega_n).
    stage = {"kind": "sadm_drive", "coordinates": [DRIVE_COORDINATE], "stiffness_nm_rad": 40.0,
             "damping_nms_rad": 8.0, "rate_deg_s": 0.5}  # fmt: skip
    scenario = SlewScenario.model_validate({"duration_s": 2.0, "joint_actuator": stage})
    ds = run_slew(driven, scenario, progress=False).dataset
    dofs = list(ds["dof"].values)
    assert f"panel_1.{DRIVE_COORDINATE}" in dofs
    angle = ds["q"].sel(dof=f"panel_2.{DRIVE_COORDINATE}").values
    lag = 0.5 / np.sqrt(40.0 / 3.1) * 2  # [deg] twice r / omega_n, the J = 3.1 kg m^2 loop's
    assert np.degrees(angle[-1]) == pytest.approx(1.0, abs=lag)
    assert np.abs(ds["sadm_torque"].values).max() > 0.0
    assert np.isfinite(ds["sadm_power"].values).all()
    # The modal analysis counts each drive angle as a rigid-body mode (no stiffness).
    analysis = modal_analysis(driven)
    assert np.all(analysis.frequencies_hz[:8] == 0.0) and analysis.frequencies_hz[8] > 0.0


def test_the_measured_design_model_follows_a_modal_drive(chain):
    # The sadm_drive stage's design_model = "measured" freezes the appendage at its
    # drive angle (ModalModel.rigid_body_at, from the packed row in numpy): J_tot there
    # equals the kernels' locked inertia (observe, eq. D.8) at that angle, and the
    # degree-2 trigonometric polynomial of docs/control.md holds it at any angle, both
    # to round-off (measured 3e-14 kg m^2 of 190; bound 1e-12 relative), about an
    # oblique axis.
    from flexsat.control.stages.sadm_drive import design_coefficients
    from flexsat.dynamics.rigid import rigid_inertia

    plant = Plant.from_config(validate_config(_driven(chain, 3, axis=[0.3, 1.0, -0.2])))
    names = plant.layout.dof_names()
    drives = [names.index(f"panel_{k}.{DRIVE_COORDINATE}") for k in (1, 2)]
    q = np.zeros(plant.n_dof)
    q[drives] = [0.7, -1.1]
    scale = np.abs(plant.locked_inertia(q)).max()
    assert np.abs(rigid_inertia(plant, q) - plant.locked_inertia(q)).max() <= 1e-12 * scale
    P = design_coefficients(plant, drives, np.zeros(plant.n_dof))[0]
    a = 0.9  # [rad]
    change = (np.cos(a) - 1.0, np.sin(a), np.cos(2.0 * a) - 1.0, np.sin(2.0 * a))
    J = rigid_inertia(plant, np.zeros(plant.n_dof)) + np.tensordot(change, P, axes=1)
    q = np.zeros(plant.n_dof)
    q[drives[0]] = a
    assert np.abs(J - rigid_inertia(plant, q)).max() <= 1e-12 * scale


def test_the_driven_modal_satellite_linearizes(chain):
    # About rest, the analytic Jacobian (M(0), K, C) against Richardson differences of
    # the accelerations, the drive angle's rows and its motor's input column included
    # (measured 6.8e-13 of the largest entry of A, 6e-15 of B; bound 1e-9, as for the
    # plate's), with the export's full modal damping matrix (C_damp's whole block).
    data = _driven(chain)
    assert all(app["data"]["damping_matrix"] for app in data["appendages"])
    plant = Plant.from_config(validate_config(data))
    analytic = linearize(plant, actuated=[DRIVE_COORDINATE])
    fd = linearize(plant, actuated=[DRIVE_COORDINATE], jacobian="richardson")
    assert np.abs(fd.A - analytic.A).max() <= 1e-9 * np.abs(analytic.A).max()
    assert np.abs(fd.B - analytic.B).max() <= 1e-9 * np.abs(analytic.B).max()
    assert analytic.input_names[3:] == tuple(f"Q_panel_{k}.{DRIVE_COORDINATE}" for k in (1, 2))


@pytest.mark.parametrize(("edits", "fragment"), [
    ({"drive_axis": None}, "drive_axis: a modal appendage on a drive needs its axis"),
    ({"drive_axis": [0.0, 0.0, 0.0]}, "drive_axis: the drive axis must be a nonzero vector"),
    ({"drive": None}, "drive_axis: only an appendage on a drive"),
    ({"drive": {"rotor_inertia_kg_m2": -1.0, "rotor_mass_kg": 2.0}},
     "drive.rotor_inertia_kg_m2: Input should be greater than 0"),
])  # fmt: skip
def test_bad_drives_give_one_message(chain, edits, fragment):
    data = _driven(chain)
    data["appendages"][0].update(edits)
    data["appendages"][0] = {k: v for k, v in data["appendages"][0].items() if v is not None}
    with pytest.raises(ConfigError) as caught:
        validate_config(data)
    message = str(caught.value)
    print(message)
    assert fragment in message and "appendages[0]" in message
    assert "\n" not in message


def test_with_sadm_leaves_a_modal_appendage_without_an_axis_alone(chain):
    config = modal_satellite(chain, 3)
    assert with_sadm(config, **ROTOR) == config
