"""Rest-to-rest eigenaxis slew reference, optionally input-shaped.

The rotation from the initial attitude q_0 to the target q_T is one rotation of
angle Theta about the fixed unit axis e (Euler's theorem, q_0^-1 (x) q_T =
[cos(Theta/2), e sin(Theta/2)]). The reference turns about e by theta(t) from 0 to
Theta::

    q_d(t) = q_0 (x) [cos(theta/2), e sin(theta/2)]
    omega_d = e theta_dot,  omega_dot_d = e theta_ddot   (frame D; e is fixed in it)

theta(t) is a rate- and acceleration-limited trapezoid (bang-coast-bang) or the
7th-order polynomial 35u^4 - 84u^5 + 70u^6 - 20u^7 of u = t / T (zero rate,
acceleration and jerk at both ends). Input shaping convolves theta with a shaper's
impulses (:mod:`~flexsat.control.stages.shapers`): theta_s(t) = sum A_i theta(t - t_i),
designed from the modes of the modal analysis the slew couples to the hub. The
shaped slew ends at ``start_s`` + the profile's duration + the shaper's length.
``docs/control.md``, "Reference trajectories and input shaping".
"""

from __future__ import annotations

from math import cos, sin, sqrt
from typing import Annotated, Literal

import numpy as np
from numba import njit
from pydantic import Field, model_validator

from flexsat.analysis.modal import modal_analysis
from flexsat.config.models import Positive, _Frozen
from flexsat.control.quaternion import quaternion_product, target_quaternion
from flexsat.control.registry import Channel
from flexsat.control.stages.registry import PlantStageConfig, StageSpec
from flexsat.control.stages.shapers import shaper_for_modes

__all__ = ["EIGENAXIS_REFERENCE", "EigenaxisReferenceConfig", "ShaperConfig", "coupled_modes"]

_TRAPEZOID, _POLYNOMIAL = 0.0, 1.0
# packed: q_0 (4), e (3), Theta, start, profile code, p1, p2, p3, n impulses, A (n), t (n),
# then the time the shaped reference comes to rest
_Q0, _AXIS, _ANGLE, _START, _CODE, _P, _N, _IMPULSES = 0, 4, 7, 8, 9, 10, 13, 14


class ShaperConfig(_Frozen):
    """Input shaper of the reference (``[reference.shaper]``)."""

    kind: Literal["zv", "zvd", "ei"] = Field("zvd", description="shaper: ZV, ZVD or EI (5 %)")
    frequencies_hz: list[Positive] | None = Field(
        None, description="modes to shape [Hz]; default: the modal analysis's modes "
        "coupled to the hub up to max_frequency_hz"
    )  # fmt: skip
    damping_ratios: list[Annotated[float, Field(ge=0.0, lt=1.0)]] | None = Field(
        None, description="their damping ratios [-]; default: modal (or 0 for given frequencies)"
    )
    max_frequency_hz: Positive = Field(2.0, description="highest coupled mode shaped [Hz]")
    frequency_scale: Annotated[float, Field(gt=0.0, le=10.0)] = Field(
        1.0, description="design frequencies = scale x the modes' (a modelling error) [-]"
    )

    @model_validator(mode="after")
    def _paired(self) -> ShaperConfig:
        if self.damping_ratios is not None and (
            self.frequencies_hz is None or len(self.damping_ratios) != len(self.frequencies_hz)
        ):
            raise ValueError("damping_ratios needs frequencies_hz, one ratio per frequency")
        return self

    def impulses(self, plant) -> tuple[np.ndarray, np.ndarray]:
        """Amplitudes (sum 1) and times [s] of the multi-mode shaper for ``plant``."""
        if self.frequencies_hz is None:
            frequencies, ratios = coupled_modes(plant, self.max_frequency_hz)
        else:
            frequencies = np.array(self.frequencies_hz)
            ratios = np.zeros(len(frequencies)) if self.damping_ratios is None \
                else np.array(self.damping_ratios)  # fmt: skip
        return shaper_for_modes(self.kind, frequencies * self.frequency_scale, ratios)


