"""Multiplicative extended Kalman filter: gyro propagation, star-tracker update.

The estimate is the attitude q_hat (scalar first) and the gyro bias b_hat; the
filter's error state is dx = [dtheta, db] (6), dtheta the small rotation with
q_true = q_hat (x) [1, dtheta / 2] (Markley and Crassidis, "Fundamentals of
Spacecraft Attitude Determination and Control", 2014, sec. 6.2.4). At each new gyro
sample (in the chain, a changed omega_meas: the gyro's mean rate over the interval
dt since its previous sample):

    omega_hat = omega_gyro - b_hat,   q_hat <- q_hat (x) exp(omega_hat dt / 2)
    P <- Phi P Phi^T + Q_d,   Phi = [[I - [omega_hat x] dt, -I dt], [0, I]]
    Q_d = [[sv^2 dt + su^2 dt^3 / 3, -su^2 dt^2 / 2], [-su^2 dt^2 / 2, su^2 dt]]

with sv the gyro's angle random walk and su its bias's random-walk density. When
the star tracker delivers a new sample q_st (in the chain, a changed q_meas),
z = 2 vec(q_hat^-1 (x) q_st), H = [I 0], R = diag(sigma_st^2): K = P H^T (H P H^T
+ R)^-1, dx = K z, q_hat <- q_hat (x) [1, dtheta / 2] (normalized), b_hat += db,
P <- (I - K H) P (I - K H)^T + K R K^T (Joseph form). The first star-tracker
sample initializes q_hat. Outputs q_meas = q_hat, omega_meas = omega_gyro - b_hat.

Recorded against the true attitude (the sensor stage sees the plant state): the
error e = 2 vec(q_hat^-1 (x) q_true) and its normalized estimation error squared
NEES = e^T P_thetatheta^-1 e, chi-square with 3 degrees of freedom when the filter
is consistent, both at each new sample (held in between) (``docs/control.md``,
'Sensors and estimation').
"""

from __future__ import annotations

from math import cos, sin, sqrt
from typing import Annotated, Literal

import numpy as np
from numba import njit
from pydantic import Field

from flexsat.control.registry import Channel
from flexsat.control.stages._truth import true_attitude
from flexsat.control.stages.registry import StageConfig, StageSpec

__all__ = ["MEKF", "MEKFConfig"]

_DEG = np.pi / 180.0
# packed: sv, su, sigma_st (3), P0 attitude std (3), P0 bias std
_SV, _SU, _SST, _P0A, _P0B = 0, 1, 2, 5, 8
# state: started, t_prev, q_hat (4), b_hat (3), omega_gyro previous (3), last q_st (4),
# P (36), scratch Phi (36), scratch T (36), K (18)
_ON, _TPREV, _Q, _B, _WPREV, _QST, _P = 0, 1, 2, 6, 9, 12, 16
_PHI, _T, _K = _P + 36, _P + 72, _P + 108
_SIZE = _K + 18
NonNegative = Annotated[float, Field(ge=0.0, allow_inf_nan=False)]


class MEKFConfig(StageConfig):
    """The MEKF (module docstring). Noise densities not given are those the sensing
    chain's gyro and star tracker declare (``estimator_noise``)."""

    kind: Literal["mekf"] = Field("mekf", description="the stage's registered name")
    gyro_arw_rad_rt_s: NonNegative | None = Field(None, description="sv [rad/sqrt(s)]")
    gyro_rrw_rad_s_rt_s: NonNegative | None = Field(None, description="su [rad/s/sqrt(s)]")
    star_tracker_noise_rad: tuple[NonNegative, NonNegative, NonNegative] | None = Field(
        None, description="sigma_st per axis [rad]"
    )
    initial_attitude_std_deg: Annotated[float, Field(gt=0.0, le=180.0)] | None = Field(
        None, description="P0 of the attitude [deg]; default sigma_st (q_hat starts at a sample)"
    )
    initial_bias_std_deg_h: Annotated[float, Field(gt=0.0)] = Field(
        0.1, description="P0 of the gyro bias [deg/h]"
    )

    def check(self, scenario) -> None:
        """Refuse an MEKF with neither a gyro nor a star tracker before it in the
        sensing chain: it would filter the ideal sensor's noiseless outputs."""
        before: dict = {}
        for _, stage in scenario.stage_chain():
            if stage is self:
                break
            if hasattr(stage, "estimator_noise"):
                before.update(stage.estimator_noise())
        if "arw" not in before and "star_tracker" not in before:
            raise ValueError(
                "kind: an MEKF needs a gyro or a star tracker (or both) before it in the "
                "sensing chain ([sensor], then [[sensor_stages]] in order); it has neither"
            )

    def packed(self, scenario) -> np.ndarray:
        declared: dict = {}
        for _, stage in scenario.stage_chain():
            if hasattr(stage, "estimator_noise"):
                declared.update(stage.estimator_noise())
        sv = self.gyro_arw_rad_rt_s if self.gyro_arw_rad_rt_s is not None else declared.get(
            "arw", 0.0)  # fmt: skip
        su = self.gyro_rrw_rad_s_rt_s if self.gyro_rrw_rad_s_rt_s is not None else declared.get(
            "rrw", 0.0)  # fmt: skip
        st = self.star_tracker_noise_rad or declared.get("star_tracker", (1e-5,) * 3)
        p0 = st if self.initial_attitude_std_deg is None else (
            (self.initial_attitude_std_deg * _DEG,) * 3)  # fmt: skip
        return np.array([sv, su, *st, *p0, self.initial_bias_std_deg_h * _DEG / 3600.0])


