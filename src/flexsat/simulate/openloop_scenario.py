"""Open-loop scenarios: initial state, body-torque profile, integration settings.

Validated, immutable models loaded from TOML like the satellite config. Angles at
this boundary are in degrees (fields ending in ``_deg``), everything else SI. The
models every run shares (its duration and steps, its initial state) live here too;
:mod:`flexsat.simulate.scenario` adds the slew's, which name every control law and
loop stage, and re-exports these. An open loop imports only this module
(docs/performance.md, 'Start-up').
"""

from __future__ import annotations

from pathlib import Path
from typing import Annotated, ClassVar, Literal

from pydantic import (
    AllowInfNan,
    Field,
    Strict,
    model_validator,
)

from flexsat.config.load import read_toml, validate_config
from flexsat.config.models import Positive, Real, Vector3, _Frozen

__all__ = [
    "MAX_STEPS",
    "AppendageInitialState",
    "InitialState",
    "OpenLoopScenario",
    "TorqueSegment",
    "check_multiples_of_dt",
    "load_scenario",
    "pulse",
    "step",
    "thesis_openloop",
]


_ZERO3 = (0.0, 0.0, 0.0)
# Initial states are bounded where they enter, like the config's magnitudes
# (docs/model.md, 'Allowed ranges of the physical inputs'): far beyond any spacecraft,
# so that a typo (1e300) is refused here instead of failing the run at t = 0.
Deflection = Annotated[float, Strict(), AllowInfNan(False), Field(ge=-10.0, le=10.0)]  # [m]
LinearRate = Annotated[float, Strict(), AllowInfNan(False), Field(ge=-1e3, le=1e3)]  # [m/s]
AngularRate = Annotated[float, Strict(), AllowInfNan(False), Field(ge=-1e4, le=1e4)]  # [deg/s]
EulerAngle = Annotated[float, Strict(), AllowInfNan(False), Field(ge=-360.0, le=360.0)]  # [deg]


class TorqueSegment(_Frozen):
    """A constant body torque applied over [start_s, end_s); ``end_s`` omitted: to the end."""

    start_s: Annotated[float, Strict(), Field(ge=0.0, allow_inf_nan=False)] = Field(
        0.0, description="switch-on time [s]"
    )
    end_s: Positive | None = Field(None, description="switch-off time; none: to the end [s]")
    torque_nm: Vector3 = Field(description="torque on the hub, hub frame B [N m]")

    @model_validator(mode="after")
    def _ordered(self) -> TorqueSegment:
        if self.end_s is not None and self.end_s <= self.start_s:
            raise ValueError(f"end_s must be > start_s ({self.start_s}), got {self.end_s}")
        return self


def step(start_s: float, torque_nm: tuple[float, float, float]) -> TorqueSegment:
    """A torque switched on at ``start_s`` and held to the end of the run.

    Parameters
    ----------
    start_s : float
        Switch-on time [s].
    torque_nm : tuple of float
        Torque on the hub, hub frame B [N m].

    Returns
    -------
    TorqueSegment
    """
    return TorqueSegment(start_s=start_s, torque_nm=torque_nm)


def pulse(
    start_s: float, duration_s: float, torque_nm: tuple[float, float, float]
) -> TorqueSegment:
    """A torque applied for ``duration_s`` from ``start_s``.

    Parameters
    ----------
    start_s : float
        Switch-on time [s].
    duration_s : float
        How long it acts [s].
    torque_nm : tuple of float
        Torque on the hub, hub frame B [N m].

    Returns
    -------
    TorqueSegment
    """
    return TorqueSegment(start_s=start_s, end_s=start_s + duration_s, torque_nm=torque_nm)


