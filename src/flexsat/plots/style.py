"""The one plot style of flexsat: colours, figure layout, time axes, and writing figures.

Every figure module draws with these helpers, so the figure sets of an open-loop
run, a slew, a campaign and a comparison look alike. Figures are created directly
(:class:`matplotlib.figure.Figure`, no pyplot), so nothing here needs a display or
changes the global backend.

- :func:`figure`: a figure of fixed margins and its 2-D array of axes.
- :func:`figure_legend`: one legend below the axes, the margin grown to hold it;
  :func:`axes_legend`, the same of every distinct label the axes carry.
- :func:`time_s`: the time coordinate of a result dataset [s].
- :func:`literal`: a user's text (names, labels, messages) drawn as written, never as mathtext.
- :func:`suptitle`: the figure title, the run's title below it and a failure notice.
- :func:`line`, :func:`envelope`: a time series, thinned to a min/max envelope when long.
- :func:`finish_time_axis`: grid, time limits and the time label of the bottom row.
- :func:`positive`: values masked to the positive ones, for a log axis.
- :func:`save_figure`, :func:`write_figures`: PNG files, one helper for every writer
  (a set is drawn by :func:`figure_workers` forked processes, :func:`forked_map`,
  both from :mod:`flexsat.parallel`).
"""

from __future__ import annotations

from collections.abc import Callable, Iterable
from functools import lru_cache
from pathlib import Path

import numpy as np
import xarray as xr
from matplotlib.axes import Axes
from matplotlib.figure import Figure
from matplotlib.ticker import LogLocator

from flexsat.files import ensure_dir, replacing
from flexsat.parallel import figure_workers, forked_map

__all__ = [
    "AXES",
    "AXIS_COLOURS",
    "BAND",
    "EULER",
    "MAX_LINE_POINTS",
    "axes_legend",
    "envelope",
    "figure",
    "figure_legend",
    "figure_workers",
    "finish_time_axis",
    "forked_map",
    "line",
    "literal",
    "positive",
    "save_figure",
    "suptitle",
    "time_s",
    "write_figures",
]

AXES = ("x", "y", "z")
"""Body-axis names, in component order."""
AXIS_COLOURS = ("tab:red", "tab:green", "tab:blue")
"""One colour per body axis x, y, z."""
EULER = (("roll", "φ"), ("pitch", "θ"), ("yaw", "ψ"))
"""Name and thesis symbol of each ZYX Euler angle, in component order."""
BAND = "tab:green"
"""Colour of requirement bands and settling markers."""
MAX_LINE_POINTS = 3000
"""Longer records are drawn as a min/max envelope of about this many points: the axes
of a figure at most 14 in wide at 120 dpi span under 1500 pixel columns, and the
envelope keeps a minimum and a maximum per 1/1500 of the record, so nothing a column
can show is lost."""


MARGINS_IN = {"left": 0.95, "right": 0.3, "top": 0.95, "bottom": 0.6}
"""Fixed figure margins [in]: the y tick labels and label at the left, the two-line
title and an axes title at the top, the x tick labels and label at the bottom. Fixed
margins replace matplotlib's constrained layout, which measured every tick label
twice per figure before rendering (about half of drawing a figure with log axes)."""
GAPS_IN = {"wspace": 1.0, "hspace": 0.45, "hspace_labelled": 0.95}
"""Gaps between axes [in]: between columns (the right column's y labels), between rows
of shared x axes (an axes title) and of own x axes (tick labels, label and title)."""
LEGEND_ROW_IN = 0.3
"""Height of one row of a figure legend at 9 pt, with its frame and padding [in]."""


@lru_cache(maxsize=64)
def _margins(size: tuple[float, float], nrows: int, ncols: int, sharex: bool) -> dict:
    """``subplots_adjust`` fractions of fixed inch margins, computed once per figure size."""
    width, height = size
    m = MARGINS_IN
    hgap = GAPS_IN["hspace" if sharex else "hspace_labelled"]
    cell_w = (width - m["left"] - m["right"] - (ncols - 1) * GAPS_IN["wspace"]) / ncols
    cell_h = (height - m["top"] - m["bottom"] - (nrows - 1) * hgap) / nrows
    return {"left": m["left"] / width, "right": 1.0 - m["right"] / width,
            "bottom": m["bottom"] / height, "top": 1.0 - m["top"] / height,
            "wspace": GAPS_IN["wspace"] / cell_w, "hspace": hgap / cell_h}  # fmt: skip