def coupled_modes(plant, max_frequency_hz: float) -> tuple[np.ndarray, np.ndarray]:
    """Frequencies and modal damping ratios of the flexible modes coupled to the hub.

    A mode is coupled if the modal analysis names a hub DOF it moves
    (``Mode.hub_dof``); its damping ratio is phi^T C phi / (2 omega) of the
    mass-normalized shape (the joints' damping, eq. 2.15).

    Parameters
    ----------
    plant : Plant
        The design plant.
    max_frequency_hz : float
        Modes above this frequency are left out [Hz].

    Returns
    -------
    frequencies : ndarray, shape (k,)
        Natural frequencies, ascending [Hz].
    ratios : ndarray, shape (k,)
        Modal damping ratios [-].
    """
    modal = modal_analysis(plant)
    C = plant.damping_matrix()
    frequencies, ratios = [], []
    for mode in modal.modes:
        if mode.kind == "rigid" or mode.hub_dof is None or mode.frequency_hz > max_frequency_hz:
            continue
        phi = modal.shapes[:, mode.index - 1]
        frequencies.append(mode.frequency_hz)
        ratios.append(float(phi @ C @ phi) / (4.0 * np.pi * mode.frequency_hz))
    return np.array(frequencies), np.array(ratios)


class EigenaxisReferenceConfig(PlantStageConfig):
    """Rest-to-rest eigenaxis slew (module docstring): ``[reference] kind = "eigenaxis"``."""

    kind: Literal["eigenaxis"] = Field("eigenaxis", description="the stage's registered name")
    profile: Literal["trapezoid", "polynomial"] = Field(
        "trapezoid", description="rate/acceleration-limited trapezoid or 7th-order polynomial"
    )
    rate_limit_deg_s: Positive = Field(2.0, description="trapezoid: peak rate [deg/s]")
    acceleration_limit_deg_s2: Positive = Field(
        0.2, description="trapezoid: peak acceleration [deg/s^2]"
    )
    duration_s: Positive | None = Field(None, description="polynomial: slew duration T [s]")
    start_s: Annotated[float, Field(ge=0.0, allow_inf_nan=False)] = Field(
        0.0, description="the reference leaves q_0 at this time [s]"
    )
    shaper: ShaperConfig | None = Field(None, description="input shaper; default none")

    @model_validator(mode="after")
    def _duration(self) -> EigenaxisReferenceConfig:
        if self.profile == "polynomial" and self.duration_s is None:
            raise ValueError("duration_s is required with profile = 'polynomial' (> 0 s)")
        return self

    def profile_parameters(self, angle: float) -> tuple[float, float, float, float]:
        """Profile code and (p1, p2, p3): trapezoid (alpha [rad/s^2], t_acc, t_coast [s]),
        polynomial (T [s], 0, 0)."""
        if self.profile == "polynomial":
            return _POLYNOMIAL, float(self.duration_s), 0.0, 0.0
        alpha = np.radians(self.acceleration_limit_deg_s2)
        rate = np.radians(self.rate_limit_deg_s)
        t_acc = rate / alpha
        if alpha * t_acc**2 >= angle:  # the rate limit is never reached: bang-bang
            return _TRAPEZOID, alpha, sqrt(angle / alpha), 0.0
        return _TRAPEZOID, alpha, t_acc, (angle - alpha * t_acc**2) / rate

    def packed(self, scenario, plant=None) -> np.ndarray:
        """q_0, e, Theta, start, profile, shaper impulses (module constants)."""
        q0 = target_quaternion(scenario.initial.attitude_deg)
        qT = target_quaternion(scenario.target_euler_deg)
        rel = np.array(quaternion_product((q0[0], -q0[1], -q0[2], -q0[3]), qT))
        if rel[0] < 0.0:  # the shorter way round
            rel = -rel
        norm = float(np.linalg.norm(rel[1:]))
        axis = rel[1:] / norm if norm > 0.0 else np.array([1.0, 0.0, 0.0])
        angle = 2.0 * np.arctan2(norm, rel[0])
        A, t = (np.ones(1), np.zeros(1)) if self.shaper is None else self.shaper.impulses(plant)
        code, p1, p2, p3 = self.profile_parameters(angle)
        end = self.start_s + (p1 if code == _POLYNOMIAL else 2.0 * p2 + p3) + t[-1]
        return np.concatenate([q0, axis, [angle, self.start_s, code, p1, p2, p3, A.size],
                               A, t, [end]])  # fmt: skip

    def duration(self, scenario, plant=None) -> float:
        """When the shaped reference comes to rest at the target [s]."""
        return float(self.packed(scenario, plant)[-1])


