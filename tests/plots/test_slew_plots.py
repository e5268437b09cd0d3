"""Slew figures: real PNG files, labelled axes, limits read from the run's scenario."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
import xarray as xr
from matplotlib.figure import Figure

import flexsat.config
from flexsat.control.laws.pd import PDConfig
from flexsat.dynamics.plant import Plant
from flexsat.plots.openloop import plot_energy, plot_root_deformation, plot_tip_displacement
from flexsat.plots.slew import (
    SLEW_FIGURES,
    attitude_error_vector,
    plot_adaptation,
    plot_disturbances,
    plot_flex_torque,
    plot_phase_plane,
    plot_pointing,
    plot_slew_attitude,
    plot_slew_quaternion,
    plot_sliding_variables,
    plot_torque_breakdown,
    plot_torque_limits,
    write_slew_figures,
)
from flexsat.simulate import run_slew
from flexsat.simulate.scenario import SlewScenario

PNG_MAGIC = b"\x89PNG\r\n\x1a\n"
TIME_FIGURES = [
    plot_slew_attitude,
    plot_slew_quaternion,
    plot_pointing,
    plot_sliding_variables,
    plot_adaptation,
    plot_disturbances,
    plot_torque_limits,
    plot_torque_breakdown,
    plot_root_deformation,
    plot_tip_displacement,
    plot_flex_torque,
    plot_energy,
]


@pytest.fixture(scope="session")
def slew_plant() -> Plant:
    return Plant.from_config(flexsat.config.nominal())


@pytest.fixture(scope="session")
def slew_ds(slew_plant: Plant) -> xr.Dataset:
    """The thesis's ASMC slew, cut to 30 s (through the switch to Lambda_max)."""
    result = run_slew(slew_plant, SlewScenario(duration_s=30.0))
    result.raise_for_status()
    return result.dataset


def _with_scenario(ds: xr.Dataset, **sections: dict) -> xr.Dataset:
    """A copy of ``ds`` whose stored scenario has some fields of its sections changed."""
    scenario = json.loads(ds.attrs["scenario"])
    for section, fields in sections.items():
        scenario[section].update(fields)
    copy = ds.copy()
    copy.attrs = {**ds.attrs, "scenario": json.dumps(scenario)}
    return copy


def _hlines(ax) -> list[float]:
    """Heights of the horizontal lines of an axes."""
    out = []
    for line in ax.get_lines():
        y = np.asarray(line.get_ydata(), dtype=float)
        if y.size == 2 and y[0] == y[1]:
            out.append(float(y[0]))
    return out


def test_write_all_figures(slew_ds, tmp_path: Path) -> None:
    out = tmp_path / "figures" / "slew"  # created, parents too
    written = write_slew_figures(slew_ds, out, dpi=60)
    assert len(written) == len(SLEW_FIGURES) == 13
    assert [p.name for p in written] == [f"{name}.png" for name in SLEW_FIGURES]
    assert sorted(out.iterdir()) == sorted(written)
    for path in written:
        assert path.read_bytes()[:8] == PNG_MAGIC, path
        assert path.stat().st_size > 5_000, path


@pytest.mark.parametrize("plot", TIME_FIGURES)
def test_time_figures_are_labelled(plot, slew_ds) -> None:
    fig = plot(slew_ds)
    assert isinstance(fig, Figure)
    assert fig.get_suptitle()
    t_end = float(slew_ds["time"].values[-1])
    plotted = [ax for ax in fig.axes if ax.get_lines()]
    assert plotted
    for ax in plotted:
        assert "[" in ax.get_ylabel(), ax.get_ylabel()  # units
        assert ax.get_xlim()[1] <= t_end + 1e-9
    assert any(ax.get_xlabel() == "time t [s]" for ax in fig.axes)
    assert fig.legends or any(ax.get_legend() is not None for ax in fig.axes)


