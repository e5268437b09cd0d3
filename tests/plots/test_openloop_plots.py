"""Open-loop figures: real PNG files, labelled axes, the modal lines on the spectrogram."""

from __future__ import annotations

import io
from pathlib import Path

import numpy as np
import pytest
import xarray as xr
from matplotlib.figure import Figure

import flexsat.config
from flexsat.analysis.modal import ModalAnalysis, modal_analysis
from flexsat.dynamics.plant import Plant
from flexsat.plots.openloop import (
    OPENLOOP_FIGURES,
    plot_angular_acceleration,
    plot_angular_momentum,
    plot_attitude,
    plot_energy,
    plot_quaternion,
    plot_root_deformation,
    plot_spectrogram,
    plot_tip_displacement,
    plot_torques,
    write_openloop_figures,
)
from flexsat.simulate import run_openloop
from flexsat.simulate.scenario import OpenLoopScenario, step

PNG_MAGIC = b"\x89PNG\r\n\x1a\n"


@pytest.fixture(scope="session")
def openloop_plant() -> Plant:
    return Plant.from_config(flexsat.config.nominal())


@pytest.fixture(scope="session")
def openloop_ds(openloop_plant: Plant) -> xr.Dataset:
    """The thesis scenario (1 N m about Z for 10 s, then free), cut to 30 s."""
    result = run_openloop(openloop_plant, OpenLoopScenario(duration_s=30.0))
    result.raise_for_status()
    return result.dataset


@pytest.fixture(scope="session")
def openloop_analysis(openloop_plant: Plant) -> ModalAnalysis:
    return modal_analysis(openloop_plant)


def test_write_all_figures(openloop_ds, openloop_analysis, tmp_path: Path) -> None:
    out = tmp_path / "figures" / "openloop"  # created, parents too
    written = write_openloop_figures(openloop_ds, openloop_analysis, out)
    assert len(written) == len(OPENLOOP_FIGURES) == 9
    assert [p.name for p in written] == [f"{name}.png" for name in OPENLOOP_FIGURES]
    assert sorted(out.iterdir()) == sorted(written)
    for path in written:
        assert path.read_bytes()[:8] == PNG_MAGIC, path
        assert path.stat().st_size > 10_000, path


def test_figures_without_analysis(openloop_ds) -> None:
    fig = plot_spectrogram(openloop_ds, None, "z")
    assert not [line for line in fig.axes[0].get_lines() if line.get_linestyle() == "--"]
    assert isinstance(plot_angular_acceleration(openloop_ds, None), Figure)


@pytest.mark.parametrize(
    "plot",
    [
        plot_attitude,
        plot_quaternion,
        plot_angular_acceleration,
        plot_torques,
        plot_root_deformation,
        plot_tip_displacement,
        plot_angular_momentum,
        plot_energy,
    ],
)
def test_time_figures_are_labelled(plot, openloop_ds) -> None:
    fig = plot(openloop_ds)
    assert isinstance(fig, Figure)
    assert fig.get_suptitle()
    t_end = float(openloop_ds["time"].values[-1])
    plotted = [ax for ax in fig.axes if ax.get_lines()]
    assert plotted
    for ax in plotted:
        assert "[" in ax.get_ylabel(), ax.get_ylabel()  # units
        assert ax.get_xlim()[1] <= t_end + 1e-9
    assert any(ax.get_xlabel() == "time t [s]" for ax in fig.axes)
    assert any(ax.get_legend() is not None for ax in fig.axes) or fig.legends


def test_root_deformation_draws_every_appendage(openloop_ds) -> None:
    fig = plot_root_deformation(openloop_ds)
    names = [str(a) for a in openloop_ds["appendage"].values]
    labels = {line.get_label() for line in fig.axes[0].get_lines()}
    assert set(names) <= labels
    # rho_z of the nominal run peaks near 0.08 deg: plotted in degrees, not radians.
    rho_z = fig.axes[4].get_lines()[0].get_ydata()
    assert 0.01 < np.nanmax(np.abs(rho_z)) < 1.0


def test_root_deformation_leaves_out_an_appendage_without_a_root_joint(openloop_plant) -> None:
    # panel_2 as modal data: no root joint, its eta and rho records are NaN; it is
    # named in the title and not drawn (nor listed in the legend).
    from flexsat.config import validate_config
    from flexsat.linear.export import modal_satellite

    modal = modal_satellite(openloop_plant, n_modes=2).model_dump()
    mixed = openloop_plant.config.model_dump()
    mixed["appendages"][1] = modal["appendages"][1]
    plant = Plant.from_config(validate_config(mixed))
    ds = run_openloop(plant, OpenLoopScenario(duration_s=2.0)).dataset
    assert np.isnan(ds["rho"].values[:, 1]).all()
    fig = plot_root_deformation(ds)
    labels = {line.get_label() for line in fig.axes[0].get_lines()}
    assert labels == {"panel_1"}
    assert "; no root joint: panel_2\n" in fig.get_suptitle()


def test_tip_displacement_in_millimetres(openloop_ds) -> None:
    fig = plot_tip_displacement(openloop_ds)
    assert len([ax for ax in fig.axes if ax.get_lines()]) == openloop_ds.sizes["appendage"]
    peak = max(np.nanmax(np.abs(line.get_ydata())) for line in fig.axes[0].get_lines())
    metres = np.linalg.norm(openloop_ds["tip_displacement"].values[:, 0], axis=-1).max()
    assert peak == pytest.approx(1e3 * metres, rel=1e-6)


def test_energy_micro_panel_is_logarithmic(openloop_ds) -> None:
    fig = plot_energy(openloop_ds)
    assert [ax.get_yscale() for ax in fig.axes] == ["linear", "log"]


def test_spectrogram_overlays_the_coupled_yaw_mode(openloop_ds, openloop_analysis) -> None:
    fig = plot_spectrogram(openloop_ds, openloop_analysis, "z")
    ax = fig.axes[0]
    assert ax.get_ylim() == pytest.approx((0.0, 3.0))
    assert "Hz" in ax.get_ylabel()
    dashed = [line.get_ydata()[0] for line in ax.get_lines() if line.get_linestyle() == "--"]
    assert any(abs(f - 1.231) < 2e-3 for f in dashed)
    assert not any(abs(f - 0.258) < 0.02 for f in dashed)  # flapping: no yaw coupling
    assert ax.get_legend() is not None
    assert len(ax.collections) == 1  # the spectrogram mesh


def test_spectrogram_rejects_unknown_axis(openloop_ds) -> None:
    with pytest.raises(ValueError, match="axis"):
        plot_spectrogram(openloop_ds, None, "w")


def test_torque_held_to_the_end(openloop_plant) -> None:
    """A run with no torque-free phase still plots (the ripple panels say so)."""
    scenario = OpenLoopScenario(duration_s=2.0, torque=[step(0.0, (0.0, 0.0, 1.0))])
    ds = run_openloop(openloop_plant, scenario).dataset
    fig = plot_angular_acceleration(ds)
    texts = [t.get_text() for ax in fig.axes for t in ax.texts]
    assert any("no torque-free phase" in t for t in texts)
    for plot in (plot_angular_momentum, plot_spectrogram, plot_torques):
        buffer = io.BytesIO()
        plot(ds).savefig(buffer, format="png", dpi=40)  # renders without error
        assert buffer.getvalue()[:8] == PNG_MAGIC
