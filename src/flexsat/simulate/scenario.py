"""Scenarios: the slew's (law, loop stages, requirements), and the open loop's re-exported.

Validated, immutable models loaded from TOML like the satellite config. Angles at
this boundary are in degrees (fields ending in ``_deg``), everything else SI. The
open-loop models and what every run shares (duration, steps, initial state) are in
:mod:`flexsat.simulate.openloop_scenario`, named here too: the slew's models name
every control law and loop stage, which an open loop does not import
(docs/performance.md, 'Start-up').
"""

from __future__ import annotations

from functools import partial
from pathlib import Path
from typing import Annotated, ClassVar

import numpy as np
from pydantic import (
    BeforeValidator,
    Field,
    SerializeAsAny,
    ValidationInfo,
    field_validator,
    model_validator,
)

from flexsat.analysis.requirements import Requirements
from flexsat.config.models import Matrix3, Vector3
from flexsat.control.disturbances import DisturbanceConfig
from flexsat.control.laws import LAWS, LawConfig, validate_law_config
from flexsat.control.stages import (
    ACTUATORS,
    JOINT_ACTUATORS,
    REFERENCES,
    SENSORS,
    ActuatorStageConfig,
    JointActuatorConfig,
    PlantStageConfig,
    StageConfig,
    validate_stage,
)
from flexsat.environment.config import EnvironmentConfig
from flexsat.orbit.config import OrbitConfig
from flexsat.simulate.openloop_scenario import (
    MAX_STEPS,
    AppendageInitialState,
    InitialState,
    OpenLoopScenario,
    TorqueSegment,
    _read_scenario,
    _TimedRun,
    check_multiples_of_dt,
    load_scenario,
    pulse,
    step,
    thesis_openloop,
)

__all__ = [
    "MAX_STEPS",
    "AppendageInitialState",
    "InitialState",
    "OpenLoopScenario",
    "Requirements",
    "SlewScenario",
    "TorqueSegment",
    "check_multiples_of_dt",
    "check_observation_window",
    "load_scenario",
    "load_slew",
    "pulse",
    "step",
    "thesis_openloop",
]

_MAX_INERTIA_KG_M2 = 1e9  # a bound far beyond any spacecraft, so J's algebra cannot overflow