def test_pointing_bands_at_the_requirements(slew_ds) -> None:
    fig = plot_pointing(slew_ds)
    r1, r2 = fig.axes[:2]
    assert r1.get_yscale() == r2.get_yscale() == "log"
    assert 0.05 in _hlines(r1)
    assert 1e-3 in _hlines(r2)
    band = [p for p in r1.patches if p.get_label().startswith("R1 band")]
    assert len(band) == 1
    assert band[0].get_bbox().y1 == pytest.approx(0.05)  # shaded up to the R1 limit
    # read from the stored scenario, not assumed
    looser = plot_pointing(_with_scenario(slew_ds, requirements={"pointing_deg": 0.1}))
    assert 0.1 in _hlines(looser.axes[0])
    assert 0.05 not in _hlines(looser.axes[0])


def test_pointing_verdicts_over_the_observation_window(slew_ds) -> None:
    # The 30 s run was planned to end before the default 90 s deadline: not judged.
    r1, r2 = plot_pointing(slew_ds).axes[:2]
    for ax, tag in ((r1, "R1"), (r2, "R2")):
        assert ax.get_title().startswith(
            f"{tag} not judged: the run ends at 30 s, before the observation window starts "
            "at 90 s (requirements.settling_deadline_s)"
        ), ax.get_title()
    # Planned to 40 s with the window from 20 s, its records stop at 30 s (as a run
    # stopped by a fault): judged, and failed.
    stopped = _with_scenario(slew_ds, requirements={"settling_deadline_s": 20.0})
    stopped.attrs["scenario"] = json.dumps({**json.loads(stopped.attrs["scenario"]),
                                            "duration_s": 40.0})  # fmt: skip
    r1 = plot_pointing(stopped).axes[0]
    assert r1.get_title().startswith(
        "R1 FAIL: the run stops at 30 s, before its window ends (40 s)"
    )
    # A 20 s deadline: the window 20-30 s is shaded, and R1 fails over it (the
    # error is still above 0.05 deg at 20 s).
    r1 = plot_pointing(_with_scenario(slew_ds, requirements={"settling_deadline_s": 20.0})).axes[0]
    assert r1.get_title().startswith("R1 FAIL over 20–30 s: max ")
    window = [p for p in r1.patches if p.get_label().startswith("observation window")]
    assert len(window) == 1
    assert (window[0].get_bbox().x0, window[0].get_bbox().x1) == pytest.approx((20.0, 30.0))


def test_torque_limits_from_the_scenario(slew_ds) -> None:
    fig = plot_torque_limits(slew_ds)
    assert {2.0, -2.0, 1.9, -1.9} <= set(_hlines(fig.axes[0]))
    wider = plot_torque_limits(_with_scenario(slew_ds, actuator={"t_max_nm": 3.0}))
    assert {3.0, -3.0, 2.85, -2.85} <= {round(v, 12) for v in _hlines(wider.axes[2])}


def test_phase_plane_error_matches_the_sliding_variable(slew_ds) -> None:
    """q_v,e from the quaternion equals (s - omega) / Lambda, the law's own surface."""
    qv = attitude_error_vector(slew_ds)
    s = slew_ds["sliding_variable"].values
    lam = slew_ds["lambda_act"].values[:, None]
    assert np.abs(qv - (s - slew_ds["omega"].values) / lam).max() < 1e-9
    assert np.linalg.norm(qv[0]) == pytest.approx(np.sin(np.radians(64.7368) / 2), rel=1e-5)

    fig = plot_phase_plane(slew_ds)
    start = fig.axes[0].collections[-1].get_segments()[0][0]  # the trajectory of axis x
    assert start == pytest.approx([qv[0, 0], 0.0])
    slopes = {round(-np.diff(line.get_ydata())[0] / np.diff(line.get_xdata())[0], 9)
              for line in fig.axes[0].get_lines() if line.get_linestyle() == "--"}  # fmt: skip
    assert slopes == {0.2, 5.0}  # initial (Lambda_min) and final (Lambda_max) surfaces
    assert all("[" in ax.get_xlabel() and "[" in ax.get_ylabel() for ax in fig.axes[:6])


