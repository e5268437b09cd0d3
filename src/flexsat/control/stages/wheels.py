"""Reaction-wheel cluster: N wheels whose momenta are integrated with the plant.

Wheel i spins about a_i (unit, hub frame B) with axial inertia I_s; its state is
its axial angular momentum h_i = I_s (a_i . omega + Omega_i), Omega_i its speed
relative to the hub. With J_rest the satellite's inertia without the wheels' axial
spin inertia (the configured hub inertia is read as J_rest: the wheels' housings
and transverse inertia are part of the hub), the total angular momentum is
H_B = J_rest omega + sum a_i h_i (+ the appendages'), and (``docs/control.md``,
'Reaction wheels')::

    h_i_dot = u_i - f_i                                 (wheel axis, net torque)
    J_rest omega_dot + omega x (J_rest omega + sum a_i h_i) = tau_ext - sum a_i h_i_dot

so the wheels exert on the hub the wrench -sum a_i (u_i - f_i) - omega x sum a_i h_i,
evaluated inside every RK4 stage (it depends on omega within the step). u_i is the
motor torque, a first-order response u_i_dot = (u_cmd,i - u_i) / tau_m to the
command; it is cut to zero while it would drive ‖h_i‖ beyond I_s Omega_max
(momentum saturation: the speed limit on the wheel's axial spin rate h_i / I_s,
within a . omega ~ 1e-5 Omega_max of its rate relative to the hub at slew rates).
A wheel is reported saturated at records where ‖h_i‖ >= 0.999 I_s Omega_max (the
drive holds it there, friction pulling it just below).
f_i = c_v Omega_i + c_c tanh(Omega_i / omega_c): viscous and Coulomb friction (the
Coulomb sign smoothed over omega_c). The motor work sum u_i Omega_i and the
friction loss sum f_i Omega_i are integrated as states: with no other torque,
E(t) - E(0) = W_motor - W_friction.

The scenario's disturbance torques act on the hub as they do with the static
actuator, the wheels' held output at each control instant: environment + residual +
sloshing ratio * tau_cmd * sin(2 pi f t) (``[disturbances]``, the same realised
values), without the static actuator's gain G_act and clip (external torques, not the
actuator's output).

At every control instant the body-torque command is allocated by the
pseudo-inverse, u_cmd = -A^+ tau_cmd - k_null (I - A^+ A)(h - I_s Omega_bias),
A = [a_1 ... a_N] (3 x N): the null-space term drives the wheels towards their
bias speed without torquing the hub. When that asks a motor for more than its
limit, u_cmd moves along a null direction of A to the smallest largest motor
torque (:mod:`flexsat.control.stages._allocation`: the exact min-max allocation of
four wheels on three axes), the hub torque unchanged; each u_cmd,i is then clipped
to the motor limit.

Microvibration (``[actuator.microvibration]``, off by default): the empirical wheel
model of Masterson, Miller and Grogan ("Development and validation of reaction wheel
disturbance models: empirical model") and of Bialke ("High fidelity mathematical
modeling of reaction wheel performance"). Each wheel, at rotor angle theta_i
(integrated, theta_i_dot = Omega_i, zero at t = 0) exerts on the hub, for each
harmonic k of a table (harmonic number h_k, coefficient C_k, random phase phi_ik)::

    radial force   F = C_k Omega_i^2 (cos x e1_i + sin x e2_i)     x = h_k theta_i + phi_ik
    axial force    F = C_k Omega_i^2 sin x a_i
    radial torque  T = C_k Omega_i^2 (cos x e1_i + sin x e2_i)

with (e1_i, e2_i, a_i) right-handed. The static imbalance U_s [kg m] is a radial
force of h = 1, the dynamic imbalance U_d [kg m^2] a radial torque of h = 1. A force
acts at the wheel's position r_i (hub frame, from the hub's reference point) and adds
the torque r_i x F about it; the force itself is not applied to the hub's translation
(the stage's wrench is a torque). The phases are drawn once from ``seed``
(numpy's default generator), so a run is reproducible.
"""

from __future__ import annotations

from math import copysign, cos, exp, pi, sin
from typing import Annotated, Literal

import numpy as np
from numba import njit
from pydantic import Field, model_validator

