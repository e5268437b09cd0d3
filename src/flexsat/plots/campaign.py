"""Campaign figures: envelopes of every case's time history and a summary table.

Each envelope figure draws the min–max band and the 5–95 % band of all successful
cases of a campaign (from the decimated histories in ``histories/<id>.nc``, see
:class:`flexsat.campaigns.store.CampaignStore`) with the nominal case's line over
it, in the style of the thesis's robustness figures: pointing error and residual
rate on log axes with the R1 and R2 bands, commanded torque per axis with the
saturation limits ±RF·T_max, tip displacement, total energy, Λ_act and JK.
The summary table gives the pass rates R1/R2/R3 and the five worst cases with
their parameters.
"""

from __future__ import annotations

import json
import warnings
from pathlib import Path

import numpy as np
import xarray as xr
from matplotlib.figure import Figure

from flexsat.campaigns.runner import summarize
from flexsat.campaigns.statistics import PERCENTILES, percentile_envelope
from flexsat.campaigns.store import CampaignStore
from flexsat.plots import style

__all__ = [
    "CAMPAIGN_FIGURES",
    "campaign_envelope",
    "campaign_percentiles",
    "plot_envelope_energy",
    "plot_envelope_gains",
    "plot_envelope_pointing",
    "plot_envelope_rate",
    "plot_envelope_tip",
    "plot_envelope_torque",
    "plot_envelopes",
    "plot_summary_table",
    "write_campaign_figures",
]

_NOMINAL = "nominal"
_ENVELOPE_ALPHA = 0.25


class _Campaign:
    """What the figures need from a store: ok histories, the nominal id, the limits."""

    def __init__(self, store_dir: str | Path) -> None:
        store = CampaignStore(store_dir)
        self.root = store.root
        self.rows = {row["case_id"]: row for row in store.rows()}
        ok = {cid for cid, row in self.rows.items() if row["status"] == "ok"}
        self.histories = {cid: ds for cid, ds in store.histories().items() if cid in ok}
        if not self.histories:
            raise ValueError(f"{store.root} holds no successful case history to plot")
        marker = store.root / "campaign.json"
        self.name = json.loads(marker.read_text())["name"] if marker.exists() else store.root.name
        self.nominal = _NOMINAL if _NOMINAL in self.histories else sorted(self.histories)[0]
        scenario = self.rows[self.nominal].get("inputs", {}).get("scenario", {})
        requirements = scenario.get("requirements", {})
        actuator = scenario.get("actuator", {})
        self.pointing_deg = float(requirements.get("pointing_deg", 0.05))
        self.jitter_deg_s = float(requirements.get("jitter_deg_s", 1e-3))
        self.torque_limit = float(actuator.get("reduction_factor", 0.95)) * float(
            actuator.get("t_max_nm", 2.0)
        )

    @property
    def time(self) -> np.ndarray:
        return np.asarray(self.histories[self.nominal]["time"].values, dtype=float)

    def title(self, fig: Figure, what: str) -> None:
        fig.suptitle(
            f"{what}\ncampaign {style.literal(repr(self.name))}: {len(self.histories)} "
            f"successful cases (bands: min–max and 5–95 %), line: case "
            f"{style.literal(repr(self.nominal))}",
            fontsize=11,
        )


def _load(store_dir) -> _Campaign:
    return store_dir if isinstance(store_dir, _Campaign) else _Campaign(store_dir)


def _stack(histories: dict[str, xr.Dataset], name: str, t: np.ndarray, axis: int | None
           ) -> np.ndarray | None:  # fmt: skip
    """Every case's variable interpolated onto ``t``, (cases, len(t)), NaN outside each
    case's own time span; None when no case has it."""
    columns = []
    for ds in histories.values():
        if name not in ds:
            continue
        values = np.asarray(ds[name].values, dtype=float)
        if axis is not None:
            values = values[:, axis]
        own = np.asarray(ds["time"].values, dtype=float)
        if own.size == 0:
            continue
        column = np.interp(t, own, values)
        column[(t < own[0] - 1e-9) | (t > own[-1] + 1e-9)] = np.nan
        columns.append(column)
    return np.vstack(columns) if columns else None


def campaign_envelope(
    histories: dict[str, xr.Dataset], name: str, t: np.ndarray, axis: int | None = None
) -> tuple[np.ndarray, np.ndarray]:
    """(min, max) over the cases of one history variable on the times ``t``.

    Each case is interpolated linearly onto ``t`` (a no-op for cases sharing its
    times); a case contributes nothing outside its own time span. Times no case
    covers come back NaN.

    Parameters
    ----------
    histories : dict of str to xarray.Dataset
        Each case's stored history, by case id.
    name : str
        The history variable.
    t : ndarray, shape (n,)
        The common times [s].
    axis : int, optional
        The component of a per-axis variable.

    Returns
    -------
    low, high : ndarray, shape (n,)
        The envelope [the variable's unit].
    """
    stack = _stack(histories, name, t, axis)
    if stack is None:
        nan = np.full(t.shape, np.nan)
        return nan, nan
    finite = np.isfinite(stack)
    covered = finite.any(axis=0)
    lo = np.where(finite, stack, np.inf).min(axis=0)
    hi = np.where(finite, stack, -np.inf).max(axis=0)
    return np.where(covered, lo, np.nan), np.where(covered, hi, np.nan)


