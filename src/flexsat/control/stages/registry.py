"""The loop-stage contract: sensor -> law -> actuator -> plant, each stage compiled.

A stage is one module that builds a :class:`StageSpec` (its parameter model, its
state size, a compiled step and what it records) and one registration line. The
slew scenario selects one sensor (``[sensor] kind = ...``) and one actuator
(``[actuator] kind = ...``); the compiled loop calls their steps through numba
first-class functions, so a stage defined in a user's own file runs at built-in
speed. Both run at every control instant (every ``control_dt_s``); their outputs
are held between instants (zero-order hold).

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

For both: ``params`` are the stage's packed parameters (:meth:`StageConfig.packed`),
``state`` (state_size,) its own state, zero at t = 0, ``record`` receives its
declared records in order. Return 0, or non-zero to stop the run.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Annotated, Any, Literal

import numpy as np
from numba import types
from pydantic import Field

from flexsat.config.models import Positive, _Frozen
from flexsat.control.registry import Channel, Registry

__all__ = [
    "ACTUATORS",
    "ACTUATOR_SIGNATURE",
    "SENSORS",
    "SENSOR_SIGNATURE",
    "ActuatorStageConfig",
    "StageConfig",
    "StageSpec",
    "register_actuator",
    "register_sensor",
    "validate_actuator_config",
    "validate_sensor_config",
]

_vec = types.float64[::1]
SENSOR_SIGNATURE = types.int64(_vec, types.int64, types.float64, _vec, _vec, _vec, _vec, _vec)
"""x, n_dof, t, params, state, q_meas (out), omega_meas (out), record (out)."""
ACTUATOR_SIGNATURE = types.int64(_vec, types.float64, types.float64, _vec, _vec, _vec, _vec)
"""tau_cmd, t, dt, params, state, tau_applied (out), record (out)."""


class StageConfig(_Frozen):
    """Base of every stage's parameter model; a subclass declares ``kind: Literal[...]``."""

    kind: str

    def packed(self, scenario: Any) -> np.ndarray:
        """The packed parameters the compiled step reads, float64, shape (n_params,).

        ``scenario`` is the whole slew scenario (a stage may read other tables, as
        the static actuator reads ``[disturbances]``).
        """
        return np.zeros(0)


class ActuatorStageConfig(StageConfig):
    """Base of every actuator's model: the limits the laws and requirement R3 read."""

    t_max_nm: Positive = Field(2.0, description="hardware saturation per axis [N m]")
    reduction_factor: Annotated[float, Field(gt=0.0, le=1.0)] = Field(
        0.95, description="software limit RF * T_max [-]"
    )


@dataclass(frozen=True)
class StageSpec:
    """A loop stage as the loop and every consumer see it.

    Parameters
    ----------
    role : {"sensor", "actuator"}
    name : str
        The ``kind`` of its parameter table.
    config : type[StageConfig]
    step : numba dispatcher
        Compiled with the role's signature (module docstring).
    state_size : int
    records : tuple[Channel, ...]
        What ``record`` holds, in order; each becomes a variable of the result.
    description : str
    """

    role: Literal["sensor", "actuator"]
    name: str
    config: type[StageConfig]
    step: Any
    state_size: int = 0
    records: tuple[Channel, ...] = ()
    description: str = ""

    @property
    def record_size(self) -> int:
        return sum(c.size for c in self.records)


SENSORS: Registry[StageSpec] = Registry("sensor", "flexsat.sensors")
ACTUATORS: Registry[StageSpec] = Registry("actuator", "flexsat.actuators")
_BY_ROLE = {"sensor": SENSORS, "actuator": ACTUATORS}


def _register(role: str, spec: StageSpec, default: bool) -> StageSpec:
    if spec.role != role:
        raise ValueError(f"stage {spec.name!r} is a {spec.role}, not a {role}")
    if spec.config.model_fields["kind"].default != spec.name:
        raise ValueError(f"stage {spec.name!r}: its config's kind must default to {spec.name!r}")
    return _BY_ROLE[role].register(spec.name, spec, default=default)


def register_sensor(spec: StageSpec, default: bool = False) -> StageSpec:
    """Register a sensor stage under ``spec.name`` (replacing one of that name)."""
    return _register("sensor", spec, default)


def register_actuator(spec: StageSpec, default: bool = False) -> StageSpec:
    """Register an actuator stage under ``spec.name`` (replacing one of that name)."""
    if not issubclass(spec.config, ActuatorStageConfig):
        raise ValueError(f"actuator {spec.name!r}: its config must derive ActuatorStageConfig")
    return _register("actuator", spec, default)


def validate_sensor_config(value: Any) -> StageConfig:
    """A ``[sensor]`` table validated by its stage's model (no ``kind``: the default)."""
    return SENSORS.validate_table(value, lambda spec: spec.config)


def validate_actuator_config(value: Any) -> ActuatorStageConfig:
    """An ``[actuator]`` table validated by its stage's model (no ``kind``: the default)."""
    return ACTUATORS.validate_table(value, lambda spec: spec.config)
