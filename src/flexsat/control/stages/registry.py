"""The loop-stage contract: sensor -> law -> actuator -> plant, each stage compiled.

A stage is one module that builds a :class:`StageSpec` (its parameter model, its
state size, a compiled step and what it records) and one registration line. The
slew scenario selects one sensor (``[sensor] kind = ...``) and one actuator
(``[actuator] kind = ...``); the compiled loop calls their steps through numba
first-class functions, so a stage defined in a user's own file runs at built-in
speed. Both run at every control instant (every ``control_dt_s``); their outputs
are held between instants (zero-order hold). Each step below is compiled with its
role's signature: at import when declared with it, else when a slew first uses it
(:func:`flexsat.compiled.first_class.first_class`; the built-ins are declared
``@njit(cache=True)``).

Sensor step, ``@njit(SENSOR_SIGNATURE, cache=True)``::

    status = step(x, n_dof, t, params, state, q_meas, omega_meas, record)

reads the plant state ``x`` (q (n_dof), q_dot (n_dof), work, dissipation; the hub's
ZYX Euler angles relative to the inertial frame N at q[3:6], their rates at
q_dot[3:6]: once the integrator has re-based the attitude, the loop hands the sensor
that view of its state, docs/model.md, 'Attitude parametrization') and writes the measured
attitude quaternion ``q_meas`` (4,), scalar first, and body rate ``omega_meas``
(3,) [rad/s].

Actuator step, ``@njit(ACTUATOR_SIGNATURE, cache=True)``::

    status = step(tau_cmd, t, dt, params, state, tau_applied, record)

maps the law's command ``tau_cmd`` (3,) [N m] to the torque applied to the hub
``tau_applied`` (3,) [N m] (actuator dynamics and disturbances), ``dt`` being the
control period [s].

Reference step, ``@njit(REFERENCE_SIGNATURE, cache=True)``, run first at every
control instant::

    status = step(t, params, state, q_d, omega_d, omega_dot_d, record)

writes the reference the law tracks: attitude ``q_d`` (4,), scalar first, rate
``omega_d`` (3,) [rad/s] and acceleration ``omega_dot_d`` (3,) [rad/s^2], both in
the reference frame D (the law rotates them into B). The default ``step`` reference
holds the target with zero rate: the thesis's step regulation.

Joint-actuator step, ``@njit(JOINT_ACTUATOR_SIGNATURE, cache=True)``, run after
the sensing chain and before the law at every control instant::

    status = step(x, n_dof, t, dt, q_d, J_design, params, state, Q, record)

reads the plant state ``x`` and the reference ``q_d`` and writes the generalized
forces it applies to appendage coordinates into ``Q[6:]`` (n_dof,) [N or N m per
coordinate], held until the next instant; they enter the plant's equations as
``Q`` of eq. 2.50, so the reaction on the hub is the joint equations' own. It never
writes ``Q[:6]`` (the hub's, overwritten by the integrator). ``J_design`` (3, 3)
[kg m^2], hub frame B, is the law's design inertia: a stage may update it in place
(``sadm_drive`` with ``design_model = "measured"``: J_tot at the measured drive
angles), and the law reads it at the same instant; it starts as the run's design
inertia and keeps the last value written. Its parameter model derives
:class:`JointActuatorConfig` and packs against the plant's state layout
(coordinates by name). The default ``none`` applies nothing.

For all: ``params`` are the stage's packed parameters (:meth:`StageConfig.packed`),
``state`` (state_size,) its own state, zero at t = 0, ``record`` receives its
declared records in order. Return 0, or non-zero to stop the run.

Chains: the scenario's ``sensor_stages`` run after ``[sensor]``, in order, on the
same ``q_meas``/``omega_meas`` (each reads what the previous wrote and refines it:
gyro, star tracker, estimator); its ``actuator_stages`` run before ``[actuator]``,
in order, each reading the previous stage's output as its ``tau_cmd`` (filter,
delay). Only the final ``[actuator]`` carries the limits (``ActuatorStageConfig``).

Continuous states, optional ``derivative`` of an actuator stage,
``@njit(DERIVATIVE_SIGNATURE, cache=True)``::

    status = derivative(x, n_dof, t, omega, params, state, state_dot, wrench)

is evaluated at every RK4 stage of every plant step, with the plant state ``x``,
the hub's body rate ``omega`` (3,) = S(Theta) Theta_dot at that state [rad/s], hub
frame B (computed once per RK4 stage with the plant's own trigonometry), and the
stage's ``state`` at that RK4 stage: its first ``integrated_size()`` entries (of
its config, :meth:`StageConfig.integrated_size`; default all ``state_size``). It writes
``state_dot`` (as long) for the entries it integrates (the loop zeroes it first:
entries left at zero are held, i.e. discrete) and adds the torque the stage exerts
on the hub to ``wrench`` (3,) [N m], hub frame B (on top of the held
``tau_applied``). The stage's discrete ``step`` still runs at every control instant
and sees the integrated entries in ``state``.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Annotated, Any, ClassVar, Literal

import numpy as np
from numba import njit, types
from pydantic import Field

from flexsat.config.models import Positive, _Frozen
from flexsat.control.registry import Channel, Registry

__all__ = [
    "ACTUATORS",
    "ACTUATOR_SIGNATURE",
    "DERIVATIVE_SIGNATURE",
    "JOINT_ACTUATORS",
    "JOINT_ACTUATOR_SIGNATURE",
    "REFERENCES",
    "REFERENCE_SIGNATURE",
    "SENSORS",
    "SENSOR_SIGNATURE",
    "ActuatorStageConfig",
    "JointActuatorConfig",
    "PlantStageConfig",
    "Role",
    "StageConfig",
    "StageSpec",
    "no_derivative",
    "register_stage",
    "validate_stage",
]

_vec = types.float64[::1]
SENSOR_SIGNATURE = types.int64(_vec, types.int64, types.float64, _vec, _vec, _vec, _vec, _vec)
"""x, n_dof, t, params, state, q_meas (out), omega_meas (out), record (out)."""
ACTUATOR_SIGNATURE = types.int64(_vec, types.float64, types.float64, _vec, _vec, _vec, _vec)
"""tau_cmd, t, dt, params, state, tau_applied (out), record (out)."""
REFERENCE_SIGNATURE = types.int64(types.float64, _vec, _vec, _vec, _vec, _vec, _vec)
"""t, params, state, q_d (out), omega_d (out), omega_dot_d (out), record (out)."""
JOINT_ACTUATOR_SIGNATURE = types.int64(
    _vec,
    types.int64,
    types.float64,
    types.float64,
    _vec,
    types.float64[:, ::1],
    _vec,
    _vec,
    _vec,
    _vec,
)
"""x, n_dof, t, dt, q_d, J_design (in/out), params, state, Q (out), record (out)."""
DERIVATIVE_SIGNATURE = types.int64(_vec, types.int64, types.float64, _vec, _vec, _vec, _vec, _vec)
"""x, n_dof, t, omega (body rate, hub frame B), params, state, state_dot (out), wrench
(in/out, added to)."""


@njit(cache=True)  # compiled with DERIVATIVE_SIGNATURE on first use
def no_derivative(x, n_dof, t, omega, params, state, state_dot, wrench):
    """The derivative of a stage without continuous states: nothing integrated.

    Parameters
    ----------
    x : ndarray, shape (2 n_dof + 2,)
        Plant state [SI].
    n_dof : int
        Number of generalized coordinates.
    t : float
        Time [s].
    omega : ndarray, shape (3,)
        Hub body rate, hub frame B [rad/s].
    params, state : ndarray
        The stage's packed parameters and state [per stage].
    state_dot : ndarray
        Left at zero [per stage per s].
    wrench : ndarray, shape (3,)
        Left as it is [N m].

    Returns
    -------
    int
        0.
    """
    return 0


class StageConfig(_Frozen):
    """Base of every stage's parameter model; a subclass declares ``kind: Literal[...]``."""

    kind: str = Field(description="the stage's registered name")

    def packed(self, scenario: Any) -> np.ndarray:
        """The packed parameters the compiled step reads, float64, shape (n_params,).

        ``scenario`` is the whole slew scenario (a stage may read other tables, as
        the static actuator reads ``[disturbances]``).
        """
        return np.zeros(0)

    def check(self, scenario: Any) -> None:
        """Refuse a setting inconsistent with the rest of ``scenario`` (ValueError whose
        message starts with the field's name); default: nothing to check."""

    def integrated_size(self) -> int | None:
        """How many leading entries of the state an actuation stage's ``derivative``
        integrates (module docstring, 'Continuous states').

        The coupled RK4 step carries only those (its cost grows with them); the rest
        are discrete, held between control instants and seen by ``step`` only. None
        (the default): all ``state_size`` entries.
        """
        return None