class AppendageInitialState(_Frozen):
    """Initial deformation of one appendage's root joint (mount frame).

    Parameters
    ----------
    name : str
        The appendage's name in the satellite config.
    eta_m : tuple of 3 float
        Root translation (x, y, z), mount frame [m].
    rho_deg : tuple of 3 float
        ZYX root rotation (x, y, z) [deg].
    eta_rate_m_s : tuple of 3 float
        Rate of the root translation [m/s].
    rho_rate_deg_s : tuple of 3 float
        Rates of the root rotation [deg/s].
    """

    name: str
    eta_m: tuple[Deflection, Deflection, Deflection] = Field(
        _ZERO3, description="root translation (x, y, z), mount frame, within +-10 m [m]"
    )
    rho_deg: Annotated[
        tuple[Real, Real, Real], Field(description="ZYX root rotation (x, y, z) [deg]")
    ] = _ZERO3
    eta_rate_m_s: tuple[LinearRate, LinearRate, LinearRate] = Field(
        _ZERO3, description="rate of the root translation, within +-1e3 m/s [m/s]"
    )
    rho_rate_deg_s: tuple[AngularRate, AngularRate, AngularRate] = Field(
        _ZERO3, description="rates of the root rotation, within +-1e4 deg/s [deg/s]"
    )

    @model_validator(mode="after")
    def _small(self) -> AppendageInitialState:
        if max(abs(a) for a in self.rho_deg) >= 45.0:
            raise ValueError("rho_deg must stay below 45 deg (small elastic deformation)")
        return self


class InitialState(_Frozen):
    """Hub attitude and rate, and appendage deformations, at t = 0.

    Parameters
    ----------
    attitude_deg : tuple of 3 float
        ZYX Euler angles (roll, pitch, yaw) relative to N [deg].
    rate_deg_s : tuple of 3 float
        Body rate, hub frame B [deg/s].
    appendages : list of AppendageInitialState
        One per deformed appendage, by name (others start undeformed).
    """

    attitude_deg: tuple[EulerAngle, EulerAngle, EulerAngle] = Field(
        _ZERO3, description="ZYX Euler angles (roll, pitch, yaw), within +-360 deg [deg]"
    )
    rate_deg_s: tuple[AngularRate, AngularRate, AngularRate] = Field(
        _ZERO3, description="body rate, hub frame B, within +-1e4 deg/s [deg/s]"
    )
    appendages: list[AppendageInitialState] = Field(default_factory=list)

    @model_validator(mode="after")
    def _pitch(self) -> InitialState:
        if abs(self.attitude_deg[1]) >= 89.0:
            raise ValueError("attitude_deg pitch must be within (-89, 89) deg (ZYX singularity)")
        names = [app.name for app in self.appendages]
        repeated = sorted({name for name in names if names.count(name) > 1})
        if repeated:
            raise ValueError(f"appendages: one initial state per appendage, repeated: {repeated}")
        return self


MAX_STEPS = 1e9
"""Most integration steps of one run: the longest documented run (1e6 s) at the
default 1 ms step; about an hour of wall time on one core."""


def check_multiples_of_dt(model: object, fields: tuple[str, ...]) -> None:
    """Check that each named period of ``model`` is a whole multiple of its ``dt_s``.

    Parameters
    ----------
    model : object
        A config with a ``dt_s`` [s] and the named periods [s] as attributes.
    fields : tuple of str
        The periods' field names.

    Raises
    ------
    ValueError
        Naming the first period that is shorter than ``dt_s`` or not a whole
        multiple of it (to 1e-6 relative).
    """
    for field in fields:
        ratio = getattr(model, field) / model.dt_s
        if ratio < 1.0 - 1e-9 or abs(ratio - round(ratio)) > 1e-6 * ratio:
            raise ValueError(
                f"{field} must be a whole multiple of dt_s ({model.dt_s}), "
                f"got {getattr(model, field)}"
            )


