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

from importlib.metadata import entry_points
from typing import Annotated, Any, Literal

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
    "AppendageConfig",
    "DriveConfig",
    "HubConfig",
    "SatelliteConfig",
    "TargetFrequencies",
    "load_appendage_plugins",
    "register_appendage_config",
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


class TargetFrequencies(_Frozen):
    """Cantilever (clamped-root) natural frequencies of one appendage, per joint DOF [Hz].

    Rotations are about the mount frame axes: flapping about X_M (out-of-plane
    bending), torsion about Y_M (the span axis), in-plane bending about Z_M.
    """

    flapping: Frequency = Field(description="out-of-plane bending, rotation about X_M [Hz]")
    in_plane: Frequency = Field(description="in-plane bending, rotation about Z_M [Hz]")
    torsion: Frequency = Field(description="torsion, rotation about Y_M [Hz]")
    translation_x: Frequency = Field(description="root translation along X_M [Hz]")
    translation_y: Frequency = Field(description="root translation along Y_M [Hz]")
    translation_z: Frequency = Field(description="root translation along Z_M [Hz]")

    def per_dof(self) -> np.ndarray:
        """Frequencies in joint-DOF order, shape (6,) [Hz].

        Order: [eta_x, eta_y, eta_z, eta_rx, eta_ry, eta_rz].
        """
        return np.array(
            [
                self.translation_x,
                self.translation_y,
                self.translation_z,
                self.flapping,
                self.torsion,
                self.in_plane,
            ]
        )


class DriveConfig(_Frozen):
    """A solar-array drive (SADM) turning a plate about its SADM axis Y_M.

    The plate becomes a two-segment chain, the rotor then the panel, its drive angle
    alpha_sadm a generalized coordinate (``eta_ry_0``) starting at the plate's
    ``sadm_angle_deg`` (``docs/model.md``, "Driven mount coordinate (SADM)"). A
    ``[joint_actuator] kind = "sadm_drive"`` is its motor.
    """

    rotor_inertia_kg_m2: Annotated[
        float, Strict(), AllowInfNan(False), Field(gt=0.0, le=1e12)
    ] = Field(description="drive rotor inertia about the SADM axis as seen at the array (a "
              "geared motor's N^2 J_motor) [kg m^2]")  # fmt: skip
    rotor_mass_kg: Mass = Field(description="rotor mass, on the axis at the root [kg]")


class AppendageConfig(_Frozen):
    """One flexible appendage: a rigid thin plate on a 6-DOF elastic root joint.

    The mount frame M is the hub frame B rotated by ``mount_yaw_deg`` about Z_B and
    then by the SADM angle about the resulting Y axis; its origin is
    ``mount_point_m``. The plate spans ``length_m`` along +Y_P or -Y_P
    (``span_direction``), ``width_m`` along X_P and ``thickness_m`` along Z_P.
    Give the mass either as ``surface_density_kg_m2`` (eq. 2.6) or as ``mass_kg``.
    """

    name: Name = Field(description="unique name of the appendage")
    model: Literal["plate"] = Field("plate", description="appendage model (registry key)")
    mount_point_m: Point3 = Field(description="root position from hub centre of mass, frame B [m]")
    mount_yaw_deg: Angle = Field(0.0, description="mount frame rotation about Z_B [deg]")
    sadm_angle_deg: Angle = Field(0.0, description="SADM angle about Y_M [deg]")
    span_direction: Literal["+y", "-y"] = Field("+y", description="span along +Y_M or -Y_M")
    length_m: Size = Field(description="span L_p [m]")
    width_m: Size = Field(description="chord W_p [m]")
    thickness_m: Thickness = Field(description="thickness t_p [m]")
    surface_density_kg_m2: Density | None = Field(None, description="rho_sup [kg/m^2]")
    mass_kg: Mass | None = Field(None, description="panel mass M_p [kg]")
    target_frequencies_hz: TargetFrequencies = Field(
        description="cantilever frequency of each joint DOF, tuning its stiffness (eq. 2.14)"
    )
    damping_ratio: Annotated[float, Strict(), AllowInfNan(False), Field(ge=0.0, lt=1.0)] = Field(
        description="viscous damping ratio zeta of every joint DOF [-]"
    )
    locked_dofs: list[Literal["eta_x", "eta_y", "eta_z", "eta_rx", "eta_ry", "eta_rz"]] = Field(
        default_factory=list,
        max_length=6,
        description="joint DOFs held rigid in time simulation (reduced model; "
        "docs/campaigns.md, 'Reduced models')",
    )
    drive: DriveConfig | None = Field(
        None, description="put the plate on a solar-array drive: its SADM angle becomes a "
        "coordinate; default: the angle is fixed"
    )  # fmt: skip

    @model_validator(mode="after")
    def _one_mass(self) -> AppendageConfig:
        if len(set(self.locked_dofs)) != len(self.locked_dofs):
            raise ValueError(f"locked_dofs names a DOF twice: {self.locked_dofs}")
        if (self.surface_density_kg_m2 is None) == (self.mass_kg is None):
            raise ValueError("give exactly one of surface_density_kg_m2 and mass_kg")
        if self.thickness_m > min(self.length_m, self.width_m):
            raise ValueError("thickness_m must not exceed length_m or width_m (thin plate)")
        if self.drive is not None:
            self._drivable()
        return self

    def _drivable(self) -> None:
        """Refuse a plate the drive's chain (``driven_plate``) cannot be built from."""
        if self.locked_dofs:
            raise ValueError(f"drive: a plate on a drive takes no locked_dofs (got "
                             f"{self.locked_dofs})")  # fmt: skip
        if abs(self.sadm_angle_deg) >= 45.0:
            angle = self.sadm_angle_deg
            raise ValueError(f"sadm_angle_deg: a plate on a drive starts its drive angle "
                             f"within -45 < alpha < 45 deg (got {angle:g})")  # fmt: skip
        if not 1e-4 <= self.mass <= 1e7:
            raise ValueError(f"drive: a plate on a drive needs a panel mass within [1e-4, 1e7] "
                             f"kg (got {self.mass:g})")  # fmt: skip

    @property
    def mass(self) -> float:
        """Panel mass M_p [kg] (eq. 2.6 when given as a surface density)."""
        if self.mass_kg is not None:
            return self.mass_kg
        return self.surface_density_kg_m2 * self.length_m * self.width_m  # eq. 2.6

    def centroidal_inertia(self) -> np.ndarray:
        """Inertia about the panel centre of mass in panel frame P, shape (3, 3) [kg m^2].

        Thin plate with the span along Y_P (eqs. 2.9-2.11).
        """
        m, length, width, t = self.mass, self.length_m, self.width_m, self.thickness_m
        return np.diag(
            [
                m * (length**2 + t**2) / 12.0,  # eq. 2.9
                m * (width**2 + t**2) / 12.0,  # eq. 2.10
                m * (length**2 + width**2) / 12.0,  # eq. 2.11
            ]
        )

    def span_sign(self) -> float:
        """+1 when the plate spans along +Y_P, -1 along -Y_P."""
        return 1.0 if self.span_direction == "+y" else -1.0


