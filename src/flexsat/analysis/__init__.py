"""Analysis of plants and results: modes, open-loop metrics, spectra, requirement verdicts.

Every name is imported on first use (PEP 562): the modal analysis (:mod:`scipy.linalg`),
the open-loop metrics (xarray) and the spectrogram (:mod:`scipy.signal`) each load
only when asked for. A closed-loop stage that needs the modal
analysis, or ``flexsat openloop`` its metrics, does not pay for the others
(docs/performance.md, 'Start-up').
"""

from flexsat._lazy import lazy_attributes

_LAZY = {
    **dict.fromkeys(("ModalAnalysis", "Mode", "dof_names", "modal_analysis"), "modal"),
    **dict.fromkeys(("Requirements", "absolute_performance_error", "error_rotation_vector",
                     "observation_window", "relative_performance_error", "settling_time",
                     "slew_metrics"), "requirements"),
    "openloop_metrics": "openloop",
    "dominant_frequency": "spectral",
    **dict.fromkeys(("DEFAULT_OVERLAP", "DEFAULT_WINDOW_S", "HUB_ROTATION_DOF",
                     "coupled_frequencies", "spectrogram"), "time_frequency"),
}  # fmt: skip

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


__getattr__, __dir__ = lazy_attributes(__name__, _LAZY)
