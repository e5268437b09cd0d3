"""The thesis study end to end and its HTML report (``flexsat study``).

The names are imported on first use (PEP 562): a command that only writes its run's
files (:mod:`flexsat.study.outputs`) does not load the study's pipeline, campaigns and
report (docs/performance.md, 'Start-up').
"""

import importlib

_LAZY = {
    **dict.fromkeys(("CAMPAIGNS", "PARTS", "run_study"), "pipeline"),
    **dict.fromkeys(("format_value", "write_report"), "report"),
}
"""The public names imported on first use, and the submodule each comes from."""

__all__ = ["CAMPAIGNS", "PARTS", "format_value", "run_study", "write_report"]


def __getattr__(name: str):
    """The study's pipeline and report, imported on first use (PEP 562)."""
    if name in _LAZY:
        value = getattr(importlib.import_module(f"{__name__}.{_LAZY[name]}"), name)
        globals()[name] = value
        return value
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def __dir__() -> list[str]:
    return sorted({*globals(), *__all__})
