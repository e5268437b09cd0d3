"""Simulation drivers: scenarios in, :class:`Result` (an xarray Dataset) out.

The names are imported on first use (PEP 562): an open-loop run
(``from flexsat.simulate import run_openloop``) does not load the closed loop, its
control laws, loop stages, orbit and environment models (docs/performance.md,
'Start-up').
"""

from flexsat._lazy import lazy_attributes

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


__getattr__, __dir__ = lazy_attributes(__name__, _LAZY)
