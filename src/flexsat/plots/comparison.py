"""One figure comparing control laws flying the same slew (thesis section 5.2).

:func:`plot_controller_comparison` overlays the runs: pointing error and residual
rate on log scales with the R1 and R2 bounds of the first run's scenario, and the
norm of the applied torque with the actuator limit.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import xarray as xr
from matplotlib.figure import Figure

from flexsat.plots import style
from flexsat.simulate.scenario import SlewScenario

__all__ = ["plot_controller_comparison", "write_comparison_figure"]

_COLOURS = ("black", "tab:orange", "tab:blue", "tab:green", "tab:purple", "tab:red")


def plot_controller_comparison(datasets: dict[str, xr.Dataset]) -> Figure:
    """Pointing error [deg], residual rate [deg/s] and ‖applied torque‖ [N m] per law.

    Parameters
    ----------
    datasets : dict of str to xarray.Dataset
        Closed-loop result datasets keyed by the law's name (e.g. ``"asmc"``, drawn
        as the law's label, "ASMC") or by a label of the caller's (drawn as given:
        ``"asmc, k = 2"``), all of the same slew; the requirements drawn are those of
        the first one's scenario.

    Returns
    -------
    matplotlib.figure.Figure
    """
    if not datasets:
        raise ValueError("no run to compare")
    first = next(iter(datasets.values()))
    scenario = SlewScenario.model_validate_json(first.attrs["scenario"])
    req = scenario.requirements
    fig, axes = style.figure(3, 1, size=(11.0, 10.0))
    panels = (
        ("pointing_error_deg", "pointing error [deg] (log)", req.pointing_deg, "R1"),
        ("rate_error_deg_s", "residual rate |ω − ω_d| [deg/s] (log)", req.jitter_deg_s, "R2"),
    )
    for ax, (name, label, bound, tag) in zip(axes[:2, 0], panels, strict=True):
        for (law, ds), colour in zip(datasets.items(), _COLOURS, strict=False):
            style.line(
                ax,
                style.time_s(ds),
                style.positive(ds[name].values),
                color=colour,
                linewidth=1.0,
                label=f"{_label(law, ds)}: final {float(ds[name].values[-1]):.3g}",
            )
        ax.axhline(
            bound,
            color="tab:green",
            linestyle="--",
            linewidth=1.0,
            label=f"{tag} bound {bound:.3g}",
        )
        ax.set_yscale("log")
        ax.set_ylabel(label)
        ax.legend(loc="upper right", fontsize=8)
    ax = axes[2, 0]
    for (law, ds), colour in zip(datasets.items(), _COLOURS, strict=False):
        norm = np.linalg.norm(np.asarray(ds["tau_applied"].values), axis=1)
        style.line(ax, style.time_s(ds), norm, color=colour, linewidth=1.0, label=_label(law, ds))
    limit = scenario.actuator.t_max_nm
    ax.axhline(
        limit * np.sqrt(3.0),
        color="tab:red",
        linestyle=":",
        linewidth=1.0,
        label=f"√3 T_max = {limit * np.sqrt(3.0):.3g} N m",
    )
    ax.set_ylabel("|τ applied| [N m]")
    ax.legend(loc="upper right", fontsize=8)
    style.finish_time_axis(axes, style.time_s(first))
    fig.suptitle(
        f"Controller comparison: the same slew, plant and disturbances\n"
        f"{first.attrs.get('title', '')}",
        fontsize=11,
    )
    return fig


def write_comparison_figure(
    datasets: dict[str, xr.Dataset], path: str | Path, *, dpi: int = 120
) -> Path:
    """Write :func:`plot_controller_comparison` to ``path`` (PNG); returns the path.

    Parameters
    ----------
    datasets : dict of str to xarray.Dataset
        Each law's slew, by label.
    path : str or Path
        The PNG file.
    dpi : int
        Resolution [dots per inch].

    Returns
    -------
    Path
        ``path``.
    """
    return style.save_figure(plot_controller_comparison(datasets), path, dpi=dpi)


def _label(key: str, ds) -> str:
    """The law's display name the run recorded when the key is the law's own name (the
    key upper-cased for older results); the caller's key otherwise, so that two runs of
    one law (``"asmc, k = 1"``, ``"asmc, k = 2"``) keep their own names."""
    if key != ds.attrs.get("controller", key):
        return style.literal(key)
    return style.literal(ds.attrs.get("controller_label", key.upper()))