@njit(cache=True, inline="always")
def _qmul(a0, a1, a2, a3, b0, b1, b2, b3):
    return (a0 * b0 - a1 * b1 - a2 * b2 - a3 * b3,
            a0 * b1 + a1 * b0 + a2 * b3 - a3 * b2,
            a0 * b2 - a1 * b3 + a2 * b0 + a3 * b1,
            a0 * b3 + a1 * b2 - a2 * b1 + a3 * b0)  # fmt: skip


@njit(cache=True, inline="always")
def _error(s, q):
    """2 vec(q_hat^-1 (x) q), the sign of the shorter rotation."""
    e = _qmul(s[_Q], -s[_Q + 1], -s[_Q + 2], -s[_Q + 3], q[0], q[1], q[2], q[3])
    sign = 1.0 if e[0] >= 0.0 else -1.0
    return 2.0 * sign * e[1], 2.0 * sign * e[2], 2.0 * sign * e[3]


@njit(cache=True, inline="always")
def _correct(s, d0, d1, d2):
    """q_hat <- q_hat (x) [1, dtheta / 2], normalized."""
    q = _qmul(s[_Q], s[_Q + 1], s[_Q + 2], s[_Q + 3], 1.0, 0.5 * d0, 0.5 * d1, 0.5 * d2)
    norm = sqrt(q[0] ** 2 + q[1] ** 2 + q[2] ** 2 + q[3] ** 2)
    for j in range(4):
        s[_Q + j] = q[j] / norm


@njit(cache=True, inline="always")
def _sandwich(P, G, T):
    """P <- G P G^T (6 x 6), T scratch."""
    for i in range(6):
        for j in range(6):
            acc = 0.0
            for k in range(6):
                acc += G[i, k] * P[k, j]
            T[i, j] = acc
    for i in range(6):
        for j in range(6):
            acc = 0.0
            for k in range(6):
                acc += T[i, k] * G[j, k]
            P[i, j] = acc


@njit(cache=True, inline="always")
def _inverse3(a00, a01, a02, a10, a11, a12, a20, a21, a22):
    c00, c01, c02 = a11 * a22 - a12 * a21, a02 * a21 - a01 * a22, a01 * a12 - a02 * a11
    c10, c11, c12 = a12 * a20 - a10 * a22, a00 * a22 - a02 * a20, a02 * a10 - a00 * a12
    c20, c21, c22 = a10 * a21 - a11 * a20, a01 * a20 - a00 * a21, a00 * a11 - a01 * a10
    det = a00 * c00 + a01 * c10 + a02 * c20
    return (c00 / det, c01 / det, c02 / det, c10 / det, c11 / det, c12 / det,
            c20 / det, c21 / det, c22 / det)  # fmt: skip


