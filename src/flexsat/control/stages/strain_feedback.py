"""Hybrid active damping from strain sensing: the root actuators of ``rate_feedback``
closed on the strain rate estimated from noisy, band-limited root-strain gauges.

Each actuated coordinate q_j (a root rotation or translation, named in the plant's
state layout) carries a strain gauge (or fibre-optic sensor) at the appendage root.
The root strain is proportional to the root deformation, so the gauge is modelled
in the coordinate's own units (gauge factor 1: rad on rotations, m on
translations): the gain and noise are then stated against the joint equations
directly, and a gauge factor G [strain/rad] only scales noise and gain together.
At every control instant k (period dt)::

    m_j[k] = q_j[k] + sigma n_j[k]                               (white, seeded)
    y_j[k] = b y_j[k-1] + (1 - b) m_j[k],   b = exp(-2 pi f_s dt)  (sensor filter)
    eps_dot_j[k] = (y_j[k] - y_j[k-1]) / dt                      (backward difference)

then the law of ``rate_feedback`` on eps_dot_j in place of the true rate q_dot_j:
Q_cmd,j = clip(-k eps_dot_j, +-Q_max), through its first-order lag of bandwidth
f_b, with its ``engage_below_deg``. The filter holds the sensor's bandwidth f_s
(the exact discretization of the first-order lag at the control period, the
measurement held over the period); the backward difference lags the true rate by
dt / 2, the filter by 1 / (2 pi f_s) at low frequency. The filter starts at the
first measurement (the gauges are on and settled before the release), so the
first estimate is 0. The noise n_j[k] is standard normal, draw (k, j) of the
stream ``seed`` (:mod:`flexsat.control.stages.noise`): the same seed gives the
same run. ``docs/control.md``, "Hybrid active damping", "Strain sensing".
"""

from __future__ import annotations

from math import exp, pi
from typing import Annotated, Literal

import numpy as np
from numba import njit
from pydantic import Field

from flexsat.control.registry import Channel
from flexsat.control.stages.joint_rate_feedback import (
    _INDICES,
    _N,
    JointRateFeedbackConfig,
    joint_rate_feedback_step,
)
from flexsat.control.stages.noise import normal
from flexsat.control.stages.registry import StageSpec
from flexsat.errors import ConfigError

__all__ = ["MAX_COORDINATES", "STRAIN_FEEDBACK", "StrainFeedbackConfig"]

MAX_COORDINATES = 24
"""Most coordinates one stage senses (its state and records are sized for them)."""
# packed after rate_feedback's parameters (at _INDICES + n): noise std, sensor
# bandwidth f_s [Hz], seed
_NOISE, _SENSOR_BW, _SEED = 0, 1, 2
# state: instants seen, then per coordinate the filtered measurement y_j and the
# estimated rate (held for the record)
_COUNT, _FILTERED = 0, 1
_RATE = _FILTERED + MAX_COORDINATES
_STATE_SIZE = _RATE + MAX_COORDINATES


class StrainFeedbackConfig(JointRateFeedbackConfig):
    """Root actuators closed by strain-rate feedback from noisy root-strain gauges
    (module docstring); the actuator and its law are ``rate_feedback``'s."""

    kind: Literal["strain_feedback"] = Field(  # type: ignore[assignment]
        "strain_feedback", description="the stage's registered name"
    )
    noise_rad: Annotated[float, Field(ge=0.0, le=1.0, allow_inf_nan=False)] = Field(
        1e-6, description="sigma, white measurement noise std per sample [rad on rotations, "
        "m on translations]"
    )  # fmt: skip
    sensor_bandwidth_hz: Annotated[float, Field(gt=0.0, le=1e5, allow_inf_nan=False)] = Field(
        50.0, description="f_s, first-order sensor filter bandwidth [Hz]"
    )
    seed: Annotated[int, Field(ge=0, lt=2**53)] = Field(1, description="noise stream")

    def indices(self, layout) -> list[int]:
        """Indices in q of the sensed and actuated coordinates (ConfigError naming an
        unknown one, or more than :data:`MAX_COORDINATES`)."""
        idx = super().indices(layout)
        if len(idx) > MAX_COORDINATES:
            raise ConfigError(f"joint_actuator.coordinates: {len(idx)} coordinates, at most "
                              f"{MAX_COORDINATES} allowed")  # fmt: skip
        return idx

    def packed(self, scenario, plant=None) -> np.ndarray:
        """rate_feedback's parameters, then sigma, f_s [Hz] and the seed."""
        base = super().packed(scenario, plant)
        return np.concatenate([base, [self.noise_rad, self.sensor_bandwidth_hz, self.seed]])


@njit(cache=True)  # compiled with JOINT_ACTUATOR_SIGNATURE on first use
def strain_feedback_step(x, n_dof, t, dt, q_d, J_design, params, state, Q, record):
    """Sense, filter and differentiate the root deformations, then ``rate_feedback``'s
    law on the estimated rates (contract in ``stages.registry``)."""
    n = int(params[_N])
    extra = _INDICES + n
    sigma, seed = params[extra + _NOISE], params[extra + _SEED]
    b = exp(-2.0 * pi * params[extra + _SENSOR_BW] * dt)
    first = state[_COUNT] == 0.0
    sensed = x.copy()  # the plant state with the estimated rates in place of the true
    for i in range(n):
        j = int(params[_INDICES + i])
        measured = x[j]
        if sigma > 0.0:
            measured += sigma * normal(seed, state[_COUNT] * MAX_COORDINATES + i)
        previous = state[_FILTERED + i]
        filtered = measured if first else b * previous + (1.0 - b) * measured
        state[_FILTERED + i] = filtered
        state[_RATE + i] = 0.0 if first else (filtered - previous) / dt
        sensed[n_dof + j] = state[_RATE + i]
    state[_COUNT] += 1.0
    status = joint_rate_feedback_step(sensed, n_dof, t, dt, q_d, J_design, params, state, Q,
                                      record)  # fmt: skip
    power = 0.0  # the actuators' true power, on the true rates
    for i in range(n):
        j = int(params[_INDICES + i])
        power += Q[j] * x[n_dof + j]
    record[0] = power
    for i in range(MAX_COORDINATES):
        record[2 + i] = state[_RATE + i] if i < n else np.nan
    return status


STRAIN_FEEDBACK = StageSpec(
    role="joint_actuator", name="strain_feedback", config=StrainFeedbackConfig,
    step=strain_feedback_step, state_size=_STATE_SIZE,
    records=(
        Channel("joint_actuator_power", "W", "sum Q_j q_dot_j of the root actuators"),
        Channel("joint_actuator_effort", "N m", "max |Q_j| over the actuated coordinates"),
        Channel("strain_rate_estimate", "rad/s", "eps_dot_j, the filtered gauges' backward "
                "difference, per actuated coordinate in order", per_unit=MAX_COORDINATES),
    ),
    description="root actuators on joint coordinates, strain-rate feedback from noisy "
    "band-limited root-strain gauges",
)  # fmt: skip
