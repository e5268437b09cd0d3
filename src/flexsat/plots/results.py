"""Figures of a run by name: what :meth:`flexsat.simulate.Result.plot` and ``flexsat plot`` use.

A run's dataset says what it is: a closed-loop slew records ``pointing_error_deg``,
an open-loop run does not. Each kind has its figure set, the figures named as
their files are (``attitude``, ``energy``...):

- open loop: :data:`flexsat.plots.openloop.OPENLOOP_FIGURES`;
- slew: :func:`flexsat.plots.slew.slew_figure_names` (no sliding-surface figures
  for a law without a surface).

The modal analysis an open-loop figure marks its modal lines with is computed
from the satellite config stored in the dataset when it is not given.
"""

from __future__ import annotations

from pathlib import Path

import xarray as xr
from matplotlib.figure import Figure

from flexsat.errors import FlexsatError
from flexsat.plots import openloop, slew, style
from flexsat.simulate.result import ResultFigures, register_result_figures

__all__ = ["figure_names", "plot_result", "result_kind", "write_result_figures"]

_NEEDS_MODES = ("angular_acceleration", "spectrogram")  # open-loop figures with modal lines


def result_kind(ds: xr.Dataset) -> str:
    """``"slew"`` for a closed-loop run, ``"openloop"`` for an open-loop one.

    Parameters
    ----------
    ds : xarray.Dataset
        A run's dataset.

    Returns
    -------
    str
        ``"slew"`` or ``"openloop"``.
    """
    return "slew" if "pointing_error_deg" in ds else "openloop"


def figure_names(ds: xr.Dataset) -> tuple[str, ...]:
    """Names of the figures this run can draw, in the order they are written.

    Parameters
    ----------
    ds : xarray.Dataset
        A run's dataset.

    Returns
    -------
    tuple of str
        The figure names.
    """
    if result_kind(ds) == "slew":
        return slew.slew_figure_names(ds)
    return openloop.OPENLOOP_FIGURES


def plot_result(ds: xr.Dataset, kind: str = "attitude", analysis=None) -> Figure:
    """Draw one figure of a run.

    Parameters
    ----------
    ds : xarray.Dataset
        A flexsat result dataset (open loop or slew).
    kind : str
        One of :func:`figure_names` for this run.
    analysis : flexsat.analysis.modal.ModalAnalysis, optional
        Modal analysis of the satellite, for an open-loop figure's modal lines;
        default: computed from the stored config when the figure needs it.

    Returns
    -------
    matplotlib.figure.Figure

    Raises
    ------
    FlexsatError
        If ``kind`` is not a figure of this run; the message lists those it has.
    """
    names = figure_names(ds)
    if kind not in names:
        raise FlexsatError(
            f"kind: {kind!r} is not a figure of this {result_kind(ds)} run; choose one of "
            + ", ".join(names)
        )
    if result_kind(ds) == "slew":
        return slew.plot_slew(ds, kind)
    if analysis is None and kind in _NEEDS_MODES:
        analysis = _modal_analysis(ds)
    return openloop.OPENLOOP_MAKERS[kind](ds, analysis)


register_result_figures(ResultFigures(names=figure_names, plot=plot_result))


def write_result_figures(
    ds: xr.Dataset,
    out_dir: str | Path,
    kinds: tuple[str, ...] | None = None,
    *,
    analysis=None,
    dpi: int = 120,
) -> list[Path]:
    """Write figures of a run as ``<out_dir>/<kind>.png``.

    Parameters
    ----------
    ds : xarray.Dataset
        The run's dataset.
    out_dir : str or Path
        Created if missing.
    kinds : tuple of str, optional
        Figures to write; default: all of :func:`figure_names`.
    analysis : ModalAnalysis, optional
        As in :func:`plot_result`; computed once for the whole set when needed.
    dpi : int
        Resolution [dots per inch].

    Returns
    -------
    list of Path
    """
    kinds = figure_names(ds) if kinds is None else tuple(kinds)
    for kind in kinds:  # refuse a bad name before drawing anything
        if kind not in figure_names(ds):
            plot_result(ds, kind)
    if analysis is None and result_kind(ds) == "openloop" and set(kinds) & set(_NEEDS_MODES):
        analysis = _modal_analysis(ds)
    return style.write_figures(
        out_dir, kinds, lambda kind: plot_result(ds, kind, analysis), dpi=dpi
    )


def _modal_analysis(ds: xr.Dataset):
    from flexsat.analysis.modal import modal_analysis
    from flexsat.plots.animation import result_plant
    from flexsat.simulate.result import Result

    return modal_analysis(result_plant(Result(ds)))
