"""The campaign store's case histories: read back exactly, written without a Dask lock."""

from __future__ import annotations

import numpy as np
import pytest
import xarray as xr

from flexsat.campaigns.store import CampaignStore

distributed = pytest.importorskip("distributed")


def test_a_history_written_beside_a_dask_client_takes_no_cluster_wide_lock(
    tmp_path, monkeypatch
) -> None:
    """With a distributed client active, xarray's ``to_netcdf`` guards every
    variable's write with a ``distributed.Lock`` (a round trip to the scheduler each:
    about 120 per history, which made the client the bottleneck of a Dask campaign).
    The store writes its own files alone, so none may be taken; the file must read
    back exactly."""
    taken = []
    acquire = distributed.Lock.acquire

    def counting(self, *args, **kwargs):
        taken.append(self.name)
        return acquire(self, *args, **kwargs)

    monkeypatch.setattr(distributed.Lock, "acquire", counting)
    time = np.linspace(0.0, 1.0, 11)
    data = {"time": time, "pointing_error_deg": time**2,
            "tau_cmd": np.column_stack([time, -time, 2 * time])}  # fmt: skip
    cluster = distributed.LocalCluster(n_workers=1, processes=False, dashboard_address=None)
    with cluster, distributed.Client(cluster):
        path = CampaignStore(tmp_path).write_history("c1", data)
    assert taken == []
    with xr.open_dataset(path) as ds:
        np.testing.assert_array_equal(ds["pointing_error_deg"].values, time**2)
        np.testing.assert_array_equal(ds["tau_cmd"].values[:, 2], 2 * time)
        assert ds["tau_cmd"].attrs["units"] == "N m"


def test_a_history_reads_back_exactly_with_its_units_and_descriptions(tmp_path) -> None:
    # The NetCDF-3 file through xarray: values bit for bit (float64 both ways), a NaN
    # gap read as missing, text attributes (non-ASCII included) as written.
    time = np.linspace(0.0, 2.0, 21)
    rate = np.sin(time)
    rate[5] = np.nan
    data = {"time": time.tolist(), "rate_error_deg_s": rate, "jk": np.outer(time, [1, 2, 3]),
            "channels": {"jk": {"units": "N m", "description": "robust gain λ·J"}}}  # fmt: skip
    path = CampaignStore(tmp_path).write_history("random-00007", data, status="failed")
    with xr.open_dataset(path) as ds:
        np.testing.assert_array_equal(ds["time"].values, time)
        np.testing.assert_array_equal(ds["rate_error_deg_s"].values, rate)  # NaN where NaN
        np.testing.assert_array_equal(ds["jk"].values, np.outer(time, [1, 2, 3]))
        assert ds["jk"].dims == ("time", "axis") and list(ds["axis"].values) == ["x", "y", "z"]
        assert ds["jk"].attrs == {"units": "N m", "description": "robust gain λ·J"}
        assert ds["rate_error_deg_s"].attrs["units"] == "deg/s"
        assert ds["time"].attrs["units"] == "s"
        assert (ds.attrs["case_id"], ds.attrs["status"]) == ("random-00007", "failed")
        assert "pointing_error_deg" not in ds  # what the case lacks is left out
    assert sorted(p.name for p in path.parent.iterdir()) == ["random-00007.nc"]  # no partial


def test_a_case_without_metrics_gets_nan_in_the_list_columns(tmp_path) -> None:
    """A case that failed before its metrics (its inputs refused while streaming, a
    worker lost) has none of the per-axis lists the flown cases have: its cells are
    NaN, and the table is still built (it raised a TypeError)."""
    store = CampaignStore(tmp_path)
    store.cases_dir.mkdir(parents=True)
    flown = {"max_abs_torque_nm": [1.0, 2.0, 3.0], "final_pointing_error_deg": 0.5}
    store.write_case({"case_id": "a", "status": "ok", "metrics": flown, "inputs_digest": "x"})
    store.write_case({"case_id": "b", "status": "failed", "metrics": {}, "inputs_digest": "y"})
    table = store.table()
    columns = [f"metrics.max_abs_torque_nm[{k}]" for k in range(3)]
    assert table.loc[0, columns].tolist() == [1.0, 2.0, 3.0]
    assert table.loc[1, columns].isna().all()
