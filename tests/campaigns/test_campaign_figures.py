"""Campaign time histories (histories/<id>.nc) and the envelope and summary figures."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest
import xarray as xr

from flexsat.campaigns import CampaignStore, run_campaign
from flexsat.campaigns.runner import HISTORY_DT_S
from flexsat.campaigns.store import HISTORY_UNITS
from flexsat.config import nominal
from flexsat.plots.campaign import (
    CAMPAIGN_FIGURES,
    campaign_envelope,
    plot_envelopes,
    write_campaign_figures,
)

from .test_campaigns import _short

PNG_MAGIC = b"\x89PNG\r\n\x1a\n"
DURATION_S = 5.0


@pytest.fixture(scope="module")
def store(tmp_path_factory):
    """The sensitivity campaign shortened to 5 s, run in this process."""
    root = tmp_path_factory.mktemp("sensitivity-5s")
    run_campaign(_short("sensitivity", DURATION_S), nominal(), root, workers=1, progress=False)
    return root


def test_every_case_has_a_netcdf_history_with_units(store):
    case_ids = {p.stem for p in (store / "cases").glob("*.json")}
    assert len(case_ids) == 12
    assert {p.stem for p in (store / "histories").glob("*.nc")} == case_ids
    assert not list((store / "histories").glob("*.partial"))
    for case_id in case_ids:
        with xr.open_dataset(store / "histories" / f"{case_id}.nc") as ds:
            assert ds.attrs["case_id"] == case_id
            assert set(HISTORY_UNITS) - {"time"} <= set(ds.data_vars)
            for name, unit in HISTORY_UNITS.items():
                assert ds[name].attrs["units"] == unit
            t = ds["time"].values
            assert t[0] == 0.0 and t[-1] == pytest.approx(DURATION_S)
            np.testing.assert_allclose(np.diff(t), HISTORY_DT_S, rtol=1e-9)
            assert ds["tau_cmd"].dims == ("time", "axis") and ds["jk"].dims == ("time", "axis")
            assert np.isfinite(ds["pointing_error_deg"].values).all()
            assert (ds["tip_displacement_max"].values >= 0.0).all()


def test_histories_stay_out_of_the_table(store):
    table = pd.read_parquet(store / "results.parquet")
    assert not [c for c in table.columns if "history" in c]
    rows = CampaignStore(store).rows()
    assert all("history" not in row for row in rows)


def test_history_matches_the_full_record(store):
    from flexsat.campaigns import replay_case

    full = replay_case(store, "nominal").dataset
    with xr.open_dataset(store / "histories" / "nominal.nc") as ds:
        at = full.sel(time=ds["time"].values, method="nearest")
        np.testing.assert_allclose(ds["pointing_error_deg"], at["pointing_error_deg"])
        np.testing.assert_allclose(ds["tau_cmd"], at["tau_cmd"])
        tips = np.linalg.norm(at["tip_displacement"].values, axis=-1).max(axis=1)
        np.testing.assert_allclose(ds["tip_displacement_max"], tips)


def test_campaign_figures_are_pngs(store, tmp_path):
    written = write_campaign_figures(store, tmp_path / "figs")
    assert len(written) == len(CAMPAIGN_FIGURES) == 7
    assert [p.stem for p in written] == list(CAMPAIGN_FIGURES)
    for path in written:
        assert path.parent == tmp_path / "figs"
        assert path.read_bytes()[:8] == PNG_MAGIC
        assert path.stat().st_size > 10_000
    assert len(plot_envelopes(store)) == 6


def test_default_figure_folder_is_in_the_store(store):
    written = write_campaign_figures(store)
    assert all(p.parent == store / "figures" for p in written)
    assert all(p.read_bytes()[:8] == PNG_MAGIC for p in written)


@pytest.mark.parametrize(
    ("name", "axis"),
    [("pointing_error_deg", None), ("rate_error_deg_s", None), ("tau_cmd", 0), ("tau_cmd", 2),
     ("tip_displacement_max", None), ("total_energy", None), ("lambda_act", None), ("jk", 1)],
)  # fmt: skip
def test_envelope_contains_the_nominal_line(store, name, axis):
    histories = CampaignStore(store).histories()
    nominal_ds = histories["nominal"]
    t = nominal_ds["time"].values
    line = nominal_ds[name].values if axis is None else nominal_ds[name].values[:, axis]
    lo, hi = campaign_envelope(histories, name, t, axis)
    assert np.isfinite(lo).all() and np.isfinite(hi).all()
    assert (lo <= line).all() and (line <= hi).all()
    if name != "lambda_act":  # Λ_act has not adapted yet within 5 s
        assert (lo < hi).any()  # the cases do differ


def test_envelope_percentiles_lie_inside_the_min_max_band(store):
    from flexsat.plots.campaign import campaign_percentiles

    histories = CampaignStore(store).histories()
    t = np.asarray(next(iter(histories.values()))["time"].values)
    lo, hi = campaign_envelope(histories, "pointing_error_deg", t)
    p5, p50, p95 = campaign_percentiles(histories, "pointing_error_deg", t)
    assert np.all(lo <= p5) and np.all(p5 <= p50) and np.all(p50 <= p95) and np.all(p95 <= hi)


def test_statistics_figures_are_written(store, tmp_path):
    from flexsat.plots.campaign_statistics import STATISTICS_FIGURES, write_statistics_figures

    paths = write_statistics_figures(store, tmp_path)
    assert [p.stem for p in paths] == list(STATISTICS_FIGURES)
    for path in paths:
        assert path.read_bytes()[:8] == PNG_MAGIC


def test_tornado_has_one_bar_per_parameter_at_its_rank_correlation(tmp_path):
    # 16 random cases of 2 s: a scaled target frequency is stored as its factor and its
    # value in Hz, which rank alike: one bar, the physical value. Each bar is scipy's
    # Spearman correlation of that column with the metric over the cases that have
    # both (the same computation, by another path: equal to 1e-12).
    from scipy.stats import spearmanr

    from flexsat.campaigns.statistics import parameter_table
    from flexsat.plots.campaign_statistics import plot_tornado

    store = tmp_path / "random"
    run_campaign(_short("montecarlo-random", 2.0), nominal(), store, n_random=15, workers=1,
                 progress=False)  # fmt: skip
    ax = plot_tornado(store).axes[0]
    labels = [tick.get_text() for tick in ax.get_yticklabels()]
    stems = [label.rsplit(" [", 1)[0] for label in labels]
    assert labels and len(stems) == len(set(stems))
    assert any(label.endswith(" [Hz]") for label in labels)
    table = CampaignStore(store).table().set_index("case_id")
    metric = table["metrics.final_pointing_error_deg"].astype(float)
    parameters = parameter_table(CampaignStore(store).rows()).set_index("case_id")
    for label, bar in zip(labels, ax.patches, strict=True):
        x = pd.to_numeric(parameters[label], errors="coerce").reindex(metric.index)
        keep = x.notna() & metric.notna()
        expected = spearmanr(x[keep], metric[keep]).statistic
        assert bar.get_width() == pytest.approx(expected, abs=1e-12)
