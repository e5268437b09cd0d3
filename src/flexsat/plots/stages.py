"""Figures of the loop stages' records: one per stage of a slew that records something.

A stage declares what it records (``StageSpec.records``, each a
:class:`~flexsat.control.registry.Channel` with its units); each record is a
variable of the result. Every stage a run flew with records gets a figure named
after the stage (``wheels``, ``mekf``, ``gyro``...), so a stage of a user's own
file, once registered, is drawn too, with nothing more to write:

- :func:`plot_stage_records`: any stage, one panel per recorded channel (per-axis
  channels as their x, y, z components), in units chosen for reading
  (:func:`readable_units`: degrees or arcseconds for ``rad``, deg/s or deg/h for
  ``rad/s``);
- :func:`plot_estimation`: the MEKF's attitude error per axis inside its ±3σ
  covariance bound, the estimated gyro bias beside the true one, and the
  normalized estimation error squared (NEES) against its χ² 95 % interval;
- :func:`plot_wheels`: the wheel cluster's momentum, the fullest wheel against
  its speed limit with the saturated intervals, and its energy flows.

A stage with a figure of its own is one entry of :data:`STAGE_FIGURES`.
"""

from __future__ import annotations

import json
from collections.abc import Callable
from math import pi

import numpy as np
import xarray as xr
from matplotlib.axes import Axes
from matplotlib.figure import Figure
from scipy.stats import chi2

from flexsat.analysis.requirements import actuator_saturation_times
from flexsat.control.registry import Channel
from flexsat.control.stages.registry import (
    ACTUATORS,
    JOINT_ACTUATORS,
    REFERENCES,
    SENSORS,
    StageSpec,
)
from flexsat.control.stages.wheels import SATURATED_RATIO
from flexsat.plots import style

__all__ = [
    "NEES_PROBABILITY",
    "STAGE_FIGURES",
    "flown_stages",
    "plot_estimation",
    "plot_stage",
    "plot_stage_records",
    "plot_wheels",
    "readable_units",
    "stage_figure_names",
    "zero_crossings",
]

_REGISTRIES = {"reference": REFERENCES, "sensor": SENSORS, "joint_actuator": JOINT_ACTUATORS,
               "actuator": ACTUATORS}  # fmt: skip
_LOOP_ORDER = (("reference", "reference"), ("sensor", "sensor"), ("sensor", "sensor_stages"),
               ("joint_actuator", "joint_actuator"), ("actuator", "actuator_stages"),
               ("actuator", "actuator"))  # fmt: skip
"""(role, scenario field) of the stages, in the order the loop runs them."""
_ARCSEC = 180.0 / pi * 3600.0  # [arcsec per rad]
_READABLE = {
    "rad": (("deg", 180.0 / pi), ("arcsec", _ARCSEC)),
    "rad/s": (("deg/s", 180.0 / pi), ("deg/h", _ARCSEC)),
}
"""Display units of recorded SI units, largest first: the first in which the peak
value reaches :data:`_SMALLEST_SHOWN` is used."""
_SMALLEST_SHOWN = 0.01
NEES_PROBABILITY = 0.95
"""Probability of the two-sided χ² interval drawn around the NEES."""


def flown_stages(ds: xr.Dataset) -> tuple[StageSpec, ...]:
    """The stages a run flew that recorded something, in the order the loop runs them.

    Read from the scenario stored with the run: the reference, the sensor and its
    chain, the joint actuator, the actuation chain and the actuator.

    Parameters
    ----------
    ds : xarray.Dataset
        A slew's dataset.

    Returns
    -------
    tuple of StageSpec
        The stages with records; one not registered in this process (a user's own,
        its module not imported) is left out.
    """
    scenario = json.loads(ds.attrs.get("scenario", "{}"))
    kinds = []
    for role, key in _LOOP_ORDER:
        entry = scenario.get(key)
        for table in entry if isinstance(entry, list) else [entry]:
            if isinstance(table, dict) and (role, table.get("kind")) not in kinds:
                kinds.append((role, table.get("kind")))
    specs = (_REGISTRIES[role].get(kind) for role, kind in kinds
             if kind in _REGISTRIES[role].names())  # fmt: skip
    return tuple(s for s in specs if s.records and s.records[0].name in ds.data_vars)