def figure(nrows: int, ncols: int = 1, *, size=(11.0, 7.5), sharex=True, **grid) -> tuple:
    """A figure of ``size`` inches with fixed margins and its axes, shape (nrows, ncols).

    The margins (:data:`MARGINS_IN`, :data:`GAPS_IN`) are fixed in inches, so the
    layout costs nothing at drawing time; a figure legend below the axes is added with
    :func:`figure_legend`, which grows the bottom margin.

    Parameters
    ----------
    nrows, ncols : int
        The grid of axes.
    size : tuple of 2 float
        Width and height [in].
    sharex : bool
        The axes share their x axis (inner rows without x tick labels).
    **grid
        Keywords of the grid (``height_ratios=...``).

    Returns
    -------
    fig : Figure
        The figure.
    axes : grid of Axes, shape (nrows, ncols)
        Its axes.
    """
    size = (float(size[0]), float(size[1]))
    fig = Figure(figsize=size)
    kw = {**_margins(size, nrows, ncols, bool(sharex)), **grid}
    axes = fig.subplots(nrows, ncols, sharex=sharex, squeeze=False, gridspec_kw=kw)
    return fig, axes


def figure_legend(fig: Figure, handles: list, labels: list[str], ncols: int) -> None:
    """One legend centred below the axes of a :func:`figure`, its bottom margin grown.

    Call it before a colorbar taken from several axes (the axes are moved up).

    Parameters
    ----------
    fig : Figure
        A figure from :func:`figure`.
    handles : list of Artist
        The legend's handles.
    labels : list of str
        Their labels.
    ncols : int
        Legend columns.
    """
    rows = -(-len(labels) // ncols)
    height = fig.get_figheight()
    fig.legend(handles, labels, loc="lower center", ncols=ncols, fontsize=9,
               bbox_to_anchor=(0.5, 0.05 / height), frameon=True)  # fmt: skip
    grid = fig.axes[0].get_subplotspec().get_gridspec()
    grid.bottom += rows * LEGEND_ROW_IN / height  # GridSpec.update moves pyplot's axes only
    for ax in fig.axes:
        spec = ax.get_subplotspec()
        if spec is not None and spec.get_gridspec() is grid:
            ax.set_position(spec.get_position(fig))


def axes_legend(fig: Figure, axes, ncols: int | None = None) -> None:
    """:func:`figure_legend` of every distinct label of ``axes``, in the order drawn.

    Parameters
    ----------
    fig : Figure
        A figure from :func:`figure`.
    axes : grid of Axes
        The axes whose labelled artists the legend lists.
    ncols : int, optional
        Legend columns; default as many as labels, at most 6.
    """
    seen: dict[str, object] = {}
    for ax in np.ravel(axes):
        for handle, label in zip(*ax.get_legend_handles_labels(), strict=True):
            seen.setdefault(label, handle)
    if seen:
        figure_legend(fig, list(seen.values()), list(seen), ncols or min(len(seen), 6))


def time_s(ds: xr.Dataset) -> np.ndarray:
    """The time coordinate of a result dataset as float64 [s].

    Parameters
    ----------
    ds : xarray.Dataset
        A run's dataset.

    Returns
    -------
    ndarray, shape (m,)
        The record times [s].
    """
    return np.asarray(ds["time"].values, dtype=float)


def literal(text: object) -> str:
    """``text`` as matplotlib draws it literally: every ``$`` escaped, no mathtext.

    matplotlib parses a text holding an even number of unescaped ``$`` as mathtext,
    where a ``\\``, ``{``, ``}``, ``^`` or ``_`` is markup and an unknown command an
    error. Every string a user wrote (a scenario, appendage, satellite, campaign or
    case name, a law's or stage's label, a failure message) enters a figure through
    this function; with no unescaped ``$`` left, matplotlib draws the text as it is
    (each ``\\$`` shown as ``$``), and next to a figure's own mathtext the escaped
    signs stay literal too.

    Parameters
    ----------
    text : object
        The user's text (``str(text)`` is drawn).

    Returns
    -------
    str
        The text to hand to matplotlib.
    """
    return str(text).replace("$", r"\$")


def suptitle(fig: Figure, ds: xr.Dataset, what: str) -> None:
    """Title ``what``, the run's title below it, and the failure message of a failed run.

    Parameters
    ----------
    fig : Figure
        The figure.
    ds : xarray.Dataset
        The run drawn.
    what : str
        What the figure shows.
    """
    scenario = literal(ds.attrs.get("title", "flexsat open-loop run"))  # names the user's
    text = f"{what}\n{scenario}"
    if ds.attrs.get("status", "ok") != "ok":
        text += f"  —  FAILED: {literal(ds.attrs.get('message', ''))}"
    fig.suptitle(text, fontsize=11)


def envelope(t: np.ndarray, y: np.ndarray, max_points: int = MAX_LINE_POINTS) -> tuple:
    """(t, y) thinned to about ``max_points`` keeping each bucket's min and max.

    Unlike plain striding this keeps the peaks of an oscillation faster than the
    thinned sampling, so the drawn envelope is the true one.

    Parameters
    ----------
    t : ndarray, shape (m,)
        Times [s].
    y : ndarray, shape (m,) or (m, k)
        Values [any unit].
    max_points : int
        About the most points kept.

    Returns
    -------
    t, y : ndarray
        The thinned times [s] and values [unit of y].
    """
    n = t.size
    if n <= max_points:
        return t, y
    size = int(np.ceil(2 * n / max_points))
    m = n // size
    head = y[: m * size].reshape(m, size)
    base = np.arange(m) * size
    lo = base + np.argmin(head, axis=1)
    hi = base + np.argmax(head, axis=1)
    keep = np.concatenate([np.sort(np.stack([lo, hi], axis=1), axis=1).ravel(),
                           np.arange(m * size, n)])  # fmt: skip
    return t[keep], y[keep]


def line(ax: Axes, t: np.ndarray, y: np.ndarray, **kw):
    """Plot ``y`` against ``t`` on ``ax`` (through :func:`envelope`); returns the line.

    Parameters
    ----------
    ax : Axes
        The axes.
    t : ndarray, shape (m,)
        Times [s].
    y : ndarray, shape (m,)
        Values [any unit].
    **kw
        Keywords of ``Axes.plot``.

    Returns
    -------
    Line2D
        The line.
    """
    return ax.plot(*envelope(t, np.asarray(y, dtype=float)), **kw)[0]


def finish_time_axis(axes, t: np.ndarray) -> None:
    """Grid and time limits on every axis, the time label on the bottom row.

    Parameters
    ----------
    axes : grid of Axes
        The figure's axes, shape (nrows, ncols) or (nrows,).
    t : ndarray, shape (m,)
        The times drawn [s].
    """
    for ax in np.ravel(axes):
        ax.grid(True, color="0.85", linewidth=0.6)
        ax.set_xlim(t[0], t[-1])
    for ax in np.atleast_2d(axes)[-1]:
        ax.set_xlabel("time t [s]")


def positive(values: np.ndarray) -> np.ndarray:
    """Values with non-positive entries masked (NaN), for a log axis.

    Parameters
    ----------
    values : ndarray
        Values for a log axis [any unit].

    Returns
    -------
    ndarray
        A copy, non-positive entries NaN [unit of values].
    """
    values = np.asarray(values, dtype=float)
    return np.where(values > 0.0, values, np.nan)


def save_figure(fig: Figure, path: str | Path, *, dpi: int) -> Path:
    """Write ``fig`` to ``path`` (format from the suffix) and release its drawing.

    Parameters
    ----------
    fig : Figure
        The figure; it is cleared afterwards to free its memory.
    path : str or Path
        Target file; its folder is created if missing, an existing file (or a
        symbolic link) replaced (:func:`flexsat.files.replacing`).
    dpi : int
        Resolution [dots per inch].

    Returns
    -------
    Path
        The file written.
    """
    path = Path(path)
    fmt = path.suffix.lower().lstrip(".") or "png"
    # PNG at zlib level 1: a fraction of the default level's time for a slightly larger file
    extra = {"pil_kwargs": {"compress_level": 1}} if fmt == "png" else {}
    _log_ticks_in_view(fig)
    with replacing(path) as handle:  # a link at path is replaced, never followed
        fig.savefig(handle, format=fmt, dpi=dpi, **extra)
    _release(fig)
    return path


class _InViewLogLocator(LogLocator):
    """The ticks of a log axis's own locator that lie in the view, its edges included.

    A log locator returns whole decades beyond both ends of the view, up to two
    decades of minor ticks that are never drawn; matplotlib still builds a tick
    (three lines, two texts) for each. Dropping them before drawing leaves every
    drawn tick and the image unchanged.
    """

    def __init__(self, inner: LogLocator) -> None:
        super().__init__()
        self.inner = inner

    def set_axis(self, axis) -> None:
        super().set_axis(axis)
        self.inner.set_axis(axis)

    def tick_values(self, vmin: float, vmax: float) -> np.ndarray:
        locs = np.asarray(self.inner.tick_values(vmin, vmax))
        lo, hi = sorted((vmin, vmax))
        # a relative slack keeps the ticks matplotlib draws at the edges of the view
        return locs[(locs >= lo * (1.0 - 1e-6)) & (locs <= hi * (1.0 + 1e-6))]

    def nonsingular(self, vmin: float, vmax: float) -> tuple:
        return self.inner.nonsingular(vmin, vmax)

    def view_limits(self, vmin: float, vmax: float) -> tuple:
        return self.inner.view_limits(vmin, vmax)


def _log_ticks_in_view(fig: Figure) -> None:
    """Give every log axis of ``fig`` locators that return the ticks in view only."""
    for ax in fig.axes:
        for axis in (ax.xaxis, ax.yaxis):
            if axis.get_scale() != "log":
                continue
            # shared axes share their locators: wrap each once
            major, minor = axis.get_major_locator(), axis.get_minor_locator()
            if type(major) is LogLocator:
                axis.set_major_locator(_InViewLogLocator(major))
            if type(minor) is LogLocator:
                axis.set_minor_locator(_InViewLogLocator(minor))


def _release(fig: Figure) -> None:
    """Empty a written figure so its artists can be freed.

    ``Figure.clear`` alone clears each axes before removing it, which rebuilds its
    axis, ticks and spines (about 10 ms per figure of a set, for nothing); the axes
    are removed first instead, so the clear only drops the figure's own artists.
    """
    for ax in fig.axes:  # every axes, those of subfigures too
        ax.remove()
    fig.clear()


def write_figures(
    out_dir: str | Path,
    names: Iterable[str],
    draw: Callable[[str], Figure],
    *,
    dpi: int,
    workers: int | None = None,
) -> list[Path]:
    """Draw and write one PNG per name, ``<out_dir>/<name>.png``, in the order given.

    Figures are drawn one at a time per process (``draw(name)``) and released once
    written, so a long set never holds more than one figure per process in memory.

    Parameters
    ----------
    out_dir : str or Path
        Created if missing.
    names : iterable of str
        The figures' names.
    draw : callable
        ``draw(name) -> Figure``.
    dpi : int
        Resolution [dots per inch].
    workers : int, optional
        Drawing processes; default :func:`figure_workers`. With more than one, the
        figures are drawn by forked processes (``draw`` need not be picklable).

    Returns
    -------
    list of Path
        The files written, in the order of ``names``.
    """
    out = ensure_dir(out_dir)
    return forked_map(lambda name: save_figure(draw(name), out / f"{name}.png", dpi=dpi),
                      names, workers)  # fmt: skip
