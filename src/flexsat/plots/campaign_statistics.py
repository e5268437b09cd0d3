"""Campaign statistics figures: distributions of every metric, parameters against a
metric, and the tornado chart of rank correlations.

Drawn from a store's table (:meth:`flexsat.campaigns.store.CampaignStore.table`) with
the statistics of :mod:`flexsat.campaigns.statistics`.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pandas as pd
from matplotlib.figure import Figure

from flexsat.campaigns.statistics import (
    PERCENTILES,
    metric_columns,
    parameter_table,
    rank_correlations,
)
from flexsat.campaigns.store import CampaignStore
from flexsat.plots import style

__all__ = [
    "STATISTICS_FIGURES",
    "plot_metric_cdfs",
    "plot_metric_histograms",
    "plot_parameter_scatter",
    "plot_tornado",
    "write_statistics_figures",
]

DEFAULT_METRIC = "final_pointing_error_deg"


def _grid(n: int, size=(12.0, 8.0)) -> tuple[Figure, list]:
    cols = min(4, max(1, n))
    rows = max(1, math.ceil(n / cols))
    fig = Figure(figsize=size, layout="constrained")
    axes = np.atleast_1d(fig.subplots(rows, cols, squeeze=False)).ravel().tolist()
    for ax in axes[n:]:
        ax.set_axis_off()
    return fig, axes[:n]


def _metrics(store: CampaignStore) -> pd.DataFrame:
    table = store.table()
    ok = table[table["status"] == "ok"].set_index("case_id")
    return ok[metric_columns(table)].apply(pd.to_numeric, errors="coerce")


def _label(column: str) -> str:
    return style.literal(column.removeprefix("metrics."))


def plot_metric_histograms(store_dir: str | Path) -> Figure:
    """A histogram of every numeric metric over the cases that ran, with its 5/50/95 %.

    Parameters
    ----------
    store_dir : str or Path
        The campaign's store folder.

    Returns
    -------
    Figure
        The figure.
    """
    metrics = _metrics(CampaignStore(store_dir))
    fig, axes = _grid(len(metrics.columns))
    for ax, column in zip(axes, metrics.columns, strict=True):
        values = metrics[column].dropna().to_numpy()
        ax.hist(values, bins=min(30, max(5, values.size // 3)), color=style.BAND, alpha=0.7)
        for q, value in zip(PERCENTILES, np.percentile(values, PERCENTILES) if values.size
                            else [], strict=False):  # fmt: skip
            ax.axvline(value, color="black", linewidth=0.8, linestyle=":" if q != 50 else "-")
        ax.set_title(_label(column), fontsize=8)
        ax.tick_params(labelsize=7)
    fig.suptitle("Metric histograms (lines: 5, 50, 95 %)", fontsize=11)
    return fig


def plot_metric_cdfs(store_dir: str | Path) -> Figure:
    """The empirical CDF of every numeric metric over the cases that ran.

    Parameters
    ----------
    store_dir : str or Path
        The campaign's store folder.

    Returns
    -------
    Figure
        The figure.
    """
    metrics = _metrics(CampaignStore(store_dir))
    fig, axes = _grid(len(metrics.columns))
    for ax, column in zip(axes, metrics.columns, strict=True):
        values = np.sort(metrics[column].dropna().to_numpy())
        if values.size:
            ax.step(values, np.arange(1, values.size + 1) / values.size, where="post",
                    color="black", linewidth=1.0)  # fmt: skip
        ax.set_ylim(0.0, 1.0)
        ax.set_title(_label(column), fontsize=8)
        ax.tick_params(labelsize=7)
    fig.suptitle("Empirical CDFs of the metrics", fontsize=11)
    return fig


def _parameters(store: CampaignStore) -> pd.DataFrame:
    """The dispersed parameters by case: physical values, and the scale factor only of
    a parameter without one (a factor and its value rank the same: one column each)."""
    table = parameter_table(store.rows()).set_index("case_id")
    numeric = table.apply(pd.to_numeric, errors="coerce")
    numeric = numeric.loc[:, numeric.nunique() > 1]
    physical = {c.rsplit(" [", 1)[0] for c in numeric.columns if not c.endswith(" [factor]")}
    return numeric[
        [
            c
            for c in numeric.columns
            if not c.endswith(" [factor]") or c.removesuffix(" [factor]") not in physical
        ]
    ]


def plot_parameter_scatter(store_dir: str | Path, metric: str = DEFAULT_METRIC) -> Figure:
    """``metric`` against every dispersed parameter (physical values where known).

    Parameters
    ----------
    store_dir : str or Path
        The campaign's store folder.
    metric : str
        The case metric (a column of the store's table without ``metrics.``).

    Returns
    -------
    Figure
        The figure.
    """
    store = CampaignStore(store_dir)
    parameters, metrics = _parameters(store), _metrics(store)
    column = f"metrics.{metric}"
    shown = list(parameters.columns)
    fig, axes = _grid(max(1, len(shown)))
    y = metrics[column] if column in metrics else pd.Series(dtype=float)
    for ax, p in zip(axes, shown, strict=False):
        x = parameters[p].reindex(y.index)
        ax.scatter(x, y, s=8, color="black", alpha=0.6)
        ax.set_xlabel(style.literal(p), fontsize=7)
        ax.tick_params(labelsize=7)
    if not shown:
        axes[0].text(0.5, 0.5, "no dispersed parameter", ha="center", va="center")
    fig.suptitle(f"{metric} against the dispersed parameters", fontsize=11)
    return fig


def plot_tornado(store_dir: str | Path, metric: str = DEFAULT_METRIC) -> Figure:
    """Tornado chart: Spearman rank correlation of ``metric`` with each parameter (its
    physical value where known), sorted by magnitude.

    Parameters
    ----------
    store_dir : str or Path
        The campaign's store folder.
    metric : str
        The case metric (a column of the store's table without ``metrics.``).

    Returns
    -------
    Figure
        The figure.
    """
    store = CampaignStore(store_dir)
    column = f"metrics.{metric}"
    metrics = _metrics(store)
    parameters = _parameters(store).reindex(metrics.index)
    rho = rank_correlations(parameters, metrics[[column]] if column in metrics
                            else pd.DataFrame(index=metrics.index))  # fmt: skip
    fig = Figure(figsize=(10.0, 6.0), layout="constrained")
    ax = fig.subplots()
    if column in rho:
        bars = rho[column].dropna()
        bars = bars.reindex(bars.abs().sort_values().index)
        ax.barh(range(bars.size), bars.to_numpy(), color=["tab:red" if v > 0 else "tab:blue"
                                                           for v in bars])  # fmt: skip
        ax.set_yticks(range(bars.size), [style.literal(p) for p in bars.index], fontsize=7)
    ax.axvline(0.0, color="black", linewidth=0.8)
    ax.set_xlim(-1.0, 1.0)
    ax.set_xlabel("Spearman rank correlation [-]")
    fig.suptitle(f"Tornado: what drives {metric}", fontsize=11)
    return fig


STATISTICS_FIGURES = ("metric_histograms", "metric_cdfs", "parameter_scatter", "tornado")
"""Names (without ``.png``) of the files :func:`write_statistics_figures` writes."""


def write_statistics_figures(
    store_dir: str | Path, out_dir: str | Path | None = None, *, metric: str = DEFAULT_METRIC,
    dpi: int = 120,
) -> list[Path]:  # fmt: skip
    """Write the statistics figures as PNG (default folder ``<store_dir>/figures``).

    Parameters
    ----------
    store_dir : str or Path
        The campaign's store folder.
    out_dir : str or Path, optional
        Where the files go; created if missing.
    metric : str
        The case metric (a column of the store's table without ``metrics.``).
    dpi : int
        Resolution [dots per inch].

    Returns
    -------
    list of Path
        The files written.
    """
    out = Path(out_dir) if out_dir is not None else Path(store_dir) / "figures"
    makers = {
        "metric_histograms": lambda: plot_metric_histograms(store_dir),
        "metric_cdfs": lambda: plot_metric_cdfs(store_dir),
        "parameter_scatter": lambda: plot_parameter_scatter(store_dir, metric),
        "tornado": lambda: plot_tornado(store_dir, metric),
    }
    return style.write_figures(out, STATISTICS_FIGURES, lambda name: makers[name](), dpi=dpi)
