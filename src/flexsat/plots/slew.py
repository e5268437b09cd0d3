"""Figures of a closed-loop slew (thesis section 5.1, figs. 5.2-5.16).

Each function takes the result dataset of :func:`flexsat.simulate.run_slew`
(``result.dataset``) and returns a :class:`matplotlib.figure.Figure` created
directly (no pyplot). The requirements, actuator limits, disturbance model and
controller gains drawn on the figures are read from the scenario stored with the
run (``ds.attrs["scenario"]``), so they match whatever scenario flew the slew.

- :func:`plot_slew_attitude`: ZYX Euler angles with the target, and body rates.
- :func:`plot_slew_quaternion`: attitude quaternion with the target quaternion.
- :func:`plot_pointing`: pointing error and residual rate (jitter) on log scales,
  with the R1 and R2 bands and the settling times.
- :func:`plot_phase_plane`: q_v,e against omega_e per axis with the sliding
  surfaces and the boundary layer.
- :func:`plot_sliding_variables`: sliding variable s per axis with the +-Phi layer.
- :func:`plot_adaptation`: adaptive slope Lambda_act and robust gain JK per axis.
- :func:`plot_disturbances`: the disturbance torques of the actuator model.
- :func:`plot_torque_limits`: commanded and applied torque against RF*T_max, T_max.
- :func:`plot_torque_breakdown`: gyroscopic, equivalent and robust parts of the law.
- :func:`plot_flex_torque`: joint torque of the appendages against the net torque.
- the open-loop figures of :mod:`flexsat.plots.openloop` (root deformation, tip
  displacement, energy) drawn from the slew's dataset; a dataset with a controller
  gets no torque-on shading (torque being commanded throughout a slew).
- :func:`attitude_error_vector`: q_v,e at every record, for the phase plane.
- the loop stages' figures (:mod:`flexsat.plots.stages`): one per stage that
  records something (wheels, gyro, star tracker, MEKF, drive...), named after it.
- :func:`write_slew_figures`: all of the above into a folder as PNG.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from itertools import pairwise
from pathlib import Path

import numpy as np
import xarray as xr
from matplotlib.axes import Axes
from matplotlib.collections import LineCollection
from matplotlib.colors import Normalize
from matplotlib.figure import Figure
from matplotlib.ticker import MaxNLocator
from pydantic import ValidationError

from flexsat.analysis.requirements import settling_time, slew_metrics
from flexsat.control.quaternion import quaternion_error, target_quaternion
from flexsat.plots import stages, style
from flexsat.plots.openloop import (
    plot_energy,
    plot_root_deformation,
    plot_tip_displacement,
)
from flexsat.simulate.scenario import SlewScenario

__all__ = [
    "SLEW_FIGURES",
    "attitude_error_vector",
    "plot_adaptation",
    "plot_disturbances",
    "plot_flex_torque",
    "plot_phase_plane",
    "plot_pointing",
    "plot_slew",
    "plot_slew_attitude",
    "plot_slew_quaternion",
    "plot_sliding_variables",
    "plot_torque_breakdown",
    "plot_torque_limits",
    "slew_figure_names",
    "write_slew_figures",
]

_SURFACE_MIN = "tab:purple"  # sliding surface with Lambda_min (far from the target)
_SURFACE_MAX = "tab:orange"  # sliding surface with Lambda_max (near the target)
_SOFT_LIMIT = "tab:orange"  # RF * T_max
_HARD_LIMIT = "tab:red"  # T_max
_PHASE_POINTS = 50_000  # longer records are strided for the phase-plane trajectory
_PHASE_COLOURS = 400  # pieces of the trajectory, each drawn in one colour


# -- scenario --------------------------------------------------------------------------


@dataclass(frozen=True)
class _Surface:
    """Sliding-surface parameters of the law that flew the run (from the result's attributes)."""

    lambda_min: float  # rad/s
    lambda_max: float  # rad/s
    phi: float  # rad/s
    jk_min: float  # N m
    theta_threshold_deg: float | None  # where the slope adapts, if it does


def _scenario(ds: xr.Dataset) -> SlewScenario:
    text = ds.attrs.get("scenario")
    if text is None:
        raise ValueError("dataset has no 'scenario' attribute: not a flexsat slew result")
    try:
        return SlewScenario.model_validate_json(text)
    except ValidationError as exc:
        raise ValueError(f"the dataset's scenario is not a slew scenario: {exc}") from exc


def _surface(ds: xr.Dataset) -> _Surface | None:
    """The sliding surface the law wrote into the result; None if it has none."""
    a = ds.attrs
    keys = ("surface_lambda_min_rad_s", "surface_lambda_max_rad_s", "boundary_layer_rad_s",
            "jk_floor_nm")  # fmt: skip
    if not all(k in a for k in keys):
        return None
    threshold = a.get("theta_threshold_deg")
    return _Surface(*(float(a[k]) for k in keys),
                    None if threshold is None else float(threshold))  # fmt: skip


def _target_quaternion(ds: xr.Dataset, scenario: SlewScenario) -> np.ndarray:
    if "target_quaternion" in ds.attrs:
        return np.asarray(ds.attrs["target_quaternion"], dtype=float).ravel()
    return target_quaternion(scenario.target_euler_deg)


def _law_name(ds: xr.Dataset) -> str:
    label = ds.attrs.get("controller_label", str(ds.attrs.get("controller", "")).upper())
    return style.literal(label) or "controller"  # a registered law's label: any text


def _no_data(ax: Axes, text: str) -> None:
    ax.text(0.5, 0.5, text, ha="center", va="center", transform=ax.transAxes, color="0.4")


def _no_surface(ds: xr.Dataset, what: str) -> str:
    """Why a sliding-mode quantity is missing from a run."""
    if ds.attrs.get("controller") == "python":
        return f"no {what}: not recorded for a plain-Python controller"
    return f"no {what}: the {_law_name(ds)} law has no sliding surface"


def _values(ds: xr.Dataset, name: str, shape: tuple[int, ...]) -> np.ndarray:
    """A recorded variable as floats; NaN where the run's law does not record it."""
    if name not in ds:
        return np.full(shape, np.nan)
    return np.asarray(ds[name].values, dtype=float)


def _recorded(values: np.ndarray) -> bool:
    return bool(np.isfinite(values).any())


def _settled(what: str, t: float) -> str:
    """When ``what`` holds for good, from a settling time (NaN: not by the end)."""
    return "not settled by the end of the run" if math.isnan(t) else f"{what} from t = {t:.4g} s"


# -- attitude error --------------------------------------------------------------------


def attitude_error_vector(ds: xr.Dataset) -> np.ndarray:
    """Vector part q_v,e of the error quaternion q_e = q_d^-1 (x) q at every record.

    Computed from the recorded attitude quaternion and the target, with the
    controllers' own :func:`flexsat.control.quaternion.quaternion_error` (sign
    chosen so that q_e0 >= 0), so it is defined for any law. For a sliding-mode
    run it equals (s - omega_e) / Lambda_act, the sliding variable solved for
    q_v,e, since omega_e = omega (rest-to-rest).

    Parameters
    ----------
    ds : xarray.Dataset
        Closed-loop result dataset.

    Returns
    -------
    ndarray, shape (n_time, 3)
        q_v,e [-], hub frame B.
    """
    q_d = tuple(float(v) for v in _target_quaternion(ds, _scenario(ds)))
    quat = np.asarray(ds["quaternion"].values, dtype=float)
    out = np.full((quat.shape[0], 3), np.nan)
    for i, q in enumerate(quat):
        if np.all(np.isfinite(q)):
            out[i] = quaternion_error(q_d, (q[0], q[1], q[2], q[3]))[1:]
    return out


# -- attitude --------------------------------------------------------------------------


def plot_slew_attitude(ds: xr.Dataset) -> Figure:
    """Hub ZYX Euler angles [deg] with the target (dashed), and body rates [deg/s].

    Parameters
    ----------
    ds : xarray.Dataset
        Closed-loop result dataset.

    Returns
    -------
    matplotlib.figure.Figure
    """
    scenario = _scenario(ds)
    t = style.time_s(ds)
    euler = np.asarray(ds["euler_deg"].values)
    rate = np.degrees(np.asarray(ds["omega"].values))
    target = scenario.target_euler_deg
    fig, axes = style.figure(2, 1, size=(11.0, 8.0), height_ratios=(1.4, 1))
    angles, rates = axes[0, 0], axes[1, 0]
    for k in range(3):
        name, symbol = style.EULER[k]
        colour = style.AXIS_COLOURS[k]
        style.line(angles, t, euler[:, k], color=colour, linewidth=1.4, label=f"{symbol} ({name})")
        angles.axhline(target[k], color=colour, linestyle="--", linewidth=1.0,
                       label=f"{symbol} target = {target[k]:.4g} deg")  # fmt: skip
        style.line(rates, t, rate[:, k], color=colour, linewidth=1.0, label=f"ω_{style.AXES[k]}")
    final = ", ".join(f"{style.EULER[k][1]} = {euler[-1, k]:.5g}" for k in range(3))
    angles.set_title(f"ZYX Euler angles (final: {final} deg)", fontsize=10)
    angles.set_ylabel("Euler angle [deg]")
    angles.legend(loc="center right", fontsize=8, ncols=2)
    rates.set_title("body rates ω (frame B)", fontsize=10)
    rates.set_ylabel("ω [deg/s]")
    rates.legend(loc="upper right", fontsize=8)
    style.finish_time_axis(axes, t)
    style.suptitle(fig, ds, f"Slew attitude ({_law_name(ds)}): Euler angles and body rates")
    return fig


def plot_slew_quaternion(ds: xr.Dataset) -> Figure:
    """Attitude quaternion components q0-q3 with the target quaternion (dashed).

    Parameters
    ----------
    ds : xarray.Dataset
        Closed-loop result dataset.

    Returns
    -------
    matplotlib.figure.Figure
    """
    scenario = _scenario(ds)
    t = style.time_s(ds)
    quat = np.asarray(ds["quaternion"].values)
    q_d = _target_quaternion(ds, scenario)
    finite = np.isfinite(quat).all(axis=1)
    if finite.any() and np.dot(quat[finite][-1], q_d) < 0.0:
        q_d = -q_d  # the same attitude, drawn on the side the trajectory ends on
    fig, axes = style.figure(1, 1, size=(11.0, 5.5))
    ax = axes[0, 0]
    colours = ("black", *style.AXIS_COLOURS)
    names = ("q0 (scalar)", "q1 (x)", "q2 (y)", "q3 (z)")
    for k in range(4):
        style.line(ax, t, quat[:, k], color=colours[k], linewidth=1.4, label=names[k])
        ax.axhline(q_d[k], color=colours[k], linestyle="--", linewidth=1.0,
                   label=f"q_d,{k} = {q_d[k]:.4f}")  # fmt: skip
    ax.set_ylabel("quaternion component [-]")
    ax.set_ylim(-1.1, 1.1)
    ax.set_title("solid: attitude q (frame B to N); dashed: target q_d", fontsize=10)
    ax.legend(loc="lower right", fontsize=8, ncols=4)
    style.finish_time_axis(axes, t)
    style.suptitle(fig, ds, f"Slew attitude quaternion ({_law_name(ds)}), scalar first")
    return fig


# -- requirements ----------------------------------------------------------------------


def _requirement_panel(ax: Axes, t: np.ndarray, values: np.ndarray, bound: float, tag: str,
                       unit: str, label: str, colour: str,
                       verdict: tuple[tuple[float, float], bool | None, float, str],
                       ) -> None:  # fmt: skip
    """``values`` on a log axis with the band below ``bound`` shaded, its settling time and
    the observation window with the verdict over it: ``verdict`` = (window, passed, the
    largest value in the window, why it is not judged); passed is None, "not judged",
    when the run was planned to end before the window does."""
    values = np.asarray(values, dtype=float)
    style.line(ax, t, style.positive(values), color=colour, linewidth=1.1, label=label)
    ax.set_yscale("log")
    positive = values[np.isfinite(values) & (values > 0.0)]
    top = max(float(positive.max()) if positive.size else bound, bound)
    bottom = min(float(positive.min()) if positive.size else bound, bound)
    bottom = max(bottom, bound * 1e-4, top * 1e-12)
    lo, hi = bottom / 3.0, top * 3.0
    ax.axhspan(
        lo,
        bound,
        color=style.BAND,
        alpha=0.15,
        linewidth=0,
        label=f"{tag} band: < {bound:.3g} {unit}",
    )
    ax.axhline(bound, color=style.BAND, linewidth=1.4, label=f"{tag}: {bound:.3g} {unit}")
    ax.set_ylim(lo, hi)
    settle = settling_time(t, values, bound)
    (start, end), passed, worst, reason = verdict
    if start < t[-1]:  # a run that ends before the deadline has no window to shade
        ax.axvspan(start, min(end, t[-1]), color="0.85", alpha=0.5, linewidth=0,
                   label=f"observation window {start:.4g}–{end:.4g} s")  # fmt: skip
    if not math.isnan(settle):
        ax.axvline(settle, color=style.BAND, linestyle=":", linewidth=1.4)
        ax.annotate(f"in the {tag} band for good\nfrom t = {settle:.4g} s", xy=(settle, bound),
                    xytext=(8, 18), textcoords="offset points", fontsize=9, color="darkgreen",
                    arrowprops={"arrowstyle": "->", "color": "darkgreen"})  # fmt: skip
    if passed is None:  # never planned to reach the window: neither pass nor fail
        judged = f"{tag} not judged: {reason}"
    elif t[-1] < start:
        judged = f"{tag} FAIL: the run ends at {t[-1]:.4g} s, before the {start:.4g} s deadline"
    elif t[-1] < end - 1e-6:
        judged = f"{tag} FAIL: the run stops at {t[-1]:.4g} s, before its window ends ({end:.4g} s)"
    else:
        judged = (f"{tag} {'PASS' if passed else 'FAIL'} over {start:.4g}–{end:.4g} s: "
                  f"max {worst:.3g} {unit} (limit {bound:.3g} {unit})")  # fmt: skip
    ax.set_title(f"{judged}, {_settled('in the band for good', settle)}", fontsize=10)
    ax.legend(loc="upper right", fontsize=8)


def plot_pointing(ds: xr.Dataset) -> Figure:
    """Pointing error [deg] and residual rate ‖omega‖ [deg/s] on log scales.

    Top: the absolute pointing error 2 asin ‖q_v,e‖ with the R1 band (below the
    scenario's ``requirements.pointing_deg``) shaded green; bottom: the residual
    rate (jitter) ‖omega - omega_d‖ with the R2 band (``requirements.jitter_deg_s``).
    Each panel marks the time its quantity enters its band for good
    (:func:`flexsat.analysis.requirements.settling_time`), shades the observation
    window and gives the verdict over it (:func:`flexsat.analysis.slew_metrics`): pass,
    fail, or "not judged" with the reason when the run was planned to end before the
    window does.

    Parameters
    ----------
    ds : xarray.Dataset
        Closed-loop result dataset.

    Returns
    -------
    matplotlib.figure.Figure
    """
    req = _scenario(ds).requirements
    metrics = slew_metrics(ds)
    window = tuple(metrics["observation_window_s"])
    reason = metrics["not_judged_reason"]
    t = style.time_s(ds)
    fig, axes = style.figure(2, 1, size=(11.0, 8.5))
    _requirement_panel(axes[0, 0], t, ds["pointing_error_deg"].values, req.pointing_deg, "R1",
                       "deg", "pointing error 2 asin|q_v,e|", "black",
                       (window, metrics["r1_pass"], metrics["ape_deg"], reason))  # fmt: skip
    axes[0, 0].set_ylabel("pointing error [deg] (log)")
    _requirement_panel(axes[1, 0], t, ds["rate_error_deg_s"].values, req.jitter_deg_s, "R2",
                       "deg/s", "residual rate |ω − ω_d|", "tab:blue",
                       (window, metrics["r2_pass"], metrics["max_rate_error_deg_s"],
                        reason))  # fmt: skip
    axes[1, 0].set_ylabel("residual rate |ω| [deg/s] (log)")
    style.finish_time_axis(axes, t)
    style.suptitle(fig, ds, f"Pointing requirements ({_law_name(ds)}): R1 pointing, R2 jitter")
    return fig


# -- sliding mode ----------------------------------------------------------------------


def _phase_limits(x: np.ndarray, y: np.ndarray) -> tuple[tuple, tuple]:
    """Axis limits holding the trajectory and the origin, with a margin."""
    xs = np.concatenate([[0.0], x[np.isfinite(x)]])
    ys = np.concatenate([[0.0], y[np.isfinite(y)]])

    def span(v):
        lo, hi = float(v.min()), float(v.max())
        pad = 0.08 * (hi - lo) if hi > lo else max(abs(hi), 1e-12)
        return lo - pad, hi + pad

    return span(xs), span(ys)


def _phase_panel(ax: Axes, q: np.ndarray, w: np.ndarray, t: np.ndarray, norm: Normalize,
                 surface: _Surface | None, first: str | None) -> LineCollection:  # fmt: skip
    """One phase-plane panel: trajectory coloured by time over the surfaces."""
    xlim, ylim = _phase_limits(q, w)
    if surface is not None:
        grid = np.linspace(*xlim, 2)
        slopes = [(surface.lambda_max, _SURFACE_MAX, "final surface ω = −Λ_max q")]
        if surface.lambda_min != surface.lambda_max:
            slopes.insert(0, (surface.lambda_min, _SURFACE_MIN, "initial surface ω = −Λ_min q"))
        else:
            slopes = [(surface.lambda_max, _SURFACE_MAX, "surface ω = −Λ q")]
        for lam, colour, label in slopes:
            layer = f"boundary layer |s| ≤ Φ: ±{surface.phi / lam:.3g} in q"
            ax.fill_between(grid, -lam * grid - surface.phi, -lam * grid + surface.phi,
                            color=colour, alpha=0.15, linewidth=0, label=layer)  # fmt: skip
            ax.plot(grid, -lam * grid, color=colour, linestyle="--", linewidth=1.3,
                    label=f"{label}, Λ = {lam:.3g} rad/s")  # fmt: skip
    ok = np.isfinite(q) & np.isfinite(w)
    points = np.column_stack([q[ok], w[ok]])
    # consecutive pieces sharing their end points, each coloured by its mid time
    edges = np.linspace(0, max(points.shape[0] - 1, 0), _PHASE_COLOURS + 1).round().astype(int)
    edges = np.unique(edges)
    pieces = [points[a : b + 1] for a, b in pairwise(edges)]
    lines = LineCollection(pieces, cmap="viridis", norm=norm, linewidths=1.4, zorder=3,
                           capstyle="round", joinstyle="round")  # fmt: skip
    times = t[ok]
    lines.set_array(0.5 * (times[edges[:-1]] + times[edges[1:]]))
    ax.add_collection(lines)
    if points.shape[0]:
        marker = {"marker": "o", "color": "black"}
        if not (first and first.startswith("start")):
            marker = {"marker": "D", "color": "black", "markerfacecolor": "white"}
        ax.plot(*points[0], linestyle="none", markersize=6, zorder=4, label=first, **marker)
        ax.plot(*points[-1], "*", color="red", markersize=11, zorder=4,
                label=f"end (t = {t[ok][-1]:.4g} s)")  # fmt: skip
    ax.axhline(0.0, color="0.5", linewidth=0.6)
    ax.axvline(0.0, color="0.5", linewidth=0.6)
    ax.set_xlim(xlim)
    ax.set_ylim(ylim)
    ax.xaxis.set_major_locator(MaxNLocator(5))
    ax.ticklabel_format(axis="both", style="sci", scilimits=(-3, 3))
    ax.grid(True, color="0.85", linewidth=0.6)
    return lines


def plot_phase_plane(ds: xr.Dataset) -> Figure:
    """Phase plane per axis: q_v,e component [-] against omega_e component [rad/s].

    q_v,e is recomputed from the recorded quaternion and the target
    (:func:`attitude_error_vector`), so every law can be drawn; omega_e = omega
    (rest-to-rest). The trajectory is coloured by time. For a sliding-mode law the
    sliding surfaces s = omega_e + Lambda q_v,e = 0 are drawn as lines of slope
    -Lambda: the initial surface with Lambda_min and the final one with Lambda_max
    (a single one for the constant-slope SMC), each with its boundary layer
    ‖s‖ <= Phi, the band of half-width Phi in omega, Phi/Lambda in q. Top row: the
    whole slew; bottom row: close to the target, from the time the pointing error
    drops below the ASMC threshold theta_th (5 deg for the other laws) on.

    Parameters
    ----------
    ds : xarray.Dataset
        Closed-loop result dataset.

    Returns
    -------
    matplotlib.figure.Figure
    """
    scenario = _scenario(ds)
    surface = _surface(ds)
    t = style.time_s(ds)
    qv = attitude_error_vector(ds)
    omega = np.asarray(ds["omega"].values, dtype=float)
    step = max(1, math.ceil(t.size / _PHASE_POINTS))
    t_s, qv_s, omega_s = t[::step], qv[::step], omega[::step]
    # colour by time up to when the rate has settled (R2): later the state stays put
    settled = settling_time(t, np.asarray(ds["rate_error_deg_s"].values),
                            scenario.requirements.jitter_deg_s)  # fmt: skip
    t_colour = float(t[-1]) if math.isnan(settled) else min(float(t[-1]), 1.1 * settled)
    norm = Normalize(vmin=t[0], vmax=max(t_colour, t[0] + 1e-9))
    threshold = surface.theta_threshold_deg if surface and surface.theta_threshold_deg else 5.0
    pointing = np.asarray(ds["pointing_error_deg"].values)
    near = np.nonzero(pointing < threshold)[0]
    t_near = float(t[near[0]]) if near.size else float(t[-1])
    zoom = t_s >= t_near

    fig, axes = style.figure(2, 3, size=(15.0, 9.5), sharex=False)
    lines = None
    for k in range(3):
        a = style.AXES[k]
        lines = _phase_panel(axes[0, k], qv_s[:, k], omega_s[:, k], t_s, norm, surface,
                             f"start (t = {t[0]:.3g} s)")  # fmt: skip
        axes[0, k].set_title(f"axis {a}: whole slew", fontsize=10)
        if zoom.sum() >= 2:
            _phase_panel(axes[1, k], qv_s[zoom, k], omega_s[zoom, k], t_s[zoom], norm, surface,
                         f"close-up from t = {t_near:.4g} s")  # fmt: skip
            axes[1, k].set_title(f"axis {a}: near the target (t ≥ {t_near:.4g} s)", fontsize=10)
        else:
            _no_data(axes[1, k], f"pointing error never below {threshold:.3g} deg")
        for row in range(2):
            axes[row, k].set_xlabel(f"q_v,e,{a} [-]")
            axes[row, k].set_ylabel(f"ω_e,{a} [rad/s]")
    style.axes_legend(fig, axes[:, 0], ncols=4)
    if lines is not None:
        extend = "max" if t_colour < t[-1] else "neither"
        label = "time t [s]" + (" (later: end colour)" if extend == "max" else "")
        fig.colorbar(lines, ax=axes.ravel().tolist(), shrink=0.85, extend=extend, label=label)
    what = "sliding surfaces s = ω_e + Λ q_v,e = 0" if surface else "no sliding surface"
    style.suptitle(fig, ds, f"Phase plane q_v,e – ω_e per axis ({_law_name(ds)}, {what})")
    return fig


def plot_sliding_variables(ds: xr.Dataset) -> Figure:
    """Sliding variable s = omega_e + Lambda_act q_v,e per axis [rad/s], symlog scale.

    The boundary layer ‖s‖ <= Phi is shaded with its edges +-Phi dashed; the
    scale is linear within Phi/1000 of zero and logarithmic beyond, so both the
    reaching phase and the small residual inside the layer show. Each panel
    gives the time s enters the layer for good.

    Parameters
    ----------
    ds : xarray.Dataset
        Closed-loop result dataset.

    Returns
    -------
    matplotlib.figure.Figure
    """
    surface = _surface(ds)
    t = style.time_s(ds)
    s = _values(ds, "sliding_variable", (t.size, 3))
    fig, axes = style.figure(3, 1, size=(11.0, 9.0))
    for k in range(3):
        ax = axes[k, 0]
        ax.set_ylabel(f"s_{style.AXES[k]} [rad/s]")
        if surface is None or not _recorded(s[:, k]):
            _no_data(ax, _no_surface(ds, "sliding variable"))
            continue
        phi = surface.phi
        ax.axhspan(-phi, phi, color=_SURFACE_MAX, alpha=0.12, linewidth=0,
                   label=f"boundary layer |s| ≤ Φ = {phi:.3g} rad/s")  # fmt: skip
        for sign in (1.0, -1.0):
            ax.axhline(sign * phi, color=_SURFACE_MAX, linestyle="--", linewidth=1.2,
                       label="±Φ" if sign > 0 else None)  # fmt: skip
        style.line(
            ax, t, s[:, k], color=style.AXIS_COLOURS[k], linewidth=1.0, label=f"s_{style.AXES[k]}"
        )
        ax.set_yscale("symlog", linthresh=phi * 1e-3, linscale=1.0)
        top = max(float(np.nanmax(np.abs(s[:, k]))), phi) * 3.0
        ax.set_ylim(-top, top)
        inside = settling_time(t, np.abs(s[:, k]), phi)
        if not math.isnan(inside):
            ax.axvline(inside, color="0.3", linestyle=":", linewidth=1.2)
        settled = _settled("inside the boundary layer for good", inside)
        ax.set_title(f"s_{style.AXES[k]}: {settled}; final {s[-1, k]:.3g} rad/s", fontsize=10)
    style.axes_legend(fig, axes)
    style.finish_time_axis(axes, t)
    scale = "symlog, linear within ±Φ/1000"
    style.suptitle(fig, ds, f"Sliding variables s = ω_e + Λ q_v,e ({_law_name(ds)}; {scale})")
    return fig


def plot_adaptation(ds: xr.Dataset) -> Figure:
    """Adaptive slope Lambda_act [rad/s] and robust gain JK per axis [N m].

    Top: Lambda_act between Lambda_min and Lambda_max (dashed), with the time it
    leaves Lambda_min and, for the ASMC, the time the pointing error drops below
    theta_th. Bottom: JK per axis between the floor JK_min and the ceiling
    RF * T_max, the software torque limit.

    Parameters
    ----------
    ds : xarray.Dataset
        Closed-loop result dataset.

    Returns
    -------
    matplotlib.figure.Figure
    """
    scenario = _scenario(ds)
    surface = _surface(ds)
    act = scenario.actuator
    ceiling = act.reduction_factor * act.t_max_nm
    t = style.time_s(ds)
    lam = _values(ds, "lambda_act", (t.size,))
    jk = _values(ds, "jk", (t.size, 3))
    fig, axes = style.figure(2, 1, size=(11.0, 8.0))
    top, bottom = axes[0, 0], axes[1, 0]
    top.set_ylabel("Λ_act [rad/s]")
    bottom.set_ylabel("JK [N m]")
    if surface is None or not _recorded(lam):
        for ax in (top, bottom):
            _no_data(ax, _no_surface(ds, "slope or robust gain"))
        style.finish_time_axis(axes, t)
        style.suptitle(fig, ds, f"Adaptation of Λ and JK ({_law_name(ds)})")
        return fig

    style.line(top, t, lam, color="black", linewidth=1.4, label="Λ_act")
    top.axhline(surface.lambda_min, color=_SURFACE_MIN, linestyle="--", linewidth=1.2,
                label=f"Λ_min = {surface.lambda_min:.3g} rad/s")  # fmt: skip
    if surface.lambda_max != surface.lambda_min:
        top.axhline(surface.lambda_max, color=_SURFACE_MAX, linestyle="--", linewidth=1.2,
                    label=f"Λ_max = {surface.lambda_max:.3g} rad/s")  # fmt: skip
    leaves = np.nonzero(lam > lam[0] * (1.0 + 1e-9))[0]
    notes = []
    if leaves.size:
        t_leave = float(t[leaves[0]])
        top.axvline(t_leave, color=_SURFACE_MIN, linestyle=":", linewidth=1.2,
                    label=f"Λ leaves Λ_min: t = {t_leave:.4g} s")  # fmt: skip
        notes.append(f"leaves Λ_min at t = {t_leave:.4g} s")
    if surface.theta_threshold_deg is not None:
        below = np.nonzero(np.asarray(ds["pointing_error_deg"].values)
                           < surface.theta_threshold_deg)[0]  # fmt: skip
        if below.size:
            t_th = float(t[below[0]])
            top.axvline(t_th, color="0.3", linestyle="-.", linewidth=1.0,
                        label=f"pointing error < θ_th = {surface.theta_threshold_deg:.3g} deg: "
                              f"t = {t_th:.4g} s")  # fmt: skip
    top.set_ylim(0.0, 1.12 * max(surface.lambda_max, float(np.nanmax(lam))))
    top.set_title("adaptive sliding-surface slope" + (f" ({notes[0]}; final "
                  f"{lam[-1]:.4g} rad/s)" if notes else f" (final {lam[-1]:.4g} rad/s)"),
                  fontsize=10)  # fmt: skip
    top.legend(loc="center right", fontsize=8)

    for k in range(3):
        style.line(
            bottom,
            t,
            jk[:, k],
            color=style.AXIS_COLOURS[k],
            linewidth=1.0,
            label=f"JK_{style.AXES[k]}",
        )
    bottom.axhline(surface.jk_min, color="black", linestyle="--", linewidth=1.2,
                   label=f"floor JK_min = {surface.jk_min:.4g} N m")  # fmt: skip
    bottom.axhline(ceiling, color=_SOFT_LIMIT, linestyle="--", linewidth=1.2,
                   label=f"ceiling RF·T_max = {ceiling:.4g} N m")  # fmt: skip
    low = min(surface.jk_min, float(np.nanmin(jk)))
    high = max(ceiling, float(np.nanmax(jk)))
    pad = 0.06 * (high - low) if high > low else 0.1
    bottom.set_ylim(low - pad, high + pad)
    bottom.set_title("robust torque gain per axis: the torque budget left to the robust term",
                     fontsize=10)  # fmt: skip
    bottom.legend(loc="upper right", fontsize=8)
    style.finish_time_axis(axes, t)
    style.suptitle(fig, ds, f"Adaptation of the slope Λ and the robust gain JK ({_law_name(ds)})")
    return fig


# -- torques ---------------------------------------------------------------------------


def plot_disturbances(ds: xr.Dataset) -> Figure:
    """Disturbance torques the actuator applies per body axis [N m].

    The scenario's ``[disturbances]`` as the run realised them
    (``attrs["realised_disturbances"]``, the layout of
    :data:`flexsat.control.stages.static_actuator.PACKED`): the constant environment
    + residual torque, the sloshing torque ratio * tau_cmd * sin(2 pi f t) and, for
    the static actuator, the gain shortfall -(1 - G_act) tau_cmd (the torque the
    actuators fail to deliver, signed as it acts on the hub). In black their sum: for
    the static actuator the recorded tau_applied - tau_cmd (which also holds any
    clipping at T_max); for an actuator that applies them as external torques (the
    wheels, whose tau_applied also holds their own reaction) the sum of the terms.
    The panel titles compare the peak with JK_min, the robust gain's floor. An
    actuator that does not apply them (``applies_disturbances``) gets a note.

    Parameters
    ----------
    ds : xarray.Dataset
        Closed-loop result dataset.

    Returns
    -------
    matplotlib.figure.Figure
    """
    from flexsat.control.stages.static_actuator import PACKED

    scenario = _scenario(ds)
    surface = _surface(ds)
    act = scenario.actuator
    t = style.time_s(ds)
    title = "Disturbance torques applied with the actuator (frame B)"
    if not act.applies_disturbances:
        fig, axes = style.figure(1, 1, size=(11.0, 4.0))
        _no_data(axes[0, 0], f"the {act.kind} actuator does not apply the scenario's "
                             "disturbances")  # fmt: skip
        style.suptitle(fig, ds, title)
        return fig
    realised = np.asarray(ds.attrs["realised_disturbances"], dtype=float)

    def packed(name, size=3):
        return realised[PACKED[name] : PACKED[name] + size]

    ratio, hz = packed("sloshing_ratio", 1)[0], packed("sloshing_hz", 1)[0]
    gain = packed("gain")
    cmd = np.asarray(ds["tau_cmd"].values, dtype=float)
    slosh = ratio * cmd * np.sin(2.0 * np.pi * hz * t)[:, None]
    constant = packed("environment_nm") + packed("residual_nm")
    static = hasattr(act, "gain")  # the static actuator: its gain, and the recorded sum
    if static:
        total = np.asarray(ds["tau_applied"].values, dtype=float) - cmd
    else:
        total = constant + slosh
    slosh_label = f"sloshing {ratio:.3g}·τ_cmd·sin(2π·{hz:.3g} Hz·t)"
    fig, axes = style.figure(3, 1, size=(11.0, 9.0))
    for k in range(3):
        ax = axes[k, 0]
        a = style.AXES[k]
        ax.axhline(constant[k], color="tab:green", linestyle="--", linewidth=1.3,
                   label="environment + residual (constant)")  # fmt: skip
        style.line(ax, t, slosh[:, k], color="tab:blue", linewidth=0.9, label=slosh_label)
        if static:
            style.line(ax, t, (gain[k] - 1.0) * cmd[:, k], color="tab:orange", linewidth=1.0,
                       label="actuator-gain shortfall −(1 − G)·τ_cmd")  # fmt: skip
        style.line(ax, t, total[:, k], color="black", linewidth=0.9, alpha=0.8,
                   label="total τ_applied − τ_cmd" if static else "total on the hub")  # fmt: skip
        ax.set_ylabel(f"d_{a} [N m]")
        peak = float(np.nanmax(np.abs(total[:, k]))) if _recorded(total[:, k]) else math.nan
        heading = f"axis {a}: constant {constant[k]:.3g} N m, "
        heading += f"G_{a} = {gain[k]:.3g}; " if static else ""
        heading += f"peak |d_{a}| = {peak:.3g} N m"
        if surface is not None:
            heading += f" (robust-gain floor JK_min = {surface.jk_min:.4g} N m)"
        ax.set_title(heading, fontsize=10)
    style.axes_legend(fig, axes, ncols=4)
    style.finish_time_axis(axes, t)
    style.suptitle(fig, ds, title)
    return fig


def plot_torque_limits(ds: xr.Dataset) -> Figure:
    """Commanded and applied torque per axis [N m] against the actuator limits.

    The software limit +-RF * T_max clips the command; the hardware saturation
    +-T_max clips the applied torque (requirement R3: ‖tau_applied‖ <= T_max).

    Parameters
    ----------
    ds : xarray.Dataset
        Closed-loop result dataset.

    Returns
    -------
    matplotlib.figure.Figure
    """
    act = _scenario(ds).actuator
    soft = act.reduction_factor * act.t_max_nm
    t = style.time_s(ds)
    cmd = np.asarray(ds["tau_cmd"].values, dtype=float)
    applied = np.asarray(ds["tau_applied"].values, dtype=float)
    fig, axes = style.figure(3, 1, size=(11.0, 9.0))
    r3 = bool(np.all(np.abs(applied[np.isfinite(applied)]) <= act.t_max_nm * (1 + 1e-12)))
    for k in range(3):
        ax = axes[k, 0]
        a = style.AXES[k]
        for sign in (1.0, -1.0):
            ax.axhline(sign * act.t_max_nm, color=_HARD_LIMIT, linewidth=1.4,
                       label=f"±T_max = {act.t_max_nm:.3g} N m" if sign > 0 else None)  # fmt: skip
            ax.axhline(sign * soft, color=_SOFT_LIMIT, linestyle="--", linewidth=1.2,
                       label=f"±RF·T_max = {soft:.3g} N m" if sign > 0 else None)  # fmt: skip
        style.line(ax, t, cmd[:, k], color="black", linewidth=1.6, label="τ_cmd (commanded)")
        style.line(
            ax,
            t,
            applied[:, k],
            color="tab:cyan",
            linewidth=1.0,
            label="τ_applied (delivered to the hub)",
        )
        ax.set_ylim(-1.15 * act.t_max_nm, 1.15 * act.t_max_nm)
        ax.set_ylabel(f"τ_{a} [N m]")
        ax.set_title(f"axis {a}: peak |τ_cmd| = {np.nanmax(np.abs(cmd[:, k])):.4g} N m, "
                     f"|τ_applied| = {np.nanmax(np.abs(applied[:, k])):.4g} N m",
                     fontsize=10)  # fmt: skip
    style.axes_legend(fig, axes, ncols=4)
    style.finish_time_axis(axes, t)
    verdict = "PASS" if r3 else "FAIL"
    style.suptitle(
        fig, ds, f"Control torque against its limits (R3 {verdict}: |τ_applied| ≤ T_max)"
    )
    return fig


def plot_torque_breakdown(ds: xr.Dataset) -> Figure:
    """The law's torque per axis [N m]: gyroscopic, equivalent (guide) and robust parts.

    tau_cmd = clip(tau_gyro + tau_guide + tau_rob, +-RF * T_max) with
    tau_gyro = omega x J omega, tau_guide = -J Lambda q_v,e_dot and
    tau_rob = -JK sat(s / Phi); the command is drawn in black.

    Parameters
    ----------
    ds : xarray.Dataset
        Closed-loop result dataset.

    Returns
    -------
    matplotlib.figure.Figure
    """
    act = _scenario(ds).actuator
    soft = act.reduction_factor * act.t_max_nm
    t = style.time_s(ds)
    parts = (
        ("tau_gyro", "tab:green", "τ_gyro = ω × Jω"),
        ("tau_guide", "tab:blue", "τ_guide = −JΛ q̇_v,e (equivalent)"),
        ("tau_rob", "tab:red", "τ_rob = −JK sat(s/Φ)"),
    )
    fig, axes = style.figure(3, 1, size=(11.0, 9.0))
    cmd = np.asarray(ds["tau_cmd"].values, dtype=float)
    for k in range(3):
        ax = axes[k, 0]
        a = style.AXES[k]
        for sign in (1.0, -1.0):
            ax.axhline(sign * soft, color=_SOFT_LIMIT, linestyle=":", linewidth=1.0,
                       label=f"±RF·T_max = {soft:.3g} N m" if sign > 0 else None)  # fmt: skip
        recorded = [name for name, _, _ in parts
                    if name in ds and _recorded(ds[name].values[:, k])]  # fmt: skip
        for name, colour, label in parts:
            if name in recorded:
                style.line(ax, t, ds[name].values[:, k], color=colour, linewidth=1.0, label=label)
        if not recorded:
            _no_data(ax, "breakdown not recorded for a plain-Python controller")
        style.line(
            ax,
            t,
            cmd[:, k],
            color="black",
            linewidth=0.9,
            linestyle="--",
            label="τ_cmd (sum, clipped)",
        )
        ax.set_ylabel(f"τ_{a} [N m]")
        ax.set_title(f"axis {a}", fontsize=10)
    style.axes_legend(fig, axes, ncols=5)
    style.finish_time_axis(axes, t)
    style.suptitle(fig, ds, f"Breakdown of the commanded torque ({_law_name(ds)})")
    return fig


def plot_flex_torque(ds: xr.Dataset) -> Figure:
    """Joint torque of the appendages on the hub against the net torque, per axis [N m].

    tau_net = tau_applied + tau_flex is what turns the hub; the applied torque is
    drawn faintly for reference.

    Parameters
    ----------
    ds : xarray.Dataset
        Closed-loop result dataset.

    Returns
    -------
    matplotlib.figure.Figure
    """
    t = style.time_s(ds)
    applied = np.asarray(ds["tau_applied"].values, dtype=float)
    flex = np.asarray(ds["tau_flex"].values, dtype=float)
    net = np.asarray(ds["tau_net"].values, dtype=float)
    fig, axes = style.figure(3, 1, size=(11.0, 9.0))
    for k in range(3):
        ax = axes[k, 0]
        a = style.AXES[k]
        style.line(ax, t, applied[:, k], color="0.6", linewidth=1.0, label="τ_applied (actuators)")
        style.line(
            ax, t, net[:, k], color="tab:blue", linewidth=1.1, label="τ_net = τ_applied + τ_flex"
        )
        style.line(
            ax,
            t,
            flex[:, k],
            color="tab:orange",
            linewidth=1.0,
            label="τ_flex (appendage joints on the hub)",
        )
        ax.set_ylabel(f"τ_{a} [N m]")
        ax.set_title(f"axis {a}: peak |τ_flex| = {np.nanmax(np.abs(flex[:, k])):.3g} N m, "
                     f"peak |τ_net| = {np.nanmax(np.abs(net[:, k])):.3g} N m",
                     fontsize=10)  # fmt: skip
    style.axes_legend(fig, axes)
    style.finish_time_axis(axes, t)
    style.suptitle(fig, ds, "Flexible torque against net torque on the hub (frame B)")
    return fig


# -- everything at once ----------------------------------------------------------------


_MAKERS = {
    "attitude": plot_slew_attitude,
    "quaternion": plot_slew_quaternion,
    "pointing": plot_pointing,
    "phase_plane": plot_phase_plane,
    "sliding_variables": plot_sliding_variables,
    "adaptation": plot_adaptation,
    "disturbances": plot_disturbances,
    "torque_limits": plot_torque_limits,
    "torque_breakdown": plot_torque_breakdown,
    "root_deformation": plot_root_deformation,
    "tip_displacement": plot_tip_displacement,
    "flex_torque": plot_flex_torque,
    "energy": plot_energy,
}

SLEW_FIGURES = tuple(_MAKERS)
"""Names (without ``.png``) of every slew figure, in order (:func:`slew_figure_names`)."""

_SURFACE_FIGURES = ("sliding_variables", "adaptation")


def slew_figure_names(ds: xr.Dataset) -> tuple[str, ...]:
    """The figures a run has something to show in: :data:`SLEW_FIGURES`, then its stages'.

    A law without a sliding surface (PD, a plain-Python controller) records no
    sliding variable, slope or robust gain: its run has no figure of them. Each
    loop stage that recorded something adds its figure, named after the stage
    (:func:`flexsat.plots.stages.stage_figure_names`).

    Parameters
    ----------
    ds : xarray.Dataset
        A slew's dataset.

    Returns
    -------
    tuple of str
        The figure names.
    """
    has_surface = _surface(ds) is not None and "sliding_variable" in ds
    own = tuple(n for n in SLEW_FIGURES if has_surface or n not in _SURFACE_FIGURES)
    return own + stages.stage_figure_names(ds)


def plot_slew(ds: xr.Dataset, name: str) -> Figure:
    """The slew figure ``name`` (one of :func:`slew_figure_names`) of a closed-loop run.

    Parameters
    ----------
    ds : xarray.Dataset
        A slew's dataset.
    name : str
        One of :data:`SLEW_FIGURES` or a flown stage's name.

    Returns
    -------
    Figure
        The figure.
    """
    maker = _MAKERS.get(name)
    return maker(ds) if maker is not None else stages.plot_stage(ds, name)


def write_slew_figures(ds: xr.Dataset, out_dir: str | Path, *, dpi: int = 120) -> list[Path]:
    """Write every figure of a closed-loop slew into a folder as PNG.

    Files, in the order of :data:`SLEW_FIGURES` (those of :func:`slew_figure_names`:
    no sliding-surface figures for a law without one): ``attitude.png``
    (:func:`plot_slew_attitude`), ``quaternion.png``, ``pointing.png``,
    ``phase_plane.png``, ``sliding_variables.png``, ``adaptation.png``,
    ``disturbances.png``, ``torque_limits.png``, ``torque_breakdown.png``,
    ``root_deformation.png`` and ``tip_displacement.png``
    (:func:`flexsat.plots.openloop.plot_root_deformation`,
    :func:`~flexsat.plots.openloop.plot_tip_displacement`), ``flex_torque.png``
    and ``energy.png`` (:func:`flexsat.plots.openloop.plot_energy`), then one
    ``<stage>.png`` per loop stage that recorded something
    (:mod:`flexsat.plots.stages`).

    Parameters
    ----------
    ds : xarray.Dataset
        Closed-loop result dataset.
    out_dir : str or Path
        Created if missing; existing files of the same names are replaced.
    dpi : int
        Resolution of the PNG files [dots per inch].

    Returns
    -------
    list of Path
        The files written.
    """
    _scenario(ds)  # fail early on a dataset that is not a slew
    names = slew_figure_names(ds)
    return style.write_figures(out_dir, names, lambda name: plot_slew(ds, name), dpi=dpi)
