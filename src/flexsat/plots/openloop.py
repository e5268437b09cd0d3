"""Figures of an open-loop run (thesis section 3.3, figs. 3.4-3.14).

Each function takes the result dataset of :func:`flexsat.simulate.run_openloop`
(``result.dataset``; see :func:`flexsat.simulate.result.build_dataset` for its
variables) and returns a :class:`matplotlib.figure.Figure` created directly (no
pyplot), so nothing here needs a display or changes the global backend. Time
runs along the horizontal axis in seconds; the intervals in which a torque is
commanded are shaded grey.

- :func:`plot_attitude`: hub ZYX Euler angles [deg] and body rates [deg/s].
- :func:`plot_quaternion`: hub attitude quaternion components.
- :func:`plot_angular_acceleration`: hub angular acceleration per body axis, with
  the yaw ripple after the torque ends magnified.
- :func:`plot_torques`: applied, joint (flexible) and net torque on the hub.
- :func:`plot_root_deformation`: root rotations rho [deg] and translations eta [m]
  of each appendage.
- :func:`plot_tip_displacement`: panel tip displacement of each appendage [mm].
- :func:`plot_angular_momentum`: total and rigid-part angular momentum and their
  difference, the momentum held by the flexible motion.
- :func:`plot_energy`: energy balance, on a linear ("macro") and a logarithmic
  ("micro") scale.
- :func:`plot_spectrogram`: spectrogram of the hub angular acceleration about one
  axis with the coupled modal frequencies overlaid.
- :func:`write_openloop_figures`: all of the above into a folder as PNG.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import xarray as xr
from matplotlib.colors import Normalize
from matplotlib.figure import Figure
from matplotlib.patches import Patch
from scipy.ndimage import maximum_filter1d

from flexsat.analysis.modal import ModalAnalysis
from flexsat.analysis.spectral import dominant_frequency
from flexsat.analysis.time_frequency import (
    DEFAULT_OVERLAP,
    DEFAULT_WINDOW_S,
    HUB_ROTATION_DOF,
    coupled_frequencies,
    spectrogram,
)
from flexsat.plots import style

__all__ = [
    "MEANINGFUL_FRACTION",
    "OPENLOOP_FIGURES",
    "OPENLOOP_MAKERS",
    "meaningful_components",
    "plot_angular_acceleration",
    "plot_angular_momentum",
    "plot_attitude",
    "plot_energy",
    "plot_quaternion",
    "plot_root_deformation",
    "plot_spectrogram",
    "plot_tip_displacement",
    "plot_torques",
    "write_openloop_figures",
]

_ROOT_ROTATION = ("flapping", "torsion", "in-plane")  # rho_x, rho_y, rho_z (mount frame)
_APPENDAGE_STYLES = ("-", "--", "-.", ":")
_RIPPLE_MIN_HZ = 0.05
_SPECTROGRAM_RANGE_DB = 80.0
_TORQUE_SHADE = "0.9"


# -- helpers ---------------------------------------------------------------------------


def _torque_intervals(ds: xr.Dataset) -> list[tuple[float, float]]:
    """[start, end) of each stretch of records in which a torque is commanded [s]."""
    t = style.time_s(ds)
    on = np.abs(np.asarray(ds["tau_cmd"].values)).max(axis=1) > 0.0
    edges = np.diff(np.concatenate([[0], on.astype(np.int8), [0]]))
    starts, ends = np.nonzero(edges == 1)[0], np.nonzero(edges == -1)[0]
    return [(t[a], t[b] if b < t.size else t[-1]) for a, b in zip(starts, ends, strict=True)]


def _free_from(ds: xr.Dataset) -> float | None:
    """Time the last commanded torque ends, or None if one is still on at the end [s]."""
    t = style.time_s(ds)
    intervals = _torque_intervals(ds)
    if not intervals:
        return float(t[0])
    end = intervals[-1][1]
    return None if end >= t[-1] and np.abs(ds["tau_cmd"].values[-1]).max() > 0.0 else float(end)


def _shaded(ds: xr.Dataset) -> bool:
    """Open-loop runs shade their torque pulses; a slew commands torque throughout."""
    return "controller" not in ds.attrs


def _shade_torque(axes, ds: xr.Dataset) -> None:
    intervals = _torque_intervals(ds) if _shaded(ds) else []
    for ax in np.ravel(axes):
        for a, b in intervals:
            ax.axvspan(a, b, color=_TORQUE_SHADE, zorder=0, linewidth=0)


def _torque_patches(ds: xr.Dataset) -> list[Patch]:
    """The legend entry of the shading, when there is shading."""
    return [Patch(color=_TORQUE_SHADE, label="torque commanded")] if _shaded(ds) else []


# -- attitude --------------------------------------------------------------------------


def plot_attitude(ds: xr.Dataset) -> Figure:
    """Hub ZYX Euler angles [deg] and body rates omega [deg/s], one panel per signal.

    A signal is drawn when its peak exceeds :data:`MEANINGFUL_FRACTION` of the
    largest peak of its kind (angles, rates); the others (the roll and pitch of a
    symmetric satellite under a yaw torque, numerically zero) are named in the
    title with their peak instead of getting a flat panel. Each panel has its own
    scale, so the small off-axis motion of an asymmetric satellite stays visible
    next to the large yaw slew.

    Parameters
    ----------
    ds : xarray.Dataset
        Open-loop result dataset.

    Returns
    -------
    matplotlib.figure.Figure
    """
    t = style.time_s(ds)
    euler = np.asarray(ds["euler_deg"].values)
    rate = np.degrees(np.asarray(ds["omega"].values))
    signals, omitted = [], []
    for values, unit, names in (
        (euler, "deg", [f"{name} {symbol}" for name, symbol in style.EULER]),
        (rate, "deg/s", [f"body rate ω_{a} (frame B)" for a in style.AXES]),
    ):
        shown = meaningful_components(values)
        for k in range(3):
            if k in shown:
                signals.append((values[:, k], unit, names[k], k))
            else:
                peak = float(np.nanmax(np.abs(values[:, k])))
                omitted.append(f"{names[k].split(' (')[0]} (peak {peak:.1g} {unit})")
    fig, axes = style.figure(len(signals), 1, size=(11.0, 1.9 + 1.6 * len(signals)))
    _shade_torque(axes, ds)
    for ax, (values, unit, name, k) in zip(axes[:, 0], signals, strict=True):
        style.line(ax, t, values, color=style.AXIS_COLOURS[k], label=name)
        ax.set_ylabel(f"[{unit}]")
        ax.set_title(name, fontsize=10, loc="left")
    if _shaded(ds):
        axes[0, 0].legend(handles=_torque_patches(ds), loc="upper left", fontsize=8)
    style.finish_time_axis(axes, t)
    title = "Hub attitude (ZYX Euler angles) and body rates"
    if omitted:
        title += "\nnot drawn, numerically zero: " + ", ".join(omitted)
    style.suptitle(fig, ds, title)
    return fig


MEANINGFUL_FRACTION = 1e-6
"""A component whose peak is below this fraction of the largest one's is not drawn."""


