"""The ``[orbit]`` table of a scenario: Keplerian elements at an epoch, or a TLE.

Angles at this boundary are in degrees, lengths in metres, the epoch an ISO 8601 UTC
time (docs/orbit.md, 'The orbit table').
"""

from __future__ import annotations

from math import sqrt
from typing import Annotated

from pydantic import AllowInfNan, Field, Strict, field_validator, model_validator

from flexsat.config.models import _Frozen
from flexsat.orbit.sun import EARTH_RADIUS_M
from flexsat.orbit.time import parse_epoch

__all__ = [
    "EARTH_J2",
    "EARTH_MU_M3_S2",
    "MIN_PERIGEE_ALTITUDE_M",
    "OrbitConfig",
    "check_tle",
]

EARTH_MU_M3_S2 = 3.986004418e14
"""Earth's gravitational parameter GM [m^3/s^2] (EGM96 / WGS-84)."""
EARTH_J2 = 1.08262668e-3
"""Earth's second zonal harmonic J2 [-] (EGM96, unnormalized)."""
MIN_PERIGEE_ALTITUDE_M = 100e3
"""Lowest perigee altitude accepted [m]: below it the orbit decays within a revolution
(the Karman line)."""
_MAX_SEMI_MAJOR_AXIS_M = 1e9  # beyond the Moon: the Earth's two-body orbit no longer holds

OrbitAngle = Annotated[float, Strict(), AllowInfNan(False), Field(ge=-360.0, le=360.0)]
Length = Annotated[float, Strict(), AllowInfNan(False), Field(ge=-1e10, le=1e10)]


def _tle_checksum(line: str) -> int:
    """The TLE checksum of a line's first 68 characters: digits summed, '-' counts 1."""
    return sum(int(c) if c.isdigit() else c == "-" for c in line[:68]) % 10


def check_tle(line1: str, line2: str) -> None:
    """Refuse a malformed two-line element set.

    Parameters
    ----------
    line1, line2 : str
        The TLE's lines (69 characters each).

    Raises
    ------
    ValueError
        Naming the line and what is wrong with it.
    """
    for k, (line, first) in enumerate(((line1, "1"), (line2, "2")), start=1):
        shown = line if len(line) <= 80 else line[:77] + "..."
        if len(line) != 69:
            raise ValueError(f"tle line {k} must be 69 characters, got {len(line)}: {shown!r}")
        if not line.startswith(first + " "):
            raise ValueError(f"tle line {k} must start with '{first} ', got {shown[:2]!r}")
        if not line[68].isdigit() or int(line[68]) != _tle_checksum(line):
            raise ValueError(
                f"tle line {k}: checksum {line[68]!r} does not match its contents "
                f"(expected {_tle_checksum(line)})"
            )
    if line1[2:7] != line2[2:7]:
        raise ValueError(
            f"tle: the two lines name different satellites ({line1[2:7]!r}, {line2[2:7]!r})"
        )


