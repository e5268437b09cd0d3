"""flexsat: simulator and control-design toolkit for flexible spacecraft.

A rigid hub carries flexible appendages; flexsat models the coupled dynamics
(thesis-validated Lagrangian model, compiled engine), analyses its modes and
produces the figures and tables of a design review.
"""

from flexsat.config import SatelliteConfig, load_config, nominal
from flexsat.dynamics.plant import Plant
from flexsat.errors import ConfigError, FlexsatError, SimulationError

__version__ = "0.1.0"

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