def stage_figure_names(ds: xr.Dataset) -> tuple[str, ...]:
    """Names of the stage figures of a run: each flown stage's name (:func:`flown_stages`).

    Parameters
    ----------
    ds : xarray.Dataset
        A slew's dataset.

    Returns
    -------
    tuple of str
        The figure names.
    """
    return tuple(spec.name for spec in flown_stages(ds))


def plot_stage(ds: xr.Dataset, name: str) -> Figure:
    """The figure of the stage ``name``: its own (:data:`STAGE_FIGURES`) or the generic one.

    Parameters
    ----------
    ds : xarray.Dataset
        A slew's dataset.
    name : str
        One of :func:`stage_figure_names`.

    Returns
    -------
    Figure
        The figure.
    """
    (spec,) = (s for s in flown_stages(ds) if s.name == name)
    return STAGE_FIGURES.get(name, plot_stage_records)(ds, spec)


def readable_units(values: np.ndarray, units: str) -> tuple[float, str]:
    """The factor and the unit a recorded quantity is shown in.

    Angles and rates recorded in ``rad`` and ``rad/s`` are shown in the largest of
    deg and arcsec, deg/s and deg/h, in which their peak reaches 0.01 (a 5 arcsec
    star-tracker noise in arcsec, a 0.05 deg/h gyro bias in deg/h); other units as
    recorded.

    Parameters
    ----------
    values : ndarray
        The recorded values [``units``].
    units : str
        Their units.

    Returns
    -------
    factor : float
        Shown = recorded * factor [unit shown per recorded unit].
    unit : str
        The unit shown.
    """
    choices = _READABLE.get(units)
    if choices is None:
        return 1.0, units
    finite = np.abs(values[np.isfinite(values)])
    peak = float(finite.max()) if finite.size else 0.0
    for unit, factor in choices:
        if peak * factor >= _SMALLEST_SHOWN:
            return factor, unit
    return choices[-1][1], choices[-1][0]


def _channel(ds: xr.Dataset, channel: Channel) -> np.ndarray:
    """A record as floats, shape (m, 3) for a per-axis channel, (m, units) for a
    per-unit one, (m,) otherwise."""
    return np.asarray(ds.variables[channel.name].values, dtype=float)


def _draw_channel(ax: Axes, t: np.ndarray, values: np.ndarray, channel: Channel) -> None:
    factor, unit = readable_units(values, channel.units)
    if channel.per_axis:
        for k in range(3):
            style.line(ax, t, factor * values[:, k], color=style.AXIS_COLOURS[k],
                       linewidth=1.0, label=style.AXES[k])  # fmt: skip
        ax.legend(loc="upper right", fontsize=8, ncols=3)
    elif channel.per_unit:
        units = [k for k in range(values.shape[1]) if np.isfinite(values[:, k]).any()]
        for k in units:
            style.line(ax, t, factor * values[:, k], color=f"C{k}", linewidth=1.0,
                       label=f"unit {k + 1}")  # fmt: skip
        ax.legend(loc="upper right", fontsize=8, ncols=max(min(len(units), 6), 1))
    else:
        style.line(ax, t, factor * values, color="tab:blue", linewidth=1.0)
    # tick labels of at most 4 digits, the power of ten above the axis: a 1e-4 W power's
    # "-0.00015" pushed its label out of the figure's fixed left margin
    ax.ticklabel_format(axis="y", style="sci", scilimits=(-3, 4), useMathText=True)
    ax.set_ylabel(style.literal(f"{channel.name} [{unit}]"), fontsize=9)  # a user stage's words
    ax.set_title(style.literal(channel.description), fontsize=10)