def meaningful_components(values: np.ndarray) -> list[int]:
    """Columns of ``values`` (shape (m, n)) worth a panel: peak above a fraction of the top.

    The column with the largest peak is always kept, so a flat record still shows.

    Parameters
    ----------
    values : ndarray, shape (m, n)
        One record per row [any unit].

    Returns
    -------
    list of int
        The columns kept.
    """
    peaks = np.nan_to_num(np.nanmax(np.abs(values), axis=0), nan=0.0)
    top = float(peaks.max())
    return [k for k in range(peaks.size) if peaks[k] > MEANINGFUL_FRACTION * top or peaks[k] == top]


def plot_quaternion(ds: xr.Dataset) -> Figure:
    """Hub attitude quaternion components q0 (scalar) and q1-q3 against time.

    Parameters
    ----------
    ds : xarray.Dataset
        Open-loop result dataset.

    Returns
    -------
    matplotlib.figure.Figure
    """
    t = style.time_s(ds)
    quat = np.asarray(ds["quaternion"].values)
    fig, axes = style.figure(1, 1, size=(11.0, 5.0))
    ax = axes[0, 0]
    _shade_torque(axes, ds)
    colours = ("black", *style.AXIS_COLOURS)
    names = ("q0 (scalar)", "q1 (x)", "q2 (y)", "q3 (z)")
    for k in range(4):
        style.line(ax, t, quat[:, k], color=colours[k], label=names[k])
    ax.set_ylabel("quaternion component [-]")
    ax.set_ylim(-1.1, 1.1)
    handles, _ = ax.get_legend_handles_labels()
    ax.legend(handles=[*handles, *_torque_patches(ds)], loc="lower left", fontsize=8, ncols=5)
    style.finish_time_axis(axes, t)
    style.suptitle(fig, ds, "Hub attitude quaternion (scalar first, frame B to N)")
    return fig


