"""Exceptions flexsat raises for problems a user can fix.

Every error a user can cause derives from :class:`FlexsatError`; the command line
prints its message and exits with code 2 instead of showing a traceback.
"""

from __future__ import annotations

__all__ = ["ConfigError", "FlexsatError", "SimulationError", "shorten"]

MAX_MESSAGE_CHARS = 2000
"""Longest error message printed; longer ones are cut in the middle (input echoed)."""


def shorten(text: str, limit: int = 80) -> str:
    """``text`` cut to at most about ``limit`` characters, saying how much was left out.

    Error messages echo what the user wrote; a 50 MB name must not give a 50 MB
    message.

    Parameters
    ----------
    text : str
        The text.
    limit : int
        About the longest result [characters].

    Returns
    -------
    str
        ``text``, or its two ends around ``...[n characters]...``.
    """
    if len(text) <= limit:
        return text
    keep = max(limit // 2, 1)
    return f"{text[:keep]}...[{len(text) - 2 * keep} characters]...{text[-keep:]}"


class FlexsatError(Exception):
    """Base class of the errors a user can fix (bad input, diverging run...).

    ``exit_code`` is the command line's exit status for it (2: bad input).
    """

    exit_code = 2


class ConfigError(FlexsatError, ValueError):
    """A configuration was refused; the message names the field and the allowed range."""


class SimulationError(FlexsatError, RuntimeError):
    """A simulation could not go on (non-finite state, singular kinematics)."""
