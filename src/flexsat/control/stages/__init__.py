"""Loop stages around the law: sensors and actuators, one module each, one registry.

Built in: the thesis's ideal sensor and static actuator. Write your own stage in
your own file (see ``docs/control.md``): a parameter model, a compiled step of
:data:`SENSOR_SIGNATURE` or :data:`ACTUATOR_SIGNATURE` and one registration line.
"""

from flexsat.control.stages.delay import DELAY
from flexsat.control.stages.gyro import GYRO
from flexsat.control.stages.ideal_sensor import IDEAL_SENSOR
from flexsat.control.stages.mekf import MEKF
from flexsat.control.stages.notch import NOTCH
from flexsat.control.stages.registry import (
    ACTUATOR_SIGNATURE,
    ACTUATORS,
    DERIVATIVE_SIGNATURE,
    SENSOR_SIGNATURE,
    SENSORS,
    ActuatorStageConfig,
    StageConfig,
    StageSpec,
    register_actuator,
    register_sensor,
    validate_actuator_config,
    validate_actuator_stage,
    validate_sensor_config,
    validate_sensor_stage,
)
from flexsat.control.stages.star_tracker import STAR_TRACKER
from flexsat.control.stages.static_actuator import STATIC_ACTUATOR
from flexsat.control.stages.wheels import WHEELS

__all__ = [
    "ACTUATORS",
    "ACTUATOR_SIGNATURE",
    "DERIVATIVE_SIGNATURE",
    "SENSORS",
    "SENSOR_SIGNATURE",
    "ActuatorStageConfig",
    "StageConfig",
    "StageSpec",
    "register_actuator",
    "register_sensor",
    "validate_actuator_config",
    "validate_actuator_stage",
    "validate_sensor_config",
    "validate_sensor_stage",
]

register_sensor(IDEAL_SENSOR, default=True)
register_sensor(GYRO)
register_sensor(STAR_TRACKER)
register_sensor(MEKF)
register_actuator(STATIC_ACTUATOR, default=True)
register_actuator(WHEELS)
register_actuator(DELAY)
register_actuator(NOTCH)