class OrbitConfig(_Frozen):
    """The satellite's orbit: osculating Keplerian elements at an epoch, or a TLE.

    Give either ``tle`` (two lines; propagated by SGP4, the epoch is the TLE's) or
    the elements: ``semi_major_axis_m`` or ``altitude_m`` (a = R_E + altitude, R_E =
    6378.137 km), ``eccentricity``, ``inclination_deg``, ``raan_deg``,
    ``arg_perigee_deg`` and ``true_anomaly_deg`` or ``mean_anomaly_deg``, at
    ``epoch`` (UTC). The elements are osculating, in the J2000 frame.
    """

    epoch: str = Field("2026-03-20T12:00:00Z", description="UTC epoch of the elements, t = 0")
    semi_major_axis_m: Length | None = Field(None, description="semi-major axis a [m]")
    altitude_m: Length | None = Field(
        None, description="a - R_E [m], instead of semi_major_axis_m (default 500 km)"
    )
    eccentricity: Annotated[float, Strict(), AllowInfNan(False)] = Field(
        0.0, description="eccentricity e, in [0, 1) [-]"
    )
    inclination_deg: Annotated[float, Strict(), AllowInfNan(False), Field(ge=0.0, le=180.0)] = (
        Field(51.6, description="inclination i, in [0, 180] [deg]")
    )
    raan_deg: OrbitAngle = Field(0.0, description="right ascension of the ascending node [deg]")
    arg_perigee_deg: OrbitAngle = Field(0.0, description="argument of perigee [deg]")
    true_anomaly_deg: OrbitAngle | None = Field(None, description="true anomaly at epoch [deg]")
    mean_anomaly_deg: OrbitAngle | None = Field(
        None, description="mean anomaly at epoch [deg], instead of true_anomaly_deg"
    )
    j2: bool = Field(True, description="propagate with the J2 zonal term (else two-body)")
    tle: tuple[str, str] | None = Field(
        None, description="a two-line element set (SGP4), instead of the elements"
    )
    ephemeris_step_s: Annotated[float, Strict(), AllowInfNan(False), Field(ge=0.1, le=600.0)] = (
        Field(10.0, description="grid step of the ephemeris the loop interpolates [s]")
    )

    @field_validator("epoch")
    @classmethod
    def _iso_epoch(cls, value: str) -> str:
        parse_epoch(value)
        return value

    @field_validator("eccentricity")
    @classmethod
    def _bound_orbit(cls, value: float) -> float:
        if not 0.0 <= value < 1.0:
            raise ValueError(
                f"must be in [0, 1) (a closed orbit), got {value:g}: e >= 1 never returns"
            )
        return value

    @field_validator("tle")
    @classmethod
    def _well_formed(cls, value: tuple[str, str] | None) -> tuple[str, str] | None:
        if value is not None:
            check_tle(value[0].rstrip("\r\n"), value[1].rstrip("\r\n"))
        return value

    @model_validator(mode="after")
    def _one_description(self) -> OrbitConfig:
        if self.semi_major_axis_m is not None and self.altitude_m is not None:
            raise ValueError("give semi_major_axis_m or altitude_m, not both")
        if self.true_anomaly_deg is not None and self.mean_anomaly_deg is not None:
            raise ValueError("give true_anomaly_deg or mean_anomaly_deg, not both")
        if self.tle is not None:
            given = [
                name
                for name in (
                    "semi_major_axis_m", "altitude_m", "true_anomaly_deg", "mean_anomaly_deg"
                )
                if getattr(self, name) is not None
            ]  # fmt: skip
            if given:
                raise ValueError(f"give the tle or the elements, not both (also gave {given})")
            return self
        a = self.semi_major_axis
        perigee = a * (1.0 - self.eccentricity)
        if perigee - EARTH_RADIUS_M < MIN_PERIGEE_ALTITUDE_M:
            raise ValueError(
                f"the orbit's perigee a (1 - e) = {perigee / 1e3:.6g} km is "
                f"{(perigee - EARTH_RADIUS_M) / 1e3:.6g} km above the surface (R_E = "
                f"{EARTH_RADIUS_M / 1e3:g} km): give semi_major_axis_m (1 - eccentricity) "
                f">= {(EARTH_RADIUS_M + MIN_PERIGEE_ALTITUDE_M) / 1e3:g} km (altitude_m >= "
                f"{MIN_PERIGEE_ALTITUDE_M:g} m for a circular orbit)"
            )
        if a > _MAX_SEMI_MAJOR_AXIS_M:
            raise ValueError(
                f"semi_major_axis_m must be at most {_MAX_SEMI_MAJOR_AXIS_M:.0e} m (the Earth's "
                f"two-body orbit), got {a:.6g} m"
            )
        return self

    @property
    def semi_major_axis(self) -> float:
        """a [m] (from ``altitude_m`` when given; 500 km altitude by default)."""
        if self.semi_major_axis_m is not None:
            return float(self.semi_major_axis_m)
        altitude = 500e3 if self.altitude_m is None else float(self.altitude_m)
        return EARTH_RADIUS_M + altitude

    @property
    def period_s(self) -> float:
        """Keplerian period 2 pi sqrt(a^3 / mu) [s] (the TLE's mean motion for a TLE)."""
        if self.tle is not None:
            revs_per_day = float(self.tle[1][52:63])
            return 86400.0 / revs_per_day
        return 2.0 * 3.141592653589793 * sqrt(self.semi_major_axis**3 / EARTH_MU_M3_S2)
