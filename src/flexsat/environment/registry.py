"""The environment-model contract: what a model declares, its compiled load kernel, the registry.

An environment model turns the orbit's state at one instant (a row of the ephemeris
table, columns :data:`EPHEMERIS_COLUMNS`), the hub attitude and the satellite's
load points (its mass elements and its surfaces, hub frame B) into forces on those
points and a torque on the hub. :mod:`flexsat.environment.loads` sums every model's
answer and maps it onto the hub torque and each appendage's own generalized forces.

Load kernel, ``@njit(cache=True)`` (compiled with :data:`LOAD_SIGNATURE` when a run
first uses the model)::

    status = load(eph, C_BN, points, surfaces, params, force, torque)

- ``eph`` (13,): the ephemeris row at the instant (:data:`EPHEMERIS_COLUMNS`, SI, ECI);
- ``C_BN`` (3, 3): the rotation taking inertial (ECI) components to hub frame B;
- ``points`` (k, 4): the mass elements, [x, y, z] from the hub centre of mass in
  frame B [m] and the mass [kg];
- ``surfaces`` (s, :data:`SURFACE_SIZE`): the surfaces (slots ``SURF_*``);
- ``params`` (p,): the model's packed parameters (its config's ``packed``);
- ``force`` (k + s, 3): the force on each mass element, then on each surface's
  centre, frame B [N], added to;
- ``torque`` (3,): a torque on the hub that acts on no point (a magnetic dipole's),
  frame B [N m], added to.

It returns 0, or non-zero to stop the run. A new model is one module (its config,
derived from :class:`EnvironmentModelConfig`, and its kernel) plus one registration
line, :func:`register_environment_model` (docs/environment.md, 'The registry').
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
from numba import types
from pydantic import BaseModel, ConfigDict, Field

__all__ = [
    "EPHEMERIS_COLUMNS",
    "EPH_GMST",
    "EPH_LIT",
    "EPH_R",
    "EPH_S",
    "EPH_SUN_DISTANCE",
    "EPH_T",
    "EPH_V",
    "LOAD_SIGNATURE",
    "SURFACE_SIZE",
    "SURF_AREA",
    "SURF_CENTRE",
    "SURF_DIFFUSE",
    "SURF_DRAG",
    "SURF_NORMAL",
    "SURF_SPECULAR",
    "EnvironmentModelConfig",
    "EnvironmentModelSpec",
    "environment_model",
    "environment_model_names",
    "load_kernel",
    "register_environment_model",
]

EPHEMERIS_COLUMNS = ("t", "rx", "ry", "rz", "vx", "vy", "vz", "sx", "sy", "sz",
                     "sun_distance", "lit", "gmst")  # fmt: skip
"""The ephemeris table's columns (the orbit package's contract)."""
EPH_T, EPH_R, EPH_V, EPH_S, EPH_SUN_DISTANCE, EPH_LIT, EPH_GMST = 0, 1, 4, 7, 10, 11, 12

# Slots of a surface row (float64, shape (SURFACE_SIZE,)).
SURF_CENTRE = 0  # (3) centre of the surface from the hub centre of mass, frame B [m]
SURF_NORMAL = 3  # (3) outward unit normal, frame B [-]
SURF_AREA = 6  # (1) area [m^2]
SURF_SPECULAR = 7  # (1) specular reflection coefficient c_s [-]
SURF_DIFFUSE = 8  # (1) diffuse reflection coefficient c_d [-] (absorbed: 1 - c_s - c_d)
SURF_DRAG = 9  # (1) drag coefficient C_D of the surface [-]
SURFACE_SIZE = 10

_v = types.float64[::1]
_m = types.float64[:, ::1]
LOAD_SIGNATURE = types.int64(_v, _m, _m, _m, _v, _m, _v)
"""``load(eph, C_BN, points, surfaces, params, force, torque) -> status``."""

_LOAD_CONTRACT = """\
    Parameters
    ----------
    eph : ndarray, shape (13,)
        The ephemeris row at the instant (``EPHEMERIS_COLUMNS``, ECI)
        [s, m, m/s, -, m, -, rad].
    C_BN : ndarray, shape (3, 3)
        Rotation from ECI to hub frame B [-].
    points : ndarray, shape (k, 4)
        Mass elements: position from the hub centre of mass, frame B [m], mass [kg].
    surfaces : ndarray, shape (s, SURFACE_SIZE)
        Surfaces (``SURF_*`` slots of :mod:`flexsat.environment.registry`) [m, -, m^2, -].
    params : ndarray, shape (p,)
        The model's packed parameters (its config's ``packed``) [SI].
    force : ndarray, shape (k + s, 3)
        Force on each mass element, then each surface's centre, frame B [N], added to.
    torque : ndarray, shape (3,)
        Torque on the hub acting on no point, frame B [N m], added to.

    Returns
    -------
    int
        0 (the load cannot fail).
