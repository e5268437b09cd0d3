"""Hybrid active damping: root actuators on appendage joint coordinates, strain-rate feedback.

Each actuated coordinate q_j (chosen by name in the plant's state layout) receives
the generalized force Q_j of an actuator at the appendage root (a torque on a root
rotation, a force on a root translation), commanded by joint-rate feedback::

    Q_cmd,j = clip(-k q_dot_j, +-Q_max)                          (authority limit)
    Q_j[k+1] = a Q_j[k] + (1 - a) Q_cmd,j[k],   a = exp(-2 pi f_b dt)

the second line the exact discretization of the first-order lag of bandwidth f_b
at the control period dt (zero-order hold on the command), so the actuator needs
no continuous state: its output is the held Q_j itself. Q enters eq. 2.50 as an
applied generalized force on the joint coordinate, so the equal and opposite
reaction on the hub is the joint equations' own (no separate hub torque is
added). With ``engage_below_deg`` the loop acts only while the true pointing
error from the reference is below it: the hub law near the target plus the
damping loop, the last phase the thesis proposes (sec. 6.2).
``docs/control.md``, "Hybrid active damping".
"""

from __future__ import annotations

from math import asin, exp, pi, sqrt
from typing import Annotated, Literal

import numpy as np
from numba import njit
from pydantic import Field

from flexsat.config.models import Positive
from flexsat.control.quaternion import euler_zyx_to_quaternion, quaternion_error
from flexsat.control.registry import Channel
from flexsat.control.stages.registry import (
    JointActuatorConfig,
    StageSpec,
)

__all__ = ["JOINT_RATE_FEEDBACK", "JointRateFeedbackConfig"]

_GAIN, _LIMIT, _BANDWIDTH, _ENGAGE, _N, _INDICES = 0, 1, 2, 3, 4, 5


class JointRateFeedbackConfig(JointActuatorConfig):
    """Root actuators closed by joint-rate (strain-rate) feedback (module docstring)."""

    kind: Literal["rate_feedback"] = Field(
        "rate_feedback", description="the stage's registered name"
    )
    coordinates: list[str] = Field(
        min_length=1,
        description="actuated coordinates: '<appendage>.<coordinate>', or '<coordinate>' "
        "for that coordinate of every appendage (names of the plant's state layout)",
    )
    gain: Positive = Field(description="k: Q = -k q_dot [N m s/rad on rotations, N s/m "
                           "on translations]")  # fmt: skip
    limit: Positive = Field(description="authority |Q| <= Q_max per coordinate [N m or N]")
    bandwidth_hz: Annotated[float, Field(gt=0.0, le=1e4, allow_inf_nan=False)] = Field(
        20.0, description="first-order lag bandwidth f_b [Hz]"
    )
    engage_below_deg: Positive | None = Field(
        None, description="act only while the pointing error is below this [deg]; "
        "default: always"
    )  # fmt: skip

    def indices(self, layout) -> list[int]:
        """Indices in q of the actuated coordinates (ConfigError naming an unknown one)."""
        return layout.appendage_indices(self.coordinates, "joint_actuator.coordinates")

    def packed(self, scenario, plant=None) -> np.ndarray:
        """k, Q_max, f_b [Hz], engage threshold [rad] (-1: always), count, indices."""
        idx = self.indices(plant.layout)
        engage = -1.0 if self.engage_below_deg is None else np.radians(self.engage_below_deg)
        return np.array([self.gain, self.limit, self.bandwidth_hz, engage, len(idx), *idx],
                        dtype=float)  # fmt: skip


@njit(cache=True)  # compiled with JOINT_ACTUATOR_SIGNATURE on first use
def joint_rate_feedback_step(x, n_dof, t, dt, q_d, J_design, params, state, Q, record):
    """Lagged, limited joint-rate feedback into Q; J_design as it is (contract in
    ``stages.registry``)."""
    k, limit = params[_GAIN], params[_LIMIT]
    a = exp(-2.0 * pi * params[_BANDWIDTH] * dt)
    active = True
    if params[_ENGAGE] > 0.0:
        e = quaternion_error(q_d, euler_zyx_to_quaternion(x[3], x[4], x[5]))
        active = 2.0 * asin(min(1.0, sqrt(e[1] ** 2 + e[2] ** 2 + e[3] ** 2))) < params[_ENGAGE]
    power, effort = 0.0, 0.0
    for i in range(int(params[_N])):
        j = int(params[_INDICES + i])
        rate = x[n_dof + j]
        command = min(limit, max(-limit, -k * rate)) if active else 0.0
        Q[j] = a * Q[j] + (1.0 - a) * command
        power += Q[j] * rate
        effort = max(effort, abs(Q[j]))
    record[0] = power
    record[1] = effort
    return 0


JOINT_RATE_FEEDBACK = StageSpec(
    role="joint_actuator", name="rate_feedback", config=JointRateFeedbackConfig,
    step=joint_rate_feedback_step,
    records=(
        Channel("joint_actuator_power", "W", "sum Q_j q_dot_j of the root actuators"),
        Channel("joint_actuator_effort", "N m", "max |Q_j| over the actuated coordinates"),
    ),
    description="root actuators on joint coordinates, joint-rate (strain-rate) feedback",
)  # fmt: skip