from flexsat.config.models import Positive, Real, _Frozen
from flexsat.control.registry import Channel
from flexsat.control.stages._allocation import minmax_shift
from flexsat.control.stages.registry import (
    ActuatorStageConfig,
    StageSpec,
)
from flexsat.control.stages.static_actuator import PACKED as DISTURBANCES

__all__ = [
    "HARMONIC_KINDS",
    "MAX_HARMONICS",
    "MAX_WHEELS",
    "SATURATED_RATIO",
    "WHEELS",
    "Harmonic",
    "MicrovibrationConfig",
    "WheelsConfig",
    "radial_basis",
    "wheel_axes",
]

MAX_WHEELS = 6
"""Most wheels in one cluster (the stage's state is sized for them)."""
# the disturbances first, as the static actuator packs them (DisturbanceConfig.packed)
_ENV, _RATIO, _HZ, _RES = (
    DISTURBANCES[k] for k in ("environment_nm", "sloshing_ratio", "sloshing_hz", "residual_nm")
)
_D = DISTURBANCES["t_max_nm"] + 1  # then the wheels'
_N, _IS, _UMAX, _WMAX, _CV, _CC, _WC, _TAU, _KNULL, _WBIAS, _W0 = range(_D, _D + 11)
_A = _D + 11  # A, row-major (3, MAX_WHEELS)
_PINV = _A + 3 * MAX_WHEELS  # A^+, row-major (MAX_WHEELS, 3)
_NULL = _PINV + 3 * MAX_WHEELS  # I - A^+ A, row-major (MAX_WHEELS, MAX_WHEELS)
# derived constants the derivative reads (multiplications instead of divisions):
# 1 / I_s, 1 / tau_m, 1 / omega_c, the momentum limit I_s Omega_max, I_s Omega_0
_INV_IS = _NULL + MAX_WHEELS * MAX_WHEELS
_INV_TAU, _INV_WC, _HMAX, _H0 = _INV_IS + 1, _INV_IS + 2, _INV_IS + 3, _INV_IS + 4
_SIZE = _INV_IS + 5
# microvibration, packed only when configured (WheelsConfig._packed_vibration): the
# number of terms at _SIZE, each wheel's e1, e2, r and on flag (10 per wheel slot), then each term's
# kind, h, C and one phase per wheel slot
_VIB_WHEELS = _SIZE + 1
_VIB_TERMS = _VIB_WHEELS + 10 * MAX_WHEELS
_VIB_STRIDE = 3 + MAX_WHEELS
# state, packed for the N wheels of the cluster (the coupled RK4 step carries its first
# 3 N + 2 entries, 4 N + 2 with microvibration, WheelsConfig.integrated_size):
# h_i - I_s Omega_0 at i, motor torque u_i at N + i, command u_cmd,i at 2 N + i (held:
# zero rate), motor work at 3 N, friction loss at 3 N + 1, rotor angle theta_i at
# 3 N + 2 + i (with microvibration only)
_RPM = 2.0 * np.pi / 60.0  # [rad/s per rpm]
SATURATED_RATIO = 0.999
"""``abs(h_i) / (I_s Omega_max)`` at and above which a wheel is reported saturated."""

NonNegative = Annotated[float, Field(ge=0.0, allow_inf_nan=False)]


def wheel_axes(preset: str, pyramid_half_angle_deg: float = 54.7356) -> np.ndarray:
    """Spin axes of a preset cluster, hub frame B.

    Parameters
    ----------
    preset : {"orthogonal3", "pyramid4"}
        ``"orthogonal3"``: the body axes. ``"pyramid4"``: four axes at the half-angle
        from +Z_B, spread 90 deg apart in azimuth from 45 deg.
    pyramid_half_angle_deg : float
        The pyramid's half-angle [deg] (54.7356 deg: equal torque capability on the
        three axes).

    Returns
    -------
    ndarray, shape (N, 3)
        Unit spin axes, hub frame B [-].
    """
    if preset == "orthogonal3":
        return np.eye(3)
    beta = np.radians(pyramid_half_angle_deg)
    phi = np.radians(45.0 + 90.0 * np.arange(4))
    return np.column_stack([np.sin(beta) * np.cos(phi), np.sin(beta) * np.sin(phi),
                            np.full(4, np.cos(beta))])  # fmt: skip


