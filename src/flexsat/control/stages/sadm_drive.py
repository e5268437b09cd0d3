"""Solar-array drive (SADM): a motor driving a mount coordinate along a commanded profile.

The driven coordinate beta_j is a real generalized coordinate of the plant: a joint
of zero stiffness between the hub and the array, with the drive rotor and the array
as its inertia (:func:`flexsat.dynamics.appendages.sadm.driven_plate` builds it for
the thesis plate). The motor closes its own stiffness/damping loop on the commanded
angle::

    Q_j = clip(k_d (beta_cmd - beta_j) + c_d (beta_dot_cmd - beta_dot_j), +-Q_max)

held between control instants (zero-order hold). The commanded profile starts at the
coordinate's initial angle beta_0 (the run's initial state): ``constant_rate``,
beta_cmd = beta_0 + r t; ``to_target``, the rate-limited move to ``target_deg`` at
abs(beta_dot_cmd) = r. Q enters eq. 2.50 as the generalized force on the joint
coordinate, so the motor's reaction on the hub is the joint equations' own.
``docs/control.md``, "Solar-array drive (SADM)".

About a constant-rate command the loop is the mass-spring-damper
J beta_e'' + c_d beta_e' + k_d beta_e = 0 in the error beta_e = beta - beta_cmd
(J the driven inertia): started at rest, the error peaks at r / (e omega_n) when
critically damped (omega_n = sqrt(k_d / J)) and decays as exp(-omega_n t).
"""

from __future__ import annotations

from typing import Annotated, Literal

import numpy as np
from numba import njit
from pydantic import Field, model_validator

from flexsat.config.models import Positive
from flexsat.control.registry import Channel
from flexsat.control.stages.registry import (
    JOINT_ACTUATOR_SIGNATURE,
    JointActuatorConfig,
    StageSpec,
)

__all__ = ["SADM_DRIVE", "SADMDriveConfig", "commanded_angle"]

_K, _C, _LIMIT, _RATE, _TO_TARGET, _N, _INDICES = 0, 1, 2, 3, 4, 5, 6
_NonNegative = Annotated[float, Field(ge=0.0, le=1e12, allow_inf_nan=False)]
_Rate = Annotated[float, Field(ge=-360.0, le=360.0, allow_inf_nan=False)]


class SADMDriveConfig(JointActuatorConfig):
    """Drive motors on mount coordinates following a commanded profile (module docstring)."""

    kind: Literal["sadm_drive"] = Field("sadm_drive", description="the stage's registered name")
    coordinates: list[str] = Field(
        min_length=1,
        description="driven coordinates: '<appendage>.<coordinate>', or '<coordinate>' for "
        "that coordinate of every appendage (e.g. 'eta_ry_0' of driven plates)",
    )
    stiffness_nm_rad: Positive = Field(description="k_d, drive loop stiffness [N m/rad]")
    damping_nms_rad: _NonNegative = Field(description="c_d, drive loop damping [N m s/rad]")
    profile: Literal["constant_rate", "to_target"] = Field(
        "constant_rate", description="constant_rate: beta_0 + r t; to_target: rate-limited "
        "move to target_deg"
    )  # fmt: skip
    rate_deg_s: _Rate = Field(description="r: the constant rate (signed) or, to_target, the "
                              "rate limit (> 0) [deg/s]")  # fmt: skip
    target_deg: Annotated[float, Field(ge=-360.0, le=360.0, allow_inf_nan=False)] | None = Field(
        None, description="to_target: the final angle of every driven coordinate [deg]"
    )
    max_torque_nm: Positive | None = Field(None, description="motor torque limit |Q| [N m]; "
                                           "default: none")  # fmt: skip

    @model_validator(mode="after")
    def _profile(self) -> SADMDriveConfig:
        if self.profile == "to_target":
            if self.target_deg is None:
                raise ValueError("target_deg: the to_target profile needs a target angle [deg]")
            if self.rate_deg_s <= 0.0:
                raise ValueError(f"rate_deg_s: the to_target rate limit must be > 0 deg/s "
                                 f"(got {self.rate_deg_s:g})")  # fmt: skip
        elif self.target_deg is not None:
            raise ValueError("target_deg: only the to_target profile takes a target")
        return self

    def packed(self, scenario, plant=None) -> np.ndarray:
        """k_d, c_d, Q_max (-1: none), r [rad/s], to_target flag, count, indices, then per
        coordinate beta_0 [rad] (the run's initial state) and the target [rad]."""
        from flexsat.simulate.openloop import initial_state

        idx = plant.layout.appendage_indices(self.coordinates, "joint_actuator.coordinates")
        q0 = initial_state(plant, scenario)[0]
        start = [float(q0[j]) for j in idx]
        target = np.radians(self.target_deg) if self.target_deg is not None else 0.0
        limit = -1.0 if self.max_torque_nm is None else self.max_torque_nm
        return np.array([self.stiffness_nm_rad, self.damping_nms_rad, limit,
                         np.radians(self.rate_deg_s), float(self.profile == "to_target"),
                         len(idx), *idx, *start, *([target] * len(idx))], dtype=float)  # fmt: skip


@njit(cache=True)
def commanded_angle(t, start, target, rate, to_target):
    """beta_cmd(t) [rad] and beta_dot_cmd(t) [rad/s] of one driven coordinate.

    Parameters
    ----------
    t : float
        Time from the start of the run [s].
    start, target : float
        Initial and (``to_target``) final angle [rad].
    rate : float
        Constant rate or (``to_target``) rate limit, > 0 [rad/s].
    to_target : bool
        The rate-limited move to ``target`` instead of the constant rate.
    """
    if not to_target:
        return start + rate * t, rate
    span = target - start
    if rate * t >= abs(span):
        return target, 0.0
    sign = 1.0 if span > 0.0 else -1.0
    return start + sign * rate * t, sign * rate


@njit(JOINT_ACTUATOR_SIGNATURE, cache=True)
def sadm_drive_step(x, n_dof, t, dt, q_d, params, state, Q, record):
    """PD drive torque on each driven coordinate into Q (contract in ``stages.registry``)."""
    k, c, limit = params[_K], params[_C], params[_LIMIT]
    n = int(params[_N])
    power, effort, error = 0.0, 0.0, 0.0
    for i in range(n):
        j = int(params[_INDICES + i])
        beta_cmd, rate_cmd = commanded_angle(
            t, params[_INDICES + n + i], params[_INDICES + 2 * n + i], params[_RATE],
            params[_TO_TARGET] > 0.0,
        )  # fmt: skip
        e = beta_cmd - x[j]
        torque = k * e + c * (rate_cmd - x[n_dof + j])
        if limit > 0.0:
            torque = min(limit, max(-limit, torque))
        Q[j] = torque
        power += torque * x[n_dof + j]
        effort = max(effort, abs(torque))
        error = max(error, abs(e))
    record[0] = power
    record[1] = effort
    record[2] = error
    return 0


SADM_DRIVE = StageSpec(
    role="joint_actuator", name="sadm_drive", config=SADMDriveConfig, step=sadm_drive_step,
    records=(
        Channel("sadm_power", "W", "sum Q_j beta_dot_j of the drive motors"),
        Channel("sadm_torque", "N m", "max |Q_j| over the driven coordinates"),
        Channel("sadm_tracking_error", "rad", "max |beta_cmd - beta_j| over the driven "
                "coordinates"),
    ),
    description="solar-array drive: PD motor loop on a commanded mount-angle profile",
)  # fmt: skip
