"""Figures of the loop stages' records: which runs get them, in what order, and what
they draw (the recorded numbers, in the units shown)."""

from __future__ import annotations

from math import pi
from typing import Literal

import numpy as np
import pytest
import xarray as xr
from matplotlib.collections import PolyCollection
from numba import njit

from flexsat.analysis.requirements import slew_metrics
from flexsat.control.registry import Channel
from flexsat.control.stages import (
    ACTUATOR_SIGNATURE,
    ACTUATORS,
    JOINT_ACTUATORS,
    REFERENCES,
    SENSORS,
    ActuatorStageConfig,
    StageSpec,
    register_stage,
)
from flexsat.plots.results import figure_names, write_result_figures
from flexsat.plots.slew import SLEW_FIGURES
from flexsat.plots.stages import plot_stage, readable_units, stage_figure_names
from flexsat.simulate import SlewScenario, run_slew
from flexsat.study.avionics import AVIONICS

ARCSEC = 180.0 / pi * 3600.0
PNG_MAGIC = b"\x89PNG\r\n\x1a\n"


def _slew(plant, duration_s: float, **fields) -> xr.Dataset:
    scenario = SlewScenario.model_validate({"duration_s": duration_s, **fields})
    return run_slew(plant, scenario).dataset


@pytest.fixture(scope="module")
def avionics_ds(nominal_plant) -> xr.Dataset:
    # The realistic chain with a one-period delay ahead of the wheels: 300 records,
    # fewer than a line's thinning threshold, so every drawn point is a record.
    return _slew(nominal_plant, 3.0, **AVIONICS,
                 actuator_stages=[{"kind": "delay", "periods": 1}])  # fmt: skip


def test_every_stage_with_records_has_a_figure_in_the_loops_order(avionics_ds, nominal_plant):
    # sensing chain (gyro, star tracker, MEKF), then the actuation chain (delay,
    # wheels): the order the loop runs them. The ideal loop records nothing.
    names = figure_names(avionics_ds)
    assert names[: len(SLEW_FIGURES)] == SLEW_FIGURES
    assert stage_figure_names(avionics_ds) == ("gyro", "star_tracker", "mekf", "delay", "wheels")
    assert names[len(SLEW_FIGURES) :] == stage_figure_names(avionics_ds)
    assert stage_figure_names(_slew(nominal_plant, 0.1)) == ()


def test_no_stage_name_shadows_a_slew_figure():
    stages = {n for r in (SENSORS, ACTUATORS, REFERENCES, JOINT_ACTUATORS) for n in r.names()}
    assert not stages & set(SLEW_FIGURES)


@pytest.mark.parametrize(
    ("value", "units", "shown", "unit"),
    [
        (5.0 / ARCSEC, "rad", 5.0, "arcsec"),  # a star tracker's noise
        (0.5, "rad", 0.5 * 180.0 / pi, "deg"),
        (0.05 / ARCSEC, "rad/s", 0.05, "deg/h"),  # a gyro's bias, 0.05 deg/h
        (0.2, "rad/s", 0.2 * 180.0 / pi, "deg/s"),
        (1.5, "N m", 1.5, "N m"),  # anything else as recorded
    ],
)
def test_readable_units(value, units, shown, unit):
    factor, chosen = readable_units(np.array([0.0, -value, np.nan]), units)
    assert chosen == unit
    assert value * factor == pytest.approx(shown, rel=1e-12)


