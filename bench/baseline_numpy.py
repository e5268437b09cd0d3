"""Baseline for the open-loop benchmark: the flexible satellite in plain NumPy + SciPy.

This is the model as a typical user writes it when porting a MATLAB script to
Python: per call, build the 18x18 mass matrix M(q) and the Coriolis and
centrifugal vector h(q, q_dot), add the joint damping C q_dot and the elastic
forces K q, and get q_ddot from ``np.linalg.solve``. It is integrated two ways:

* :func:`run_baseline_rk4`: classic RK4 at a fixed 1 ms step in a plain Python
  ``for`` loop, the torque held over each step (what the thesis's MATLAB script
  does);
* :func:`run_baseline_solve_ivp`: ``scipy.integrate.solve_ivp`` (DOP853 by
  default, rtol 1e-8, atol 1e-10), restarted at the torque switch t = 10 s.

Scenario (thesis open loop): at rest, body torque (0, 0, 1) N m for 0 <= t < 10 s,
then free, to 120 s. Expected: final yaw rate about 3.2207 deg/s, total angular
momentum about Z 10 N m s.

Where M(q) and h(q, q_dot) come from
------------------------------------
Two routes a user would take are written here; ``model=`` picks one.

``"sympy"`` (the default, used by the benchmark): the SymPy-generated functions
of :func:`flexsat.dynamics.symbolic.reference_model`, i.e. the equations derived
symbolically by Euler-Lagrange and turned into code with common subexpressions
eliminated. That is exactly the MATLAB workflow (Symbolic Toolbox, then
``matlabFunction``), and it is the faster of the two routes (about 0.25 ms per
q_ddot against 0.35 ms on a 2-CPU x86-64 machine), so the speed-ups the
benchmark reports are the conservative ones.

``"jacobian"``: a hand-written, independent numpy implementation. The satellite
is a set of rigid bodies (hub, two panels); body b has a centre-of-mass velocity
v_b = Jv_b(q) q_dot (inertial frame N) and an angular velocity w_b = Jw_b(q) q_dot
(its own frame), and Lagrange's equations take the textbook form

    M(q)        = sum_b  Jv_b^T m_b Jv_b + Jw_b^T I_b Jw_b
    h(q, q_dot) = sum_b  Jv_b^T m_b (dJv_b/dt q_dot)
                         + Jw_b^T (I_b (dJw_b/dt q_dot) + w_b x I_b w_b)

The Jacobians are written out from the kinematics; dJ/dt q_dot, the one term a
user would rather not differentiate by hand, is a central finite difference
along the motion, (J(q + s q_dot) - J(q - s q_dot)) / (2 s) with s = 1e-5 s
(h agrees with the exact one to about 1e-10 relative). It shares no code with
flexsat, so it checks both flexsat's compiled engine and the generated route
(:func:`check_against_flexsat`), and it gives the angular momentum reported by
both routes.

flexsat is used only for the configuration (``flexsat.config.nominal()``), the
tuned joint stiffness and damping (``Plant.from_config(cfg).stiffness`` and
``.damping``), the generated functions of the ``"sympy"`` route and, in
:func:`check_against_flexsat`, to compare results.

Conventions (the same as flexsat's): q = [r (3), Theta = (phi, theta, psi),
eta_1 (3), rho_1 (3), eta_2 (3), rho_2 (3)]; R_NB = Rz(psi) Ry(theta) Rx(phi);
omega_B = S(phi, theta) Theta_dot; a body torque tau gives Q[3:6] = S^T tau.

Run ``python bench/baseline_numpy.py [duration_s] [sympy|jacobian]`` for the
checks and both runs.
"""

from __future__ import annotations

import math
import sys
import time

import numpy as np
from scipy.integrate import solve_ivp

import harness  # the benchmarks run with bench/ on sys.path
from flexsat import Plant
from flexsat.config import nominal
from flexsat.dynamics.symbolic import ReferenceParameters, reference_model

