"""Linearization of the nonlinear plant about rest or about a steady spin.

The state of the linear model is written in body-frame variables, in which the
dynamics of a free satellite are autonomous also about a spin:

``x = [r_B, dTheta, eta, v_B, omega_BN_B, eta_dot]``

- ``r_B`` hub position, hub frame B [m]; ``v_B`` its inertial velocity in B [m/s];
- ``dTheta`` ZYX Euler angles (phi, theta, psi) of the hub attitude relative to
  the reference motion (the rest attitude, or the attitude spinning at a constant
  body rate ``W``) [rad];
- ``eta`` the joint coordinates of every appendage (as in the plant) and their rates;
- ``omega_BN_B`` body rate [rad/s].

Jacobians
---------
Complex-step differentiation does not pass through the numba kernels (compiled
for float64), and the kernels carry no automatic derivatives. So:

- **about rest**, A and B are the exact analytic form of the linearized eq. 2.50:
  ``A = [[0, I], [-M0^-1 K, -M0^-1 C]]``, ``B = [0; M0^-1 G]``, from the plant's
  own M(0), K_sys and C_damp (the bias forces h are quadratic in the rates and
  vanish to first order; S(0) = I so the Euler rates are the body rate). G holds
  one unit column per input: ``[0; I_3; 0]`` for the body torque, and the unit
  vector of the coordinate for each actuated appendage coordinate;
- **about a spin**, the centrifugal and gyroscopic terms come from the plant's
  compiled ``accelerations`` by central differences with one Richardson
  extrapolation (truncation error O(h^4)); with h = 1e-4 in the scaled state it is
  ~1e-16 and the round-off ~1e-12 relative. The same differences at rest reproduce
  the analytic A to ~1e-9 (tested), which validates both.

The output matrices C, D (tip displacements, tau_flex) are obtained by the same
Richardson differences of the plant's output maps at the equilibrium.

Inputs
------
``u = [tau_B (3), Q_a (len(actuated))]``: the body torque [N m], then one
generalized force per actuated appendage coordinate (a root actuator's torque on a
rotation [N m], force on a translation [N]), added to Q[j] of eq. 2.50 exactly as
the closed loop's joint actuator applies it.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence

import numpy as np
from scipy.spatial.transform import Rotation

from flexsat.dynamics.plant import Plant
from flexsat.errors import ConfigError, SimulationError
from flexsat.linear.model import LinearModel

__all__ = ["OUTPUT_GROUPS", "body_frame_derivative", "linearize", "output_map", "signal_names"]

OUTPUT_GROUPS = ("attitude", "rate", "tip", "joint", "tau_flex")
_AXES = ("x", "y", "z")
_FD_STEP = 1e-4  # scaled step of the central differences (see the module notes)
_EQUILIBRIUM_TOL = 1e-12  # residual of the relative equilibrium, scaled
_EQUILIBRIUM_MAX_ITER = 30
_SPIN_MIN = 1e-12  # [rad/s] a spin vector shorter than this is "zero length"


def signal_names(
    plant: Plant, actuated: Sequence[str] = ()
) -> dict[str, tuple[tuple[str, ...], tuple[str, ...]]]:
    """Names and units of the states, inputs and of each output group.

    Parameters
    ----------
    plant : Plant
        The satellite.
    actuated : sequence of str
        Actuated appendage coordinates, as for :func:`linearize`.

    Returns
    -------
    dict
        ``"states"``, ``"inputs"`` and every key of :data:`OUTPUT_GROUPS`, each a
        pair (names, units).
    """
    apps = [a.name for a in plant.config.appendages]
    # Each appendage's own coordinates, as the plant's layout names them.
    eta = plant.layout.dof_names()[6:]
    eta_units = plant.layout.dof_units()[6:]
    acted = plant.layout.appendage_indices(actuated, "actuated")
    all_names, all_units = plant.layout.dof_names(), plant.layout.dof_units()
    states = (
        [f"r_B_{a}" for a in _AXES] + ["phi", "theta", "psi"] + eta
        + [f"v_B_{a}" for a in _AXES] + [f"omega_{a}" for a in _AXES]
        + [f"{n}_dot" for n in eta]
    )  # fmt: skip
    state_units = (
        ["m"] * 3 + ["rad"] * 3 + eta_units + ["m/s"] * 3 + ["rad/s"] * 3
        + [f"{u}/s" for u in eta_units]
    )  # fmt: skip
    return {
        "states": (tuple(states), tuple(state_units)),
        "inputs": (
            tuple(f"tau_{a}" for a in _AXES) + tuple(f"Q_{all_names[j]}" for j in acted),
            ("N m",) * 3 + tuple(_force_unit(all_units[j]) for j in acted),
        ),
        "attitude": (("phi", "theta", "psi"), ("rad",) * 3),
        "rate": (tuple(f"omega_{a}" for a in _AXES), ("rad/s",) * 3),
        "tip": (tuple(f"{a}.tip_{x}" for a in apps for x in _AXES), ("m",) * (3 * len(apps))),
        "joint": (tuple(eta), tuple(eta_units)),
        "tau_flex": (tuple(f"tau_flex_{a}" for a in _AXES), ("N m",) * 3),
    }


def _force_unit(unit: str) -> str:
    """SI unit of the generalized force work-conjugate to a coordinate in ``unit``."""
    return {"m": "N", "rad": "N m"}.get(unit, f"J/({unit})")


def _split(plant: Plant, x: np.ndarray):
    n = plant.n_dof
    return x[0:3], x[3:6], x[6:n], x[n : n + 3], x[n + 3 : n + 6], x[n + 6 :]


def _rotation_IB(dTheta: np.ndarray) -> np.ndarray:
    """R_IB = Rz(psi) Ry(theta) Rx(phi) of ZYX Euler angles (phi, theta, psi)."""
    return Rotation.from_euler("ZYX", dTheta[::-1]).as_matrix()


def _euler_rate_matrix(phi: float, theta: float) -> np.ndarray:
    """S(Theta) of eq. 2.28: omega_BN_B = S Theta_dot."""
    c1, s1, c2, s2 = np.cos(phi), np.sin(phi), np.cos(theta), np.sin(theta)
    return np.array([[1.0, 0.0, -s2], [0.0, c1, c2 * s1], [0.0, -s1, c2 * c1]])


def _plant_state(plant: Plant, x: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(q, q_dot) of the plant at body-frame state x (reference attitude at identity), R_IB."""
    r_B, dTheta, eta, v_B, omega, eta_dot = _split(plant, x)
    R_IB = _rotation_IB(dTheta)
    S = _euler_rate_matrix(dTheta[0], dTheta[1])
    q = np.concatenate([R_IB @ r_B, dTheta, eta])
    qd = np.concatenate([R_IB @ v_B, np.linalg.solve(S, omega), eta_dot])  # Theta_dot = S^-1 w
    return q, qd, R_IB