def test_the_estimation_figure_draws_the_error_inside_its_covariance(avionics_ds):
    fig = plot_stage(avionics_ds, "mekf")
    axes = fig.axes
    error = avionics_ds["estimation_error"].values * ARCSEC
    sigma3 = 3.0 * avionics_ds["estimation_sigma"].values * ARCSEC
    for k in range(3):
        ax = axes[2 * k]  # left column: the error per axis, in arcsec
        (line,) = ax.get_lines()
        np.testing.assert_array_equal(line.get_ydata(), error[:, k])
        bands = [c for c in ax.collections if isinstance(c, PolyCollection)]
        top = max(path.vertices[:, 1].max() for band in bands for path in band.get_paths())
        assert top == pytest.approx(sigma3[:, k].max(), rel=1e-12)
        inside = np.mean(np.abs(error[:, k]) <= sigma3[:, k])
        assert f"{100 * inside:.1f} % inside ±3σ" in ax.get_title()
    nees_ax = axes[6]
    # The two-sided 95 % interval of chi-square with 3 dof: 0.2158 and 9.348
    # (published tables, 4 digits).
    bounds = sorted(line.get_ydata()[0] for line in nees_ax.get_lines()[1:])
    np.testing.assert_allclose(bounds, [0.2158, 9.348], rtol=5e-4)
    nees = avionics_ds["estimation_nees"].values
    share = np.mean((nees > bounds[0]) & (nees < bounds[1]))
    assert f"{100 * share:.1f} % inside" in nees_ax.get_title()
    # The right column: the estimated bias beside the gyro's true one [deg/h].
    truth, estimate = axes[1].get_lines()
    bias, bias_hat = avionics_ds["gyro_bias"].values, avionics_ds["estimated_gyro_bias"].values
    np.testing.assert_allclose(truth.get_ydata(), bias[:, 0] * ARCSEC)
    np.testing.assert_allclose(estimate.get_ydata(), bias_hat[:, 0] * ARCSEC)


def test_a_stage_without_a_figure_of_its_own_gets_every_record(avionics_ds):
    # The gyro records its true bias, per axis, in rad/s: shown in deg/h.
    fig = plot_stage(avionics_ds, "gyro")
    (ax,) = fig.axes
    assert ax.get_ylabel() == "gyro_bias [deg/h]"
    for k, line in enumerate(ax.get_lines()):
        np.testing.assert_allclose(line.get_ydata(), avionics_ds["gyro_bias"].values[:, k] * ARCSEC)
    (ax,) = plot_stage(avionics_ds, "delay").axes
    assert ax.get_ylabel() == "control_delay [s]"
    np.testing.assert_array_equal(ax.get_lines()[0].get_ydata(),
                                  avionics_ds["control_delay"].values)  # fmt: skip


def test_the_wheel_figure_says_when_each_wheel_saturated(nominal_plant, avionics_ds):
    title = plot_stage(avionics_ds, "wheels").axes[1].get_title()
    assert title == "no wheel reached 99.9 % of its limit"
    # 0.1 kg m^2 at 30 rpm holds 0.31 N m s per wheel; the slew needs several N m s
    # within seconds: the wheels saturate, R3 says when, and so does the figure.
    ds = _slew(nominal_plant, 5.0, actuator={"kind": "wheels", "max_speed_rpm": 30.0})
    saturation = slew_metrics(ds)["actuator_saturation_s"]
    assert saturation
    ax = plot_stage(ds, "wheels").axes[1]
    for unit, t in saturation.items():
        assert f"wheel {unit} at t = {t:.4g} s" in ax.get_title()
    assert any(c.get_label() == "a wheel at its limit" for c in ax.collections)
    ratio = ax.get_lines()[0].get_ydata()
    np.testing.assert_allclose(ratio, 100.0 * ds["wheel_speed_ratio"].values)
    assert ratio.max() >= 99.9


class EchoConfig(ActuatorStageConfig):
    kind: Literal["echo"] = "echo"


@njit(ACTUATOR_SIGNATURE, cache=True)
def echo_step(tau_cmd, t, dt, params, state, tau_applied, record):
    """Passes the command on; records it and counts the instants."""
    state[0] += 1.0
    for a in range(3):
        tau_applied[a] = tau_cmd[a]
        record[a] = tau_cmd[a]
    record[3] = state[0]
    return 0


ECHO = StageSpec(role="actuator", name="echo", config=EchoConfig, step=echo_step, state_size=1,
                 records=(Channel("echo_torque", "N m", "the command passed on", per_axis=True),
                          Channel("echo_instants", "1", "control instants seen")))  # fmt: skip


@pytest.fixture
def echo():
    register_stage(ECHO)
    yield
    ACTUATORS.unregister(ECHO.name)


