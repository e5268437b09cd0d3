"""Validated, immutable parameter models of the flexible satellite.

The models are frozen pydantic objects: they check themselves on construction and
refuse unknown keys, wrong types, non-finite numbers and out-of-range values.
Variants are derived by validating a modified dict (``load.validate_config``),
never by mutation.

Units are SI; angles at this boundary are in degrees and every such field says so
(``sadm_angle_deg``). Frames: hub body frame B, mount frame M_i (fixed to the hub at
the appendage root), panel frame P_i (moves with the appendage); see
``docs/model.md``.
"""

from __future__ import annotations

from importlib import import_module
from importlib.metadata import entry_points
from typing import Annotated, Any

import numpy as np
from pydantic import (
    AllowInfNan,
    BaseModel,
    ConfigDict,
    Field,
    SerializeAsAny,
    Strict,
    ValidatorFunctionWrapHandler,
    WrapValidator,
    model_validator,
)

__all__ = [
    "APPENDAGE_CONFIGS",
    "APPENDAGE_ENTRY_POINTS",
    "BUILTIN_APPENDAGES",
    "DEFAULT_APPENDAGE_MODEL",
    "DriveConfig",
    "HubConfig",
    "SatelliteConfig",
    "appendage_config_class",
    "load_appendage_plugins",
    "register_appendage_config",
    "table_model",
]

# A real number: ints are accepted, strings and booleans are not, NaN and inf are not.
Real = Annotated[float, Strict(), AllowInfNan(False)]
Positive = Annotated[float, Strict(), AllowInfNan(False), Field(gt=0.0)]
Angle = Annotated[float, Strict(), AllowInfNan(False), Field(ge=-360.0, le=360.0)]
Vector3 = tuple[Real, Real, Real]
Matrix3 = tuple[Vector3, Vector3, Vector3]

# Physical magnitudes are bounded at the boundary, so that nothing downstream
# overflows (a 1e154 m hub radius squared) or loses every digit (a 5e-324 kg hub):
# each range spans far beyond any spacecraft, from a chip-sat to a space station.
Mass = Annotated[float, Strict(), AllowInfNan(False), Field(ge=1e-4, le=1e7)]  # [kg]
Size = Annotated[float, Strict(), AllowInfNan(False), Field(ge=1e-3, le=1e3)]  # [m]
Thickness = Annotated[float, Strict(), AllowInfNan(False), Field(ge=1e-6, le=1e3)]  # [m]
Coordinate = Annotated[float, Strict(), AllowInfNan(False), Field(ge=-1e3, le=1e3)]  # [m]
Point3 = tuple[Coordinate, Coordinate, Coordinate]
Density = Annotated[float, Strict(), AllowInfNan(False), Field(ge=1e-4, le=1e5)]  # [kg/m^2]
Frequency = Annotated[float, Strict(), AllowInfNan(False), Field(ge=1e-3, le=1e4)]  # [Hz]
InertiaEntry = Annotated[float, Strict(), AllowInfNan(False), Field(ge=-1e12, le=1e12)]
# Names are printed in tables, figure titles and messages: plain characters only.
Name = Annotated[
    str, Field(min_length=1, max_length=64, pattern=r"^[A-Za-z0-9_][A-Za-z0-9_ .+\-()#,:]*$")
]


class _Frozen(BaseModel):
    model_config = ConfigDict(frozen=True, extra="forbid", validate_default=True)


class HubConfig(_Frozen):
    """Rigid central body.

    Give either ``radius_m`` and ``height_m`` (homogeneous cylinder about hub Z,
    thesis eqs. 2.3-2.4) or an explicit ``inertia_kg_m2`` about the hub centre of
    mass in hub frame B.
    """

    mass_kg: Mass = Field(description="hub mass [kg]")
    radius_m: Size | None = Field(None, description="cylinder radius [m]")
    height_m: Size | None = Field(None, description="cylinder height along hub Z [m]")
    inertia_kg_m2: (
        tuple[
            tuple[InertiaEntry, InertiaEntry, InertiaEntry],
            tuple[InertiaEntry, InertiaEntry, InertiaEntry],
            tuple[InertiaEntry, InertiaEntry, InertiaEntry],
        ]
        | None
    ) = Field(None, description="inertia about the hub centre of mass, hub frame B [kg m^2]")

    @model_validator(mode="after")
    def _geometry_or_inertia(self) -> HubConfig:
        has_cylinder = self.radius_m is not None or self.height_m is not None
        if self.inertia_kg_m2 is not None:
            if has_cylinder:
                raise ValueError("give either radius_m and height_m or inertia_kg_m2, not both")
            _check_inertia(np.array(self.inertia_kg_m2, dtype=float))
        elif self.radius_m is None or self.height_m is None:
            raise ValueError("give both radius_m and height_m (cylinder), or inertia_kg_m2 (3x3)")
        return self

    def inertia(self) -> np.ndarray:
        """Inertia about the hub centre of mass in hub frame B, shape (3, 3) [kg m^2]."""
        if self.inertia_kg_m2 is not None:
            return np.array(self.inertia_kg_m2, dtype=float)
        m, r, h = self.mass_kg, self.radius_m, self.height_m
        j_xx = m * (3.0 * r**2 + h**2) / 12.0  # eq. 2.3
        j_zz = 0.5 * m * r**2  # eq. 2.4
        return np.diag([j_xx, j_xx, j_zz])


