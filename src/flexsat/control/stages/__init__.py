"""Loop stages around the law: sensors and actuators, one module each, one registry.

Built in: the thesis's ideal sensor and static actuator; the reference generators
(the thesis's ``step``, the shaped ``eigenaxis`` slew, and ``nadir`` and ``sun``
pointing along an orbit) and the joint actuators
(``none``, the thesis's hub-only control, ``rate_feedback``, hybrid active
damping, ``strain_feedback``, the same through noisy root strain gauges, and
``sadm_drive``, the solar-array drive). Write your own stage in your
own file (see ``docs/control.md``): a parameter model, a compiled step of its role's
signature and one registration line.
"""

from flexsat.control.stages.delay import DELAY
from flexsat.control.stages.eigenaxis_reference import EIGENAXIS_REFERENCE
from flexsat.control.stages.gyro import GYRO
from flexsat.control.stages.ideal_sensor import IDEAL_SENSOR
from flexsat.control.stages.joint_rate_feedback import JOINT_RATE_FEEDBACK
from flexsat.control.stages.mekf import MEKF
from flexsat.control.stages.nadir_reference import NADIR_REFERENCE
from flexsat.control.stages.no_joint_actuator import NO_JOINT_ACTUATOR
from flexsat.control.stages.notch import NOTCH
from flexsat.control.stages.registry import (
    ACTUATOR_SIGNATURE,
    ACTUATORS,
    DERIVATIVE_SIGNATURE,
    JOINT_ACTUATOR_SIGNATURE,
    JOINT_ACTUATORS,
    REFERENCE_SIGNATURE,
    REFERENCES,
    SENSOR_SIGNATURE,
    SENSORS,
    ActuatorStageConfig,
    JointActuatorConfig,
    PlantStageConfig,
    Role,
    StageConfig,
    StageSpec,
    register_stage,
    validate_stage,
)
from flexsat.control.stages.sadm_drive import SADM_DRIVE
from flexsat.control.stages.star_tracker import STAR_TRACKER
from flexsat.control.stages.static_actuator import STATIC_ACTUATOR
from flexsat.control.stages.step_reference import STEP_REFERENCE
from flexsat.control.stages.strain_feedback import STRAIN_FEEDBACK
from flexsat.control.stages.sun_reference import SUN_REFERENCE
from flexsat.control.stages.wheels import WHEELS

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
    "register_stage",
    "validate_stage",
]

register_stage(IDEAL_SENSOR, default=True)
register_stage(GYRO)
register_stage(STAR_TRACKER)
register_stage(MEKF)
register_stage(STATIC_ACTUATOR, default=True)
register_stage(STEP_REFERENCE, default=True)
register_stage(EIGENAXIS_REFERENCE)
register_stage(NADIR_REFERENCE)
register_stage(SUN_REFERENCE)
register_stage(NO_JOINT_ACTUATOR, default=True)
register_stage(JOINT_RATE_FEEDBACK)
register_stage(STRAIN_FEEDBACK)
register_stage(SADM_DRIVE)
register_stage(WHEELS)
register_stage(DELAY)
register_stage(NOTCH)