def test_adaptation_floor_and_ceiling(slew_ds) -> None:
    fig = plot_adaptation(slew_ds)
    lam, jk = fig.axes[:2]
    assert {0.2, 5.0} <= set(_hlines(lam))
    assert {0.8925, 1.9} <= {round(v, 12) for v in _hlines(jk)}


def test_reused_figures_lose_the_torque_shading(slew_ds) -> None:
    for plot in (plot_root_deformation, plot_tip_displacement, plot_energy):
        fig = plot(slew_ds)
        legends = [*fig.legends, *(ax.get_legend() for ax in fig.axes if ax.get_legend())]
        assert legends
        labels = {text.get_text() for leg in legends for text in leg.texts}
        assert "torque commanded" not in labels
        assert not any(ax.patches for ax in fig.axes)


def test_law_without_sliding_surface(slew_plant) -> None:
    ds = run_slew(slew_plant, SlewScenario(duration_s=2.0, controller=PDConfig())).dataset
    fig = plot_sliding_variables(ds)
    assert any("no sliding surface" in t.get_text() for ax in fig.axes for t in ax.texts)
    fig = plot_phase_plane(ds)
    assert not [line for line in fig.axes[0].get_lines() if line.get_linestyle() == "--"]


def test_rejects_a_dataset_without_a_slew_scenario(slew_ds) -> None:
    bare = slew_ds.copy()
    bare.attrs = {k: v for k, v in slew_ds.attrs.items() if k != "scenario"}
    with pytest.raises(ValueError, match="scenario"):
        plot_pointing(bare)


def _line(ax, label: str, t: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The record indices a labelled line draws (long series are thinned for drawing)
    and its values."""
    (line,) = [ln for ln in ax.get_lines() if ln.get_label() == label]
    index = np.searchsorted(t, np.asarray(line.get_xdata(), dtype=float))
    np.testing.assert_array_equal(t[index], line.get_xdata())
    return index, np.asarray(line.get_ydata(), dtype=float)


def test_disturbance_figure_draws_the_realised_torques(slew_ds, slew_plant) -> None:
    # Static actuator (the thesis's, disturbances at maximum): the black line is the
    # recorded tau_applied - tau_cmd, the dashed one 0.005 N m, as realised.
    ax = plot_disturbances(slew_ds).axes[0]
    recorded = slew_ds["tau_applied"].values[:, 0] - slew_ds["tau_cmd"].values[:, 0]
    index, drawn = _line(ax, "total τ_applied − τ_cmd", slew_ds["time"].values)
    np.testing.assert_array_equal(drawn, recorded[index])
    assert _hlines(ax)[0] == 0.005
    # Wheels, one random draw: the drawn constant is the realised one (within the
    # +-0.005 N m bound, not the bound), the total on the hub the sum of the constant
    # and the sloshing terms (the wheels' own reaction is not a disturbance), exactly.
    ds = run_slew(slew_plant, SlewScenario.model_validate({
        "duration_s": 2.0, "actuator": {"kind": "wheels"},
        "disturbances": {"mode": "random", "seed": 3}})).dataset  # fmt: skip
    realised = ds.attrs["realised_disturbances"]
    fig = plot_disturbances(ds)
    for k, ax in enumerate(fig.axes[:3]):
        constant = realised[3 + k] + realised[8 + k]
        assert _hlines(ax)[0] == constant and abs(constant) < 0.005
        label = next(ln.get_label() for ln in ax.get_lines()
                     if ln.get_label().startswith("sloshing"))  # fmt: skip
        t = ds["time"].values
        slosh_index, slosh = _line(ax, label, t)
        index, total = _line(ax, "total on the hub", t)
        np.testing.assert_array_equal(index, slosh_index)
        np.testing.assert_array_equal(total, constant + slosh)
        assert not any("shortfall" in ln.get_label() for ln in ax.get_lines())
