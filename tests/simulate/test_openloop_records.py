"""An open loop's metrics from its records as plain arrays are its dataset's, bit for bit.

``flexsat openloop`` without ``--out`` builds no ``xarray.Dataset``
(``run_openloop(..., records=True)``, docs/performance.md, 'Start-up'): the records it
reads are the arrays the dataset would hold, and the JSON it prints must not change.
Every comparison is exact: the same arrays go through the same arithmetic.
"""

from __future__ import annotations

import numpy as np
import pytest

from flexsat.analysis.openloop import openloop_metrics
from flexsat.analysis.run_records import RunRecords
from flexsat.config import validate_config
from flexsat.dynamics.integrators import applied_torque
from flexsat.simulate import OpenLoopScenario, run_openloop
from flexsat.simulate.openloop import commanded_torques
from flexsat.simulate.result import Result
from flexsat.study.outputs import fly_openloop

# The thesis's pulse (1 N m about Z for 10 s), shortened to 20 s: the free ripple after
# the pulse holds enough records for the dominant frequency.
_PULSE = {"duration_s": 20.0}
# 1 MN m about Z from t = 0 (tests/simulate/test_divergence.py): the run overflows near
# t = 10.17 s, so the metrics come from the finite part of the records.
_HUGE_TORQUE = {"duration_s": 11.0, "torque": [{"start_s": 0.0, "torque_nm": [0, 0, 1e6]}]}
SEED = 46
"""The random segment torques' seed (fixed, printed)."""


def _same(a, b) -> bool:
    """Equal, NaN equal to NaN, lists element by element."""
    if isinstance(a, list):
        return len(a) == len(b) and all(_same(x, y) for x, y in zip(a, b, strict=True))
    if isinstance(a, float) and np.isnan(a):
        return isinstance(b, float) and np.isnan(b)
    return a == b


@pytest.mark.parametrize("settings", [_PULSE, _HUGE_TORQUE], ids=["pulse", "diverging"])
def test_the_metrics_without_a_dataset_are_the_datasets(nominal_plant, settings):
    scenario = validate_config(settings, model=OpenLoopScenario)
    result, with_dataset = fly_openloop(nominal_plant, scenario, progress=False)
    records, without = fly_openloop(nominal_plant, scenario, progress=False, dataset=False)
    assert isinstance(result, Result) and isinstance(records, RunRecords)
    assert with_dataset.keys() == without.keys()
    for key in with_dataset.keys() - {"wall_time_s"}:  # the run's own timing differs
        assert _same(with_dataset[key], without[key]), key
    assert (without["status"] == "ok") == (settings is _PULSE)
    # the records are the dataset's variables, bit for bit
    ds = result.dataset
    assert set(records.variables) == set(ds.variables)
    for name, var in records.variables.items():
        assert var.dims == ds.variables[name].dims, name
        floats = np.issubdtype(var.values.dtype, np.floating)  # labels: no NaN to match
        assert np.array_equal(var.values, ds.variables[name].values, equal_nan=floats), name
        assert dict(var.attrs) == dict(ds.variables[name].attrs), name
    assert {k: v for k, v in records.attrs.items() if k != "wall_time_s"} == {
        k: v for k, v in ds.attrs.items() if k != "wall_time_s"
    }


def test_openloop_metrics_read_a_dataset_and_records_alike(nominal_plant):
    scenario = OpenLoopScenario(duration_s=12.0)
    held = run_openloop(nominal_plant, scenario, progress=False, records=True)
    built = run_openloop(nominal_plant, scenario, progress=False)
    a, b = openloop_metrics(held), openloop_metrics(built.dataset)
    assert all(_same(a[k], b[k]) for k in a.keys() - {"wall_time_s"})


def test_the_files_of_out_need_the_dataset(nominal_plant, tmp_path):
    with pytest.raises(ValueError, match="dataset=True"):
        fly_openloop(nominal_plant, OpenLoopScenario(duration_s=1.0), tmp_path, dataset=False)


def test_commanded_torques_are_the_per_record_applied_torques():
    # Segments that overlap, start and end between and on record times, one never
    # ending: the batch must sum them exactly as applied_torque does record by record.
    print(f"seed = {SEED}")
    rng = np.random.default_rng(SEED)
    t = np.arange(0.0, 20.0 + 1e-9, 0.01)
    seg_start = np.array([0.0, 2.5, 3.0, 7.123, 15.0])
    seg_end = np.array([10.0, 2.5, 12.0, 7.125, np.inf])
    seg_torque = rng.normal(size=(5, 3))
    expected = np.array([applied_torque(tk, seg_start, seg_end, seg_torque, np.zeros(3))
                         for tk in t])  # fmt: skip
    got = commanded_torques(t, seg_start, seg_end, seg_torque)
    assert got.shape == (t.size, 3)
    assert np.array_equal(got, expected)  # exact: the same additions in the same order
    assert commanded_torques(t[:0], seg_start, seg_end, seg_torque).shape == (0, 3)