@njit(cache=True)
def _profile(p, tau):
    """theta, theta_dot, theta_ddot of the unshaped profile at tau [s] after its start."""
    angle = p[_ANGLE]
    if tau <= 0.0:
        return 0.0, 0.0, 0.0
    if p[_CODE] == _POLYNOMIAL:
        T = p[_P]
        if tau >= T:
            return angle, 0.0, 0.0
        u = tau / T
        u2 = u * u
        u3 = u2 * u
        s = u3 * u * (35.0 - 84.0 * u + 70.0 * u2 - 20.0 * u3)
        ds = u3 * (140.0 - 420.0 * u + 420.0 * u2 - 140.0 * u3) / T
        dds = u2 * (420.0 - 1680.0 * u + 2100.0 * u2 - 840.0 * u3) / (T * T)
        return angle * s, angle * ds, angle * dds
    alpha, t_acc, t_coast = p[_P], p[_P + 1], p[_P + 2]
    peak = alpha * t_acc
    end = 2.0 * t_acc + t_coast
    if tau < t_acc:
        return 0.5 * alpha * tau * tau, alpha * tau, alpha
    if tau < t_acc + t_coast:
        return 0.5 * alpha * t_acc * t_acc + peak * (tau - t_acc), peak, 0.0
    if tau < end:
        r = end - tau
        return angle - 0.5 * alpha * r * r, alpha * r, -alpha
    return angle, 0.0, 0.0


@njit(cache=True)  # compiled with REFERENCE_SIGNATURE on first use
def eigenaxis_reference_step(t, params, state, q_d, omega_d, omega_dot_d, record):
    """The shaped eigenaxis reference at t (contract in ``stages.registry``)."""
    n = int(params[_N])
    theta, rate, acc = 0.0, 0.0, 0.0
    if t >= params[_IMPULSES + 2 * n]:  # at rest at the target: no impulse to sum
        theta = params[_ANGLE]
        n = 0
    for i in range(n):  # theta_s(t) = sum A_i theta(t - t_i)
        a = params[_IMPULSES + i]
        th, w, dw = _profile(params, t - params[_START] - params[_IMPULSES + n + i])
        theta += a * th
        rate += a * w
        acc += a * dw
    c, s = cos(0.5 * theta), sin(0.5 * theta)
    e = (params[_AXIS], params[_AXIS + 1], params[_AXIS + 2])
    q = quaternion_product((params[_Q0], params[_Q0 + 1], params[_Q0 + 2], params[_Q0 + 3]),
                           (c, s * e[0], s * e[1], s * e[2]))  # fmt: skip
    for i in range(4):
        q_d[i] = q[i]
    for i in range(3):
        omega_d[i] = e[i] * rate
        omega_dot_d[i] = e[i] * acc
    record[0] = theta
    return 0


EIGENAXIS_REFERENCE = StageSpec(
    role="reference", name="eigenaxis", config=EigenaxisReferenceConfig,
    step=eigenaxis_reference_step,
    records=(Channel("reference_angle", "rad", "theta_s: the reference's angle about e"),),
    description="rest-to-rest eigenaxis slew (trapezoid or polynomial), optionally shaped",
)  # fmt: skip
