"""Gravity gradient: the hub torque, the tidal loads on a panel, and the pitch libration."""

from __future__ import annotations

import numpy as np
from scipy.integrate import solve_ivp
from scipy.spatial.transform import Rotation

from flexsat.environment.config import EnvironmentConfig
from flexsat.environment.geometry import load_geometry
from flexsat.environment.gravity_gradient import MU_EARTH, gravity_gradient_load
from flexsat.environment.loads import environment_data, environment_loads
from tests.environment.orbits import circular_ephemeris

SEED = 20261207


def _params(J: np.ndarray) -> np.ndarray:
    return np.concatenate([[MU_EARTH], J.ravel()])


def _hub_torque(eph_row, C_BN, J) -> np.ndarray:
    torque = np.zeros(3)
    gravity_gradient_load(eph_row, np.ascontiguousarray(C_BN), np.zeros((0, 4)),
                          np.zeros((0, 10)), _params(J), np.zeros((0, 3)), torque)  # fmt: skip
    return torque


def test_hub_torque_is_the_exact_field_on_point_masses_to_first_order() -> None:
    """3 mu/r^3 o x (J o) against the torque the exact inverse-square field puts on six
    point masses with the same inertia: they differ by O(rho/r) = 1e-6 (rho ~ 5 m,
    r ~ 7e6 m), so 1e-5 relative to the torque's size."""
    rng = np.random.default_rng(SEED)
    print(f"seed {SEED}")
    eph = circular_ephemeris(500e3, 51.6, 600.0, 10.0)[17]
    R = eph[1:4]
    for _ in range(5):
        C_BN = Rotation.random(random_state=rng).as_matrix()
        a = rng.uniform(1.0, 5.0, 3)  # +- a_i along each body axis, mass m each
        m = 10.0
        J = np.diag([2 * m * (a[1] ** 2 + a[2] ** 2), 2 * m * (a[0] ** 2 + a[2] ** 2),
                     2 * m * (a[0] ** 2 + a[1] ** 2)])  # fmt: skip
        exact = np.zeros(3)
        for axis in range(3):
            for sign in (1.0, -1.0):
                rho_B = np.zeros(3)
                rho_B[axis] = sign * a[axis]
                p = R + C_BN.T @ rho_B
                f_N = -MU_EARTH * m * p / np.linalg.norm(p) ** 3
                exact += np.cross(rho_B, C_BN @ f_N)
        torque = _hub_torque(eph, C_BN, J)
        assert np.linalg.norm(torque - exact) < 1e-5 * np.linalg.norm(exact)
        o = -C_BN @ R / np.linalg.norm(R)
        analytic = 3.0 * MU_EARTH / np.linalg.norm(R) ** 3 * np.cross(o, J @ o)
        # the same expression: only round-off apart
        assert np.allclose(torque, analytic, rtol=1e-12, atol=1e-15 * np.abs(analytic).max())


def test_force_on_a_panel_is_the_sum_over_its_mass_elements(nominal_plant) -> None:
    """The generalized forces on a plate's root translation (mount frame) are R_MB times
    the sum of its elements' tidal forces, which for a uniform plate is the tidal field
    at its centre of mass times its mass (the field is linear in position). Both are
    exact for the cut cells (first moments kept), so 1e-9 relative: the central
    difference of a linear map, round-off only."""
    config = EnvironmentConfig(models={"gravity_gradient": {}}, cells_per_side=3)
    eph = circular_ephemeris(500e3, 51.6, 600.0, 10.0)
    env = environment_data(nominal_plant, config, eph, "2026-01-01T00:00:00Z")
    geometry = load_geometry(nominal_plant, config)
    env.row[:] = eph[11]
    C_BN = Rotation.from_euler("ZYX", [30.0, 20.0, -40.0], degrees=True).as_matrix()
    env.C_BN[:] = C_BN
    assert environment_loads(env, np.zeros(1)) == 0
    R = eph[11, 1:4]
    r = np.linalg.norm(R)
    o = -C_BN @ R / r
    k = MU_EARTH / r**3
    for app, model, params, block in zip(nominal_plant.config.appendages, nominal_plant.models,
                                         nominal_plant.params, nominal_plant.layout.blocks,
                                         strict=True):  # fmt: skip
        body = model.rigid_body(params)
        total_B = body.mass * k * (3.0 * o * (o @ body.r_B) - body.r_B)
        R_BM = model.mount_rotation(params)
        Q_eta = env.Q[block.offset : block.offset + 3]
        assert np.allclose(Q_eta, R_BM.T @ total_B, rtol=1e-9, atol=1e-9 * np.abs(total_B).max())
        mine = geometry.appendage == nominal_plant.config.appendages.index(app)
        summed = env.force[mine].sum(axis=0)
        assert np.allclose(summed, total_B, rtol=1e-9, atol=1e-9 * np.abs(total_B).max())