N_DOF = 18
TORQUE_ON = np.array([0.0, 0.0, 1.0])  # body torque during the pulse [N m]
TORQUE_END_S = 10.0  # the torque acts for 0 <= t < 10 s
FD_STEP_S = 1e-5  # finite-difference step for dJ/dt q_dot [s]
MODELS = ("sympy", "jacobian")


# ---------------------------------------------------------------------------
# Rotations
# ---------------------------------------------------------------------------


def rot_x(a):
    c, s = np.cos(a), np.sin(a)
    return np.array([[1.0, 0.0, 0.0], [0.0, c, -s], [0.0, s, c]])


def rot_y(a):
    c, s = np.cos(a), np.sin(a)
    return np.array([[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]])


def rot_z(a):
    c, s = np.cos(a), np.sin(a)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


def rot_zyx(angles):
    """Rz(a_z) Ry(a_y) Rx(a_x) for angles = (a_x, a_y, a_z), written out (thesis eq. 2.25)."""
    cx, sx = math.cos(angles[0]), math.sin(angles[0])
    cy, sy = math.cos(angles[1]), math.sin(angles[1])
    cz, sz = math.cos(angles[2]), math.sin(angles[2])
    return np.array(
        [
            [cz * cy, cz * sy * sx - sz * cx, cz * sy * cx + sz * sx],
            [sz * cy, sz * sy * sx + cz * cx, sz * sy * cx - cz * sx],
            [-sy, cy * sx, cy * cx],
        ]
    )


def euler_rate_matrix(angles):
    """S with omega (body frame) = S @ ZYX angle rates (thesis eq. 2.28)."""
    ca, sa = math.cos(angles[0]), math.sin(angles[0])
    cb, sb = math.cos(angles[1]), math.sin(angles[1])
    return np.array([[1.0, 0.0, -sb], [0.0, ca, cb * sa], [0.0, -sa, cb * ca]])


def skew(v):
    """Cross-product matrix: skew(a) @ b == np.cross(a, b) (np.cross is ~40 us on 3-vectors)."""
    return np.array([[0.0, -v[2], v[1]], [v[2], 0.0, -v[0]], [-v[1], v[0], 0.0]])


# ---------------------------------------------------------------------------
# Parameters
# ---------------------------------------------------------------------------


def load_parameters(cfg=None):
    """Numeric parameters of the satellite (a dict, like a MATLAB parameter struct)."""
    cfg = cfg or nominal()
    plant = Plant.from_config(cfg)  # only for the tuned joint stiffness and damping
    panels = []
    for app in cfg.appendages:
        yaw, sadm = np.radians(app.mount_yaw_deg), np.radians(app.sadm_angle_deg)
        panels.append(
            {
                "m": app.mass,
                "J": app.centroidal_inertia(),  # about the panel CoM, panel frame
                "r_m": np.array(app.mount_point_m, dtype=float),  # root in hub frame
                "R_BM": rot_z(yaw) @ rot_y(sadm),  # mount frame -> hub frame
                "d": np.array([0.0, 0.5 * app.span_sign() * app.length_m, 0.0]),  # root -> CoM
            }
        )
    if 6 + 6 * len(panels) != N_DOF:
        raise ValueError(f"the baseline is written for two panels, got {len(panels)}")
    k = np.concatenate([np.zeros(6), plant.stiffness.ravel()])
    c = np.concatenate([np.zeros(6), plant.damping.ravel()])
    return {
        "config": cfg,
        "stiffness": plant.stiffness.reshape(-1, 6),
        "damping": plant.damping.reshape(-1, 6),
        "m_hub": cfg.hub.mass_kg,
        "J_hub": cfg.hub.inertia(),
        "panels": panels,
        "K": np.diag(k),
        "C": np.diag(c),
    }


# ---------------------------------------------------------------------------
# Equations of motion
# ---------------------------------------------------------------------------