class ActuatorStageConfig(StageConfig):
    """Base of every actuator's model: the limits the laws and requirement R3 read.

    ``applies_disturbances`` (class attribute, default False): whether the actuator,
    as the final ``[actuator]``, applies the scenario's ``[disturbances]`` (the
    static actuator and the wheels do); the disturbance figure draws them only then.
    """

    applies_disturbances: ClassVar[bool] = False

    t_max_nm: Positive = Field(2.0, description="hardware saturation per axis [N m]")
    reduction_factor: Annotated[float, Field(gt=0.0, le=1.0)] = Field(
        0.95, description="software limit RF * T_max [-]"
    )


class PlantStageConfig(StageConfig):
    """Base of the stages designed against the plant they fly (reference, joint actuator).

    ``moving_target`` (class attribute, default False): a reference whose target moves
    (nadir, Sun): the run's pointing and rate errors are then taken from the reference
    it produced at each record, not from the scenario's fixed target.
    """

    moving_target: ClassVar[bool] = False

    def packed(self, scenario: Any, plant: Any = None) -> np.ndarray:
        """Packed parameters; ``plant`` is the :class:`~flexsat.dynamics.plant.Plant`
        the run flies (its state layout names the coordinates, its modal analysis
        gives the modes)."""
        return np.zeros(0)