def _check_inertia(j: np.ndarray) -> None:
    scale = float(np.max(np.abs(j)))
    if scale == 0.0:
        raise ValueError("inertia_kg_m2 must be positive definite, got all zeros")
    if np.max(np.abs(j - j.T)) > 1e-9 * scale:
        raise ValueError("inertia_kg_m2 must be symmetric (J == J^T)")
    principal = np.linalg.eigvalsh(j)
    if principal[0] <= 0.0:
        raise ValueError(
            f"inertia_kg_m2 must be positive definite (principal moments > 0, "
            f"got {principal.min():.6g})"
        )
    # A rigid body's principal moments obey the triangle inequality J1 + J2 >= J3.
    if principal[0] + principal[1] < principal[2] * (1.0 - 1e-9):
        raise ValueError(
            "inertia_kg_m2 is not a rigid body's: the principal moments must satisfy J1 + J2 >= J3"
        )


class DriveConfig(_Frozen):
    """A solar-array drive (SADM) turning an appendage about its SADM axis.

    Its drive angle alpha_sadm becomes a generalized coordinate starting at the
    appendage's ``sadm_angle_deg``. A plate or a chain becomes a chain whose first
    segment is the rotor (coordinate ``eta_ry_0``; ``docs/model.md``, "Driven mount
    coordinate (SADM)"); a modal appendage keeps its modes on a frame the drive turns
    about its ``drive_axis`` (coordinate ``drive_angle``; ``docs/model.md``, "Modal
    appendage on a drive"). A ``[joint_actuator] kind = "sadm_drive"`` is its motor.
    """

    rotor_inertia_kg_m2: Annotated[
        float, Strict(), AllowInfNan(False), Field(gt=0.0, le=1e12)
    ] = Field(description="drive rotor inertia about the SADM axis as seen at the array (a "
              "geared motor's N^2 J_motor) [kg m^2]")  # fmt: skip
    rotor_mass_kg: Mass = Field(description="rotor mass, on the axis at the root [kg]")


APPENDAGE_CONFIGS: dict[str, type[BaseModel]] = {}
"""Config class of each appendage model, by its ``model`` key (the registry of
:mod:`flexsat.dynamics.appendages` fills it)."""

DEFAULT_APPENDAGE_MODEL = "plate"
"""The model of an appendage table that names none: the thesis's plate."""

BUILTIN_APPENDAGES = "flexsat.dynamics.appendages"
"""The package whose import registers the built-in models (plate, chain, modal): found
by name, as a plug-in is, so that the configuration layer imports no physics."""

APPENDAGE_ENTRY_POINTS = "flexsat.appendages"
"""Entry-point group of third-party appendage models: each entry point names a module
whose import registers its model (``register_appendage_model``)."""
_PLUGINS_LOADED = False


def load_appendage_plugins() -> None:
    """Import the built-in models and every module of the ``flexsat.appendages``
    entry-point group, once."""
    global _PLUGINS_LOADED
    if _PLUGINS_LOADED:
        return
    _PLUGINS_LOADED = True
    import_module(BUILTIN_APPENDAGES)  # registers plate, chain and modal
    for point in entry_points(group=APPENDAGE_ENTRY_POINTS):
        point.load()  # importing the module registers its model


def register_appendage_config(model: str, config_class: type[BaseModel]) -> None:
    """Accept ``model = "<model>"`` appendage tables, validated as ``config_class``.

    Parameters
    ----------
    model : str
        The ``model`` key's value.
    config_class : type of BaseModel
        The table's model; it needs the fields ``name`` and ``model``.
    """
    fields = config_class.model_fields
    if "name" not in fields or "model" not in fields:
        raise TypeError(f"{config_class.__name__} needs the fields 'name' and 'model'")
    APPENDAGE_CONFIGS[model] = config_class


