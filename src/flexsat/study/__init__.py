"""The thesis study end to end and its HTML report (``flexsat study``).

The names are imported on first use (PEP 562): a command that only writes its run's
files (:mod:`flexsat.study.outputs`) does not load the study's pipeline, campaigns and
report (docs/performance.md, 'Start-up').
"""

from flexsat._lazy import lazy_attributes

_LAZY = {
    **dict.fromkeys(("CAMPAIGNS", "PARTS", "run_study"), "pipeline"),
    **dict.fromkeys(("format_value", "write_report"), "report"),
}
"""The public names imported on first use, and the submodule each comes from."""

__all__ = ["CAMPAIGNS", "PARTS", "format_value", "run_study", "write_report"]


__getattr__, __dir__ = lazy_attributes(__name__, _LAZY)
