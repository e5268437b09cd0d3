"""Exceptions flexsat raises for problems a user can fix.

Every error a user can cause derives from :class:`FlexsatError`; the command line
prints its message and exits with code 2 instead of showing a traceback.
"""

from __future__ import annotations

__all__ = ["ConfigError", "FlexsatError", "SimulationError"]


class FlexsatError(Exception):
    """Base class of the errors a user can fix (bad input, diverging run...)."""


class ConfigError(FlexsatError, ValueError):
    """A configuration was refused; the message names the field and the allowed range."""


class SimulationError(FlexsatError, RuntimeError):
    """A simulation could not go on (non-finite state, singular kinematics)."""
