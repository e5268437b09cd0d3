"""The satellite in its orbit: elements or a TLE, propagation, the Sun, the shadow, ephemeris."""

from __future__ import annotations

from flexsat.orbit.config import OrbitConfig
from flexsat.orbit.ephemeris import (
    EPHEMERIS_COLUMNS,
    Ephemeris,
    build_ephemeris,
    ephemeris_at,
)

__all__ = ["EPHEMERIS_COLUMNS", "Ephemeris", "OrbitConfig", "build_ephemeris", "ephemeris_at"]