# -- angular acceleration --------------------------------------------------------------


def plot_angular_acceleration(ds: xr.Dataset, analysis: ModalAnalysis | None = None) -> Figure:
    """Hub angular acceleration omega_dot per body axis [rad/s^2].

    Three panels (x, y, z) over the whole run, then two views of the yaw
    acceleration after the last commanded torque ends, when any acceleration left
    is the appendages' reaction, the ripple of the coupled flexible modes: a
    close-up of the switch-off (from 2 s before to 8 s after, the grey band the
    torque-on time) and ``|omega_dot_z|`` on a logarithmic scale over the whole
    torque-free phase, where a damped mode decays along a straight line. The
    ripple's strongest spectral line (:func:`dominant_frequency`) is given in the
    title, next to the coupled modal frequencies when an analysis is passed.

    Parameters
    ----------
    ds : xarray.Dataset
        Open-loop result dataset.
    analysis : ModalAnalysis, optional
        Modal analysis of the same satellite, to quote the coupled yaw frequencies.

    Returns
    -------
    matplotlib.figure.Figure
    """
    t = style.time_s(ds)
    acc = np.asarray(ds["omega_dot"].values)
    units = ds["omega_dot"].attrs.get("units", "rad/s^2")
    fig = Figure(figsize=(11.0, 10.5), layout="constrained")
    upper, lower = fig.subfigures(2, 1, height_ratios=(3.0, 1.6))
    axes = list(upper.subplots(3, 1, sharex=True))
    close, decay = lower.subplots(1, 2)
    _shade_torque([*axes, close], ds)
    for k, ax in enumerate(axes):
        style.line(
            ax, t, acc[:, k], color=style.AXIS_COLOURS[k], linewidth=0.9, label=f"ω̇_{style.AXES[k]}"
        )
        ax.set_ylabel(f"ω̇_{style.AXES[k]} [{units}]")
        handles, _ = ax.get_legend_handles_labels()
        ax.legend(handles=handles + (_torque_patches(ds) if k == 0 else []), loc="upper right",
                  fontsize=8)  # fmt: skip
    style.finish_time_axis(np.array(axes)[:, None], t)
    for ax in axes[:2]:
        ax.tick_params(labelbottom=False)

    free_from = _free_from(ds)
    free = t >= free_from if free_from is not None else np.zeros(t.size, bool)
    for ax in (close, decay):
        ax.set_xlabel("time t [s]")
        ax.grid(True, color="0.85", linewidth=0.6)
    close.set_ylabel(f"ω̇_z [{units}]")
    decay.set_ylabel(f"|ω̇_z| [{units}] (log)")
    if free.sum() < 8:
        for ax in (close, decay):
            ax.text(0.5, 0.5, "no torque-free phase in this run", ha="center", va="center",
                    transform=ax.transAxes, color="0.4")  # fmt: skip
        style.suptitle(fig, ds, "Hub angular acceleration ω̇ (frame B)")
        return fig

    window = (t >= free_from - 2.0) & (t <= free_from + 8.0)
    close.plot(t[window], acc[window, 2], color=style.AXIS_COLOURS[2], linewidth=1.0)
    close.axvline(free_from, color="black", linewidth=0.8, linestyle=":")
    close.set_xlim(t[window][0], t[window][-1])
    close.set_title(f"close-up: torque switched off at t = {free_from:.3g} s", fontsize=10)
    ripple = np.abs(acc[free, 2])
    style.line(
        decay,
        t[free],
        style.positive(ripple),
        color=style.AXIS_COLOURS[2],
        linewidth=0.5,
        alpha=0.35,
        label="|ω̇_z|",
    )
    decay.set_yscale("log")
    decay.set_xlim(t[free][0], t[-1])
    decay_title = "decay of the ripple with no torque applied"

    title = f"Yaw ripple after the torque ends (t ≥ {free_from:.3g} s)"
    f = 0.0
    if free.sum() >= 64:
        dt = float(t[1] - t[0])
        f = dominant_frequency(acc[free, 2], dt, _RIPPLE_MIN_HZ)
    if f > 0.0:  # no line when the yaw acceleration has no ripple (none excited)
        title += f": dominant line {f:.4g} Hz"
        envelope = maximum_filter1d(ripple, size=max(3, round(1.0 / (f * dt))))
        style.line(
            decay,
            t[free],
            style.positive(envelope),
            color=style.AXIS_COLOURS[2],
            linewidth=1.4,
            label="envelope (max over one period)",
        )
        rate = _decay_rate(t[free], envelope)
        if rate is not None:
            decay_title = (f"ripple decay, no torque: σ = {rate:.3g} 1/s, "
                           f"ζ ≈ σ/(2πf) = {rate / (2 * np.pi * f):.3g}")  # fmt: skip
        decay.legend(loc="upper right", fontsize=8)
    decay.set_title(decay_title, fontsize=10)
    if analysis is not None:
        lines = coupled_frequencies(analysis, "z")
        if lines.size:
            title += f"; modes coupled to yaw: {', '.join(f'{v:.4g}' for v in lines)} Hz"
    lower.suptitle(title, fontsize=10)
    style.suptitle(fig, ds, "Hub angular acceleration ω̇ (frame B)")
    return fig


