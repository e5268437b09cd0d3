"""Compiled attitude control laws: ASMC (thesis ch. 4), classical SMC and quaternion PD.

All laws share one signature so the compiled closed loop can call any of them::

    tau_cmd = control_law(kind, gains, J, q_d, q, omega_B, dt, memory, diag)

``kind`` selects the law, ``gains`` is its packed parameter vector (see the
``*_GAINS`` layouts), ``J`` the design inertia J_tot (rigid model: the controller
knows nothing else), ``q_d``/``q`` scalar-first quaternions, ``omega_B`` the body
rate [rad/s], ``dt`` the control period [s], ``memory`` (2,) the law's state kept
between calls, and ``diag`` (DIAG_SIZE,) receives the diagnostics recorded in the
result: s (3), Lambda, JK (3), tau_gyro (3), tau_guide (3), tau_rob (3), theta_err.
The returned torque is already limited to the software limit RF * T_max per axis.
"""

from __future__ import annotations

from math import asin, sqrt

from numba import njit

from flexsat.control.quaternion import quaternion_error
from flexsat.dynamics.linalg3 import cross, mv

__all__ = [
    "ASMC",
    "ASMC_GAINS",
    "DIAG_NAMES",
    "DIAG_SIZE",
    "PD",
    "PD_GAINS",
    "SMC",
    "SMC_GAINS",
    "CompiledLaw",
    "control_law",
]

ASMC, SMC, PD = 0, 1, 2
ASMC_GAINS = (
    "t_max", "reduction_factor", "jk_min", "lambda_min", "lambda_max", "phi",
    "theta_threshold", "include_lambda_dot",
)  # fmt: skip
SMC_GAINS = ("t_max", "reduction_factor", "jk", "lambda_", "phi")
PD_GAINS = ("t_max", "reduction_factor", "kp", "kd")
DIAG_NAMES = (
    "s_x", "s_y", "s_z", "lambda", "jk_x", "jk_y", "jk_z",
    "tau_gyro_x", "tau_gyro_y", "tau_gyro_z", "tau_guide_x", "tau_guide_y", "tau_guide_z",
    "tau_rob_x", "tau_rob_y", "tau_rob_z", "theta_err",
)  # fmt: skip
DIAG_SIZE = len(DIAG_NAMES)


@njit(cache=True)
def _sat(x):
    return min(1.0, max(-1.0, x))


@njit(cache=True)
def _jk(jk_min, limit, tau_gyro, tau_guide, s, phi):
    """Eq. 4.30 on one axis: JK_min + (JK_avail - JK_min) min(|s| / Phi, 1)."""
    avail = max(jk_min, limit - abs(tau_gyro) - abs(tau_guide))
    return jk_min + (avail - jk_min) * min(abs(s) / phi, 1.0)


@njit(cache=True)
def _errors(q_d, q, omega_B):
    """q_v,e, its rate (eq. 4.3) and the pointing error angle 2 asin |q_v,e| [rad]."""
    e = quaternion_error(q_d, q)
    qv = (e[1], e[2], e[3])
    omega_e = omega_B  # omega_d = 0: rest-to-rest regulation (eq. 4.2)
    cross_term = cross(qv, omega_e)  # S(q_v,e) omega_e
    qv_dot = (
        0.5 * (e[0] * omega_e[0] + cross_term[0]),
        0.5 * (e[0] * omega_e[1] + cross_term[1]),
        0.5 * (e[0] * omega_e[2] + cross_term[2]),
    )
    norm = sqrt(qv[0] ** 2 + qv[1] ** 2 + qv[2] ** 2)
    return qv, qv_dot, omega_e, 2.0 * asin(min(1.0, norm))