APPENDAGE_CONFIGS: dict[str, type[BaseModel]] = {"plate": AppendageConfig}
"""Config class of each appendage model, by its ``model`` key (the registry of
:mod:`flexsat.dynamics.appendages` adds to it)."""


APPENDAGE_ENTRY_POINTS = "flexsat.appendages"
"""Entry-point group of third-party appendage models: each entry point names a module
whose import registers its model (``register_appendage_model``)."""
_PLUGINS_LOADED = False


def load_appendage_plugins() -> None:
    """Import every module of the ``flexsat.appendages`` entry-point group, once."""
    global _PLUGINS_LOADED
    if _PLUGINS_LOADED:
        return
    _PLUGINS_LOADED = True
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


def _by_model(value: Any, handler: ValidatorFunctionWrapHandler) -> Any:
    """Validate an appendage table with the config class its ``model`` key names."""
    if isinstance(value, BaseModel):
        return value if type(value) in APPENDAGE_CONFIGS.values() else handler(value)
    model = value.get("model", "plate") if isinstance(value, dict) else "plate"
    if model == "plate":
        return handler(value)
    if model not in APPENDAGE_CONFIGS:
        load_appendage_plugins()
    if model not in APPENDAGE_CONFIGS:
        raise ValueError(
            f"model: unknown appendage model {model!r} (allowed: {', '.join(APPENDAGE_CONFIGS)})"
        )
    return APPENDAGE_CONFIGS[model].model_validate(value)


# An appendage table: the plate's by default, else the config class of its model.
Appendage = SerializeAsAny[Annotated[AppendageConfig, WrapValidator(_by_model)]]


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
    u = np.linspace(-0.5, 0.5, 65)[:, None]  # across the chord, times the width
    v = np.linspace(0.0, 1.0, 257)[None, :]  # along the span, times the length
    for k, app in enumerate(config.appendages):
        if not isinstance(app, AppendageConfig):
            continue
        yaw, sadm = np.radians(app.mount_yaw_deg), np.radians(app.sadm_angle_deg)
        # R_BM = Rz(yaw) Ry(sadm): the chord X_M and the span +-Y_M in B.
        chord = np.array([np.cos(yaw) * np.cos(sadm), np.sin(yaw) * np.cos(sadm), -np.sin(sadm)])
        span = app.span_sign() * np.array([-np.sin(yaw), np.cos(yaw), 0.0])
        points = (np.array(app.mount_point_m)[:, None, None] + chord[:, None, None] * u
                  * app.width_m + span[:, None, None] * v * app.length_m)  # fmt: skip
        depth_r = hub.radius_m - np.hypot(points[0], points[1])
        depth_z = 0.5 * hub.height_m - np.abs(points[2])
        inside = np.minimum(depth_r, depth_z) > 1e-9 * hub.radius_m
        if inside.any():
            j = np.argwhere(inside)[0]
            where = points[:, j[0], j[1]]
            raise ValueError(
                f"appendages[{k}] ({app.name}) passes through the hub: its point "
                f"{np.round(where, 4).tolist()} m of the plate (width {app.width_m:g} m, "
                f"length {app.length_m:g} m from mount_point_m) is inside the hub (radius "
                f"{hub.radius_m:g} m, height {hub.height_m:g} m); a plate must lie outside "
                "the hub"
            )
