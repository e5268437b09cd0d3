"""Compiled pieces shared by the built-in laws: attitude errors, the gyroscopic term,
saturation and the software torque limit (thesis ch. 4)."""

from __future__ import annotations

from math import asin, sqrt

import numpy as np
from numba import njit

from flexsat.compiled.linalg3 import cross, mv
from flexsat.control.quaternion import quaternion_error
from flexsat.control.registry import Channel

__all__ = [
    "SLIDING_DIAGNOSTICS",
    "clip_and_store",
    "errors",
    "inertia3",
    "integral_diagnostics",
    "law_terms",
    "linear_sliding_feedback",
    "sat",
    "store_integral_breakdown",
    "surface",
    "surface_attributes",
    "surface_guide",
]


def linear_sliding_feedback(J: np.ndarray, lam: float, jk: float, phi: float) -> np.ndarray:
    """Static gain K (3, 6) of a sliding-mode law inside its boundary layer, about rest.

    With |s| < Phi, q_v,e ~ theta / 2 and q_v,e_dot ~ omega / 2, the law
    tau = -Lambda J q_v,e_dot - JK s / Phi, s = omega + Lambda q_v,e (eqs. 4.13-4.14),
    is tau = -K [theta; omega] (the gyroscopic term is quadratic in the rate).
    """
    k = jk / phi
    return np.hstack([0.5 * k * lam * np.eye(3), 0.5 * lam * np.asarray(J) + k * np.eye(3)])


def surface_attributes(
    lambda_min: float, lambda_max: float, phi: float | None = None, jk_floor: float | None = None
) -> dict[str, float]:
    """A sliding-mode law's :meth:`~flexsat.control.laws.LawConfig.plot_attributes`.

    Parameters
    ----------
    lambda_min, lambda_max : float
        Slopes of the surface at its two ends, equal for a constant slope [rad/s].
    phi : float, optional
        Boundary-layer width Phi [rad/s]; None: the law has none.
    jk_floor : float, optional
        Floor of the robust gain JK [N m]; None: the law has none.

    Returns
    -------
    dict of str to float
        The attributes the slew plots read, in their units.
    """
    out = {"surface_lambda_min_rad_s": lambda_min, "surface_lambda_max_rad_s": lambda_max}
    if phi is not None:
        out["boundary_layer_rad_s"] = phi
    if jk_floor is not None:
        out["jk_floor_nm"] = jk_floor
    return out


@njit(cache=True)
def sat(x):
    """sat(x) = max(-1, min(1, x)) (eq. 4.16)."""
    return min(1.0, max(-1.0, x))


@njit(cache=True)
def _to_body(e, v):
    """Components in B of a vector given in D: C(q_e)^T v, q_e = q_d^-1 (x) q (eq. 4.1)."""
    qv = (e[1], e[2], e[3])
    a = cross(qv, v)
    b = cross(qv, a)
    return (v[0] - 2.0 * e[0] * a[0] + 2.0 * b[0], v[1] - 2.0 * e[0] * a[1] + 2.0 * b[1],
            v[2] - 2.0 * e[0] * a[2] + 2.0 * b[2])  # fmt: skip


@njit(cache=True)
def errors(q_d, omega_d, omega_dot_d, q, omega_B):
    """q_v,e, its rate (eq. 4.3), omega_e, the pointing error 2 asin |q_v,e| [rad] and the
    reference acceleration in B [rad/s^2].

    omega_e = omega - omega_d (eq. 4.2) with omega_d, given in the reference frame D,
    rotated into B; the reference acceleration in B is d/dt (C omega_d) =
    C omega_dot_d - omega_e x (C omega_d), the omega_dot_d of the tracking term
    J omega_dot_d of eq. 4.12. A step reference (omega_d = omega_dot_d = 0, the
    thesis's regulation) gives omega_e = omega and zero acceleration exactly.
    """
    e = quaternion_error(q_d, q)
    qv = (e[1], e[2], e[3])
    w_d = _to_body(e, omega_d)
    omega_e = (omega_B[0] - w_d[0], omega_B[1] - w_d[1], omega_B[2] - w_d[2])
    cross_term = cross(qv, omega_e)  # S(q_v,e) omega_e
    qv_dot = (
        0.5 * (e[0] * omega_e[0] + cross_term[0]),
        0.5 * (e[0] * omega_e[1] + cross_term[1]),
        0.5 * (e[0] * omega_e[2] + cross_term[2]),
    )
    norm = sqrt(qv[0] ** 2 + qv[1] ** 2 + qv[2] ** 2)
    a_d = _to_body(e, omega_dot_d)
    transport = cross(omega_e, w_d)
    w_dot_d = (a_d[0] - transport[0], a_d[1] - transport[1], a_d[2] - transport[2])
    return qv, qv_dot, omega_e, 2.0 * asin(min(1.0, norm)), w_dot_d