def body_jacobians(q, p):
    """[(m, I, Jv, Jw, R_NX, r_N)] for the hub and each panel.

    Jv (3 x 18) maps q_dot to the centre-of-mass velocity in frame N; Jw (3 x 18)
    to the body's angular velocity in its own frame; I is the inertia about the
    centre of mass in that frame, R_NX the body's attitude and r_N its centre of mass.
    """
    Theta = q[3:6]
    R_NB = rot_zyx(Theta)
    S = euler_rate_matrix(Theta)

    Jv = np.zeros((3, N_DOF))
    Jw = np.zeros((3, N_DOF))
    Jv[:, 0:3] = np.eye(3)
    Jw[:, 3:6] = S
    bodies = [(p["m_hub"], p["J_hub"], Jv, Jw, R_NB, q[0:3])]

    for i, panel in enumerate(p["panels"]):
        o = 6 + 6 * i
        eta, rho = q[o : o + 3], q[o + 3 : o + 6]
        R_BM = panel["R_BM"]
        R_MP = rot_zyx(rho)
        R_BP = R_BM @ R_MP
        S_rho = euler_rate_matrix(rho)
        r_G = panel["r_m"] + R_BM @ (eta + R_MP @ panel["d"])  # panel CoM in hub frame

        # v_G = r_dot + R_NB (omega_B x r_G + R_BM eta_dot + R_BP (omega_rel x d))
        Jv = np.zeros((3, N_DOF))
        Jv[:, 0:3] = np.eye(3)
        Jv[:, 3:6] = -R_NB @ skew(r_G) @ S
        Jv[:, o : o + 3] = R_NB @ R_BM
        Jv[:, o + 3 : o + 6] = -R_NB @ R_BP @ skew(panel["d"]) @ S_rho
        # omega_P = R_BP^T omega_B + S(rho) rho_dot
        Jw = np.zeros((3, N_DOF))
        Jw[:, 3:6] = R_BP.T @ S
        Jw[:, o + 3 : o + 6] = S_rho
        bodies.append((panel["m"], panel["J"], Jv, Jw, R_NB @ R_BP, q[0:3] + R_NB @ r_G))
    return bodies


def mass_matrix(bodies):
    M = np.zeros((N_DOF, N_DOF))
    for m, inertia, Jv, Jw, _, _ in bodies:
        M += m * Jv.T @ Jv + Jw.T @ inertia @ Jw
    return M


def coriolis_centrifugal(q, qd, p, bodies):
    """h(q, q_dot), with dJ/dt q_dot from a central difference along q_dot."""
    ahead = body_jacobians(q + FD_STEP_S * qd, p)
    behind = body_jacobians(q - FD_STEP_S * qd, p)
    h = np.zeros(N_DOF)
    for (m, inertia, Jv, Jw, _, _), fwd, bwd in zip(bodies, ahead, behind, strict=True):
        Jv_dot = (fwd[2] - bwd[2]) / (2.0 * FD_STEP_S)
        Jw_dot = (fwd[3] - bwd[3]) / (2.0 * FD_STEP_S)
        w = Jw @ qd
        h += m * Jv.T @ (Jv_dot @ qd)
        h += Jw.T @ (inertia @ (Jw_dot @ qd) + skew(w) @ (inertia @ w))
    return h


def generalized_forces(q, torque):
    """Q of a body torque on the hub (frame B): Q[3:6] = S(Theta)^T tau."""
    Q = np.zeros(N_DOF)
    Q[3:6] = euler_rate_matrix(q[3:6]).T @ torque
    return Q


def jacobian_accelerations(q, qd, torque, p):
    """q_ddot from M q_ddot + h + C q_dot + K q = Q, M and h from the body Jacobians."""
    bodies = body_jacobians(q, p)
    M = mass_matrix(bodies)
    h = coriolis_centrifugal(q, qd, p, bodies)
    Q = generalized_forces(q, torque)
    return np.linalg.solve(M, Q - h - p["C"] @ qd - p["K"] @ q)


def make_accelerations(p, model="sympy"):
    """The function (q, q_dot, torque) -> q_ddot of the chosen route (see the module doc)."""
    if model == "jacobian":
        return lambda q, qd, torque: jacobian_accelerations(q, qd, torque, p)
    if model != "sympy":
        raise ValueError(f"model must be one of {MODELS}, got {model!r}")

    generated = reference_model(len(p["panels"]))  # symbolic derivation + code generation
    params = ReferenceParameters.from_config(p["config"], p["stiffness"], p["damping"])

    def sympy_accelerations(q, qd, torque):
        terms = generated.evaluate(params, q, qd)  # M, h, k_el = K q, C
        Q = generalized_forces(q, torque)
        return np.linalg.solve(terms["M"], Q - terms["h"] - terms["C"] @ qd - terms["k_el"])

    return sympy_accelerations


