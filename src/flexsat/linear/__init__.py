"""Linear analysis: state-space models of the flexible satellite, reductions, margins."""

from flexsat.linear.linearize import OUTPUT_GROUPS, linearize, signal_names
from flexsat.linear.model import MAT_VARIABLES, LinearModel

__all__ = ["MAT_VARIABLES", "OUTPUT_GROUPS", "LinearModel", "linearize", "signal_names"]
