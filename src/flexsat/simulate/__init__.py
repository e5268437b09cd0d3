"""Simulation drivers: scenarios in, :class:`Result` (an xarray Dataset) out."""

from flexsat.simulate.closedloop import design_inertia, run_slew, slew_design_inertia
from flexsat.simulate.openloop import initial_state, run_openloop
from flexsat.simulate.result import Result
from flexsat.simulate.scenario import (
    OpenLoopScenario,
    Requirements,
    SlewScenario,
    TorqueSegment,
    load_scenario,
    load_slew,
    pulse,
    step,
    thesis_openloop,
)

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
