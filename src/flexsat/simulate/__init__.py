"""Simulation drivers: scenarios in, :class:`Result` (an xarray Dataset) out.

The names are imported on first use (PEP 562): an open-loop run
(``from flexsat.simulate import run_openloop``) does not load the closed loop, its
control laws, loop stages, orbit and environment models (docs/performance.md,
'Start-up').
"""

import importlib

_LAZY = {
    **dict.fromkeys(("design_inertia", "run_slew", "slew_design_inertia"), "closedloop"),
    **dict.fromkeys(("initial_state", "run_openloop"), "openloop"),
    "Result": "result",
    **dict.fromkeys(("OpenLoopScenario", "Requirements", "SlewScenario", "TorqueSegment",
                     "load_scenario", "load_slew", "pulse", "step", "thesis_openloop"),
                    "scenario"),
}  # fmt: skip
"""The public names imported on first use, and the submodule each comes from."""

__all__ = [
    "OpenLoopScenario",
    "Requirements",
    "Result",
    "SlewScenario",
    "TorqueSegment",
    "design_inertia",
    "initial_state",
    "load_scenario",
    "load_slew",
    "pulse",
    "run_openloop",
    "run_slew",
    "slew_design_inertia",
    "step",
    "thesis_openloop",
]


def __getattr__(name: str):
    """The drivers, scenarios and the result, imported on first use (PEP 562)."""
    if name in _LAZY:
        value = getattr(importlib.import_module(f"{__name__}.{_LAZY[name]}"), name)
        globals()[name] = value
        return value
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def __dir__() -> list[str]:
    return sorted({*globals(), *__all__})
