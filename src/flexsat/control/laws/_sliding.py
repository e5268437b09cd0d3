"""Compiled pieces shared by the built-in laws: attitude errors, the gyroscopic term,
saturation and the software torque limit (thesis ch. 4)."""

from __future__ import annotations

from math import asin, sqrt

import numpy as np
from numba import njit

from flexsat.control.quaternion import quaternion_error
from flexsat.control.registry import Channel
from flexsat.dynamics.linalg3 import cross

__all__ = [
    "SLIDING_DIAGNOSTICS",
    "clip_and_store",
    "errors",
    "inertia3",
    "linear_sliding_feedback",
    "sat",
]


def linear_sliding_feedback(J: np.ndarray, lam: float, jk: float, phi: float) -> np.ndarray:
    """Static gain K (3, 6) of a sliding-mode law inside its boundary layer, about rest.

    With |s| < Phi, q_v,e ~ theta / 2 and q_v,e_dot ~ omega / 2, the law
    tau = -Lambda J q_v,e_dot - JK s / Phi, s = omega + Lambda q_v,e (eqs. 4.13-4.14),
    is tau = -K [theta; omega] (the gyroscopic term is quadratic in the rate).
    """
    k = jk / phi
    return np.hstack([0.5 * k * lam * np.eye(3), 0.5 * lam * np.asarray(J) + k * np.eye(3)])


@njit(cache=True)
def sat(x):
    """sat(x) = max(-1, min(1, x)) (eq. 4.16)."""
    return min(1.0, max(-1.0, x))


@njit(cache=True)
def errors(q_d, q, omega_B):
    """q_v,e, its rate (eq. 4.3), omega_e and the pointing error 2 asin |q_v,e| [rad].

    Rest-to-rest regulation as in the thesis (eq. 4.2 with omega_d = 0).
    """
    e = quaternion_error(q_d, q)
    qv = (e[1], e[2], e[3])
    omega_e = (omega_B[0], omega_B[1], omega_B[2])
    cross_term = cross(qv, omega_e)  # S(q_v,e) omega_e
    qv_dot = (
        0.5 * (e[0] * omega_e[0] + cross_term[0]),
        0.5 * (e[0] * omega_e[1] + cross_term[1]),
        0.5 * (e[0] * omega_e[2] + cross_term[2]),
    )
    norm = sqrt(qv[0] ** 2 + qv[1] ** 2 + qv[2] ** 2)
    return qv, qv_dot, omega_e, 2.0 * asin(min(1.0, norm))


@njit(cache=True)
def inertia3(J):
    """The (3, 3) design inertia as nested tuples for the ``linalg3`` helpers."""
    return ((J[0, 0], J[0, 1], J[0, 2]), (J[1, 0], J[1, 1], J[1, 2]), (J[2, 0], J[2, 1], J[2, 2]))


@njit(cache=True)
def clip_and_store(limit, tau_gyro, tau_guide, tau_rob, tau_cmd):
    """tau_cmd = clip(tau_gyro + tau_guide + tau_rob, +-limit) per axis [N m]."""
    for a in range(3):
        tau_cmd[a] = min(limit, max(-limit, tau_gyro[a] + tau_guide[a] + tau_rob[a]))


SLIDING_DIAGNOSTICS = (
    Channel("sliding_variable", "rad/s", "s = w_e + L q_v,e", per_axis=True),
    Channel("lambda_act", "rad/s", "Lambda_act"),
    Channel("jk", "N m", "robust torque gain JK per axis", per_axis=True),
    Channel("tau_gyro", "N m", "w x J w", per_axis=True),
    Channel("tau_guide", "N m", "-J L q_v,e_dot", per_axis=True),
    Channel("tau_rob", "N m", "-JK sat(s/Phi)", per_axis=True),
)
"""The diagnostics of a sliding-mode law: surface, slope, robust gain, torque breakdown."""
