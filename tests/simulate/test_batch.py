"""Slews flown together in one compiled call give the records of slews flown alone."""

from __future__ import annotations

import numpy as np
import pytest

from flexsat.dynamics.plant import Plant
from flexsat.simulate import SlewScenario, run_slew
from flexsat.simulate.batch import fly_prepared
from flexsat.simulate.closedloop import finish_slew, prepare_slew

from ..conftest import one_panel

SHORT = {"duration_s": 2.0}
SCENARIOS = [
    SHORT,
    {**SHORT, "controller": {"kind": "pd"}},  # another law: the same loop type
    {**SHORT, "sensor_stages": [{"kind": "gyro"}]},  # a longer chain, padded: one loop type
    {**SHORT, "target_euler_deg": [10.0, -20.0, 5.0]},
    # diverges in a few steps: its status and partial records as alone
    {**SHORT, "controller": {"kind": "pd"}, "actuator": {"t_max_nm": 1e7},
     "disturbances": {"environment_nm": [1e6, 1e6, 1e6]}},
]  # fmt: skip


@pytest.mark.parametrize("threads", [1, 2])
def test_a_batch_gives_the_records_of_each_slew_alone(nominal_plant, threads):
    # Bit for bit (tolerance 0): the batch runs the same compiled chunks with the same
    # arithmetic, each case on its own arrays, whatever thread flies it.
    plants = [nominal_plant] * len(SCENARIOS) + [Plant.from_config(one_panel())]
    scenarios = [SlewScenario.model_validate(s) for s in SCENARIOS] + [
        SlewScenario.model_validate(SHORT)  # one appendage: other shapes, same type
    ]
    # each run on its own Plant: the packed plant holds the kernels' scratch arrays
    runs = [prepare_slew(Plant.from_config(p.config), s)
            for p, s in zip(plants, scenarios, strict=True)]  # fmt: skip
    flown = fly_prepared(runs, threads)
    for run, (status, done, rows), plant, scenario in zip(runs, flown, plants, scenarios,
                                                         strict=True):  # fmt: skip
        together = finish_slew(run, int(status), int(done), int(rows), 0.0).dataset
        alone = run_slew(plant, scenario, progress=False).dataset
        assert together.attrs["status"] == alone.attrs["status"]
        for name in ("q", "qd", "tau_cmd", "tau_applied", "pointing_error_deg"):
            np.testing.assert_array_equal(together[name].values, alone[name].values)
    assert flown[4, 0] != 0 and flown[0, 0] == 0  # the diverging case failed, alone


def test_a_slews_type_by_structure_is_numbas_typeof(nominal_plant):
    # item_type keys numba's type on what typeof reads (arrays' dtype, dimensions,
    # layout, writeability; tuples; kernels' declared types): exactly typeof's type
    # for slews of other laws, chains and appendages, and for an array made read-only
    # or non-contiguous after the first slew of that structure was typed.
    from numba import typeof

    from flexsat.simulate.batch import batch_item, item_type

    plants = [nominal_plant] * len(SCENARIOS) + [Plant.from_config(one_panel())]
    scenarios = [SlewScenario.model_validate(s) for s in SCENARIOS] + [
        SlewScenario.model_validate(SHORT)
    ]
    items = [batch_item(prepare_slew(Plant.from_config(p.config), s))
             for p, s in zip(plants, scenarios, strict=True)]  # fmt: skip
    readonly = items[0]._replace(x=items[0].x.copy())
    readonly.x.flags.writeable = False
    strided = items[0]._replace(rec_t=np.zeros(2 * items[0].rec_t.size)[::2])
    for item in [*items, readonly, strided]:
        assert item_type(item) == typeof(item)
    assert item_type(readonly) != item_type(items[0]) != item_type(strided)