def angular_momentum(q, qd, p):
    """Total angular momentum about the inertial origin, frame N [N m s]."""
    H = np.zeros(3)
    for m, inertia, Jv, Jw, R_NX, r_N in body_jacobians(q, p):
        H += m * skew(r_N) @ (Jv @ qd) + R_NX @ (inertia @ (Jw @ qd))
    return H


def body_rate(q, qd):
    """Hub angular velocity in the hub frame [rad/s]."""
    return euler_rate_matrix(q[3:6]) @ qd[3:6]


def torque_at(t):
    return TORQUE_ON if t < TORQUE_END_S else np.zeros(3)


def _summary(p, t_end, y, wall, **extra):
    q, qd = y[:N_DOF], y[N_DOF:]
    return {
        "simulated_s": t_end,
        "wall_time_s": wall,
        "final_rate_deg_s": float(np.degrees(body_rate(q, qd)[2])),
        "angular_momentum_z": float(angular_momentum(q, qd, p)[2]),
        "final_state": y,
        **extra,
    }


# ---------------------------------------------------------------------------
# Integration
# ---------------------------------------------------------------------------


def run_baseline_rk4(duration_s=120.0, dt=1e-3, model="sympy", record_dt=1e-2):
    """Fixed-step RK4 in a Python loop, torque held over each step; states every record_dt.

    Returns a dict: simulated_s, wall_time_s (the loop alone), final_rate_deg_s,
    angular_momentum_z, steps, evaluations, final_state, t_record, y_record, model.
    """
    p = load_parameters()
    accelerations = make_accelerations(p, model)

    def f(y, torque):
        q, qd = y[:N_DOF], y[N_DOF:]
        return np.concatenate([qd, accelerations(q, qd, torque)])

    n_steps = round(duration_s / dt)
    every = max(1, round(record_dt / dt))
    y = np.zeros(2 * N_DOF)  # at rest
    t_rec, y_rec = [0.0], [y.copy()]

    start = time.perf_counter()
    for k in range(n_steps):
        t = k * dt
        torque = torque_at(t)
        k1 = f(y, torque)
        k2 = f(y + 0.5 * dt * k1, torque)
        k3 = f(y + 0.5 * dt * k2, torque)
        k4 = f(y + dt * k3, torque)
        y = y + dt / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4)
        if (k + 1) % every == 0:
            t_rec.append((k + 1) * dt)
            y_rec.append(y)
    wall = time.perf_counter() - start

    return _summary(
        p, n_steps * dt, y, wall,
        steps=n_steps, evaluations=4 * n_steps, t_record=np.array(t_rec),
        y_record=np.array(y_rec), model=model,
    )  # fmt: skip


def run_baseline_solve_ivp(
    duration_s=120.0, method="DOP853", rtol=1e-8, atol=1e-10, model="sympy", record_dt=1e-2
):
    """scipy ``solve_ivp``, one call per constant-torque segment (split at t = 10 s).

    Returns a dict: simulated_s, wall_time_s (the solve_ivp calls and the dense-output
    sampling), final_rate_deg_s, angular_momentum_z, steps (accepted), evaluations,
    final_state, t_record, y_record (sampled every record_dt), method, model.
    """
    p = load_parameters()
    accelerations = make_accelerations(p, model)

    def f(t, y, torque):
        q, qd = y[:N_DOF], y[N_DOF:]
        return np.concatenate([qd, accelerations(q, qd, torque)])

    segments = [(0.0, min(TORQUE_END_S, duration_s))]  # constant torque on each
    if duration_s > TORQUE_END_S:
        segments.append((TORQUE_END_S, duration_s))
    t_rec = np.arange(math.floor(duration_s / record_dt + 1e-9) + 1) * record_dt
    y_rec = np.zeros((t_rec.size, 2 * N_DOF))
    y = np.zeros(2 * N_DOF)  # at rest
    evaluations = steps = 0

    start = time.perf_counter()
    for a, b in segments:
        sol = solve_ivp(
            f, (a, b), y, method=method, rtol=rtol, atol=atol, dense_output=True,
            args=(torque_at(a),),
        )  # fmt: skip
        if not sol.success:
            raise RuntimeError(f"solve_ivp failed on [{a}, {b}] s: {sol.message}")
        evaluations += sol.nfev
        steps += sol.t.size - 1
        inside = (t_rec >= a) & (t_rec <= b)
        y_rec[inside] = sol.sol(t_rec[inside]).T
        y = sol.y[:, -1]
    wall = time.perf_counter() - start

    return _summary(
        p, duration_s, y, wall,
        steps=steps, evaluations=evaluations, t_record=t_rec, y_record=y_rec,
        method=method, model=model,
    )  # fmt: skip