def plot_stage_records(ds: xr.Dataset, spec: StageSpec) -> Figure:
    """Every record of one stage against time, one panel per channel.

    Parameters
    ----------
    ds : xarray.Dataset
        A slew's dataset holding the stage's records.
    spec : StageSpec
        The stage (:func:`flown_stages`).

    Returns
    -------
    Figure
        The figure.
    """
    t = style.time_s(ds)
    channels = [c for c in spec.records if c.name in ds.data_vars]
    fig, axes = style.figure(len(channels), 1, size=(11.0, 1.5 + 2.3 * len(channels)))
    for ax, channel in zip(axes[:, 0], channels, strict=True):
        _draw_channel(ax, t, _channel(ds, channel), channel)
    style.finish_time_axis(axes, t)
    style.suptitle(fig, ds, style.literal(f"{spec.name} ({spec.role}): {spec.description}"))
    return fig


def plot_estimation(ds: xr.Dataset, spec: StageSpec) -> Figure:
    """The MEKF: attitude error inside ±3σ, gyro bias estimate, NEES against χ².

    Left column, per body axis: the estimation error 2 vec(q̂⁻¹ ⊗ q_true) [arcsec]
    with the filter's ±3σ (σ = sqrt(diag P) of the attitude). Right column, per
    axis: the estimated gyro bias b̂ inside its ±3σ (σ = sqrt(diag P) of the bias)
    against the gyro's true bias when the run recorded it [deg/h]. Bottom: the NEES
    eᵀ P⁻¹ e of the attitude, χ² with 3 degrees of freedom for a consistent filter,
    with its two-sided 95 % interval, the share of records inside it and its mean
    (3 when consistent).

    Parameters
    ----------
    ds : xarray.Dataset
        A slew's dataset with the MEKF's records.
    spec : StageSpec
        The MEKF stage.

    Returns
    -------
    Figure
        The figure.
    """
    t = style.time_s(ds)
    error = _values(ds, "estimation_error") * _ARCSEC
    sigma3 = 3.0 * _values(ds, "estimation_sigma") * _ARCSEC
    bias_hat = _values(ds, "estimated_gyro_bias") * _ARCSEC
    bias_sigma3 = (3.0 * _values(ds, "estimated_gyro_bias_sigma") * _ARCSEC
                   if "estimated_gyro_bias_sigma" in ds.data_vars else None)  # fmt: skip
    bias = _values(ds, "gyro_bias") * _ARCSEC if "gyro_bias" in ds.data_vars else None
    nees = _values(ds, "estimation_nees")
    fig, axes = style.figure(4, 2, size=(13.0, 10.5))
    for k, a in enumerate(style.AXES):
        ax = axes[k, 0]
        ax.fill_between(*style.envelope(t, sigma3[:, k]), color="0.85", label="±3σ (filter)")
        ax.fill_between(*style.envelope(t, -sigma3[:, k]), color="0.85")
        style.line(ax, t, error[:, k], color="tab:blue", linewidth=0.9, label="estimation error")
        inside = np.mean(np.abs(error[:, k]) <= sigma3[:, k])
        rms = np.sqrt(np.nanmean(error[:, k] ** 2))
        ax.set_ylabel(f"δθ_{a} [arcsec]")
        ax.set_title(f"axis {a}: RMS {rms:.3g} arcsec, {100 * inside:.1f} % inside ±3σ",
                     fontsize=10)  # fmt: skip
        ax = axes[k, 1]
        if bias_sigma3 is not None:
            ax.fill_between(t, bias_hat[:, k] - bias_sigma3[:, k],
                            bias_hat[:, k] + bias_sigma3[:, k], color="0.85",
                            label="b̂ ± 3σ (filter)")  # fmt: skip
        if bias is not None:
            style.line(ax, t, bias[:, k], color="0.2", linewidth=1.2, label="true bias (gyro)")
        style.line(ax, t, bias_hat[:, k], color="tab:orange", linewidth=1.0,
                   label="estimated bias b̂")  # fmt: skip
        ax.set_ylabel(f"b_{a} [deg/h]")
        ax.set_title(f"gyro bias, axis {a}", fontsize=10)
    low, high = chi2.interval(NEES_PROBABILITY, 3)
    ax = axes[3, 0]
    style.line(ax, t, style.positive(nees), color="tab:purple", linewidth=0.8, label="NEES")
    for bound, label in ((low, f"χ²(3) {100 * NEES_PROBABILITY:.0f} % interval"), (high, None)):
        ax.axhline(bound, color=style.BAND, linestyle="--", linewidth=1.0, label=label)
    ax.set_yscale("log")
    share = np.mean((nees > low) & (nees < high))
    ax.set_ylabel("eᵀ P⁻¹ e [-]")
    ax.set_title(f"NEES: {100 * share:.1f} % inside the χ²(3) {100 * NEES_PROBABILITY:.0f} % "
                 f"interval [{low:.3g}, {high:.3g}], mean {np.nanmean(nees):.3g} (3 if "
                 "consistent)", fontsize=10)  # fmt: skip
    ax = axes[3, 1]
    for k in range(3):
        style.line(ax, t, style.positive(sigma3[:, k] / 3.0), color=style.AXIS_COLOURS[k],
                   linewidth=1.0, label=f"σ_{style.AXES[k]}")  # fmt: skip
    ax.set_yscale("log")
    ax.set_ylabel("σ [arcsec]")
    ax.set_title("attitude 1σ of the filter (sqrt(diag P))", fontsize=10)
    for ax in (axes[0, 0], axes[0, 1], axes[3, 0], axes[3, 1]):
        ax.legend(loc="upper right", fontsize=8, ncols=3)
    style.finish_time_axis(axes, t)
    style.suptitle(fig, ds, "Attitude estimation (MEKF): error, covariance, gyro bias")
    return fig