def _decay_rate(t: np.ndarray, envelope: np.ndarray) -> float | None:
    """Exponential decay rate sigma [1/s] of an envelope, fitted on its log above the floor.

    Only the part above 1e-7 of its peak counts (below that round-off shows); None
    if the envelope does not decay or too little of it is left.
    """
    usable = envelope > 1e-7 * envelope.max()
    if usable.sum() < 16 or envelope.max() <= 0.0:
        return None
    slope = np.polyfit(t[usable], np.log(envelope[usable]), 1)[0]
    return float(-slope) if slope < 0.0 else None


# -- torques ---------------------------------------------------------------------------


def plot_torques(ds: xr.Dataset) -> Figure:
    """Torques on the hub per body axis [N m]: applied tau, joint tau_flex, net sum.

    ``tau_flex`` is the torque of the appendages' root joints on the hub about its
    centre of mass; ``tau_net = tau + tau_flex``. The z panel, the commanded axis of
    the thesis's scenario, is drawn taller.

    Parameters
    ----------
    ds : xarray.Dataset
        Open-loop result dataset.

    Returns
    -------
    matplotlib.figure.Figure
    """
    t = style.time_s(ds)
    applied = np.asarray(ds["tau_applied"].values)
    flex = np.asarray(ds["tau_flex"].values)
    net = np.asarray(ds["tau_net"].values)
    fig, axes = style.figure(3, 1, size=(11.0, 9.0), height_ratios=(1, 1, 2))
    _shade_torque(axes, ds)
    for k in range(3):
        ax = axes[k, 0]
        style.line(
            ax, t, applied[:, k], color="black", linewidth=1.4, label=f"τ_{style.AXES[k]} applied"
        )
        style.line(
            ax,
            t,
            flex[:, k],
            color="tab:orange",
            linewidth=0.9,
            label=f"τ_flex,{style.AXES[k]} (joints on hub)",
        )
        style.line(
            ax,
            t,
            net[:, k],
            color="tab:blue",
            linewidth=0.9,
            alpha=0.85,
            label=f"τ_net,{style.AXES[k]} = τ + τ_flex",
        )
        ax.set_ylabel(f"torque about {style.AXES[k]}_B [N m]")
        ax.set_title(
            f"{style.AXES[k]} axis  (peak |τ_flex| = {np.abs(flex[:, k]).max():.3g} N m)",
            fontsize=10,
        )
        handles, _ = ax.get_legend_handles_labels()
        ax.legend(handles=[*handles, *_torque_patches(ds)], loc="upper right", fontsize=8, ncols=2)
    style.finish_time_axis(axes, t)
    style.suptitle(fig, ds, "Torques on the hub: applied, flexible reaction, net (frame B)")
    return fig


# -- appendages ------------------------------------------------------------------------


def _appendage_names(ds: xr.Dataset) -> list[str]:
    return [style.literal(a) for a in ds["appendage"].values]