def body_frame_derivative(
    plant: Plant,
    x: np.ndarray,
    torque_B: np.ndarray,
    spin: np.ndarray,
    actuated: Sequence[int] = (),
) -> np.ndarray:
    """Time derivative of the body-frame state x under the input ``torque_B``.

    Parameters
    ----------
    plant : Plant
        The satellite.
    x : ndarray, shape (2 n_dof,)
        Body-frame state (module docstring) [m, rad, m/s, rad/s]; its attitude is
        relative to a reference spinning at the constant body rate ``spin``, taken at
        the identity.
    torque_B : ndarray, shape (3 + len(actuated),)
        Torque on the hub, hub frame B [N m], then the generalized forces on the
        actuated coordinates [N or N m].
    spin : ndarray, shape (3,)
        Body rate of the reference motion W [rad/s].
    actuated : sequence of int
        Indices in q of the actuated appendage coordinates.

    Returns
    -------
    ndarray, shape (2 n_dof,)
        dx/dt [unit of x per s].
    """
    r_B, dTheta, _, v_B, omega, eta_dot = _split(plant, x)
    q, qd, R_IB = _plant_state(plant, x)
    qdd = plant.accelerations(q, qd, _forces(plant, q, torque_B, actuated))  # eq. 2.50
    S = _euler_rate_matrix(dTheta[0], dTheta[1])
    Theta_dot = qd[3:6]
    # d/dt (S Theta_dot) = S Theta_ddot + S_dot Theta_dot; S_dot from eq. 2.28.
    c1, s1, c2, s2 = np.cos(dTheta[0]), np.sin(dTheta[0]), np.cos(dTheta[1]), np.sin(dTheta[1])
    dphi, dtheta, dpsi = Theta_dot
    S_dot_Theta_dot = np.array([
        -c2 * dtheta * dpsi,
        -s1 * dphi * dtheta + (c2 * c1 * dphi - s2 * s1 * dtheta) * dpsi,
        -c1 * dphi * dtheta - (c2 * s1 * dphi + s2 * c1 * dtheta) * dpsi,
    ])  # fmt: skip
    # R = R_ref R_d with R_ref spinning at W: body rate of R_d is omega - R_d^T W.
    dTheta_dot = np.linalg.solve(S, omega - R_IB.T @ spin)
    return np.concatenate([
        R_IB.T @ qd[0:3] - np.cross(omega, r_B),  # d/dt (R^T r)
        dTheta_dot,
        eta_dot,
        R_IB.T @ qdd[0:3] - np.cross(omega, v_B),  # d/dt (R^T v)
        S @ qdd[3:6] + S_dot_Theta_dot,
        qdd[6:],
    ])  # fmt: skip


