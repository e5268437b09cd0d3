"""The campaign store's files under a Dask client: written with local locks."""

from __future__ import annotations

import numpy as np
import pytest
import xarray as xr

from flexsat.campaigns.store import CampaignStore

distributed = pytest.importorskip("distributed")


def test_a_history_written_beside_a_dask_client_takes_no_cluster_wide_lock(
    tmp_path, monkeypatch
) -> None:
    """With a distributed client active, xarray would guard every variable's write
    with a ``distributed.Lock`` (a round trip to the scheduler each: about 120 per
    history, which made the client the bottleneck of a Dask campaign). The store
    writes its own files alone, so none may be taken; the file must read back
    exactly."""
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