# ---------------------------------------------------------------------------
# Checks against flexsat
# ---------------------------------------------------------------------------


def check_against_flexsat(seed=0):
    """Largest relative differences from flexsat's engine at a random state.

    Compares M, h, q_ddot and the angular momentum of the Jacobian route, and
    q_ddot of the SymPy-generated route.
    """
    cfg = nominal()
    plant = Plant.from_config(cfg)
    p = load_parameters(cfg)
    rng = np.random.default_rng(seed)
    q = rng.normal(scale=0.2, size=N_DOF)
    qd = rng.normal(scale=0.2, size=N_DOF)
    torque = rng.normal(size=3)
    bodies = body_jacobians(q, p)
    a_ref = plant.accelerations(q, qd, plant.generalized_forces(q, torque))

    def rel(x, ref):
        return float(np.max(np.abs(x - ref)) / np.max(np.abs(ref)))

    return {
        "M": rel(mass_matrix(bodies), plant.mass_matrix(q)),
        "h": rel(coriolis_centrifugal(q, qd, p, bodies), plant.bias_forces(q, qd)),
        "q_ddot (jacobian)": rel(jacobian_accelerations(q, qd, torque, p), a_ref),
        "q_ddot (sympy)": rel(make_accelerations(p, "sympy")(q, qd, torque), a_ref),
        "angular_momentum": rel(angular_momentum(q, qd, p), plant.angular_momentum(q, qd)),
    }


def time_per_call_us(model="sympy", calls=500, repeats=5, seed=0):
    """Wall time of one q_ddot evaluation of the chosen route, best of ``repeats`` [us]."""
    p = load_parameters()
    accelerations = make_accelerations(p, model)
    rng = np.random.default_rng(seed)
    q = rng.normal(scale=0.1, size=N_DOF)
    qd = rng.normal(scale=0.1, size=N_DOF)

    def batch():
        for _ in range(calls):
            accelerations(q, qd, TORQUE_ON)

    accelerations(q, qd, TORQUE_ON)
    best, _ = harness.best_of(batch, repeats)
    return 1e6 * best / calls


def main(argv):
    duration = float(argv[1]) if len(argv) > 1 else 120.0
    model = argv[2] if len(argv) > 2 else "sympy"
    print("relative difference from flexsat:")
    for name, value in check_against_flexsat().items():
        print(f"  {name:18s} {value:.1e}")
    for route in MODELS:
        print(f"q_ddot per call, {route} route: {time_per_call_us(route):.0f} us")
    for name, run in (("RK4 loop", run_baseline_rk4), ("solve_ivp", run_baseline_solve_ivp)):
        out = run(duration, model=model)
        print(
            f"{name:10s} {out['simulated_s']:6.1f} s simulated in {out['wall_time_s']:8.2f} s, "
            f"yaw rate {out['final_rate_deg_s']:.6f} deg/s, "
            f"H_z {out['angular_momentum_z']:.9f} N m s, "
            f"{out['steps']} steps, {out['evaluations']} evaluations"
        )


if __name__ == "__main__":
    main(sys.argv)