def _forces(plant: Plant, q: np.ndarray, u: np.ndarray, actuated: Sequence[int]) -> np.ndarray:
    """Q of eq. 2.50 for u = [tau_B, Q_a]: the torque's, plus Q_a on the actuated q."""
    Q = plant.generalized_forces(q, u[:3])
    Q[list(actuated)] += u[3:]
    return Q


def output_map(
    plant: Plant, groups: Sequence[str], actuated: Sequence[int] = ()
) -> Callable[[np.ndarray, np.ndarray], np.ndarray]:
    """y(x, u) of the named output groups (see :data:`OUTPUT_GROUPS`), concatenated.

    Parameters
    ----------
    plant : Plant
        The satellite.
    groups : sequence of str
        Names of :data:`OUTPUT_GROUPS`, in output order.
    actuated : sequence of int
        Indices in q of the actuated coordinates: ``u = [tau_B, Q_a]`` as in
        :func:`body_frame_derivative`.

    Returns
    -------
    callable
        ``y(x, u)``, an ndarray of the groups' outputs [each group's units].

    Raises
    ------
    ConfigError
        For a group that is not one of :data:`OUTPUT_GROUPS`.
    """
    for g in groups:
        if g not in OUTPUT_GROUPS:
            raise ConfigError(
                f"outputs: unknown output {g!r} (allowed: {', '.join(OUTPUT_GROUPS)})"
            )

    def y(x: np.ndarray, u: np.ndarray) -> np.ndarray:
        _, dTheta, eta, _, omega, _ = _split(plant, x)
        q, qd, _ = _plant_state(plant, x)
        parts = {
            "attitude": lambda: dTheta,
            "rate": lambda: omega,
            "tip": lambda: plant.tip_displacement(q).ravel(),
            "joint": lambda: eta,
            "tau_flex": lambda: plant.joint_wrench_on_hub(q, qd, _forces(plant, q, u, actuated))[1],
        }
        return np.concatenate([parts[g]() for g in groups])

    return y


