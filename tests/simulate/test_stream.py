"""Long open-loop records streamed to disk: the same records, in bounded memory."""

from __future__ import annotations

import tracemalloc

import numpy as np
import pytest

from flexsat.errors import ConfigError
from flexsat.simulate import OpenLoopScenario, run_openloop
from flexsat.simulate.result import Result

# 120 s at 4 ms, every step recorded: 3e4 records, about 30 MB as a dataset (three
# times that while it is built), against a record budget of 8 MB. 4 ms keeps RK4
# stable on the 100 Hz root-translation modes (omega dt = 2.5 < 2.83).
_LONG = {"duration_s": 120.0, "dt_s": 0.004, "record_dt_s": 0.004}
_BUDGET_BYTES = 8e6


def test_a_streamed_run_records_what_a_run_in_memory_records(nominal_plant, tmp_path):
    scenario = OpenLoopScenario(duration_s=30.0)
    held = run_openloop(nominal_plant, scenario, progress=False)
    # 2 MB for 3001 records of about 1 kB each: streamed, in blocks of about 480.
    streamed = run_openloop(nominal_plant, scenario, progress=False,
                            record_path=tmp_path / "r.nc", record_budget_bytes=2e6)  # fmt: skip
    assert held.path is None and streamed.path == tmp_path / "r.nc"
    assert streamed.dataset.sizes["time"] == held.dataset.sizes["time"] == 3001
    # Same compiled chunks, same arithmetic: every record is bit-identical.
    for name, var in held.dataset.data_vars.items():
        assert np.array_equal(streamed.dataset[name].values, var.values), name
    timing = {"wall_time_s": streamed.metrics()["wall_time_s"]}
    assert streamed.metrics() == {**held.metrics(), **timing}
    copy = streamed.to_netcdf(tmp_path / "copy.nc")  # copied, not loaded whole
    assert Result.from_netcdf(copy).dataset["q"].shape == held.dataset["q"].shape


def test_records_beyond_the_budget_stream_in_bounded_memory(nominal_plant):
    scenario = OpenLoopScenario.model_validate(_LONG)
    tracemalloc.start()
    try:
        result = run_openloop(nominal_plant, scenario, progress=False,
                              record_budget_bytes=_BUDGET_BYTES)  # fmt: skip
        metrics = result.metrics()
        _, peak = tracemalloc.get_traced_memory()
    finally:
        tracemalloc.stop()
    assert result.ok and result.path is not None and result.path.is_file()
    assert result.dataset.sizes["time"] == 30_001
    # In memory the records alone would take 3e4 x ~1 kB x 3 copies = 90 MB. Streamed:
    # one buffer (a quarter of the budget), one block's dataset, and for the metrics one
    # variable at a time (q: 3e4 x 18 x 8 B = 4.3 MB, a few copies): under 30 MB.
    assert peak < 30e6
    # 1 N m about Z for 10 s (2500 whole steps) about the yaw axis alone: the final
    # angular momentum is the impulse, 10 N m s; RK4 conserves it to round-off (1e-9
    # relative leaves room for 3e4 steps of accumulated rounding).
    assert metrics["final_angular_momentum_nms"][2] == pytest.approx(10.0, rel=1e-9)
    result.path.unlink()


def test_records_that_cannot_be_streamed_are_refused(nominal_plant):
    # DOP853 output is not streamed: its records must fit in memory.
    scenario = OpenLoopScenario.model_validate({**_LONG, "solver": "dop853"})
    with pytest.raises(ConfigError, match="GiB in memory"):
        run_openloop(nominal_plant, scenario, record_budget_bytes=_BUDGET_BYTES)
