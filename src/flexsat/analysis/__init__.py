"""Analysis of plants and results: modes, open-loop metrics, spectra, requirement verdicts."""

from flexsat.analysis.modal import (
    ModalAnalysis,
    Mode,
    dof_names,
    modal_analysis,
)
from flexsat.analysis.openloop import openloop_metrics
from flexsat.analysis.requirements import (
    Requirements,
    absolute_performance_error,
    error_rotation_vector,
    observation_window,
    relative_performance_error,
    settling_time,
    slew_metrics,
)
from flexsat.analysis.spectral import dominant_frequency
from flexsat.analysis.spectrogram import (
    DEFAULT_OVERLAP,
    DEFAULT_WINDOW_S,
    HUB_ROTATION_DOF,
    coupled_frequencies,
    spectrogram,
)

__all__ = [
    "DEFAULT_OVERLAP",
    "DEFAULT_WINDOW_S",
    "HUB_ROTATION_DOF",
    "ModalAnalysis",
    "Mode",
    "Requirements",
    "absolute_performance_error",
    "coupled_frequencies",
    "dof_names",
    "dominant_frequency",
    "error_rotation_vector",
    "modal_analysis",
    "observation_window",
    "openloop_metrics",
    "relative_performance_error",
    "settling_time",
    "slew_metrics",
    "spectrogram",
]