def plot_wheels(ds: xr.Dataset, spec: StageSpec) -> Figure:
    """The reaction wheels: momentum, the fullest wheel against its limit, energy.

    Top: the cluster's momentum Σ a_i h_i per hub axis [N m s]. Middle: the
    fullest wheel's momentum as a share of its limit I_s Ω_max [%], the
    intervals where a wheel is held at its limit shaded and the first
    saturation of each wheel in the title. Third: each wheel's speed h_i / I_s
    [rpm] against ±Ω_max, its zero crossings and the largest motor torque asked of
    a wheel (R3's) in the title. Bottom: the wheels' kinetic energy
    Σ h_i² / (2 I_s), the motor work and the friction loss [J].

    Parameters
    ----------
    ds : xarray.Dataset
        A slew's dataset with the wheels' records.
    spec : StageSpec
        The wheel stage.

    Returns
    -------
    Figure
        The figure.
    """
    t = style.time_s(ds)
    momentum = _values(ds, "wheel_momentum_B")
    ratio = 100.0 * _values(ds, "wheel_speed_ratio")
    fig, axes = style.figure(4, 1, size=(11.0, 12.0))
    ax = axes[0, 0]
    for k in range(3):
        style.line(ax, t, momentum[:, k], color=style.AXIS_COLOURS[k], linewidth=1.0,
                   label=f"h_{style.AXES[k]}")  # fmt: skip
    ax.set_ylabel("Σ a_i h_i [N m s]")
    ax.set_title("wheel momentum, hub frame B", fontsize=10)
    ax = axes[1, 0]
    style.line(ax, t, ratio, color="tab:blue", linewidth=1.0, label="fullest wheel")
    ax.axhline(100.0, color="tab:red", linewidth=1.0, label="limit I_s Ω_max")
    saturated = np.nan_to_num(_values(ds, "actuator_saturated")) != 0.0
    if saturated.any():
        ax.fill_between(t, 0.0, 1.0, where=saturated, color="tab:red", alpha=0.15,
                        transform=ax.get_xaxis_transform(),
                        label="a wheel at its limit")  # fmt: skip
    ax.set_ylim(0.0, max(105.0, float(np.nanmax(ratio, initial=0.0)) * 1.05))
    ax.set_ylabel("max |h_i| / (I_s Ω_max) [%]")
    ax.set_title(_first_saturations(ds), fontsize=10)
    ax = axes[2, 0]
    _draw_wheel_speeds(ds, t, ax)
    ax = axes[3, 0]
    for name, colour, label in (
        ("wheel_kinetic_energy", "tab:blue", "kinetic energy Σ h_i² / (2 I_s)"),
        ("wheel_motor_work", "tab:green", "motor work ∫ Σ u_i Ω_i dt"),
        ("wheel_friction_loss", "tab:orange", "friction loss ∫ Σ f_i Ω_i dt"),
    ):
        style.line(ax, t, _values(ds, name), color=colour, linewidth=1.0, label=label)
    ax.set_ylabel("energy [J]")
    ax.set_title("wheel energy", fontsize=10)
    for ax in axes[:, 0]:
        ax.legend(loc="upper left", fontsize=8, ncols=3)
    style.finish_time_axis(axes, t)
    style.suptitle(fig, ds, f"Reaction wheels ({spec.description})")
    return fig