class _TimedRun(_Frozen):
    """Duration, RK4 step and recording rate shared by every kind of run."""

    name: str = Field("run", description="name of the run, in the result's attributes")
    duration_s: Annotated[float, Field(gt=0.0, le=1e6, allow_inf_nan=False)] = Field(
        120.0, description="simulated time [s]"
    )
    dt_s: Annotated[float, Field(gt=0.0, le=0.1, allow_inf_nan=False)] = Field(
        1e-3, description="RK4 step [s]"
    )
    record_dt_s: Annotated[float, Field(gt=0.0, allow_inf_nan=False)] = Field(
        1e-2, description="interval between records, a multiple of dt_s [s]"
    )

    _MULTIPLES_OF_DT: ClassVar[tuple[str, ...]] = ("record_dt_s",)

    @model_validator(mode="after")
    def _steps(self) -> _TimedRun:
        check_multiples_of_dt(self, self._MULTIPLES_OF_DT)
        if self.duration_s < self.record_dt_s:
            raise ValueError(f"duration_s must be at least record_dt_s ({self.record_dt_s})")
        steps = self.duration_s / self.dt_s
        if steps > MAX_STEPS:
            raise ValueError(
                f"duration_s / dt_s = {steps:.3g} steps is more than the {MAX_STEPS:.0e} "
                f"allowed (duration_s {self.duration_s:g} s at dt_s {self.dt_s:g} s); "
                "use a larger dt_s or a shorter run"
            )
        return self

    @property
    def n_steps(self) -> int:
        return round(self.duration_s / self.dt_s)

    @property
    def record_every(self) -> int:
        return round(self.record_dt_s / self.dt_s)


class OpenLoopScenario(_TimedRun):
    """An open-loop run. The default is the thesis's (section 3.3): at rest,
    1 N m about body Z for 0 <= t < 10 s, then free, to 120 s, RK4 at 1 ms."""

    name: str = Field("thesis-openloop", description="name of the run")
    solver: Literal["rk4", "dop853"] = Field(
        "rk4", description="compiled fixed-step RK4 or adaptive DOP853 (scipy)"
    )
    rtol: Annotated[float, Field(gt=0.0, lt=1.0)] = Field(
        1e-10, description="relative tolerance of DOP853 [-]"
    )
    atol: Annotated[float, Field(gt=0.0, lt=1.0)] = Field(
        1e-12, description="absolute tolerance of DOP853 [SI units of the state]"
    )
    initial: InitialState = Field(default_factory=InitialState, description="state at t = 0")
    torque: list[TorqueSegment] = Field(
        default_factory=lambda: [TorqueSegment(start_s=0.0, end_s=10.0, torque_nm=(0, 0, 1.0))],
        description="commanded torque segments (they add up where they overlap)",
    )
    disturbance_torque_nm: Vector3 = Field(_ZERO3, description="constant body torque [N m]")

    @model_validator(mode="after")
    def _segments_inside_the_run(self) -> OpenLoopScenario:
        for k, segment in enumerate(self.torque):
            if segment.start_s >= self.duration_s:
                raise ValueError(
                    f"torque[{k}].start_s = {segment.start_s:g} s is at or after the end of "
                    f"the run (duration_s = {self.duration_s:g} s): it would never act"
                )
        return self


def _read_scenario(path: str | Path | None, model: type[_Frozen]) -> _Frozen:
    """``model`` validated from the TOML file ``path``; its defaults when ``path`` is None."""
    if path is None:
        return model()
    data = read_toml(path, "scenario")
    controller = data.get("controller")
    name = controller.get("file") if isinstance(controller, dict) else None
    if isinstance(name, str) and name and not Path(name).is_absolute():
        # a controller file (statespace law) is relative to the scenario's folder
        data = {**data, "controller": {**controller, "file": str(Path(path).parent / name)}}
    return validate_config(data, source=str(path), model=model)


def thesis_openloop() -> OpenLoopScenario:
    """The thesis's open-loop validation scenario (section 3.3)."""
    return OpenLoopScenario()


def load_scenario(path: str | Path | None = None) -> OpenLoopScenario:
    """Read and validate an open-loop scenario TOML; ``None`` gives :func:`thesis_openloop`.

    Parameters
    ----------
    path : str or Path, optional
        The TOML file.

    Returns
    -------
    OpenLoopScenario

    Raises
    ------
    ConfigError
        Naming the file, the field and the allowed range.
    """
    return _read_scenario(path, OpenLoopScenario)