def plot_root_deformation(ds: xr.Dataset) -> Figure:
    """Root-joint deformations of each appendage (mount frame).

    Left column: the ZYX root rotations rho_x (flapping), rho_y (torsion), rho_z
    (in-plane bending) [deg]; right column: the root translations eta_x, eta_y,
    eta_z [m]. One line per appendage (colour and dash differ, so coinciding
    lines of a symmetric satellite both stay visible); an appendage without a root
    joint (a modal one: its records are NaN) is named in the title, not drawn.

    Parameters
    ----------
    ds : xarray.Dataset
        Open-loop result dataset.

    Returns
    -------
    matplotlib.figure.Figure
    """
    t = style.time_s(ds)
    rho = np.degrees(np.asarray(ds["rho"].values))
    eta = np.asarray(ds["eta"].values)
    eta_units = ds["eta"].attrs.get("units", "m")
    names = _appendage_names(ds)
    jointed = [j for j in range(len(names))
               if np.isfinite(rho[:, j]).any() or np.isfinite(eta[:, j]).any()]  # fmt: skip
    fig, axes = style.figure(3, 2, size=(13.0, 9.0))
    _shade_torque(axes, ds)
    for k in range(3):
        for j in jointed:
            name = names[j]
            look = {"color": f"C{j % 10}", "linestyle": _APPENDAGE_STYLES[j % 4],
                     "linewidth": 1.0, "label": name}  # fmt: skip
            style.line(axes[k, 0], t, rho[:, j, k], **look)
            style.line(axes[k, 1], t, eta[:, j, k], **look)
        axes[k, 0].set_ylabel(f"ρ_{style.AXES[k]} [deg]")
        axes[k, 0].set_title(f"root rotation ρ_{style.AXES[k]} ({_ROOT_ROTATION[k]})", fontsize=10)
        axes[k, 1].set_ylabel(f"η_{style.AXES[k]} [{eta_units}]")
        axes[k, 1].set_title(f"root translation η_{style.AXES[k]}", fontsize=10)
    handles, _ = axes[0, 0].get_legend_handles_labels()
    items = [*handles, *_torque_patches(ds)]
    style.figure_legend(fig, items, [item.get_label() for item in items], len(handles) + 1)
    style.finish_time_axis(axes, t)
    title = "Appendage root-joint deformations (mount frame)"
    if len(jointed) < len(names):
        unjointed = ", ".join(n for j, n in enumerate(names) if j not in jointed)
        title += f"; no root joint: {unjointed}"
    style.suptitle(fig, ds, title)
    return fig


def plot_tip_displacement(ds: xr.Dataset) -> Figure:
    """Panel tip displacement of each appendage [mm], mount frame.

    One panel per appendage with the x, y, z components and the magnitude (black).

    Parameters
    ----------
    ds : xarray.Dataset
        Open-loop result dataset.

    Returns
    -------
    matplotlib.figure.Figure
    """
    t = style.time_s(ds)
    tips = 1e3 * np.asarray(ds["tip_displacement"].values)  # m -> mm
    names = _appendage_names(ds)
    n = len(names)
    fig, axes = style.figure(max(n, 1), 1, size=(11.0, 2.0 + 2.6 * max(n, 1)))
    _shade_torque(axes, ds)
    for j, name in enumerate(names):
        ax = axes[j, 0]
        norm = np.linalg.norm(tips[:, j], axis=-1)
        for k in range(3):
            style.line(
                ax,
                t,
                tips[:, j, k],
                color=style.AXIS_COLOURS[k],
                linewidth=0.9,
                label=f"δ_{style.AXES[k]}",
            )
        style.line(ax, t, norm, color="black", linewidth=0.8, linestyle=":", label="|δ|")
        ax.set_ylabel("tip displacement [mm]")
        ax.set_title(f"{name}  (peak |δ| = {norm.max():.3g} mm)", fontsize=10)
    handles, _ = axes[0, 0].get_legend_handles_labels()
    items = [*handles, *_torque_patches(ds)]
    style.figure_legend(fig, items, [item.get_label() for item in items], len(handles) + 1)
    style.finish_time_axis(axes, t)
    style.suptitle(fig, ds, "Panel tip displacement (mount frame)")
    return fig


# -- angular momentum ------------------------------------------------------------------