def zero_crossings(values: np.ndarray) -> int:
    """How many times a record changes sign (records at exactly zero passed over).

    Parameters
    ----------
    values : ndarray, shape (m,)
        A record [any unit: only its sign is read]; NaN records passed over.

    Returns
    -------
    int
        The sign changes between consecutive non-zero records [-].
    """
    signs = np.sign(np.asarray(values, dtype=float))
    signs = signs[np.isfinite(signs) & (signs != 0.0)]
    return int(np.count_nonzero(np.diff(signs)))


def _draw_wheel_speeds(ds: xr.Dataset, t: np.ndarray, ax: Axes) -> None:
    """Each wheel's speed [rpm] with its limit ±Ω_max and zero, the motor torque asked
    of the wheels over their limit in the title (R3's, ``actuator_torque_ratio``)."""
    if "wheel_speed" not in ds.data_vars:  # a run recorded before the channel existed
        ax.set_title("wheel speeds not recorded", fontsize=10)
        return
    speed = _values(ds, "wheel_speed")
    units = [k for k in range(speed.shape[1]) if np.isfinite(speed[:, k]).any()]
    for k in units:
        style.line(ax, t, speed[:, k], color=f"C{k}", linewidth=1.0, label=f"wheel {k + 1}")
    actuator = json.loads(ds.attrs.get("scenario", "{}")).get("actuator", {})
    limit = actuator.get("max_speed_rpm")
    if limit is not None:
        ax.axhline(limit, color="tab:red", linewidth=1.0, label="±Ω_max")
        ax.axhline(-limit, color="tab:red", linewidth=1.0)
    ax.axhline(0.0, color="0.4", linewidth=0.6)
    crossings = sum(zero_crossings(speed[:, k]) for k in units)
    title = f"wheel speeds h_i / I_s: {crossings} zero crossings"
    if "actuator_torque_ratio" in ds.data_vars:
        asked = float(np.nanmax(_values(ds, "actuator_torque_ratio"), initial=0.0))
        title += f"; largest motor torque asked {100 * asked:.3g} % of the limit"
    ax.set_ylabel("Ω_i [rpm]")
    ax.set_title(title, fontsize=10)


def _first_saturations(ds: xr.Dataset) -> str:
    """The title of the speed panel: when each wheel first reached its limit
    (:func:`flexsat.analysis.requirements.actuator_saturation_times`, R3's)."""
    times = actuator_saturation_times(ds)
    if not times:
        return f"no wheel reached {100 * SATURATED_RATIO:.1f} % of its limit"
    return "saturated: " + ", ".join(f"wheel {unit} at t = {t:.4g} s" for unit, t in times.items())


def _values(ds: xr.Dataset, name: str) -> np.ndarray:
    return np.asarray(ds.variables[name].values, dtype=float)


STAGE_FIGURES: dict[str, Callable[[xr.Dataset, StageSpec], Figure]] = {
    "mekf": plot_estimation,
    "wheels": plot_wheels,
}
"""Stages drawn by a figure of their own; every other flown stage with records by
:func:`plot_stage_records`."""
