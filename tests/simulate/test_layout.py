"""The loop layout: every piece of a closed loop's state and records has its own place."""

from __future__ import annotations

import dataclasses
import itertools

import pytest

from flexsat.control.laws import get_law
from flexsat.control.registry import Channel
from flexsat.control.stages import ACTUATORS, SENSORS
from flexsat.dynamics.layout import StateLayout
from flexsat.simulate.layout import LoopLayout

# The nominal satellite's plant state: two plates of six joint coordinates each.
_PLATE = (("eta_x", "eta_y", "eta_z", "eta_rx", "eta_ry", "eta_rz"), ("m",) * 3 + ("rad",) * 3)
PLANT = StateLayout.build([("+Y", "plate", *_PLATE), ("-Y", "plate", *_PLATE)])


def _layout(law: str = "asmc") -> LoopLayout:
    return LoopLayout(PLANT, get_law(law), SENSORS.get("ideal"), ACTUATORS.get("static"))


def test_plant_state_offsets_are_the_plants():
    layout = _layout()
    assert (layout.plant.q, layout.plant.qd) == (slice(0, 18), slice(18, 36))
    assert (layout.plant.work_in, layout.plant.dissipated, layout.plant.size) == (36, 37, 38)


def test_record_columns_follow_each_other_without_gaps():
    layout = _layout()
    # tau_cmd (3), tau_applied (3), then the ASMC's 16 diagnostics
    assert layout.law_diag == slice(6, 22)
    assert layout.record_size == 22 and layout.state_size == 2
    columns = [columns for _, columns in layout.channels()]
    assert columns[0].start == 6 and columns[-1].stop == 22
    assert all(a.stop == b.start for a, b in itertools.pairwise(columns))


def test_stage_records_come_after_the_law_diagnostics():
    actuator = dataclasses.replace(
        ACTUATORS.get("static"), state_size=4, records=(Channel("extra", "N m", "", True),)
    )
    layout = LoopLayout(PLANT, get_law("pd"), SENSORS.get("ideal"), actuator)
    assert layout.law_diag == slice(6, 12)  # the PD's tau_gyro and tau_guide
    assert layout.actuator_record == slice(12, 15)
    assert layout.actuator_state == slice(0, 4)  # the PD and the ideal sensor keep none


def test_a_channel_named_twice_is_refused():
    law = dataclasses.replace(get_law("pd"), diagnostics=(Channel("tau_cmd", "N m", ""),))
    with pytest.raises(ValueError, match="named twice: tau_cmd"):
        LoopLayout(PLANT, law, SENSORS.get("ideal"), ACTUATORS.get("static"))


def test_stage_chains_tile_the_state_and_the_record_row():
    sensors = tuple(SENSORS.get(k) for k in ("ideal", "gyro", "star_tracker", "mekf"))
    actuators = tuple(ACTUATORS.get(k) for k in ("notch", "delay", "wheels"))
    layout = LoopLayout(PLANT, get_law("pd"), sensors, actuators)
    pieces = [layout.law_state, *layout.sensor_states, *layout.actuator_states]
    assert all(a.stop == b.start for a, b in itertools.pairwise(pieces))
    assert pieces[-1].stop == layout.state_size
    assert layout.sensor_state == slice(layout.sensor_states[0].start,
                                        layout.sensor_states[-1].stop)  # fmt: skip
    rows = [layout.law_diag, *layout.sensor_records, *layout.actuator_records]
    assert all(a.stop == b.start for a, b in itertools.pairwise(rows))
    # Only the wheels integrate states: the coupled RK4 step carries their piece alone,
    # not the long delay buffer before them.
    assert layout.continuous
    assert layout.continuous_state == layout.actuator_states[-1]
    assert not _layout().continuous
