"""flexsat: simulator and control-design toolkit for flexible spacecraft.

A rigid hub carries flexible appendages; flexsat models the coupled dynamics
(thesis-validated Lagrangian model, compiled engine), analyses its modes and
produces the figures and tables of a design review.

The configuration names, :class:`~flexsat.dynamics.plant.Plant` and ``__version__``
(read from the installed distribution's metadata) are resolved on first use
(PEP 562): ``import flexsat`` alone, and so ``flexsat --help``, loads neither numba,
SciPy nor pydantic's models (docs/performance.md, 'Start-up').
"""

import importlib

from flexsat._compiled_cache import drop_stale_caches

drop_stale_caches()  # before any compiled module loads its cache

from flexsat.errors import ConfigError, FlexsatError, SimulationError  # noqa: E402

_LAZY = {
    "Plant": "flexsat.dynamics.plant",
    "SatelliteConfig": "flexsat.config",
    "load_config": "flexsat.config",
    "nominal": "flexsat.config",
}
"""The public names imported on first use, and the module each comes from."""

__all__ = [
    "ConfigError",
    "FlexsatError",
    "Plant",
    "SatelliteConfig",
    "SimulationError",
    "__version__",
    "load_config",
    "nominal",
]


def __getattr__(name: str):
    """The configuration names, the plant and the version, on first use (PEP 562)."""
    if name == "__version__":  # the distribution's metadata, read when asked for
        from flexsat._version import package_version

        value = globals()["__version__"] = package_version()
        return value
    if name in _LAZY:
        value = getattr(importlib.import_module(_LAZY[name]), name)
        globals()[name] = value
        return value
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def __dir__() -> list[str]:
    return sorted({*globals(), *__all__})
