"""Linear analysis: state-space models of the flexible satellite, reductions, margins."""

from flexsat.linear.frequency import (
    LoopMargins,
    effective_inertia,
    law_gains,
    loop_margins,
    pd_gains,
    pd_loop,
    rigid_model,
)
from flexsat.linear.linearize import OUTPUT_GROUPS, linearize, signal_names
from flexsat.linear.model import MAT_VARIABLES, LinearModel
from flexsat.linear.reduce import ReducedModel, balanced_truncation, modal_truncation

__all__ = [
    "MAT_VARIABLES",
    "OUTPUT_GROUPS",
    "LinearModel",
    "LoopMargins",
    "ReducedModel",
    "balanced_truncation",
    "effective_inertia",
    "law_gains",
    "linearize",
    "loop_margins",
    "modal_truncation",
    "pd_gains",
    "pd_loop",
    "rigid_model",
    "signal_names",
]