@njit(cache=True)
def inertia3(J):
    """The (3, 3) design inertia as nested tuples for the ``linalg3`` helpers."""
    return ((J[0, 0], J[0, 1], J[0, 2]), (J[1, 0], J[1, 1], J[1, 2]), (J[2, 0], J[2, 1], J[2, 2]))


@njit(cache=True)
def clip_and_store(limit, tau_gyro, tau_guide, tau_rob, tau_cmd):
    """tau_cmd = clip(tau_gyro + tau_guide + tau_rob, +-limit) per axis [N m]."""
    for a in range(3):
        tau_cmd[a] = min(limit, max(-limit, tau_gyro[a] + tau_guide[a] + tau_rob[a]))


@njit(cache=True)
def law_terms(q_d, omega_d, omega_dot_d, q, omega_B, J):
    """The terms every built-in law starts from (law contract's arguments, SI).

    Returns q_v,e, its rate, omega_e and the pointing error [rad] (:func:`errors`),
    the design inertia as nested tuples (:func:`inertia3`), the tracking feed-forward
    J omega_dot_d in B (eq. 4.12) [N m] and the gyroscopic torque omega x (J omega)
    [N m].
    """
    qv, qv_dot, omega_e, theta_err, w_dot_d = errors(q_d, omega_d, omega_dot_d, q, omega_B)
    J3 = inertia3(J)
    return qv, qv_dot, omega_e, theta_err, J3, mv(J3, w_dot_d), cross(omega_B, mv(J3, omega_B))


@njit(cache=True)
def surface(omega_e, lam, qv):
    """The sliding variable s = omega_e + lambda q_v,e per axis (eq. 4.6) [rad/s]."""
    return (omega_e[0] + lam * qv[0], omega_e[1] + lam * qv[1], omega_e[2] + lam * qv[2])


@njit(cache=True)
def surface_guide(J_w_dot_d, lam, J_qv_dot):
    """J (omega_dot_d - lambda q_v,e_dot) per axis, the guiding torque of a surface of
    slope ``lam`` [rad/s] (eqs. 4.12-4.14) [N m]."""
    return (
        J_w_dot_d[0] - lam * J_qv_dot[0],
        J_w_dot_d[1] - lam * J_qv_dot[1],
        J_w_dot_d[2] - lam * J_qv_dot[2],
    )


def integral_diagnostics(
    surface_note: str, integral: Channel, guide_note: str, rob_note: str
) -> tuple[Channel, ...]:
    """The first five diagnostics of a law whose surface carries an integral state, in
    the order :func:`store_integral_breakdown` writes them.

    Parameters
    ----------
    surface_note, guide_note, rob_note : str
        Descriptions of s [rad/s], tau_guide and tau_rob [N m].
    integral : Channel
        The integral state's channel (per axis).

    Returns
    -------
    tuple of Channel
        s, the integral, tau_gyro, tau_guide, tau_rob, each per axis.
    """
    return (
        Channel("sliding_variable", "rad/s", surface_note, per_axis=True),
        integral,
        Channel("tau_gyro", "N m", "w x J w", per_axis=True),
        Channel("tau_guide", "N m", guide_note, per_axis=True),
        Channel("tau_rob", "N m", rob_note, per_axis=True),
    )


@njit(cache=True)
def store_integral_breakdown(limit, s, integral, tau_gyro, tau_guide, tau_rob, tau_cmd, diag):
    """The command of a law whose surface carries an integral state, and its first 15
    diagnostics: s, the integral, tau_gyro, tau_guide, tau_rob (3 each, in that order).

    ``tau_cmd`` as :func:`clip_and_store` [N m]; ``diag[0:15]`` overwritten [SI].
    """
    clip_and_store(limit, tau_gyro, tau_guide, tau_rob, tau_cmd)
    diag[0], diag[1], diag[2] = s
    diag[3], diag[4], diag[5] = integral
    diag[6], diag[7], diag[8] = tau_gyro
    diag[9], diag[10], diag[11] = tau_guide
    diag[12], diag[13], diag[14] = tau_rob


SLIDING_DIAGNOSTICS = (
    Channel("sliding_variable", "rad/s", "s = w_e + L q_v,e", per_axis=True),
    Channel("lambda_act", "rad/s", "Lambda_act"),
    Channel("jk", "N m", "robust torque gain JK per axis", per_axis=True),
    Channel("tau_gyro", "N m", "w x J w", per_axis=True),
    Channel("tau_guide", "N m", "-J L q_v,e_dot", per_axis=True),
    Channel("tau_rob", "N m", "-JK sat(s/Phi)", per_axis=True),
)
"""The diagnostics of a sliding-mode law: surface, slope, robust gain, torque breakdown."""