def campaign_percentiles(
    histories: dict[str, xr.Dataset], name: str, t: np.ndarray, axis: int | None = None,
    percentiles: tuple[float, ...] = PERCENTILES,
) -> np.ndarray:  # fmt: skip
    """Percentiles over the cases (5/50/95 % by default) on the times ``t``,
    shape (len(percentiles), len(t)); interpolated as :func:`campaign_envelope`.

    Parameters
    ----------
    histories : dict of str to xarray.Dataset
        Each case's stored history, by case id.
    name : str
        The history variable.
    t : ndarray, shape (n,)
        The common times [s].
    axis : int, optional
        The component of a per-axis variable.
    percentiles : tuple of float
        The percentiles, in [0, 100] [%].

    Returns
    -------
    ndarray, shape (len(percentiles), n)
        The percentile curves [the variable's unit].
    """
    stack = _stack(histories, name, t, axis)
    if stack is None:
        return np.full((len(percentiles), t.size), np.nan)
    with warnings.catch_warnings():  # a time no case covers is NaN, as documented
        warnings.simplefilter("ignore", RuntimeWarning)
        return percentile_envelope(stack, percentiles)


def _nominal(campaign: _Campaign, name: str, axis: int | None = None) -> np.ndarray:
    ds = campaign.histories[campaign.nominal]
    if name not in ds:
        return np.full(campaign.time.shape, np.nan)
    values = np.asarray(ds[name].values, dtype=float)
    return values[:, axis] if axis is not None else values


def _band_and_line(
    ax,
    campaign: _Campaign,
    name: str,
    *,
    axis: int | None = None,
    scale: float = 1.0,
    colour: str = "black",
    log: bool = False,
) -> None:
    t = campaign.time
    lo, hi = campaign_envelope(campaign.histories, name, t, axis)
    line = _nominal(campaign, name, axis)
    lo, hi, line = scale * lo, scale * hi, scale * line
    if log:
        lo, hi, line = style.positive(lo), style.positive(hi), style.positive(line)
    ax.fill_between(
        t, lo, hi, color=colour, alpha=_ENVELOPE_ALPHA, linewidth=0, label="all cases (min–max)"
    )
    p5, _, p95 = scale * campaign_percentiles(campaign.histories, name, t, axis)
    if log:
        p5, p95 = style.positive(p5), style.positive(p95)
    ax.fill_between(t, p5, p95, color=colour, alpha=2 * _ENVELOPE_ALPHA, linewidth=0,
                    label="5–95 % of the cases")  # fmt: skip
    ax.plot(t, line, color=colour, linewidth=1.1, label=style.literal(campaign.nominal))
    if log:
        ax.set_yscale("log")


def _requirement(ax, bound: float, tag: str, unit: str) -> None:
    ax.axhspan(
        ax.get_ylim()[0],
        bound,
        color=style.BAND,
        alpha=0.15,
        linewidth=0,
        label=f"{tag} band: < {bound:.3g} {unit}",
    )
    ax.axhline(bound, color=style.BAND, linewidth=1.4, label=f"{tag}: {bound:.3g} {unit}")


def _log_panel(
    campaign: _Campaign,
    name: str,
    bound: float,
    tag: str,
    unit: str,
    ylabel: str,
    what: str,
    colour: str,
) -> Figure:
    fig, axes = style.figure(1, 1, size=(11.0, 5.5))
    ax = axes[0, 0]
    _band_and_line(ax, campaign, name, colour=colour, log=True)
    bottom, top = ax.get_ylim()
    ax.set_ylim(min(bottom, bound / 3.0), max(top, bound * 3.0))
    _requirement(ax, bound, tag, unit)
    ax.set_ylabel(ylabel)
    ax.legend(loc="upper right", fontsize=8)
    style.finish_time_axis(axes, campaign.time)
    campaign.title(fig, what)
    return fig


def plot_envelope_pointing(store_dir: str | Path) -> Figure:
    """Pointing error [deg] of every case (log) with the R1 band.

    Parameters
    ----------
    store_dir : str or Path
        The campaign's store folder.

    Returns
    -------
    Figure
        The figure.
    """
    c = _load(store_dir)
    return _log_panel(
        c,
        "pointing_error_deg",
        c.pointing_deg,
        "R1",
        "deg",
        "pointing error [deg] (log)",
        "Pointing error envelope (R1)",
        "black",
    )


