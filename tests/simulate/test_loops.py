"""The compiled loop's stage chains: padded to one numba type, only their own stages run."""

from __future__ import annotations

from typing import Literal

import numpy as np
import pytest
from numba import njit, typeof

from flexsat.control import StageConfig, StageSpec, register_stage
from flexsat.control.stages import ACTUATOR_SIGNATURE, ACTUATORS
from flexsat.simulate import SlewScenario, run_slew
from flexsat.simulate.closedloop import prepare_slew
from flexsat.simulate.loops import CHAIN_SLOTS

SHORT = {"duration_s": 1.0}
AVIONICS = {  # four sensing stages, three actuation stages (two of them integrate states)
    "sensor_stages": [{"kind": "gyro"}, {"kind": "star_tracker"}, {"kind": "mekf"}],
    "actuator_stages": [{"kind": "delay", "periods": 1}],
    "actuator": {"kind": "wheels"},
}


class GainConfig(StageConfig):
    kind: Literal["gain"] = "gain"
    gain: float = 0.5

    def packed(self, scenario) -> np.ndarray:
        return np.array([self.gain])


@njit(ACTUATOR_SIGNATURE, cache=True)
def gain_step(tau_cmd, t, dt, params, state, tau_applied, record):
    for a in range(3):
        tau_applied[a] = params[0] * tau_cmd[a]
    return 0


@pytest.fixture(scope="module")
def gain_stage():
    register_stage(StageSpec(role="actuator", name="gain", config=GainConfig, step=gain_step))
    yield
    ACTUATORS.unregister("gain")


def _types(plant, fields: dict) -> tuple:
    run = prepare_slew(plant, SlewScenario.model_validate({**SHORT, **fields}))
    return typeof(run.stages), typeof(run.data)


def test_every_chain_of_up_to_four_stages_is_one_loop_type(nominal_plant, gain_stage):
    # One numba type: the closed loop compiles once for all of them (docs/performance.md).
    ideal = _types(nominal_plant, {})
    assert _types(nominal_plant, AVIONICS) == ideal
    assert _types(nominal_plant, {"actuator_stages": [{"kind": "delay"}]}) == ideal
    five = [{"kind": "gain"}] * CHAIN_SLOTS  # + the actuator: 5 stages, padded to 8
    assert _types(nominal_plant, {"actuator_stages": five}) != ideal


def test_a_chain_longer_than_the_slots_runs_each_of_its_stages(nominal_plant, gain_stage):
    # Four gains of 1/2, then the actuator, apply what one gain of 1/16 does: bit for
    # bit, as halving is exact in binary floating point (tolerance 0). A loop that
    # skipped, repeated or reordered a stage would change the torque by a factor 2.
    chained = {"actuator_stages": [{"kind": "gain", "gain": 0.5}] * CHAIN_SLOTS}
    single = {"actuator_stages": [{"kind": "gain", "gain": 0.5**CHAIN_SLOTS}]}
    a, b = (run_slew(nominal_plant, SlewScenario.model_validate({**SHORT, **f}),
                     progress=False).dataset for f in (chained, single))  # fmt: skip
    assert a.attrs["actuator"].count("gain") == CHAIN_SLOTS
    np.testing.assert_array_equal(a["tau_applied"].values, b["tau_applied"].values)
    np.testing.assert_array_equal(a["tau_cmd"].values, b["tau_cmd"].values)
    assert np.max(np.abs(a["tau_applied"].values)) > 0.01  # the slew applies torque [N m]
