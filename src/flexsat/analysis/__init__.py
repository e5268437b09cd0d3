"""Analysis of plants and results: modal analysis (more to come: energy, spectra, requirements)."""

from flexsat.analysis.modal import ModalAnalysis, Mode, dof_names, modal_analysis

__all__ = ["ModalAnalysis", "Mode", "dof_names", "modal_analysis"]