MAX_HARMONICS = 32
"""Most harmonics of one microvibration table (radial force, axial force, radial torque)."""
HARMONIC_KINDS = ("radial_force", "axial_force", "radial_torque")
"""The microvibration tables, in the order the packed terms carry their kind (0, 1, 2)."""
_HarmonicNumber = Annotated[float, Field(gt=0.0, le=1000.0, allow_inf_nan=False)]
_Coefficient = Annotated[float, Field(ge=0.0, le=1.0, allow_inf_nan=False)]


class Harmonic(_Frozen):
    """One harmonic of the empirical wheel model: C Omega^2 at h Omega."""

    number: _HarmonicNumber = Field(description="h, harmonic number of the wheel speed [-]")
    coefficient: _Coefficient = Field(
        description="C: amplitude C Omega^2 [kg m for a force, kg m^2 for a torque]"
    )


class MicrovibrationConfig(_Frozen):
    """The wheels' imbalances and harmonic tables (module docstring, 'Microvibration')."""

    static_imbalance_kg_m: _Coefficient = Field(0.0, description="U_s, static imbalance [kg m]")
    dynamic_imbalance_kg_m2: _Coefficient = Field(
        0.0, description="U_d, dynamic imbalance [kg m^2]"
    )
    radial_force: tuple[Harmonic, ...] = Field(
        (), max_length=MAX_HARMONICS, description="radial force harmonics, C [kg m]"
    )
    axial_force: tuple[Harmonic, ...] = Field(
        (), max_length=MAX_HARMONICS, description="axial force harmonics, C [kg m]"
    )
    radial_torque: tuple[Harmonic, ...] = Field(
        (), max_length=MAX_HARMONICS, description="radial torque harmonics, C [kg m^2]"
    )
    positions_m: tuple[tuple[Real, Real, Real], ...] | None = Field(
        None,
        description="each wheel's position r_i from the hub's reference point, hub frame B "
        "[m]; default: every wheel at the reference point (forces add no torque)",
    )
    wheels: tuple[Annotated[int, Field(ge=1, le=MAX_WHEELS)], ...] | None = Field(
        None, min_length=1, description="the wheels (1-based) that vibrate; default: all"
    )
    seed: Annotated[int, Field(ge=0, lt=2**53)] = Field(1, description="phase stream")

    def vibrating(self, n_wheels: int) -> np.ndarray:
        """Whether each wheel vibrates, shape (n_wheels,)."""
        on = np.ones(n_wheels, dtype=bool)
        if self.wheels is not None:
            on[:] = False
            on[[w - 1 for w in self.wheels]] = True
        return on

    def terms(self) -> list[tuple[int, float, float]]:
        """Every harmonic as (kind index in :data:`HARMONIC_KINDS`, h, C), the imbalances
        first (a radial force and a radial torque of h = 1)."""
        out = [(0, 1.0, self.static_imbalance_kg_m), (2, 1.0, self.dynamic_imbalance_kg_m2)]
        for kind, name in enumerate(HARMONIC_KINDS):
            out += [(kind, h.number, h.coefficient) for h in getattr(self, name)]
        return [t for t in out if t[2] > 0.0]

    def phases(self, n_wheels: int) -> np.ndarray:
        """phi_ik, shape (n_terms, n_wheels), uniform in [0, 2 pi) from ``seed`` [rad]."""
        rng = np.random.default_rng(self.seed)
        return rng.uniform(0.0, 2.0 * np.pi, size=(len(self.terms()), n_wheels))