def appendage_config_class(model: str) -> type[BaseModel]:
    """The config class of appendage model ``model`` (registered, built-in or plug-in).

    Parameters
    ----------
    model : str
        The ``model`` key of an appendage table.

    Returns
    -------
    type of BaseModel
        Its config class.

    Raises
    ------
    ValueError
        Naming the registered models when ``model`` is none of them.
    """
    if model not in APPENDAGE_CONFIGS:
        load_appendage_plugins()
    if model not in APPENDAGE_CONFIGS:
        raise ValueError(
            f"model: unknown appendage model {model!r} (allowed: {', '.join(APPENDAGE_CONFIGS)})"
        )
    return APPENDAGE_CONFIGS[model]


def table_model(value: Any) -> str:
    """The ``model`` key of an appendage table, the default model when it names none.

    Parameters
    ----------
    value : Any
        An appendage table as read from a file (a dict), or anything else.

    Returns
    -------
    str
        The model's registered name [-]; ``DEFAULT_APPENDAGE_MODEL`` when ``value``
        is not a table or names no model.
    """
    if isinstance(value, dict):
        return value.get("model", DEFAULT_APPENDAGE_MODEL)
    return DEFAULT_APPENDAGE_MODEL


def _by_model(value: Any, handler: ValidatorFunctionWrapHandler) -> Any:
    """Validate an appendage table with the config class its ``model`` key names."""
    if isinstance(value, BaseModel):
        if type(value) in APPENDAGE_CONFIGS.values():
            return value
        value = value.model_dump()
    return appendage_config_class(table_model(value)).model_validate(value)


# An appendage table, validated by the config class of its model (default the plate).
Appendage = SerializeAsAny[Annotated[BaseModel, WrapValidator(_by_model)]]


class SatelliteConfig(_Frozen):
    """A hub and its list of appendages (each validated by its model's config class)."""

    name: Name = Field("satellite", description="name of the satellite")
    hub: HubConfig = Field(description="the rigid hub")
    appendages: Annotated[list[Appendage], Field(min_length=1, max_length=64)] = Field(
        description="the appendages, each by its model (default the plate)"
    )

    @model_validator(mode="after")
    def _unique_names(self) -> SatelliteConfig:
        names = [a.name for a in self.appendages]
        duplicated = sorted({n for n in names if names.count(n) > 1})
        if duplicated:
            raise ValueError(f"appendage names must be unique, repeated: {duplicated}")
        hub = self.hub
        if hub.radius_m is not None:  # a cylinder: its surface is known
            for k, app in enumerate(self.appendages):
                root = getattr(app, "mount_point_m", None)  # a model without a root point
                if root is None:
                    continue
                x, y, z = root
                if np.hypot(x, y) < hub.radius_m and abs(z) < 0.5 * hub.height_m:
                    raise ValueError(
                        f"appendages[{k}].mount_point_m {list(app.mount_point_m)} is inside the "
                        f"hub (radius {hub.radius_m:g} m, height {hub.height_m:g} m); mount "
                        "appendages on or outside its surface"
                    )
        _check_interference(self)
        return self


_MOUNT_SEPARATION_M = 1e-3  # two roots closer than this are one mount point [m]


def _check_interference(config: SatelliteConfig) -> None:
    """Refuse appendages that overlap (docs/model.md, 'Geometric interference').

    Two appendages may not share a mount point (roots closer than 1 mm), and no point
    of a plate (its mid-plane rectangle, width by length, from its root along its
    span) may lie inside a cylindrical hub.
    """
    roots = [(k, getattr(app, "mount_point_m", None)) for k, app in enumerate(config.appendages)]
    roots = [(k, np.array(r, dtype=float)) for k, r in roots if r is not None]
    for i, (k, a) in enumerate(roots):
        for m, b in roots[i + 1 :]:
            if np.linalg.norm(a - b) < _MOUNT_SEPARATION_M:
                raise ValueError(
                    f"appendages[{m}].mount_point_m {b.tolist()} is the mount point of "
                    f"appendages[{k}]: two appendages need mount points at least "
                    f"{_MOUNT_SEPARATION_M * 1e3:g} mm apart"
                )
    hub = config.hub
    if hub.radius_m is None:  # an inertia without a shape: nothing to intersect
        return
    for k, app in enumerate(config.appendages):
        surface = getattr(app, "surface_points_m", None)  # a model that declares its surface
        if surface is None:
            continue
        points = np.asarray(surface(), dtype=float).reshape(3, -1)
        depth_r = hub.radius_m - np.hypot(points[0], points[1])
        depth_z = 0.5 * hub.height_m - np.abs(points[2])
        inside = np.minimum(depth_r, depth_z) > 1e-9 * hub.radius_m
        if inside.any():
            where = points[:, np.argmax(inside)]
            raise ValueError(
                f"appendages[{k}] ({app.name}) passes through the hub: its point "
                f"{np.round(where, 4).tolist()} m is inside the hub (radius "
                f"{hub.radius_m:g} m, height {hub.height_m:g} m); an appendage must lie "
                "outside the hub"
            )