def plot_angular_momentum(ds: xr.Dataset) -> Figure:
    """Angular momentum about the system centre of mass, inertial components [N m s].

    Top: the total angular momentum H (solid) and its rigid part J(eta) omega, the
    locked-satellite inertia times the hub rate (dashed). Bottom: their difference
    H - J(eta) omega, the momentum carried by the appendages' motion relative to
    the hub: while the torque acts it grows, afterwards it oscillates while the
    total stays constant — the exchange between hub and appendages.

    Parameters
    ----------
    ds : xarray.Dataset
        Open-loop result dataset.

    Returns
    -------
    matplotlib.figure.Figure
    """
    t = style.time_s(ds)
    H = np.asarray(ds["angular_momentum"].values)
    rigid = np.asarray(ds["rigid_angular_momentum"].values)
    units = ds["angular_momentum"].attrs.get("units", "N m s")
    fig, axes = style.figure(2, 1, size=(11.0, 8.0), height_ratios=(1.3, 1))
    _shade_torque(axes, ds)
    for k in range(3):
        c = style.AXIS_COLOURS[k]
        style.line(axes[0, 0], t, H[:, k], color=c, linewidth=1.6, label=f"H_{style.AXES[k]} total")
        style.line(
            axes[0, 0],
            t,
            rigid[:, k],
            color=c,
            linewidth=1.0,
            linestyle="--",
            label=f"(J(η)ω)_{style.AXES[k]} rigid part",
        )
        style.line(
            axes[1, 0],
            t,
            H[:, k] - rigid[:, k],
            color=c,
            linewidth=0.9,
            label=f"H_{style.AXES[k]} − (J(η)ω)_{style.AXES[k]}",
        )
    free_from = _free_from(ds)
    drift = ""
    if free_from is not None and free_from < t[-1]:
        free = t >= free_from
        spread = np.abs(H[free] - H[free][0]).max()
        drift = f"  (|H − H(t={free_from:.3g} s)| ≤ {spread:.2g} {units} with no torque)"
    axes[0, 0].set_title(f"total H and rigid part J(η)ω, frame N{drift}", fontsize=10)
    axes[0, 0].set_ylabel(f"angular momentum [{units}]")
    axes[1, 0].set_title("flexible part H − J(η)ω: momentum exchanged with the appendages",
                         fontsize=10)  # fmt: skip
    axes[1, 0].set_ylabel(f"H − J(η)ω [{units}]")
    handles, _ = axes[0, 0].get_legend_handles_labels()
    axes[0, 0].legend(handles=[*handles, *_torque_patches(ds)], loc="center right", fontsize=8,
                      ncols=2)  # fmt: skip
    handles, _ = axes[1, 0].get_legend_handles_labels()
    axes[1, 0].legend(handles=handles, loc="upper right", fontsize=8)
    style.finish_time_axis(axes, t)
    style.suptitle(fig, ds, "Angular momentum about the system centre of mass (frame N)")
    return fig


# -- energy ----------------------------------------------------------------------------


def plot_energy(ds: xr.Dataset) -> Figure:
    """Energy balance [J]: the "macro" view (linear) and the "micro" view (log).

    Top: kinetic energy T, elastic energy U, total E = T + U, cumulative work of
    the applied torque W_in and cumulative damper dissipation W_diss; E tracks
    W_in - W_diss. Bottom, on a logarithmic scale: U, W_diss and the magnitude of
    the balance error ‖E - E(0) - W_in + W_diss‖, the integration's numerical error.

    Parameters
    ----------
    ds : xarray.Dataset
        Open-loop result dataset.

    Returns
    -------
    matplotlib.figure.Figure
    """
    t = style.time_s(ds)
    kinetic = np.asarray(ds["kinetic_energy"].values)
    elastic = np.asarray(ds["elastic_energy"].values)
    total = np.asarray(ds["total_energy"].values)
    work = np.asarray(ds["work_in"].values)
    dissipated = np.asarray(ds["dissipated_energy"].values)
    error = np.abs(np.asarray(ds["energy_balance_error"].values))
    fig, axes = style.figure(2, 1, size=(11.0, 8.5))
    _shade_torque(axes, ds)
    macro, micro = axes[0, 0], axes[1, 0]
    style.line(macro, t, work, color="black", linewidth=2.4, alpha=0.35, label="W_in (work of τ)")
    style.line(macro, t, total, color="tab:purple", linewidth=1.2, label="E = T + U")
    style.line(
        macro, t, kinetic, color="tab:blue", linewidth=1.0, linestyle="--", label="T kinetic"
    )
    style.line(macro, t, elastic, color="tab:orange", linewidth=1.0, label="U elastic")
    style.line(macro, t, dissipated, color="tab:red", linewidth=1.0, label="W_diss (dissipated)")
    macro.set_ylabel("energy [J]")
    macro.set_title("macro: energy flow (linear scale)", fontsize=10)

    style.line(
        micro, t, style.positive(elastic), color="tab:orange", linewidth=0.9, label="U elastic"
    )
    style.line(
        micro,
        t,
        style.positive(dissipated),
        color="tab:red",
        linewidth=0.9,
        label="W_diss (dissipated)",
    )
    style.line(
        micro,
        t,
        style.positive(error),
        color="black",
        linewidth=0.9,
        label="|E − E(0) − W_in + W_diss| (integration error)",
    )
    micro.set_yscale("log")
    micro.set_ylabel("energy [J] (log)")
    relative = error.max() / max(np.abs(work).max(), np.abs(total).max(), np.finfo(float).tiny)
    micro.set_title(f"micro: elastic energy and balance error (log scale); max error "
                    f"{error.max():.2g} J = {relative:.2g} of the energy put in",
                    fontsize=10)  # fmt: skip
    for ax in (macro, micro):
        handles, _ = ax.get_legend_handles_labels()
        ax.legend(handles=[*handles, *_torque_patches(ds)], loc="center right", fontsize=8)
    style.finish_time_axis(axes, t)
    style.suptitle(fig, ds, "Energy balance")
    return fig