def radial_basis(axes: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """e1_i, e2_i: unit vectors spanning each wheel's plane, (e1, e2, a) right-handed.

    Parameters
    ----------
    axes : ndarray, shape (N, 3)
        Unit spin axes a_i, hub frame B [-].

    Returns
    -------
    e1, e2 : ndarray, shape (N, 3)
        e1 the hub axis least aligned with a_i made perpendicular to it, e2 = a x e1 [-].
    """
    e1 = np.eye(3)[np.argmin(np.abs(axes), axis=1)]
    e1 = e1 - np.sum(e1 * axes, axis=1)[:, None] * axes
    e1 /= np.linalg.norm(e1, axis=1)[:, None]
    return e1, np.cross(axes, e1)


class WheelsConfig(ActuatorStageConfig):
    """A reaction-wheel cluster (module docstring); ``t_max_nm`` is the body-torque
    limit the law clips its command to."""

    applies_disturbances = True  # [disturbances] act with it

    kind: Literal["wheels"] = Field("wheels", description="the stage's registered name")
    preset: Literal["orthogonal3", "pyramid4"] = Field(
        "pyramid4", description="spin-axis layout when ``axes`` is not given"
    )
    pyramid_half_angle_deg: Annotated[float, Field(gt=0.0, lt=90.0)] = Field(
        54.7356, description="half-angle of the pyramid4 preset from +Z_B [deg]"
    )
    axes: tuple[tuple[Real, Real, Real], ...] | None = Field(
        None, description="spin axes a_i, hub frame B (normalized) [-]; overrides the preset"
    )
    spin_inertia_kg_m2: Positive = Field(
        0.1, description="I_s, axial inertia of each wheel [kg m^2]"
    )
    max_torque_nm: Positive = Field(2.0, description="motor torque limit per wheel [N m]")
    max_speed_rpm: Positive = Field(6000.0, description="speed limit |Omega_i| [rpm]")
    viscous_nm_s_rad: NonNegative = Field(1e-5, description="c_v [N m s/rad]")
    coulomb_nm: NonNegative = Field(1e-3, description="c_c [N m]")
    coulomb_smoothing_rad_s: Positive = Field(0.1, description="omega_c [rad/s]")
    motor_time_constant_s: Positive = Field(0.01, description="tau_m [s]")
    null_space_gain_1_s: NonNegative = Field(0.0, description="k_null [1/s]")
    bias_speed_rpm: Real = Field(0.0, description="Omega_bias, null-space target [rpm]")
    initial_speed_rpm: Real = Field(0.0, description="Omega_i at t = 0, hub at rest [rpm]")
    microvibration: MicrovibrationConfig | None = Field(
        None, description="imbalances and harmonic tables of the wheels (default: none)"
    )

    @model_validator(mode="after")
    def _spanning(self) -> WheelsConfig:
        A = self.spin_axes().T
        if A.shape[1] > MAX_WHEELS:
            raise ValueError(f"axes: at most {MAX_WHEELS} wheels, got {A.shape[1]}")
        if np.linalg.matrix_rank(A, tol=1e-6) < 3:
            raise ValueError("axes: the spin axes must span 3D (rank 3), they do not")
        vib = self.microvibration
        if vib is not None and vib.positions_m is not None and len(vib.positions_m) != A.shape[1]:
            raise ValueError(
                f"microvibration.positions_m: one position per wheel ({A.shape[1]}), "
                f"got {len(vib.positions_m)}"
            )
        if vib is not None and vib.wheels is not None and max(vib.wheels) > A.shape[1]:
            raise ValueError(
                f"microvibration.wheels: wheel numbers from 1 to {A.shape[1]}, "
                f"got {max(vib.wheels)}"
            )
        return self

    def spin_axes(self) -> np.ndarray:
        """a_i, shape (N, 3), unit."""
        if self.axes is None:
            return wheel_axes(self.preset, self.pyramid_half_angle_deg)
        axes = np.array(self.axes, dtype=float).reshape(-1, 3)
        norms = np.linalg.norm(axes, axis=1)
        if np.any(norms < 1e-9):
            raise ValueError("axes: every spin axis needs a non-zero length")
        return axes / norms[:, None]

    def integrated_size(self) -> int:
        """h, u and u_cmd of each wheel (u_cmd held: the motor's response reads it), the
        motor work and the friction loss: 3 N + 2; with microvibration, each rotor's
        angle too: 4 N + 2."""
        n = self.spin_axes().shape[0]
        return (4 if self._vibrating() else 3) * n + 2

    def _vibrating(self) -> bool:
        return self.microvibration is not None and bool(self.microvibration.terms())

    def check(self, scenario) -> None:
        if self.motor_time_constant_s < scenario.dt_s:
            raise ValueError(
                f"motor_time_constant_s must be at least dt_s ({scenario.dt_s} s) "
                f"for the RK4 step to follow it, got {self.motor_time_constant_s}"
            )

    def packed(self, scenario) -> np.ndarray:
        axes = self.spin_axes()
        n = axes.shape[0]
        A = np.zeros((3, MAX_WHEELS))
        A[:, :n] = axes.T
        pinv = np.zeros((MAX_WHEELS, 3))
        pinv[:n] = np.linalg.pinv(axes.T)
        null = np.zeros((MAX_WHEELS, MAX_WHEELS))
        null[:n, :n] = np.eye(n) - pinv[:n] @ axes.T
        head = [n, self.spin_inertia_kg_m2, self.max_torque_nm, self.max_speed_rpm * _RPM,
                self.viscous_nm_s_rad, self.coulomb_nm, self.coulomb_smoothing_rad_s,
                self.motor_time_constant_s, self.null_space_gain_1_s,
                self.bias_speed_rpm * _RPM, self.initial_speed_rpm * _RPM]  # fmt: skip
        derived = [1.0 / self.spin_inertia_kg_m2, 1.0 / self.motor_time_constant_s,
                   1.0 / self.coulomb_smoothing_rad_s, self.spin_inertia_kg_m2 * head[3],
                   self.spin_inertia_kg_m2 * head[10]]  # fmt: skip
        disturbances = scenario.disturbances.packed(self)  # gain 1: not read
        return np.concatenate([disturbances, head, A.ravel(), pinv.ravel(), null.ravel(),
                               derived, self._packed_vibration(axes)])  # fmt: skip

    def _packed_vibration(self, axes: np.ndarray) -> np.ndarray:
        """Empty without microvibration (the packed parameters end at ``_SIZE``); else
        n_terms, then per wheel e1, e2, r and whether it vibrates (10 each, MAX_WHEELS
        slots), then per term its
        kind, h, C and one phase per wheel (3 + MAX_WHEELS each)."""
        if not self._vibrating():
            return np.zeros(0)
        vib = self.microvibration
        n = axes.shape[0]
        e1, e2 = radial_basis(axes)
        r = np.zeros((n, 3)) if vib.positions_m is None else np.array(vib.positions_m, float)
        wheels = np.zeros((MAX_WHEELS, 10))
        wheels[:n] = np.hstack([e1, e2, r, vib.vibrating(n)[:, None]])
        terms = vib.terms()
        rows = np.zeros((len(terms), 3 + MAX_WHEELS))
        rows[:, :3] = terms
        rows[:, 3 : 3 + n] = vib.phases(n)
        return np.concatenate([[len(terms)], wheels.ravel(), rows.ravel()])


@njit(cache=True, inline="always")
def _momentum(p, s, i):
    """h_i: the state holds its change from I_s Omega_0."""
    return p[_IS] * p[_W0] + s[i]


# tanh(x) = x + x^3 P(x^2) / Q(x^2) for abs(x) < 0.625 (Cephes' tanh.c, S. L. Moshier's
# minimax coefficients; Q's leading coefficient is 1)
_TANH_P = (-9.64399179425052238628e-1, -9.92877231001918586564e1, -1.61468768441708447952e3)
_TANH_Q = (1.12811678491632931402e2, 2.23548839060100448583e3, 4.84406305325125486048e3)


@njit(cache=True, inline="always")
def _smooth_sign(z):
    """tanh(z), the Coulomb sign smoothed, at half the C library's cost.

    Written out because the wheels' derivative evaluates it for every wheel at every
    RK4 stage, and the C library's tanh (a range reduction around ``expm1``) was
    the largest item the wheels add to a step (``CHANGELOG.md``, "The friction's sign
    from one exponential"). Below
    abs(z) = 0.55, Cephes' rational form z + z^3 P(z^2) / Q(z^2) (one division, 1 ulp
    of ``math.tanh`` there); above, with e = exp(-2 abs(z)),
    tanh(z) = sign(z) (1 - e) / (1 + e): one exponential;
    from abs(z) = 22 both are exactly +-1. Within 2 ulp of ``math.tanh`` everywhere
    (``tests/control/stages/test_wheels.py``); zero keeps its sign, NaN stays NaN.
    """
    a = abs(z)
    if a < 0.55:
        if a == 0.0:
            return z
        s = z * z
        p = (_TANH_P[0] * s + _TANH_P[1]) * s + _TANH_P[2]
        q = ((s + _TANH_Q[0]) * s + _TANH_Q[1]) * s + _TANH_Q[2]
        return z + z * (s * p / q)
    if a >= 22.0:
        return copysign(1.0, z)
    e = exp(-2.0 * a)  # NaN passes through
    return copysign((1.0 - e) / (1.0 + e), z)


@njit(cache=True, inline="always")
def _vibration(p, s, n, w0, w1, w2, state_dot):
    """The microvibration torque on the hub, sum_i sum_k (r_i x F_ik + T_ik) [N m], hub
    frame B; writes theta_i_dot = Omega_i (module docstring, 'Microvibration')."""
    tx, ty, tz = 0.0, 0.0, 0.0
    n_terms = int(p[_SIZE])
    for i in range(n):
        ax, ay, az = p[_A + i], p[_A + MAX_WHEELS + i], p[_A + 2 * MAX_WHEELS + i]
        speed = (p[_H0] + s[i]) * p[_INV_IS] - (ax * w0 + ay * w1 + az * w2)
        state_dot[3 * n + 2 + i] = speed
        theta = s[3 * n + 2 + i]
        w = _VIB_WHEELS + 10 * i
        if p[w + 9] == 0.0:
            continue  # a wheel without imbalance: only its angle is integrated
        fx, fy, fz, mx, my, mz = 0.0, 0.0, 0.0, 0.0, 0.0, 0.0
        for k in range(n_terms):
            t = _VIB_TERMS + _VIB_STRIDE * k
            kind, amplitude = p[t], p[t + 2] * speed * speed
            x = p[t + 1] * theta + p[t + 3 + i]
            if kind == 1.0:  # axial force
                a = amplitude * sin(x)
                fx, fy, fz = fx + a * ax, fy + a * ay, fz + a * az
                continue
            c, d = amplitude * cos(x), amplitude * sin(x)
            vx = c * p[w] + d * p[w + 3]
            vy = c * p[w + 1] + d * p[w + 4]
            vz = c * p[w + 2] + d * p[w + 5]
            if kind == 0.0:  # radial force
                fx, fy, fz = fx + vx, fy + vy, fz + vz
            else:  # radial torque
                mx, my, mz = mx + vx, my + vy, mz + vz
        rx, ry, rz = p[w + 6], p[w + 7], p[w + 8]
        tx += mx + ry * fz - rz * fy
        ty += my + rz * fx - rx * fz
        tz += mz + rx * fy - ry * fx
    return tx, ty, tz


@njit(cache=True, error_model="numpy")  # compiled with DERIVATIVE_SIGNATURE on first use
def wheels_derivative(x, n_dof, t, omega, params, state, state_dot, wrench):
    """h_dot, u_dot, motor power, friction power; the wheels' wrench on the hub.

    Evaluated at every RK4 stage: it multiplies by the packed reciprocals instead of
    dividing, and with ``error_model="numpy"`` carries no zero-division checks (the
    divisors are validated positive).
    """
    p, s = params, state
    n = int(p[_N])
    # read once: the stores below could alias every array for the compiler
    w0, w1, w2 = omega[0], omega[1], omega[2]  # S(Theta) Theta_dot (eq. 2.28)
    h0, inv_is, h_max, inv_tau = p[_H0], p[_INV_IS], p[_HMAX], p[_INV_TAU]
    c_v, c_c, inv_wc = p[_CV], p[_CC], p[_INV_WC]
    tx, ty, tz = wrench[0], wrench[1], wrench[2]
    hx, hy, hz, work, loss = 0.0, 0.0, 0.0, 0.0, 0.0
    for i in range(n):
        ax, ay, az = p[_A + i], p[_A + MAX_WHEELS + i], p[_A + 2 * MAX_WHEELS + i]
        h = h0 + s[i]  # the state holds the change from I_s Omega_0
        speed = h * inv_is - (ax * w0 + ay * w1 + az * w2)  # Omega_i
        u = s[n + i]
        if abs(h) >= h_max and u * h > 0.0:
            u = 0.0  # the drive cuts the torque that would pass the momentum limit
        friction = c_v * speed + c_c * _smooth_sign(speed * inv_wc)
        h_dot = u - friction
        state_dot[i] = h_dot
        state_dot[n + i] = (s[2 * n + i] - s[n + i]) * inv_tau
        work += u * speed
        loss += friction * speed
        tx -= ax * h_dot
        ty -= ay * h_dot
        tz -= az * h_dot
        hx += ax * h
        hy += ay * h
        hz += az * h
    state_dot[3 * n] = work
    state_dot[3 * n + 1] = loss
    if p.size > _SIZE:  # microvibration: packed only when configured
        vx, vy, vz = _vibration(p, s, n, w0, w1, w2, state_dot)
        tx, ty, tz = tx + vx, ty + vy, tz + vz
    # - omega x sum a_i h_i
    wrench[0] = tx - (w1 * hz - w2 * hy)
    wrench[1] = ty - (w2 * hx - w0 * hz)
    wrench[2] = tz - (w0 * hy - w1 * hx)
    return 0


@njit(cache=True)  # compiled with ACTUATOR_SIGNATURE on first use
def wheels_step(tau_cmd, t, dt, params, state, tau_applied, record):
    """Allocate the body torque to the motors (module docstring); held on the hub: the
    disturbance torques (the wheels act through their derivative)."""
    p, s = params, state
    n = int(p[_N])
    bias = p[_IS] * p[_WBIAS]
    hx, hy, hz, h2, h_abs, saturated, asked = 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0
    u = s[2 * n : 3 * n]  # the motor commands, written here
    for i in range(n):
        u[i] = 0.0
        for a in range(3):
            u[i] -= p[_PINV + 3 * i + a] * tau_cmd[a]
        if p[_KNULL] != 0.0:  # null-space momentum management, off by default
            for j in range(n):
                u[i] -= p[_KNULL] * p[_NULL + MAX_WHEELS * i + j] * (_momentum(p, s, j) - bias)
        asked = max(asked, abs(u[i]))
    if asked > p[_UMAX]:  # beyond a motor's limit: the min-max allocation (_allocation)
        j = 0
        for i in range(n):
            if p[_NULL + (MAX_WHEELS + 1) * i] > p[_NULL + (MAX_WHEELS + 1) * j]:
                j = i
        if p[_NULL + (MAX_WHEELS + 1) * j] > 1e-12:  # column j of I - A^+ A: a null direction
            d = p[_NULL + j : _NULL + MAX_WHEELS * n : MAX_WHEELS]
            step = minmax_shift(u, d, n)
            asked = 0.0
            for i in range(n):
                u[i] += step * d[i]
                asked = max(asked, abs(u[i]))
    for i in range(n):
        u[i] = min(p[_UMAX], max(-p[_UMAX], u[i]))
        h = _momentum(p, s, i)
        record[8 + i] = h * p[_INV_IS] / _RPM  # the axial spin rate [rpm]
        hx += p[_A + i] * h
        hy += p[_A + MAX_WHEELS + i] * h
        hz += p[_A + 2 * MAX_WHEELS + i] * h
        h2 += h * h
        h_abs = max(h_abs, abs(h))
        if abs(h) >= SATURATED_RATIO * p[_HMAX]:
            saturated += 2.0**i
    slosh = p[_RATIO] * sin(2.0 * pi * p[_HZ] * t)
    for a in range(3):
        tau_applied[a] = p[_ENV + a] + slosh * tau_cmd[a] + p[_RES + a]
    record[0], record[1], record[2] = hx, hy, hz
    record[3] = 0.5 * h2 / p[_IS]  # the divisions once, not per wheel
    record[4] = s[3 * n]
    record[5] = s[3 * n + 1]
    record[6] = h_abs / p[_IS] / p[_WMAX]  # the max of each wheel's ratio, bit for bit
    record[7] = saturated
    for i in range(n, MAX_WHEELS):
        record[8 + i] = np.nan  # no such wheel
    record[8 + MAX_WHEELS] = asked / p[_UMAX]
    return 0


WHEELS = StageSpec(
    role="actuator", name="wheels", config=WheelsConfig, step=wheels_step,
    derivative=wheels_derivative, state_size=4 * MAX_WHEELS + 2,
    records=(
        Channel("wheel_momentum_B", "N m s", "sum a_i h_i, hub frame B", per_axis=True),
        Channel("wheel_kinetic_energy", "J", "sum h_i^2 / (2 I_s)"),
        Channel("wheel_motor_work", "J", "integral of sum u_i Omega_i"),
        Channel("wheel_friction_loss", "J", "integral of sum f_i Omega_i"),
        Channel("wheel_speed_ratio", "1", "max |h_i| / (I_s Omega_max)"),
        Channel("actuator_saturated", "1", "bit i set: wheel i at its momentum limit"),
        Channel("wheel_speed", "rpm", "h_i / I_s: each wheel's axial spin rate (its speed "
                "relative to the hub plus a_i . omega)", per_unit=MAX_WHEELS),
        Channel("actuator_torque_ratio", "1",
                "max |u_cmd,i| / u_max: the largest motor torque asked of a wheel (before "
                "its clip) over the motor limit"),
    ),
    description="reaction-wheel cluster, momenta integrated with the plant",
)  # fmt: skip
