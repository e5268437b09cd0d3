"""Environment loads: gravity gradient, solar radiation pressure, drag, geomagnetic field.

Each model is one module and one registration line (:mod:`flexsat.environment.registry`);
:mod:`flexsat.environment.loads` sums them onto the hub and every appendage's own
coordinates in the closed loop. A scenario opts in with its ``[environment]`` table
(:class:`~flexsat.environment.config.EnvironmentConfig`; docs/environment.md).
"""

from flexsat.environment.drag import DRAG
from flexsat.environment.gravity_gradient import GRAVITY_GRADIENT
from flexsat.environment.magnetic import MAGNETIC
from flexsat.environment.registry import (
    LOAD_SIGNATURE,
    EnvironmentModelConfig,
    EnvironmentModelSpec,
    environment_model,
    environment_model_names,
    register_environment_model,
)
from flexsat.environment.srp import SRP

__all__ = [
    "LOAD_SIGNATURE",
    "EnvironmentModelConfig",
    "EnvironmentModelSpec",
    "environment_model",
    "environment_model_names",
    "register_environment_model",
]

register_environment_model(GRAVITY_GRADIENT)
register_environment_model(SRP)
register_environment_model(DRAG)
register_environment_model(MAGNETIC)