# -- spectrogram -----------------------------------------------------------------------


def plot_spectrogram(
    ds: xr.Dataset,
    analysis: ModalAnalysis | None = None,
    axis: str = "z",
    *,
    max_hz: float = 3.0,
    window_s: float = DEFAULT_WINDOW_S,
    overlap: float = DEFAULT_OVERLAP,
) -> Figure:
    """Spectrogram of the detrended hub angular acceleration about one body axis.

    Left: power spectral density of omega_dot about ``axis`` (see
    :func:`flexsat.analysis.time_frequency.spectrogram`) in dB relative to
    1 (rad/s^2)^2/Hz over 0 to ``max_hz``, colour range the top 80 dB, each
    column at the centre time of its window. Right: the same spectrum averaged
    over time. The natural frequencies of the flexible modes that drive the hub
    about ``axis`` (:func:`flexsat.analysis.time_frequency.coupled_frequencies`) are
    overlaid as dashed lines when an analysis is given.

    Parameters
    ----------
    ds : xarray.Dataset
        Open-loop result dataset.
    analysis : ModalAnalysis, optional
        Modal analysis of the same satellite, for the modal lines.
    axis : {"x", "y", "z"}
        Body axis of the angular acceleration.
    max_hz : float
        Upper end of the frequency axis [Hz].
    window_s, overlap : float
        Window length [s] and overlap fraction, see :func:`spectrogram`.

    Returns
    -------
    matplotlib.figure.Figure
    """
    if axis not in style.AXES:
        raise ValueError(f"axis must be one of x, y, z, got {axis!r}")
    k = style.AXES.index(axis)
    t = style.time_s(ds)
    units = ds["omega_dot"].attrs.get("units", "rad/s^2")
    fig = Figure(figsize=(12.0, 6.5), layout="constrained")
    grid = fig.add_gridspec(1, 2, width_ratios=(4, 1))
    ax = fig.add_subplot(grid[0])
    side = fig.add_subplot(grid[1], sharey=ax)
    style.suptitle(fig, ds, f"Spectrogram of the hub angular acceleration ω̇_{axis} (detrended)")
    ax.set_ylim(0.0, max_hz)
    ax.set_ylabel("frequency [Hz]")
    ax.set_xlabel("time t [s] (window centre)")
    side.set_xlabel("mean PSD [dB]")
    side.tick_params(labelleft=False)
    if t.size < 16:
        ax.text(0.5, 0.5, "record too short for a spectrogram", ha="center", va="center",
                transform=ax.transAxes, color="0.4")  # fmt: skip
        return fig

    dt = float(t[1] - t[0])
    freqs, times, power = spectrogram(ds["omega_dot"].values[:, k], dt, window_s, overlap)
    band = freqs <= max_hz * 1.02
    freqs, power = freqs[band], power[band]
    tiny = np.finfo(float).tiny
    level = 10.0 * np.log10(np.maximum(power, tiny))
    top = float(level.max())
    norm = Normalize(vmin=top - _SPECTROGRAM_RANGE_DB, vmax=top)
    mesh = ax.pcolormesh(t[0] + times, freqs, level, shading="nearest", cmap="viridis",
                         norm=norm, rasterized=True)  # fmt: skip
    bar = fig.colorbar(mesh, ax=side, pad=0.02)
    bar.set_label(f"PSD [dB re 1 ({units})²/Hz]")
    mean = 10.0 * np.log10(np.maximum(power.mean(axis=1), tiny))
    side.plot(mean, freqs, color="black", linewidth=1.0, label="time average")
    side.set_xlim(top - _SPECTROGRAM_RANGE_DB, max(top, mean.max()) + 3.0)
    side.grid(True, color="0.85", linewidth=0.6)

    n_seg = window_s / dt
    ax.set_title(
        f"window {min(window_s, t[-1] - t[0]):.3g} s (Hann, {overlap:.0%} overlap), "
        f"bins {1.0 / (min(n_seg, t.size) * dt):.3g} Hz; torque-on intervals: "
        + (", ".join(f"{a:.3g}–{b:.3g} s" for a, b in _torque_intervals(ds)) or "none"),
        fontsize=10,
    )
    handles = []
    if analysis is not None:
        lines = coupled_frequencies(analysis, axis)
        dof = HUB_ROTATION_DOF[axis]
        by_freq = {m.frequency_hz: m for m in analysis.modes if m.hub_dof == dof}
        for j, f in enumerate(lines[lines <= max_hz]):
            mode = by_freq.get(f)
            label = f"{f:.4g} Hz"
            if mode is not None:
                symmetry = "no mirror parity" if mode.symmetry == "none" else mode.symmetry
                label = (f"mode {mode.index}: {f:.4g} Hz, {mode.kind.replace('_', '-')}, "
                         f"{symmetry}")  # fmt: skip
            colour = ("white", "tab:red", "tab:orange", "magenta")[j % 4]
            h = ax.axhline(f, color=colour, linestyle="--", linewidth=1.3, label=label)
            side.axhline(f, color=colour, linestyle="--", linewidth=1.0)
            handles.append(h)
        if handles:
            leg = ax.legend(handles=handles, loc="upper right", fontsize=8,
                            title=f"flexible modes driving the hub about {axis}_B ({dof})",
                            title_fontsize=8, framealpha=0.85)  # fmt: skip
            leg.get_frame().set_facecolor("0.3")
            for text in [*leg.get_texts(), leg.get_title()]:
                text.set_color("white")
        else:
            ax.text(0.99, 0.98, f"no flexible mode below {max_hz:.3g} Hz drives hub {dof}",
                    ha="right", va="top", transform=ax.transAxes, color="white",
                    fontsize=8)  # fmt: skip
    return fig


