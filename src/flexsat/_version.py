"""The package version, read from the installed distribution's metadata.

``pyproject.toml`` is the one place the version is written; a source tree that is
not installed reports :data:`UNKNOWN_VERSION`.
"""

from __future__ import annotations

from importlib.metadata import PackageNotFoundError, version

__all__ = ["UNKNOWN_VERSION", "package_version"]

UNKNOWN_VERSION = "0+unknown"


def package_version(distribution: str = "flexsat") -> str:
    """Version of the installed ``distribution``; :data:`UNKNOWN_VERSION` if not installed."""
    try:
        return version(distribution)
    except PackageNotFoundError:
        return UNKNOWN_VERSION