def plot_envelope_rate(store_dir: str | Path) -> Figure:
    """Residual rate ‖ω − ω_d‖ [deg/s] of every case (log) with the R2 band.

    Parameters
    ----------
    store_dir : str or Path
        The campaign's store folder.

    Returns
    -------
    Figure
        The figure.
    """
    c = _load(store_dir)
    return _log_panel(
        c,
        "rate_error_deg_s",
        c.jitter_deg_s,
        "R2",
        "deg/s",
        "residual rate [deg/s] (log)",
        "Residual rate envelope (R2)",
        "tab:blue",
    )


def plot_envelope_torque(store_dir: str | Path) -> Figure:
    """Commanded torque per axis [N m] of every case with the limits ±RF·T_max.

    Parameters
    ----------
    store_dir : str or Path
        The campaign's store folder.

    Returns
    -------
    Figure
        The figure.
    """
    c = _load(store_dir)
    fig, axes = style.figure(3, 1, size=(11.0, 8.5))
    for k in range(3):
        ax = axes[k, 0]
        _band_and_line(ax, c, "tau_cmd", axis=k, colour=style.AXIS_COLOURS[k])
        for sign in (1.0, -1.0):
            ax.axhline(
                sign * c.torque_limit,
                color="0.3",
                linestyle="--",
                linewidth=1.0,
                label=f"±RF·T_max = ±{c.torque_limit:.3g} N m" if sign > 0 else None,
            )
        ax.set_ylim(-1.15 * c.torque_limit, 1.15 * c.torque_limit)
        ax.set_ylabel(f"τ_cmd,{style.AXES[k]} [N m]")
        ax.legend(loc="upper right", fontsize=8)
    style.finish_time_axis(axes, c.time)
    c.title(fig, "Commanded torque envelope per axis")
    return fig


def _single(c: _Campaign, name: str, scale: float, ylabel: str, what: str, colour: str) -> Figure:
    fig, axes = style.figure(1, 1, size=(11.0, 5.5))
    _band_and_line(axes[0, 0], c, name, scale=scale, colour=colour)
    axes[0, 0].set_ylabel(ylabel)
    axes[0, 0].legend(loc="upper right", fontsize=8)
    style.finish_time_axis(axes, c.time)
    c.title(fig, what)
    return fig


def plot_envelope_tip(store_dir: str | Path) -> Figure:
    """Largest panel tip displacement magnitude [mm] of every case.

    Parameters
    ----------
    store_dir : str or Path
        The campaign's store folder.

    Returns
    -------
    Figure
        The figure.
    """
    return _single(
        _load(store_dir),
        "tip_displacement_max",
        1e3,
        "max tip displacement |δ| [mm]",
        "Tip displacement envelope",
        "tab:purple",
    )


def plot_envelope_energy(store_dir: str | Path) -> Figure:
    """Total energy T + U [J] of every case.

    Parameters
    ----------
    store_dir : str or Path
        The campaign's store folder.

    Returns
    -------
    Figure
        The figure.
    """
    return _single(
        _load(store_dir),
        "total_energy",
        1.0,
        "total energy [J]",
        "Total energy envelope",
        "tab:orange",
    )


def plot_envelope_gains(store_dir: str | Path) -> Figure:
    """Adaptive gains of every case: Λ_act [rad/s] and JK per axis [N m].

    Parameters
    ----------
    store_dir : str or Path
        The campaign's store folder.

    Returns
    -------
    Figure
        The figure.
    """
    c = _load(store_dir)
    fig, axes = style.figure(4, 1, size=(11.0, 10.0))
    _band_and_line(axes[0, 0], c, "lambda_act", colour="black")
    axes[0, 0].set_ylabel("Λ_act [rad/s]")
    for k in range(3):
        _band_and_line(axes[k + 1, 0], c, "jk", axis=k, colour=style.AXIS_COLOURS[k])
        axes[k + 1, 0].set_ylabel(f"JK_{style.AXES[k]} [N m]")
    for ax in axes[:, 0]:
        ax.legend(loc="upper right", fontsize=8)
    style.finish_time_axis(axes, c.time)
    c.title(fig, "Adaptive gain envelopes: Λ_act and JK")
    return fig


_ENVELOPES = {
    "envelope_pointing": plot_envelope_pointing,
    "envelope_rate": plot_envelope_rate,
    "envelope_torque": plot_envelope_torque,
    "envelope_tip_displacement": plot_envelope_tip,
    "envelope_energy": plot_envelope_energy,
    "envelope_gains": plot_envelope_gains,
}