class JointActuatorConfig(PlantStageConfig):
    """Base of every joint actuator's model."""


Role = Literal["sensor", "actuator", "reference", "joint_actuator"]
"""Where a stage sits in the loop; each role has its registry and its table."""


@dataclass(frozen=True)
class StageSpec:
    """A loop stage as the loop and every consumer see it.

    Parameters
    ----------
    role : {"sensor", "actuator", "reference", "joint_actuator"}
        Where the stage sits in the loop.
    name : str
        The ``kind`` of its parameter table.
    config : type of StageConfig
        Its parameter model.
    step : numba dispatcher
        Compiled with the role's signature (module docstring).
    state_size : int
        Length of its state array (0 for a stateless stage).
    records : tuple of Channel
        What ``record`` holds, in order; each becomes a variable of the result.
    description : str
        One line for listings.
    derivative : numba dispatcher, optional
        Actuators only: compiled with :data:`DERIVATIVE_SIGNATURE`; its entries of
        ``state`` are integrated with the plant inside each RK4 step.
    overwrites, leaves : tuple of {"q_meas", "omega_meas"}
        Sensors only: the outputs the stage sets from the plant state alone, never
        reading their incoming value, and those it neither reads nor writes. A stage
        declaring neither is taken to read both. A stage without state or records
        whose every output a later stage overwrites before any reads it is left out
        of the flown chain (:func:`flexsat.simulate.stage_chain.flown_chain`).
    """

    role: Role
    name: str
    config: type[StageConfig]
    step: Any
    state_size: int = 0
    records: tuple[Channel, ...] = ()
    description: str = ""
    derivative: Any = None
    overwrites: tuple[str, ...] = ()
    leaves: tuple[str, ...] = ()

    @property
    def record_size(self) -> int:
        return sum(c.size for c in self.records)


