"""Simulation drivers: scenarios in, :class:`Result` (an xarray Dataset) out."""

from flexsat.simulate.openloop import initial_state, run_openloop
from flexsat.simulate.result import Result
from flexsat.simulate.scenario import (
    OpenLoopScenario,
    TorqueSegment,
    load_scenario,
    pulse,
    step,
    thesis_openloop,
)

__all__ = [
    "OpenLoopScenario",
    "Result",
    "TorqueSegment",
    "initial_state",
    "load_scenario",
    "pulse",
    "run_openloop",
    "step",
    "thesis_openloop",
]