@njit(cache=True)  # compiled with SENSOR_SIGNATURE on first use
def mekf_step(x, n_dof, t, params, state, q_meas, omega_meas, record):
    """Propagate with the gyro, update on a new star-tracker sample (module docstring)."""
    p, s = params, state
    new_rate, fresh = False, False
    for i in range(3):
        new_rate |= omega_meas[i] != s[_WPREV + i]
    for j in range(4):
        fresh |= q_meas[j] != s[_QST + j]
    if s[_ON] != 0.0 and not (new_rate or fresh):  # between samples: the estimate held
        for i in range(3):
            omega_meas[i] = omega_meas[i] - s[_B + i]
        for j in range(4):
            q_meas[j] = s[_Q + j]
        return 0
    P = s[_P : _P + 36].reshape((6, 6))
    G = s[_PHI : _PHI + 36].reshape((6, 6))
    T = s[_T : _T + 36].reshape((6, 6))
    K = s[_K : _K + 18].reshape((6, 3))
    if s[_ON] == 0.0:
        s[_ON], s[_TPREV] = 1.0, t
        for j in range(4):
            s[_Q + j] = q_meas[j]
            s[_QST + j] = q_meas[j]
        P[:, :] = 0.0
        for i in range(3):
            P[i, i] = p[_P0A + i] ** 2
            P[3 + i, 3 + i] = p[_P0B] ** 2
            s[_WPREV + i] = omega_meas[i]
        new_rate, fresh = False, False  # the first samples initialize the estimate
    dt = t - s[_TPREV]
    if new_rate and dt > 0.0:
        s[_TPREV] = t
        w0, w1, w2 = (omega_meas[0] - s[_B], omega_meas[1] - s[_B + 1],
                      omega_meas[2] - s[_B + 2])  # fmt: skip
        rate = sqrt(w0 * w0 + w1 * w1 + w2 * w2)
        half = 0.5 * rate * dt
        k = 0.5 * dt if rate == 0.0 else sin(half) / rate
        q = _qmul(s[_Q], s[_Q + 1], s[_Q + 2], s[_Q + 3], cos(half), k * w0, k * w1, k * w2)
        for j in range(4):
            s[_Q + j] = q[j]
        G[:, :] = 0.0
        for i in range(6):
            G[i, i] = 1.0
        G[0, 1], G[0, 2], G[1, 0], G[1, 2], G[2, 0], G[2, 1] = (
            w2 * dt,
            -w1 * dt,
            -w2 * dt,
            w0 * dt,
            w1 * dt,
            -w0 * dt,
        )  # I - [w x] dt
        for i in range(3):
            G[i, 3 + i] = -dt
        _sandwich(P, G, T)
        sv2, su2 = p[_SV] ** 2, p[_SU] ** 2
        for i in range(3):
            P[i, i] += sv2 * dt + su2 * dt**3 / 3.0
            P[i, 3 + i] -= su2 * dt**2 / 2.0
            P[3 + i, i] -= su2 * dt**2 / 2.0
            P[3 + i, 3 + i] += su2 * dt
    if fresh:
        for j in range(4):
            s[_QST + j] = q_meas[j]
        z = _error(s, q_meas)
        r0, r1, r2 = p[_SST] ** 2, p[_SST + 1] ** 2, p[_SST + 2] ** 2
        Si = _inverse3(P[0, 0] + r0, P[0, 1], P[0, 2], P[1, 0], P[1, 1] + r1, P[1, 2],
                       P[2, 0], P[2, 1], P[2, 2] + r2)  # fmt: skip
        for i in range(6):
            for j in range(3):
                K[i, j] = P[i, 0] * Si[j] + P[i, 1] * Si[3 + j] + P[i, 2] * Si[6 + j]
        dx0 = K[0, 0] * z[0] + K[0, 1] * z[1] + K[0, 2] * z[2]
        dx1 = K[1, 0] * z[0] + K[1, 1] * z[1] + K[1, 2] * z[2]
        dx2 = K[2, 0] * z[0] + K[2, 1] * z[1] + K[2, 2] * z[2]
        for i in range(3):
            s[_B + i] += K[3 + i, 0] * z[0] + K[3 + i, 1] * z[1] + K[3 + i, 2] * z[2]
        _correct(s, dx0, dx1, dx2)
        G[:, :] = 0.0
        for i in range(6):
            G[i, i] = 1.0
            for j in range(3):
                G[i, j] -= K[i, j]
        _sandwich(P, G, T)
        for i in range(6):  # + K R K^T
            for j in range(6):
                P[i, j] += K[i, 0] * r0 * K[j, 0] + K[i, 1] * r1 * K[j, 1] + K[i, 2] * r2 * K[j, 2]
    for i in range(3):
        s[_WPREV + i] = omega_meas[i]
        omega_meas[i] = omega_meas[i] - s[_B + i]
    for j in range(4):
        q_meas[j] = s[_Q + j]
    if not (new_rate or fresh):
        return 0  # nothing new: estimate and records held
    e = _error(s, true_attitude(x, n_dof))
    Pi = _inverse3(P[0, 0], P[0, 1], P[0, 2], P[1, 0], P[1, 1], P[1, 2], P[2, 0], P[2, 1],
                   P[2, 2])  # fmt: skip
    nees = 0.0
    for i in range(3):
        for j in range(3):
            nees += e[i] * Pi[3 * i + j] * e[j]
    record[0], record[1], record[2] = e
    record[3] = nees
    record[4], record[5], record[6] = sqrt(P[0, 0]), sqrt(P[1, 1]), sqrt(P[2, 2])
    record[7], record[8], record[9] = s[_B], s[_B + 1], s[_B + 2]
    record[10], record[11], record[12] = sqrt(P[3, 3]), sqrt(P[4, 4]), sqrt(P[5, 5])
    return 0


MEKF = StageSpec(
    role="sensor", name="mekf", config=MEKFConfig, step=mekf_step, state_size=_SIZE,
    records=(
        Channel("estimation_error", "rad", "2 vec(q_hat^-1 q_true), hub frame", per_axis=True),
        Channel("estimation_nees", "1", "e^T P^-1 e of the attitude (chi-square, 3 dof)"),
        Channel("estimation_sigma", "rad", "sqrt(diag P) of the attitude", per_axis=True),
        Channel("estimated_gyro_bias", "rad/s", "b_hat", per_axis=True),
        Channel("estimated_gyro_bias_sigma", "rad/s", "sqrt(diag P) of the gyro bias",
                per_axis=True),
    ),
    description="multiplicative extended Kalman filter (gyro + star tracker)",
)  # fmt: skip
