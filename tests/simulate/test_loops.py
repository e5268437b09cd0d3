"""The compiled loop's stage chains: padded to one numba type, only their own stages run."""

from __future__ import annotations

from typing import Literal

import numpy as np
import pytest
from numba import njit, typeof

from flexsat.control import StageConfig, StageSpec, register_stage
from flexsat.control.stages import ACTUATOR_SIGNATURE, ACTUATORS
from flexsat.simulate import SlewScenario, run_slew, stage_chain
from flexsat.simulate.closedloop import prepare_slew
from flexsat.simulate.coupled import CHAIN_SLOTS

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


@pytest.mark.parametrize(
    ("stages", "ideal_runs"),
    [
        (["gyro", "star_tracker", "mekf"], False),  # both outputs replaced, then read
        (["gyro", "star_tracker"], False),
        (["gyro"], True),  # the law reads the ideal attitude
        (["star_tracker"], True),  # the law reads the ideal rate
        (["gyro", "mekf", "star_tracker"], True),  # the estimator reads the ideal attitude
    ],
)
def test_the_ideal_sensor_runs_only_where_something_reads_it(stages, ideal_runs):
    scenario = SlewScenario.model_validate({"sensor_stages": [{"kind": k} for k in stages]})
    chain, n_sensors = stage_chain.flown_chain(scenario)
    kinds = [config.kind for _, config in chain[:n_sensors]]
    assert kinds == (["ideal"] if ideal_runs else []) + stages


def test_leaving_the_unread_ideal_sensor_out_changes_no_output(nominal_plant, monkeypatch):
    # The same avionics slew with the ideal sensor run (the whole chain forced) and
    # left out: every recorded variable bit for bit, so nothing read its outputs.
    scenario = SlewScenario.model_validate({**AVIONICS, **SHORT})
    lean = run_slew(nominal_plant, scenario, progress=False).dataset
    monkeypatch.setattr(stage_chain, "flown_chain", lambda s: (
        s.stage_chain(), 1 + len(s.sensor_stages)))  # fmt: skip
    full = run_slew(nominal_plant, scenario, progress=False).dataset
    for name in full.data_vars:
        if full[name].dtype.kind == "f" and name != "wall_time_s":
            np.testing.assert_array_equal(lean[name].values, full[name].values, err_msg=name)
