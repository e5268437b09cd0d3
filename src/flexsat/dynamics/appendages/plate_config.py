"""Configuration of the thesis's appendage: a rigid thin plate on a 6-DOF elastic root joint.

The plate is one appendage model among others (``model = "plate"``, the default of a
table that names no model); its config is validated at the boundary like the
chain's (:mod:`flexsat.dynamics.appendages.chain_config`) and the modal appendage's.
Frames and symbols: docs/model.md, 'Frames and names'.
"""

from __future__ import annotations

from typing import Annotated, Literal

import numpy as np
from pydantic import AllowInfNan, Field, Strict, model_validator

from flexsat.config.models import (
    Angle,
    Density,
    DriveConfig,
    Frequency,
    Mass,
    Name,
    Point3,
    Size,
    Thickness,
    _Frozen,
)

__all__ = ["PlateConfig", "TargetFrequencies"]


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


class PlateConfig(_Frozen):
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
    def _one_mass(self) -> PlateConfig:
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

    def surface_points_m(self) -> np.ndarray:
        """Points of the plate's mid-plane rectangle at rest, hub frame B, shape (3, 65, 257) [m].

        Width by length from the root along the span, on a 65 x 257 grid: what the
        hub-interference check of :class:`~flexsat.config.models.SatelliteConfig`
        tests (docs/model.md, 'Geometric interference').
        """
        u = np.linspace(-0.5, 0.5, 65)[:, None]  # across the chord, times the width
        v = np.linspace(0.0, 1.0, 257)[None, :]  # along the span, times the length
        yaw, sadm = np.radians(self.mount_yaw_deg), np.radians(self.sadm_angle_deg)
        # R_BM = Rz(yaw) Ry(sadm): the chord X_M and the span +-Y_M in B.
        chord = np.array([np.cos(yaw) * np.cos(sadm), np.sin(yaw) * np.cos(sadm), -np.sin(sadm)])
        span = self.span_sign() * np.array([-np.sin(yaw), np.cos(yaw), 0.0])
        return (np.array(self.mount_point_m)[:, None, None] + chord[:, None, None] * u
                * self.width_m + span[:, None, None] * v * self.length_m)  # fmt: skip