def plot_envelopes(store_dir: str | Path) -> list[Figure]:
    """Every envelope figure of a stored campaign, in the order of :data:`CAMPAIGN_FIGURES`.

    Parameters
    ----------
    store_dir : str or Path
        The campaign's store folder.

    Returns
    -------
    list of Figure
        The figures.
    """
    campaign = _load(store_dir)
    return [make(campaign) for make in _ENVELOPES.values()]


def _parameters(row: dict) -> str:
    parameters = row.get("parameters") or {}
    if not parameters:
        return "(nominal)"
    text = ", ".join(
        f"{key} = {value:.4g}" if isinstance(value, float) else f"{key} = {value}"
        for key, value in parameters.items()
    )
    return text if len(text) <= 90 else text[:87] + "..."


def plot_summary_table(store_dir: str | Path) -> Figure:
    """Pass rates R1/R2/R3 and the five worst cases (final pointing error) with parameters.

    A pass rate is over the judged cases; R1 and R2 of a case whose run ends before
    its observation window read "not judged" (counted beside the rate, or in its
    place when no case is judged).

    Parameters
    ----------
    store_dir : str or Path
        The campaign's store folder.

    Returns
    -------
    Figure
        The figure.
    """
    store = CampaignStore(store_dir)
    summary = summarize(store.root)
    rows = {row["case_id"]: row for row in store.rows()}
    fig = Figure(figsize=(12.0, 5.5), layout="constrained")
    top, bottom = fig.subplots(2, 1, gridspec_kw={"height_ratios": [1, 1.6]})
    for ax in (top, bottom):
        ax.set_axis_off()

    def percent(requirement: str) -> str:
        value = summary[f"{requirement}_pass_rate"]
        unjudged = summary.get(f"{requirement}_not_judged", 0)
        if value is None or value != value:  # no case judged (None), or none stored
            return "not judged" if unjudged else "—"
        text = f"{100.0 * value:.1f} %"
        return f"{text} ({unjudged} not judged)" if unjudged else text

    rates = [
        [
            str(summary["cases"]),
            str(summary["failed"]),
            percent("r1"),
            percent("r2"),
            percent("r3"),
        ]
    ]
    table = top.table(
        cellText=rates,
        colLabels=["cases", "failed", "R1 pass", "R2 pass", "R3 pass"],
        loc="center",
        cellLoc="center",
    )
    table.scale(1.0, 1.6)
    top.set_title("Pass rates", fontsize=10)
    worst = [
        [
            style.literal(w["case_id"]),
            f"{w['final_pointing_error_deg']:.4g}",
            style.literal(_parameters(rows.get(w["case_id"], {}))),
        ]
        for w in summary["worst_cases"]
    ]
    if worst:
        table = bottom.table(
            cellText=worst,
            colLabels=["case", "final pointing error [deg]", "parameters"],
            loc="upper center",
            cellLoc="left",
            colWidths=[0.15, 0.18, 0.67],
        )
        table.auto_set_font_size(False)
        table.set_fontsize(8)
        table.scale(1.0, 1.5)
    else:
        bottom.text(0.5, 0.5, "no successful case", ha="center", va="center")
    bottom.set_title("Five worst cases (largest final pointing error)", fontsize=10)
    marker = store.root / "campaign.json"
    name = json.loads(marker.read_text())["name"] if marker.exists() else store.root.name
    fig.suptitle(f"Campaign {style.literal(repr(name))}: summary", fontsize=11)
    return fig


CAMPAIGN_FIGURES = (*_ENVELOPES, "summary_table")
"""Names (without ``.png``) of the files :func:`write_campaign_figures` writes, in order."""


def write_campaign_figures(
    store_dir: str | Path, out_dir: str | Path | None = None, *, dpi: int = 120
) -> list[Path]:
    """Write every campaign figure as PNG (default folder ``<store_dir>/figures``).

    Files, in the order of :data:`CAMPAIGN_FIGURES`: ``envelope_pointing.png``,
    ``envelope_rate.png``, ``envelope_torque.png``, ``envelope_tip_displacement.png``,
    ``envelope_energy.png``, ``envelope_gains.png`` and ``summary_table.png``.

    Parameters
    ----------
    store_dir : str or Path
        The campaign's store folder.
    out_dir : str or Path, optional
        Where the files go; created if missing.
    dpi : int
        Resolution [dots per inch].

    Returns
    -------
    list of Path
        The files written.
    """
    out = Path(out_dir) if out_dir is not None else Path(store_dir) / "figures"
    campaign = _Campaign(store_dir)
    makers = {**_ENVELOPES, "summary_table": lambda _: plot_summary_table(store_dir)}
    return style.write_figures(out, CAMPAIGN_FIGURES, lambda name: makers[name](campaign), dpi=dpi)
