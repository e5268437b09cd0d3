"""flexsat: simulator and control-design toolkit for flexible spacecraft.

A rigid hub carries flexible appendages; flexsat models the coupled dynamics
(thesis-validated Lagrangian model, compiled engine), analyses its modes and
produces the figures and tables of a design review.
"""

from flexsat._version import package_version

__version__ = package_version()

from flexsat._compiled_cache import drop_stale_caches

drop_stale_caches()  # before any compiled module loads its cache

from flexsat.config import SatelliteConfig, load_config, nominal  # noqa: E402
from flexsat.dynamics.plant import Plant  # noqa: E402
from flexsat.errors import ConfigError, FlexsatError, SimulationError  # noqa: E402

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