SENSORS: Registry[StageSpec] = Registry("sensor", "flexsat.sensors")
ACTUATORS: Registry[StageSpec] = Registry("actuator", "flexsat.actuators")
REFERENCES: Registry[StageSpec] = Registry("reference", "flexsat.references")
JOINT_ACTUATORS: Registry[StageSpec] = Registry("joint actuator", "flexsat.joint_actuators")


@dataclass(frozen=True)
class _RoleRules:
    """What a role asks of its stages' parameter models."""

    registry: Registry[StageSpec]
    base: type[StageConfig]  # every stage of the role derives it
    final: type[StageConfig]  # the one a role's own table ([actuator]...) selects derives it


_ROLES: dict[str, _RoleRules] = {
    "sensor": _RoleRules(SENSORS, StageConfig, StageConfig),
    "actuator": _RoleRules(ACTUATORS, StageConfig, ActuatorStageConfig),  # limits: R3
    "reference": _RoleRules(REFERENCES, PlantStageConfig, PlantStageConfig),
    "joint_actuator": _RoleRules(JOINT_ACTUATORS, JointActuatorConfig, JointActuatorConfig),
}


def register_stage(spec: StageSpec, default: bool = False) -> StageSpec:
    """Register a loop stage in its role's registry under ``spec.name`` (replacing one
    of that name).

    The role is ``spec.role``. Its config's ``kind`` must default to ``spec.name``; a
    joint actuator's config derives :class:`JointActuatorConfig`, a reference's
    :class:`PlantStageConfig`. Only an actuator whose config derives
    :class:`ActuatorStageConfig` (the limits) can be the final ``[actuator]`` (and so
    the default); any actuator can be one of the ``actuator_stages``.

    Parameters
    ----------
    spec : StageSpec
        The stage: its role, name, config model, compiled step and records.
    default : bool
        Make it the stage its role's table (``[sensor]``, ``[actuator]``,
        ``[reference]``, ``[joint_actuator]``) selects when it gives no ``kind``.

    Returns
    -------
    StageSpec
        ``spec``, so a module can keep it: ``X = register_stage(StageSpec(...))``.
    """
    rules = _ROLES[spec.role]
    if spec.config.model_fields["kind"].default != spec.name:
        raise ValueError(f"stage {spec.name!r}: its config's kind must default to {spec.name!r}")
    required = rules.final if default else rules.base
    if not issubclass(spec.config, required):
        raise ValueError(f"{spec.role} {spec.name!r}: its config must derive {required.__name__}")
    return rules.registry.register(spec.name, spec, default=default)


def validate_stage(role: Role, value: Any, chained: bool = False) -> StageConfig:
    """A stage's table validated by the model of the stage its ``kind`` names.

    Parameters
    ----------
    role : {"sensor", "actuator", "reference", "joint_actuator"}
        The registry the ``kind`` is looked up in.
    value : dict or StageConfig
        The table (no ``kind``: the role's default stage), or an already validated model.
    chained : bool
        The table is one of the ``sensor_stages`` or ``actuator_stages`` (any stage of
        the role), not the role's own table (whose stage must carry what the loop
        reads of it, e.g. the final ``[actuator]``'s limits).

    Returns
    -------
    StageConfig
        The validated model, of the stage's own config class.
    """
    rules = _ROLES[role]
    config = rules.registry.validate_table(value, lambda spec: spec.config)
    if not chained and not isinstance(config, rules.final):
        raise ValueError(f"kind {config.kind!r} cannot be the [{role}] (its config does not "
                         f"derive {rules.final.__name__}): it can only be one of the "
                         f"{role}_stages, before the final [{role}]")  # fmt: skip
    return config