def test_a_users_stage_is_drawn_once_registered(echo, nominal_plant, tmp_path):
    ds = _slew(nominal_plant, 0.5, actuator_stages=[{"kind": "echo"}])
    assert stage_figure_names(ds) == ("echo",)
    torque_ax, count_ax = plot_stage(ds, "echo").axes
    assert torque_ax.get_ylabel() == "echo_torque [N m]"
    assert count_ax.get_ylabel() == "echo_instants [1]"
    for k, line in enumerate(torque_ax.get_lines()):
        np.testing.assert_array_equal(line.get_ydata(), ds["tau_cmd"].values[:, k])
    np.testing.assert_array_equal(count_ax.get_lines()[0].get_ydata(), ds["echo_instants"].values)
    (written,) = write_result_figures(ds, tmp_path, kinds=("echo",))
    assert written.name == "echo.png" and written.read_bytes()[:8] == PNG_MAGIC


def test_the_wheel_figure_draws_each_wheels_speed_against_its_limit(avionics_ds):
    # Third panel: the four pyramid wheels' recorded speeds [rpm] as drawn, the limit
    # +-6000 rpm (the stage's default), and the sign changes of the speeds counted.
    ax = plot_stage(avionics_ds, "wheels").axes[2]
    speed = avionics_ds["wheel_speed"].values
    lines = ax.get_lines()
    for k in range(4):
        assert lines[k].get_label() == f"wheel {k + 1}"
        np.testing.assert_array_equal(lines[k].get_ydata(), speed[:, k])
    assert sorted(line.get_ydata()[0] for line in lines[4:6]) == [-6000.0, 6000.0]
    nonzero = [s[s != 0.0] for s in speed[:, :4].T]
    crossings = sum(int(np.sum(s[:-1] * s[1:] < 0.0)) for s in nonzero)
    assert f"{crossings} zero crossings" in ax.get_title()
    asked = 100.0 * avionics_ds["actuator_torque_ratio"].values.max()
    assert f"asked {asked:.3g} % of the limit" in ax.get_title()


def test_the_estimation_figure_draws_the_bias_inside_its_3_sigma(avionics_ds):
    # The right column's grey band is b_hat +- 3 sigma of the bias [deg/h].
    ax = plot_stage(avionics_ds, "mekf").axes[1]
    (band,) = ax.collections
    y = band.get_paths()[0].vertices[:, 1]
    bias_hat = avionics_ds["estimated_gyro_bias"].values[:, 0] * ARCSEC
    sigma3 = 3.0 * avionics_ds["estimated_gyro_bias_sigma"].values[:, 0] * ARCSEC
    np.testing.assert_allclose([y.min(), y.max()],
                               [(bias_hat - sigma3).min(), (bias_hat + sigma3).max()])  # fmt: skip


def test_a_small_power_keeps_its_axis_label_inside_the_figure():
    # The SADM's motor power is ~1e-4 W (0.1 N m at the 1e-3 rad/s of one turn per
    # orbit): its tick labels "-0.00015" pushed "sadm_power [W]" past the figure's
    # left edge. Drawn with its power of ten above the axis, every label starts
    # inside the figure (x0 >= 0 px).
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    from flexsat.control.stages.sadm_drive import SADM_DRIVE
    from flexsat.plots.stages import plot_stage_records

    t = np.arange(0.0, 120.0, 0.01)
    ds = xr.Dataset({"sadm_power": ("time", 1.2e-4 * np.sin(t)),
                     "sadm_torque": ("time", 0.1 * np.abs(np.sin(t))),
                     "sadm_tracking_error": ("time", 4e-4 * np.abs(np.sin(t))),
                     "design_inertia_change": ("time", 0.0 * t)},
                    coords={"time": t}, attrs={"scenario": "{}"})  # fmt: skip
    fig = plot_stage_records(ds, SADM_DRIVE)
    canvas = FigureCanvasAgg(fig)
    canvas.draw()
    renderer = canvas.get_renderer()
    for ax in fig.axes:
        assert ax.yaxis.label.get_window_extent(renderer).x0 >= 0.0, ax.get_ylabel()