class SlewScenario(_TimedRun):
    """A closed-loop rest-to-rest slew. The default is the thesis's (section 5.1):
    from the identity to 45 deg on roll, pitch and yaw, ASMC, disturbances at their
    maximum, 120 s, RK4 at 1 ms with the controller at every step."""

    name: str = Field("thesis-slew", description="name of the run")
    control_dt_s: Annotated[float, Field(gt=0.0, le=10.0, allow_inf_nan=False)] = Field(
        1e-3, description="control period, a multiple of dt_s (torque held between) [s]"
    )
    initial: InitialState = Field(default_factory=InitialState, description="state at t = 0")
    target_euler_deg: Vector3 = Field(
        (45.0, 45.0, 45.0), description="target ZYX Euler angles (roll, pitch, yaw) [deg]"
    )
    controller: SerializeAsAny[LawConfig] = Field(
        default_factory=lambda: LAWS.get(LAWS.default).config(),
        description="the control law: any registered law's table, by its kind",
    )
    sensor: SerializeAsAny[StageConfig] = Field(
        default_factory=lambda: SENSORS.get(SENSORS.default).config(),
        description="the sensor stage, by its kind",
    )
    actuator: SerializeAsAny[ActuatorStageConfig] = Field(
        default_factory=lambda: ACTUATORS.get(ACTUATORS.default).config(),
        description="the actuator stage, by its kind",
    )
    sensor_stages: tuple[
        Annotated[
            SerializeAsAny[StageConfig],
            BeforeValidator(partial(validate_stage, "sensor", chained=True)),
        ],
        ...,
    ] = Field((), description="sensing stages run after [sensor], in order ([[sensor_stages]])")
    actuator_stages: tuple[
        Annotated[
            SerializeAsAny[StageConfig],
            BeforeValidator(partial(validate_stage, "actuator", chained=True)),
        ],
        ...,
    ] = Field((), description="actuation stages run before [actuator], in order "
              "([[actuator_stages]])")  # fmt: skip
    disturbances: DisturbanceConfig = Field(
        default_factory=DisturbanceConfig, description="disturbance torques"
    )
    requirements: Requirements = Field(
        default_factory=Requirements, description="R1-R3 and their observation window"
    )
    design_inertia_kg_m2: Matrix3 | None = Field(
        None,
        description="the controller's design inertia J [kg m^2] (3x3, symmetric positive "
        "definite); default: J_tot of the rigidized nominal satellite of the config",
    )
    reference: SerializeAsAny[PlantStageConfig] = Field(
        default_factory=lambda: REFERENCES.get(REFERENCES.default).config(),
        description="the reference the law tracks, by its kind (default: the step to the "
        "target, the thesis's regulation)",
    )
    joint_actuator: SerializeAsAny[JointActuatorConfig] = Field(
        default_factory=lambda: JOINT_ACTUATORS.get(JOINT_ACTUATORS.default).config(),
        description="actuators on appendage joint coordinates, by kind (default: none)",
    )
    environment: EnvironmentConfig | None = Field(
        None, description="environment models along the orbit (docs/environment.md); "
        "default: none, the [disturbances] torques only"
    )  # fmt: skip

    orbit: OrbitConfig | None = Field(
        None, description="the satellite's orbit (docs/orbit.md); default none: the "
        "attitude alone in an inertial frame"
    )  # fmt: skip

    _MULTIPLES_OF_DT: ClassVar[tuple[str, ...]] = ("control_dt_s", "record_dt_s")

    @field_validator("controller", mode="before")
    @classmethod
    def _registered_law(cls, value: object) -> LawConfig:
        return validate_law_config(value)  # at validation time: laws registered later count

    @field_validator("sensor", "actuator", "reference", "joint_actuator", mode="before")
    @classmethod
    def _registered_stage(cls, value: object, info: ValidationInfo) -> StageConfig:
        return validate_stage(info.field_name, value)  # each field is named by its role

    @field_validator("design_inertia_kg_m2")
    @classmethod
    def _spd(cls, value: Matrix3 | None) -> Matrix3 | None:
        if value is None:
            return value
        J = np.array(value, dtype=float)
        if np.abs(J).max() > _MAX_INERTIA_KG_M2:
            raise ValueError(f"entries must be within +-{_MAX_INERTIA_KG_M2:.0e} kg m^2")
        if not np.allclose(J, J.T, rtol=1e-12, atol=1e-12 * np.abs(J).max()):
            raise ValueError("must be symmetric (J = J^T)")
        if np.linalg.eigvalsh(J).min() <= 0.0:
            raise ValueError("must be positive definite (every eigenvalue > 0 kg m^2)")
        return value

    @model_validator(mode="after")
    def _disturbances_within_the_actuator(self) -> SlewScenario:
        # The constant torques are added before the actuator's saturation (docs/control.md,
        # 'Torque budget, Λ and saturation order'): one beyond T_max would be clipped to it.
        limit = self.actuator.t_max_nm
        for field in ("environment_nm", "residual_nm"):
            values = getattr(self.disturbances, field)
            if max(abs(v) for v in values) > limit:
                raise ValueError(
                    f"disturbances.{field}: each axis must be within +-actuator.t_max_nm = "
                    f"+-{limit:g} N m (it is added before the actuator's saturation), got "
                    f"{[float(f'{v:.6g}') for v in values]}"
                )
        return self

    @model_validator(mode="after")
    def _target_on_the_orbit(self) -> SlewScenario:
        if self.reference.moving_target and self.orbit is None:
            raise ValueError(
                f"reference.kind = {self.reference.kind!r} points at a target along the "
                "orbit: add an [orbit] table (docs/orbit.md, 'The orbit table')"
            )
        return self

    @model_validator(mode="after")
    def _magnetorquers_dump_the_wheels(self) -> SlewScenario:
        # They unload the wheels' stored momentum (docs/environment.md, 'Magnetorquers
        # and momentum dumping'): refused here, so a campaign refuses it before its
        # first case flies.
        if self.environment is not None and self.environment.magnetorquers is not None:
            if self.actuator.kind != "wheels":
                raise ValueError(
                    "environment.magnetorquers: they dump the reaction wheels' momentum: "
                    f"the [actuator] must be kind = 'wheels', got {self.actuator.kind!r}"
                )
        return self

    @model_validator(mode="after")
    def _stages_fit_the_run(self) -> SlewScenario:
        for field, stage in [("controller", self.controller), *self.stage_chain()]:
            try:
                stage.check(self)
            except ValueError as error:
                raise ValueError(f"{field}.{error}") from None
        return self

    def stage_chain(self) -> list[tuple[str, StageConfig]]:
        """Every stage in loop order with its field path: the sensing chain
        (``sensor``, ``sensor_stages[i]``), then the actuation chain
        (``actuator_stages[i]``, ``actuator``)."""
        return (
            [("sensor", self.sensor)]
            + [(f"sensor_stages[{i}]", s) for i, s in enumerate(self.sensor_stages)]
            + [(f"actuator_stages[{i}]", s) for i, s in enumerate(self.actuator_stages)]
            + [("actuator", self.actuator)]
        )

    @property
    def control_every(self) -> int:
        return round(self.control_dt_s / self.dt_s)