@njit(cache=True)
def control_law(kind, gains, J, q_d, q, omega_B, dt, memory, diag):
    """Command torque of the selected law, body frame [N m] (module docstring)."""
    t_max, rf = gains[0], gains[1]
    limit = rf * t_max
    qv, qv_dot, omega_e, theta_err = _errors(q_d, q, omega_B)
    J3 = ((J[0, 0], J[0, 1], J[0, 2]), (J[1, 0], J[1, 1], J[1, 2]), (J[2, 0], J[2, 1], J[2, 2]))
    tau_gyro = cross(omega_B, mv(J3, omega_B))  # omega x (J omega)
    J_qv_dot = mv(J3, qv_dot)
    lam = 0.0
    jk = (0.0, 0.0, 0.0)
    s = (0.0, 0.0, 0.0)
    tau_guide = (0.0, 0.0, 0.0)
    tau_rob = (0.0, 0.0, 0.0)
    if kind == PD:
        kp, kd = gains[2], gains[3]
        u = (kp * qv[0] + kd * omega_e[0], kp * qv[1] + kd * omega_e[1],
             kp * qv[2] + kd * omega_e[2])  # fmt: skip
        Ju = mv(J3, u)
        tau_guide = (-Ju[0], -Ju[1], -Ju[2])
    else:
        phi = gains[5] if kind == ASMC else gains[4]
        if kind == ASMC:
            jk_min, lam_min, lam_max, theta_th = gains[2], gains[3], gains[4], gains[6]
            # eq. 4.27: target slope from the pointing error
            lam_target = lam_max - (lam_max - lam_min) * min(1.0, theta_err / theta_th)
            # eqs. 4.23, 4.28: budget-feasible slope; the most restrictive axis decides
            lam_feasible = 1e300
            for a in range(3):
                budget = limit - abs(tau_gyro[a]) - jk_min
                if abs(J_qv_dot[a]) > 0.0:
                    lam_feasible = min(lam_feasible, max(0.0, budget) / abs(J_qv_dot[a]))
            lam = max(lam_min, min(lam_target, lam_feasible))  # eq. 4.29
        else:
            lam = gains[3]
        s = (omega_e[0] + lam * qv[0], omega_e[1] + lam * qv[1], omega_e[2] + lam * qv[2])
        tau_guide = (-lam * J_qv_dot[0], -lam * J_qv_dot[1], -lam * J_qv_dot[2])
        if kind == ASMC:
            # eq. 4.30, per axis: all the residual budget outside the boundary layer,
            # scaled down towards JK_min inside it.
            jk = (
                _jk(jk_min, limit, tau_gyro[0], tau_guide[0], s[0], phi),
                _jk(jk_min, limit, tau_gyro[1], tau_guide[1], s[1], phi),
                _jk(jk_min, limit, tau_gyro[2], tau_guide[2], s[2], phi),
            )
            if gains[7] > 0.0 and memory[1] > 0.0:
                # -J Lambda_dot q_v,e (eq. 4.12), omitted by default as in eq. 4.14
                lam_dot = (lam - memory[0]) / dt
                Jq = mv(J3, qv)
                tau_guide = (tau_guide[0] - lam_dot * Jq[0], tau_guide[1] - lam_dot * Jq[1],
                             tau_guide[2] - lam_dot * Jq[2])  # fmt: skip
            memory[0] = lam
            memory[1] = 1.0
        else:
            jk = (gains[2], gains[2], gains[2])
        tau_rob = (-jk[0] * _sat(s[0] / phi), -jk[1] * _sat(s[1] / phi), -jk[2] * _sat(s[2] / phi))
    tau = (
        min(limit, max(-limit, tau_gyro[0] + tau_guide[0] + tau_rob[0])),
        min(limit, max(-limit, tau_gyro[1] + tau_guide[1] + tau_rob[1])),
        min(limit, max(-limit, tau_gyro[2] + tau_guide[2] + tau_rob[2])),
    )
    diag[0], diag[1], diag[2] = s
    diag[3] = lam
    diag[4], diag[5], diag[6] = jk
    diag[7], diag[8], diag[9] = tau_gyro
    diag[10], diag[11], diag[12] = tau_guide
    diag[13], diag[14], diag[15] = tau_rob
    diag[16] = theta_err
    return tau


class CompiledLaw:
    """A built-in law as a plain-Python controller (the ``Controller`` protocol).

    Calls the same compiled :func:`control_law` the closed loop runs internally, so
    a slew flown through the Python-callback path with it reproduces the compiled
    loop; useful to check a custom loop or to wrap a built-in law.

    Parameters
    ----------
    config : ASMCConfig, SMCConfig or PDConfig
    actuator : ActuatorConfig
    J : ndarray, shape (3, 3)
        Design inertia [kg m^2].
    q_d : ndarray, shape (4,)
        Target quaternion, scalar first.
    control_dt : float
        Control period [s] (for the Lambda_dot term).
    """

    def __init__(self, config, actuator, J, q_d, control_dt: float) -> None:
        import numpy as np

        self.kind = {"asmc": ASMC, "smc": SMC, "pd": PD}[config.kind]
        self.gains = config.gains(actuator)
        self.J = np.ascontiguousarray(J, dtype=float)
        self.q_d = tuple(float(v) for v in q_d)
        self.dt = float(control_dt)
        self.memory = np.zeros(2)
        self.diag = np.empty(DIAG_SIZE)

    def __call__(self, t, q, omega_B):
        return control_law(
            self.kind, self.gains, self.J, self.q_d, tuple(q), tuple(omega_B), self.dt,
            self.memory, self.diag,
        )  # fmt: skip
