"""Analysis of plants and results: modes, open-loop metrics, spectra, requirement verdicts.

The open-loop metrics and the spectra (:mod:`scipy.signal`, about 0.8 s to import) are
imported on first use: the closed-loop stages import this package for its modal
analysis, and a study's runs and figures other than the open loop's never need them.
"""

import importlib

from flexsat.analysis.modal import (
    ModalAnalysis,
    Mode,
    dof_names,
    modal_analysis,
)
from flexsat.analysis.requirements import (
    Requirements,
    absolute_performance_error,
    error_rotation_vector,
    observation_window,
    relative_performance_error,
    settling_time,
    slew_metrics,
)

_LAZY = {
    "openloop_metrics": "openloop",
    "dominant_frequency": "spectral",
    **dict.fromkeys(("DEFAULT_OVERLAP", "DEFAULT_WINDOW_S", "HUB_ROTATION_DOF",
                     "coupled_frequencies", "spectrogram"), "spectrogram"),
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


def __getattr__(name: str):
    """The open-loop and spectral names, imported on first use (PEP 562)."""
    if name in _LAZY:
        value = getattr(importlib.import_module(f"{__name__}.{_LAZY[name]}"), name)
        globals()[name] = value
        return value
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def __dir__() -> list[str]:
    return sorted({*globals(), *__all__})
