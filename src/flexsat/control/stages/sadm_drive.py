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

The law's rigid design model either stays at the drives' initial angles
(``design_model = "initial"``) or follows the measured angles (``"measured"``, the
drive's encoder being the coordinate beta_j itself): at each control instant,
before the law, the stage writes

    J_design = J_design,0 + sum_j [J_j(beta_j) - J_j(beta_j,0)]

where J_j(a) is J_tot of the rigid design model (:func:`flexsat.dynamics.rigid.rigid_inertia`,
about the hub centre of mass) with drive j at angle a and the others at their
initial angle. J_tot is a sum over the frozen bodies of R J_c R^T + m ((r . r) I - r r^T)
about the hub centre of mass, a fixed point of B: a drive turning its bodies about
a fixed axis by a makes R(a) = I + sin a [u]x + (1 - cos a) [u]x^2 and each centre of
mass r(a) affine in (cos a, sin a), so each term, and J_j, is the trigonometric
polynomial of degree 2

    J_j(a) = P0 + P1 cos a + P2 sin a + P3 cos 2a + P4 sin 2a

(3x3 matrices; no term of the satellite's moving centre of mass enters, the
reference point being the hub's). Different drives move different bodies, so their
changes add. :meth:`SADMDriveConfig.packed` samples the rigid model at five
equally spaced angles per drive and solves the 5x5 system for P1..P4: exact to
round-off, and the one rigid model.
"""

from __future__ import annotations

from math import cos, sin
from typing import Annotated, Literal

import numpy as np
from numba import njit
from pydantic import Field, model_validator

from flexsat.config.models import Positive
from flexsat.control.registry import Channel
from flexsat.control.stages.registry import (
    JointActuatorConfig,
    StageSpec,
)
from flexsat.dynamics.initial import initial_state

__all__ = ["SADM_DRIVE", "SADMDriveConfig", "commanded_angle", "design_coefficients"]

_K, _C, _LIMIT, _RATE, _TO_TARGET, _N, _INDICES = 0, 1, 2, 3, 4, 5, 6
_HARMONICS = 4  # P1..P4 of J_j(a): cos a, sin a, cos 2a, sin 2a
_FLAG = 9  # state: J_design,0 (9, row-major), then its captured flag
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
    design_model: Literal["initial", "measured"] = Field(
        "initial", description="the law's rigid design inertia: at the drives' initial "
        "angles, or following the measured angles (J_tot at each control instant)"
    )  # fmt: skip

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
        coordinate beta_0 [rad] (the run's initial state) and the target [rad], then the
        measured-design flag and, if set, each coordinate's P1..P4 [kg m^2]
        (:func:`design_coefficients`)."""
        idx = plant.layout.appendage_indices(self.coordinates, "joint_actuator.coordinates")
        q0 = initial_state(plant, scenario)[0]
        start = [float(q0[j]) for j in idx]
        target = np.radians(self.target_deg) if self.target_deg is not None else 0.0
        limit = -1.0 if self.max_torque_nm is None else self.max_torque_nm
        measured = self.design_model == "measured"
        design = design_coefficients(plant, idx, q0).ravel() if measured else np.zeros(0)
        return np.array([self.stiffness_nm_rad, self.damping_nms_rad, limit,
                         np.radians(self.rate_deg_s), float(self.profile == "to_target"),
                         len(idx), *idx, *start, *([target] * len(idx)), float(measured),
                         *design], dtype=float)  # fmt: skip


def design_coefficients(plant, indices: list[int], q0: np.ndarray) -> np.ndarray:
    """P1..P4 of J_j(a), the rigid design model's J_tot with drive j at angle a.

    J_j(a) = P0 + P1 cos a + P2 sin a + P3 cos 2a + P4 sin 2a (module docstring),
    from :func:`~flexsat.dynamics.rigid.rigid_inertia` at five angles beta_j,0 + 2 pi
    k / 5 (the others at :func:`~flexsat.dynamics.rigid.design_coordinates`).

    Parameters
    ----------
    plant : Plant
        The satellite.
    indices : list of int
        Indices in q of the driven coordinates, rotations each of its own appendage.
    q0 : ndarray, shape (n_dof,)
        The run's initial coordinates [m, rad].

    Returns
    -------
    ndarray, shape (len(indices), 4, 3, 3)
        P1..P4 per driven coordinate, hub frame B [kg m^2].

    Raises
    ------
    ConfigError
        Naming ``joint_actuator.design_model``: a driven coordinate that is not a
        rotation, two in one appendage, or a model that cannot freeze at an angle.
    """
    from flexsat.dynamics.rigid import design_coordinates, rigid_inertia
    from flexsat.errors import ConfigError

    _check_measurable(plant, indices)
    reference = design_coordinates(plant, q0)
    out = np.empty((len(indices), _HARMONICS, 3, 3))
    for i, j in enumerate(indices):
        angles = q0[j] + 2.0 * np.pi * np.arange(5) / 5.0
        basis = np.column_stack([np.ones(5), np.cos(angles), np.sin(angles),
                                 np.cos(2.0 * angles), np.sin(2.0 * angles)])  # fmt: skip
        samples = np.empty((5, 9))
        for k, angle in enumerate(angles):
            q = reference.copy()
            q[j] = angle
            try:
                samples[k] = rigid_inertia(plant, q).ravel()
            except ValueError as exc:
                raise ConfigError(
                    f"joint_actuator.design_model: 'measured' cannot freeze "
                    f"{plant.layout.dof_names()[j]!r} at an angle: {exc}"
                ) from None
        out[i] = np.linalg.solve(basis, samples)[1:].reshape(_HARMONICS, 3, 3)
    return out


def _check_measurable(plant, indices: list[int]) -> None:
    """Refuse driven coordinates the degree-2 polynomial does not describe (ConfigError)."""
    from flexsat.errors import ConfigError

    names = plant.layout.dof_names()
    owners = []
    for j in indices:
        block = next(b for b in plant.layout.blocks if b.slice.start <= j < b.slice.stop)
        if block.units[j - block.offset] != "rad":
            raise ConfigError(
                f"joint_actuator.design_model: 'measured' follows rotation "
                f"angles only, {names[j]!r} is in {block.units[j - block.offset]}"
            )
        owners.append(block.appendage)
    if len(set(owners)) != len(owners):
        raise ConfigError(
            "joint_actuator.design_model: 'measured' follows one driven "
            f"coordinate per appendage (got {[names[j] for j in indices]})"
        )


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


@njit(cache=True)
def follow_design(x, params, n, J_design, state):
    """J_design = J_design,0 + sum_j [J_j(beta_j) - J_j(beta_j,0)] (module docstring).

    Parameters
    ----------
    x : ndarray, shape (2 n_dof + 2,)
        Plant state; beta_j = x[j], the drive's encoder [rad].
    params : ndarray
        The stage's packed parameters (:meth:`SADMDriveConfig.packed`, measured).
    n : int
        Number of driven coordinates.
    J_design : ndarray, shape (3, 3)
        Written: the design inertia at the measured angles, hub frame B [kg m^2].
    state : ndarray, shape (10,)
        J_design,0 row-major and its flag, captured at the first call (zero at t = 0).

    Returns
    -------
    float
        The largest entry of abs(J_design - J_design,0) [kg m^2].
    """
    if state[_FLAG] == 0.0:  # the run's design inertia, before any change
        for a in range(9):
            state[a] = J_design[a // 3, a % 3]
        state[_FLAG] = 1.0
    for a in range(9):
        J_design[a // 3, a % 3] = state[a]
    for i in range(n):
        beta, beta0 = x[int(params[_INDICES + i])], params[_INDICES + n + i]
        f1, f2 = cos(beta) - cos(beta0), sin(beta) - sin(beta0)
        f3, f4 = cos(2.0 * beta) - cos(2.0 * beta0), sin(2.0 * beta) - sin(2.0 * beta0)
        base = _INDICES + 3 * n + 1 + 9 * _HARMONICS * i
        for a in range(9):
            J_design[a // 3, a % 3] += (
                f1 * params[base + a] + f2 * params[base + 9 + a]
                + f3 * params[base + 18 + a] + f4 * params[base + 27 + a]
            )  # fmt: skip
    change = 0.0
    for a in range(9):
        change = max(change, abs(J_design[a // 3, a % 3] - state[a]))
    return change


@njit(cache=True)  # compiled with JOINT_ACTUATOR_SIGNATURE on first use
def sadm_drive_step(x, n_dof, t, dt, q_d, J_design, params, state, Q, record):
    """PD drive torque on each driven coordinate into Q and, with ``design_model =
    "measured"``, the design inertia at the measured angles into J_design (contract in
    ``stages.registry``)."""
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
    if params[_INDICES + 3 * n] > 0.0:
        record[3] = follow_design(x, params, n, J_design, state)
    return 0


SADM_DRIVE = StageSpec(
    role="joint_actuator", name="sadm_drive", config=SADMDriveConfig, step=sadm_drive_step,
    records=(
        Channel("sadm_power", "W", "sum Q_j beta_dot_j of the drive motors"),
        Channel("sadm_torque", "N m", "max |Q_j| over the driven coordinates"),
        Channel("sadm_tracking_error", "rad", "max |beta_cmd - beta_j| over the driven "
                "coordinates"),
        Channel("design_inertia_change", "kg m^2", "max |J_design - J_design,0| over the "
                "entries: the design model following the drives (0: design_model initial)"),
    ),
    state_size=_FLAG + 1,
    description="solar-array drive: PD motor loop on a commanded mount-angle profile",
)  # fmt: skip