def _libration_frequency(inertia: np.ndarray, altitude_m: float) -> tuple[float, float]:
    """Integrate a rigid satellite's attitude under the gravity-gradient kernel (scipy,
    tight tolerances) from a 1 deg pitch offset in the orbit frame; return the
    measured pitch frequency (zero crossings) and the orbit rate n."""
    a = 6_378_137.0 + altitude_m
    n = np.sqrt(MU_EARTH / a**3)
    J = np.diag(inertia)

    def orbit(t):
        c, s = np.cos(n * t), np.sin(n * t)
        return a * np.array([c, s, 0.0]), a * n * np.array([-s, c, 0.0])

    def lvlh(t):  # rows: along-track x, -orbit normal y, nadir z (ECI components)
        r, v = orbit(t)
        z = -r / np.linalg.norm(r)
        y = -np.cross(r, v) / np.linalg.norm(np.cross(r, v))
        return np.array([np.cross(y, z), y, z])

    eph = np.zeros(13)

    def rhs(t, y):
        q, w = y[:4] / np.linalg.norm(y[:4]), y[4:]
        C_BN = Rotation.from_quat(q).as_matrix().T  # q: B -> N (scalar last)
        eph[1:4] = orbit(t)[0]
        tau = _hub_torque(eph, C_BN, J)
        w_dot = np.linalg.solve(J, tau - np.cross(w, J @ w))
        qw = np.array([*w, 0.0])
        return np.concatenate([0.5 * _quat_mul(q, qw), w_dot])

    pitch0 = np.radians(1.0)
    R_NB = lvlh(0.0).T @ Rotation.from_euler("y", pitch0).as_matrix()
    w0 = np.array([0.0, -n, 0.0])  # turning with the orbit frame (y is -orbit normal)
    period = 2 * np.pi / (n * np.sqrt(3 * (inertia[0] - inertia[2]) / inertia[1]))
    times = np.linspace(0.0, 3.0 * period, 3000)
    sol = solve_ivp(rhs, (0, times[-1]), np.concatenate([Rotation.from_matrix(R_NB).as_quat(),
                    w0]), t_eval=times, rtol=1e-11, atol=1e-13, method="DOP853")  # fmt: skip
    pitch = np.array([
        Rotation.from_matrix(lvlh(t) @ Rotation.from_quat(q).as_matrix()).as_euler("xyz")[1]
        for t, q in zip(sol.t, sol.y[:4].T, strict=True)
    ])  # fmt: skip
    crossings = []
    for i in range(len(times) - 1):
        if pitch[i] > 0.0 >= pitch[i + 1] or pitch[i] < 0.0 <= pitch[i + 1]:
            w = pitch[i] / (pitch[i] - pitch[i + 1])
            crossings.append(times[i] + w * (times[i + 1] - times[i]))
    half_periods = np.diff(crossings)
    return np.pi / half_periods.mean(), n


def _quat_mul(p, q):  # scalar last
    pv, pw, qv, qw = p[:3], p[3], q[:3], q[3]
    return np.array([*(pw * qv + qw * pv + np.cross(pv, qv)), pw * qw - pv @ qv])


def test_pitch_libration_of_a_gravity_gradient_stable_satellite() -> None:
    """Pitch libration at n sqrt(3 (I_x - I_z) / I_y) (Wie, sec. 6.3) within 0.5 %: a
    1 deg amplitude shifts the frequency by ~1e-4 (the sin(2 theta) nonlinearity), the
    zero-crossing estimate over three periods sampled 1000 times each by < 1e-4."""
    inertia = np.array([120.0, 100.0, 40.0])  # roll (along-track), pitch, yaw (nadir)
    measured, n = _libration_frequency(inertia, 500e3)
    expected = n * np.sqrt(3.0 * (inertia[0] - inertia[2]) / inertia[1])
    print(f"pitch libration {measured:.6e} rad/s, expected {expected:.6e} rad/s")
    assert abs(measured / expected - 1.0) < 5e-3


def test_the_panels_tidal_forces_torque_the_hub(nominal_plant) -> None:
    """The hub's appendages are carried by it: their elements' moments reach its attitude,
    so the satellite's gravity-gradient torque is 3 mu/r^3 o x (J o) with J the whole
    satellite's inertia about the hub centre of mass (hub + each panel frozen, from the
    plant's rigid bodies). The cells keep each panel's first and second moments of area,
    not its thickness (J_p,xx and J_p,yy take M_p t_p^2 / 12, 3e-4 of them for the
    nominal 2 cm panels; measured 2e-5 of the torque), so 1e-4 relative to the torque's
    size; the hub's own term alone is off by more than 10 %."""
    config = EnvironmentConfig(models={"gravity_gradient": {}}, cells_per_side=4)
    eph = circular_ephemeris(500e3, 51.6, 600.0, 10.0)
    env = environment_data(nominal_plant, config, eph, "2026-01-01T00:00:00Z")
    env.row[:] = eph[23]
    C_BN = Rotation.from_euler("ZYX", [10.0, -35.0, 50.0], degrees=True).as_matrix()
    env.C_BN[:] = C_BN
    assert environment_loads(env, np.zeros(1)) == 0
    J = nominal_plant.config.hub.inertia().copy()
    for model, params in zip(nominal_plant.models, nominal_plant.params, strict=True):
        body = model.rigid_body(params)
        r = body.r_B
        J += body.J_B + body.mass * ((r @ r) * np.eye(3) - np.outer(r, r))
    R = eph[23, 1:4]
    o = -C_BN @ R / np.linalg.norm(R)
    expected = 3.0 * MU_EARTH / np.linalg.norm(R) ** 3 * np.cross(o, J @ o)
    hub_only = 3.0 * MU_EARTH / np.linalg.norm(R) ** 3 * np.cross(
        o, nominal_plant.config.hub.inertia() @ o)  # fmt: skip
    print(f"torque {env.torque} N m, expected {expected} N m, hub alone {hub_only} N m")
    assert np.linalg.norm(env.torque - expected) < 1e-4 * np.linalg.norm(expected)
    assert np.linalg.norm(hub_only - expected) > 0.1 * np.linalg.norm(expected)