"""


def load_kernel(kernel):
    """Give a load kernel's docstring the contract's parameters and return value.

    Its ``{contract}`` line becomes the numpydoc sections every load shares (the
    arguments of :data:`LOAD_SIGNATURE`), written once here. Apply it beneath
    ``njit``.

    Parameters
    ----------
    kernel : function
        The Python function of a load, its docstring holding ``{contract}``.

    Returns
    -------
    function
        ``kernel``, its docstring completed.
    """
    kernel.__doc__ = kernel.__doc__.replace("    {contract}\n", _LOAD_CONTRACT)
    return kernel


class EnvironmentModelConfig(BaseModel):
    """Base of every environment model's parameter table (``[environment.<name>]``)."""

    model_config = ConfigDict(frozen=True, extra="forbid", validate_default=True)

    enabled: bool = Field(True, description="whether the model acts")

    def packed(self, context: Any) -> np.ndarray:
        """The packed parameters the kernel reads, float64, shape (p,).

        ``context`` is a :class:`flexsat.environment.loads.LoadContext`: the plant,
        the ephemeris and the hub's mass properties, for a model that tabulates a
        quantity along the orbit (the IGRF field, the NRLMSIS density).
        """
        return np.zeros(0)


@dataclass(frozen=True)
class EnvironmentModelSpec:
    """An environment model as the loads see it.

    Parameters
    ----------
    name : str
        Its key in the ``[environment]`` table (``gravity_gradient``...).
    config : type of EnvironmentModelConfig
        Its parameter model.
    load : numba dispatcher
        Its load kernel (module docstring), compiled with :data:`LOAD_SIGNATURE`.
    description : str
        One line for listings and the docs.
    """

    name: str
    config: type[EnvironmentModelConfig]
    load: Any
    description: str = ""


_MODELS: dict[str, EnvironmentModelSpec] = {}


def register_environment_model(spec: EnvironmentModelSpec) -> EnvironmentModelSpec:
    """Register an environment model under ``spec.name`` (replacing one of that name).

    Parameters
    ----------
    spec : EnvironmentModelSpec
        The model: its name, parameter model and load kernel.

    Returns
    -------
    EnvironmentModelSpec
        ``spec``, so a module can keep it.
    """
    if not issubclass(spec.config, EnvironmentModelConfig):
        raise ValueError(f"environment model {spec.name!r}: its config must derive "
                         "EnvironmentModelConfig")  # fmt: skip
    _MODELS[spec.name] = spec
    return spec


def environment_model(name: str) -> EnvironmentModelSpec:
    """The model registered as ``name``; ValueError listing the names if none.

    Parameters
    ----------
    name : str
        Its key in the ``[environment]`` table.

    Returns
    -------
    EnvironmentModelSpec
        The registered model.
    """
    try:
        return _MODELS[name]
    except KeyError:
        raise ValueError(f"unknown environment model {name!r}: must be one of "
                         f"{', '.join(_MODELS)}") from None  # fmt: skip


def environment_model_names() -> tuple[str, ...]:
    """Every registered model's name, in registration order."""
    return tuple(_MODELS)