def check_observation_window(scenario: SlewScenario, source: str = "scenario") -> SlewScenario:
    """Refuse a slew whose observation window is not inside its run.

    R1 and R2 are judged from ``requirements.settling_deadline_s`` to
    ``requirements.window_end_s`` (default: the end of the run,
    :func:`flexsat.analysis.requirements.observation_window`). A run that ends before
    the window opens, or before a stated end of it, could only fail them, and would
    do so without saying why: such a scenario is bad input. Checked where a user's
    scenario meets a run (a scenario file, the ``flexsat slew`` options); a short run
    built in code (a quick look, a compilation run) is not refused.

    Parameters
    ----------
    scenario : SlewScenario
        The slew.
    source : str
        What the scenario came from, for the message (a file name, the options).

    Returns
    -------
    SlewScenario
        ``scenario``, unchanged.

    Raises
    ------
    ConfigError
        Naming ``duration_s`` and the window's field, and the range allowed.
    """
    from flexsat.errors import ConfigError

    duration, req = scenario.duration_s, scenario.requirements
    if req.settling_deadline_s >= duration:
        raise ConfigError(
            f"{source}: duration_s = {duration:g} s ends the run before its observation "
            f"window opens (requirements.settling_deadline_s = {req.settling_deadline_s:g} "
            f"s), so R1 and R2 could not be judged: give duration_s > "
            f"{req.settling_deadline_s:g} s or requirements.settling_deadline_s < "
            f"{duration:g} s"
        )
    if req.window_end_s is not None and req.window_end_s > duration:
        raise ConfigError(
            f"{source}: requirements.window_end_s = {req.window_end_s:g} s is after the "
            f"run ends (duration_s = {duration:g} s), so R1 and R2 could not be judged: "
            f"give requirements.window_end_s <= duration_s, or no window_end_s (the end "
            f"of the run)"
        )
    return scenario


def load_slew(path: str | Path | None = None, *, check_window: bool = True) -> SlewScenario:
    """Read and validate a slew scenario TOML; ``None`` gives the thesis's slew.

    Parameters
    ----------
    path : str or Path, optional
        The TOML file.
    check_window : bool
        Refuse a scenario whose observation window is not inside its run
        (:func:`check_observation_window`); False for a caller that changes the
        duration and checks the result.

    Returns
    -------
    SlewScenario

    Raises
    ------
    ConfigError
        Naming the file, the field and the allowed range.
    """
    scenario = _read_scenario(path, SlewScenario)
    if path is None or not check_window:
        return scenario
    return check_observation_window(scenario, str(path))