def _jacobian(f: Callable[[np.ndarray], np.ndarray], z0: np.ndarray, scale: np.ndarray):
    """df/dz at z0 by central differences with one Richardson step, O(h^4)."""
    cols = []
    for j in range(z0.size):
        h = _FD_STEP * scale[j]
        e = np.zeros_like(z0)
        e[j] = 1.0

        def central(step, e=e):
            return (f(z0 + step * e) - f(z0 - step * e)) / (2.0 * step)

        cols.append((4.0 * central(0.5 * h) - central(h)) / 3.0)
    return np.column_stack(cols)


def _state_scale(plant: Plant, spin: np.ndarray) -> np.ndarray:
    """Step scale per state: 1 m, 1 rad; rates 1 m/s, 1 rad/s (or |W| if larger)."""
    n = plant.n_dof
    s = np.ones(2 * n)
    s[n:] = max(1.0, float(np.linalg.norm(spin)))
    return s


def _relative_equilibrium(plant: Plant, spin: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(x0, u0) of the steady spin at body rate W: deformed joints, holding torque.

    Unknowns r_B, eta, v_B and the torque u0; omega = W, dTheta = 0, eta_dot = 0.
    Solved by Gauss-Newton (least squares: the hub position along W is free).
    """
    n = plant.n_dof
    free = np.r_[0:3, 6:n, n : n + 3]
    x = np.zeros(2 * n)
    x[n + 3 : n + 6] = spin
    z = np.zeros(free.size + 3)

    def residual(z):
        xz = x.copy()
        xz[free] = z[:-3]
        return body_frame_derivative(plant, xz, z[-3:], spin)

    scale = np.ones(z.size)
    for _ in range(_EQUILIBRIUM_MAX_ITER):
        r = residual(z)
        if np.max(np.abs(r)) < _EQUILIBRIUM_TOL:
            break
        J = _jacobian(residual, z, scale)
        z = z - np.linalg.lstsq(J, r, rcond=None)[0]
    else:
        raise SimulationError(
            f"no steady spin found at W = {spin.tolist()} rad/s (residual {np.max(np.abs(r)):.3g})"
        )
    x[free] = z[:-3]
    return x, z[-3:]


def linearize(
    plant: Plant,
    about: str | Sequence[float] = "rest",
    outputs: Sequence[str] = ("attitude", "rate", "tip", "joint", "tau_flex"),
    jacobian: str = "auto",
    actuated: Sequence[str] = (),
) -> LinearModel:
    """Linear model of the plant about rest or about a steady spin.

    Parameters
    ----------
    plant : Plant
        The satellite.
    about : "rest" or array_like, shape (3,)
        ``"rest"``, or the body rate W of a steady spin, hub frame B [rad/s]. The
        equilibrium deformation and the torque holding the spin (zero about a
        principal axis of the deformed satellite) are solved for.
    outputs : sequence of str
        Output groups, from :data:`OUTPUT_GROUPS`: hub attitude (small ZYX angles
        [rad]), body rate [rad/s], tip displacements (mount frames [m]), joint
        deflections, tau_flex (torque of the appendages on the hub [N m]).
    jacobian : {"auto", "analytic", "richardson"}
        ``"auto"``: analytic at rest, Richardson differences about a spin.
    actuated : sequence of str
        Appendage coordinates driven by a root actuator, named as the closed loop's
        joint actuator names them: ``"<appendage>.<coordinate>"``, or
        ``"<coordinate>"`` for that coordinate of every appendage. Each adds the input
        ``Q_<appendage>.<coordinate>``, its generalized force [N on a translation,
        N m on a rotation].

    Returns
    -------
    LinearModel
        States, inputs (body torque [N m], then the actuated coordinates' forces) and
        outputs named as in :func:`signal_names`.

    Raises
    ------
    ConfigError
        Unknown output group, Jacobian method or actuated coordinate, a spin vector
        that is not three finite numbers or has zero length, an analytic Jacobian
        about a spin.
    """
    spin = _spin(about)
    if jacobian not in ("auto", "analytic", "richardson"):
        raise ConfigError(
            f"jacobian: unknown method {jacobian!r} (allowed: auto, analytic, richardson)"
        )
    if jacobian == "analytic" and spin is not None:
        raise ConfigError("jacobian: 'analytic' exists about rest only; use 'richardson'")
    acted = plant.layout.appendage_indices(actuated, "actuated")
    y = output_map(plant, list(outputs), acted)
    n = plant.n_dof
    W = np.zeros(3) if spin is None else spin
    if spin is None:
        x0, u0 = np.zeros(2 * n), np.zeros(3)
    else:
        x0, u0 = _relative_equilibrium(plant, spin)
    u0 = np.concatenate([u0, np.zeros(len(acted))])  # the actuators hold no force
    if jacobian == "richardson" or spin is not None:
        method = "richardson"
        scale = _state_scale(plant, W)
        A = _jacobian(lambda x: body_frame_derivative(plant, x, u0, W, acted), x0, scale)
        B = _jacobian(lambda u: body_frame_derivative(plant, x0, u, W, acted), u0,
                      np.ones(u0.size))  # fmt: skip
    else:
        method = "analytic"
        A, B = _rest_matrices(plant, acted)
    scale = _state_scale(plant, W)
    C = _jacobian(lambda x: y(x, u0), x0, scale)
    D = _jacobian(lambda u: y(x0, u), u0, np.ones(u0.size))
    names = signal_names(plant, actuated)
    out_names = tuple(s for g in outputs for s in names[g][0])
    out_units = tuple(s for g in outputs for s in names[g][1])
    return LinearModel(
        A=A, B=B, C=C, D=D, x0=x0, u0=u0, spin=W,
        state_names=names["states"][0], input_names=names["inputs"][0], output_names=out_names,
        state_units=names["states"][1], input_units=names["inputs"][1], output_units=out_units,
        jacobian=method,
    )  # fmt: skip


def _rest_matrices(plant: Plant, actuated: Sequence[int]) -> tuple[np.ndarray, np.ndarray]:
    """Exact A, B about rest from M(0), K_sys, C_damp (linearized eq. 2.50)."""
    n = plant.n_dof
    M0 = plant.mass_matrix()
    A = np.zeros((2 * n, 2 * n))
    A[:n, n:] = np.eye(n)
    A[n:, :n] = -np.linalg.solve(M0, plant.stiffness_matrix())
    A[n:, n:] = -np.linalg.solve(M0, plant.damping_matrix())
    G = np.zeros((n, 3 + len(actuated)))
    G[3:6, :3] = np.eye(3)  # Q_Theta = S(0)^T tau = tau
    G[list(actuated), np.arange(3, G.shape[1])] = 1.0  # Q_j = u_j on an actuated q_j
    # The torque's columns by a solve of their own: the same call as without actuated
    # coordinates, so they are bit for bit the torque-only model's (one solve of all the
    # columns may block its triangular solves differently and move the last bit).
    torque, coordinates = np.linalg.solve(M0, G[:, :3]), np.linalg.solve(M0, G[:, 3:])
    B = np.vstack([np.zeros_like(G), np.hstack([torque, coordinates])])
    return A, B


def _spin(about) -> np.ndarray | None:
    if isinstance(about, str):
        if about == "rest":
            return None
        raise ConfigError(f"about: expected 'rest' or a spin rate vector [rad/s], got {about!r}")
    W = np.asarray(about, dtype=float)
    if W.shape != (3,) or not np.all(np.isfinite(W)):
        raise ConfigError(f"about: a spin rate must be three finite numbers [rad/s], got {about!r}")
    if np.linalg.norm(W) < _SPIN_MIN:
        raise ConfigError("about: the spin axis has zero length; give a nonzero rate or 'rest'")
    return W