# -- everything at once ----------------------------------------------------------------


OPENLOOP_MAKERS = {
    "attitude": lambda ds, analysis: plot_attitude(ds),
    "quaternion": lambda ds, analysis: plot_quaternion(ds),
    "angular_acceleration": plot_angular_acceleration,
    "torques": lambda ds, analysis: plot_torques(ds),
    "root_deformation": lambda ds, analysis: plot_root_deformation(ds),
    "tip_displacement": lambda ds, analysis: plot_tip_displacement(ds),
    "angular_momentum": lambda ds, analysis: plot_angular_momentum(ds),
    "energy": lambda ds, analysis: plot_energy(ds),
    "spectrogram": lambda ds, analysis: plot_spectrogram(ds, analysis, "z"),
}
"""Each open-loop figure's drawing function, ``(dataset, modal analysis or None) -> Figure``."""

OPENLOOP_FIGURES = tuple(OPENLOOP_MAKERS)
"""Names (without ``.png``) of the files :func:`write_openloop_figures` writes, in order."""


def write_openloop_figures(
    ds: xr.Dataset,
    analysis: ModalAnalysis | None,
    out_dir: str | Path,
    *,
    dpi: int = 120,
) -> list[Path]:
    """Write every open-loop figure of a run into a folder as PNG.

    Files, in this order: ``attitude.png`` (:func:`plot_attitude`),
    ``quaternion.png``, ``angular_acceleration.png``, ``torques.png``,
    ``root_deformation.png``, ``tip_displacement.png``, ``angular_momentum.png``,
    ``energy.png`` and ``spectrogram.png`` (yaw, 0-3 Hz) — see
    :data:`OPENLOOP_FIGURES`.

    Parameters
    ----------
    ds : xarray.Dataset
        Open-loop result dataset.
    analysis : ModalAnalysis or None
        Modal analysis of the same satellite, for the modal frequencies on the
        spectrogram and in the yaw-ripple title; None leaves them out.
    out_dir : str or Path
        Created if missing; existing files of the same names are replaced.
    dpi : int
        Resolution of the PNG files [dots per inch].

    Returns
    -------
    list of Path
        The files written.
    """
    return style.write_figures(
        out_dir, OPENLOOP_FIGURES, lambda name: OPENLOOP_MAKERS[name](ds, analysis), dpi=dpi
    )
