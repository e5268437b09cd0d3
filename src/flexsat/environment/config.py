"""The scenario's ``[environment]`` table: the models that act, their parameters, the surfaces.

A slew opts in with::

    [environment.models.gravity_gradient]
    [environment.models.srp]
    [environment.models.drag]
    density = "exponential"
    [environment.models.magnetic]
    residual_dipole_a_m2 = [0.1, 0.0, 0.0]
    [environment.magnetorquers]       # dump the wheels' momentum
    dipole_max_a_m2 = 10.0
    [environment.surfaces.front]      # also hub, back
    specular = 0.1
    diffuse = 0.1
    absorbed = 0.8

Each ``models`` entry is validated by the config of the registered model of its name
(:mod:`flexsat.environment.registry`). Without the table every run is the thesis's,
with its constant disturbance torques only (docs/environment.md).
"""

from __future__ import annotations

from typing import Annotated, Any

from pydantic import Field, field_validator, model_validator

from flexsat.config.models import _Frozen
from flexsat.environment.magnetorquers import MagnetorquerConfig
from flexsat.environment.registry import (
    EnvironmentModelConfig,
    environment_model,
    environment_model_names,
)

__all__ = ["EnvironmentConfig", "SurfaceOptics", "SurfacesConfig"]

Fraction = Annotated[float, Field(ge=0.0, le=1.0, allow_inf_nan=False)]
SUM_TOLERANCE = 1e-6
"""How far from 1 the three optical coefficients of a surface may sum (rounding of
values written with six decimals)."""


class SurfaceOptics(_Frozen):
    """How a surface treats light and the flow: its optical fractions and drag coefficient."""

    specular: Fraction = Field(0.1, description="c_s, specularly reflected fraction [-]")
    diffuse: Fraction = Field(0.1, description="c_d, diffusely reflected fraction [-]")
    absorbed: Fraction = Field(0.8, description="c_a, absorbed fraction [-]")
    drag_coefficient: Annotated[float, Field(gt=0.0, le=10.0, allow_inf_nan=False)] = Field(
        2.2, description="C_D of the surface [-]"
    )

    @model_validator(mode="after")
    def _sum_to_one(self) -> SurfaceOptics:
        total = self.specular + self.diffuse + self.absorbed
        if abs(total - 1.0) > SUM_TOLERANCE:
            raise ValueError(
                f"specular + diffuse + absorbed must sum to 1 (within {SUM_TOLERANCE:g}), "
                f"got {self.specular:g} + {self.diffuse:g} + {self.absorbed:g} = {total:g}"
            )
        return self


class SurfacesConfig(_Frozen):
    """The optics of the hub's faces and of the panels' front (+Z of the panel) and back."""

    hub: SurfaceOptics = Field(
        SurfaceOptics(specular=0.2, diffuse=0.3, absorbed=0.5), description="hub faces"
    )
    front: SurfaceOptics = Field(
        SurfaceOptics(specular=0.05, diffuse=0.05, absorbed=0.9),
        description="the panels' front (solar cells)",
    )
    back: SurfaceOptics = Field(
        SurfaceOptics(specular=0.1, diffuse=0.2, absorbed=0.7), description="the panels' back"
    )


class EnvironmentConfig(_Frozen):
    """The environment models that act on the satellite (module docstring)."""

    models: dict[str, Any] = Field(
        default_factory=dict,
        description="model name -> its parameter table ({} for its defaults)",
    )
    surfaces: SurfacesConfig = Field(SurfacesConfig(), description="optics of every surface")
    cells_per_side: Annotated[int, Field(ge=1, le=32)] = Field(
        4, description="mass elements and surface cells per side of each panel [-]"
    )
    hub_facets: Annotated[int, Field(ge=3, le=64)] = Field(
        8, description="flat faces around the hub cylinder's side [-]"
    )
    period_s: Annotated[float, Field(gt=0.0, le=60.0, allow_inf_nan=False)] = Field(
        0.1, description="interval between evaluations of the loads, rounded to a whole "
        "number of control periods (at least one) [s]"
    )  # fmt: skip
    magnetorquers: MagnetorquerConfig | None = Field(
        None, description="magnetorquers dumping the reaction wheels' momentum; default: none"
    )

    @field_validator("models", mode="before")
    @classmethod
    def _validate_models(cls, value: Any) -> dict[str, EnvironmentModelConfig]:
        if not isinstance(value, dict):
            raise ValueError("expected a table of model tables")
        out = {}
        for name, table in value.items():
            if name not in environment_model_names():
                raise ValueError(f"unknown environment model {name!r}: must be one of "
                                 f"{', '.join(environment_model_names())}")  # fmt: skip
            model = environment_model(name).config
            out[name] = table if isinstance(table, model) else model.model_validate(table or {})
        return out

    @model_validator(mode="after")
    def _field_for_the_magnetorquers(self) -> EnvironmentConfig:
        if self.magnetorquers is not None and "magnetic" not in self.active():
            raise ValueError("magnetorquers: they act on the geomagnetic field: add the "
                             "magnetic model ([environment.models.magnetic])")  # fmt: skip
        return self

    def active(self) -> dict[str, EnvironmentModelConfig]:
        """The enabled models, by name, in the table's order."""
        return {n: c for n, c in self.models.items() if c.enabled}
