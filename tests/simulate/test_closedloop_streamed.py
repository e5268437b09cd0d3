"""A slew streamed to disk block by block holds the records of the same run kept in memory."""

from __future__ import annotations

import numpy as np

from flexsat.config import nominal
from flexsat.dynamics.plant import Plant
from flexsat.simulate.closedloop import run_slew
from flexsat.simulate.scenario import SlewScenario


def test_streamed_nadir_run_equals_the_run_in_memory(tmp_path):
    scenario = SlewScenario.model_validate({
        "duration_s": 50.0, "dt_s": 2e-3, "control_dt_s": 1e-2, "record_dt_s": 1e-2,
        "controller": {"kind": "pd"}, "reference": {"kind": "nadir"},
        "orbit": {"altitude_m": 500e3, "inclination_deg": 51.6},
        "initial": {"attitude_deg": (-90.0, -51.6, 90.0), "rate_deg_s": (0.0, -0.063414, 0.0)},
    })  # fmt: skip
    plant = Plant.from_config(nominal())
    kept = run_slew(plant, scenario, progress=False).dataset
    # a budget of one byte: blocks of two compiled chunks (4,002 rows), so the 5,001
    # records are written in two appends
    streamed = run_slew(plant, scenario, progress=False, record_path=tmp_path / "r.nc",
                        record_budget_bytes=1.0)  # fmt: skip
    assert streamed.path == tmp_path / "r.nc"
    ds = streamed.dataset
    assert ds.sizes["time"] == kept.sizes["time"] == 5001
    assert ds.attrs["status"] == kept.attrs["status"] == "ok"
    for name, variable in kept.data_vars.items():
        # the same arithmetic in the same order: equal to the bit, NaN where NaN
        np.testing.assert_array_equal(ds[name].values, variable.values, err_msg=name)
    assert "reference_quaternion" in ds
