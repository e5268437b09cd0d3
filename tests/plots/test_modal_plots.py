"""Modal figures: real PNG/GIF files, sensible content, no display needed."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from matplotlib.figure import Figure
from PIL import Image

import flexsat.config
from flexsat.analysis.modal import ModalAnalysis, modal_analysis
from flexsat.dynamics.plant import Plant
from flexsat.plots import (
    animate_mode,
    default_animated_modes,
    mode_amplitude,
    plot_frequencies,
    plot_interaction_map,
    satellite_geometry,
    write_modal_figures,
)

PNG_MAGIC = b"\x89PNG\r\n\x1a\n"
GIF_MAGIC = (b"GIF89a", b"GIF87a")


@pytest.fixture(scope="module")
def analysis() -> ModalAnalysis:
    return modal_analysis(Plant.from_config(flexsat.config.nominal()))


def _is_png(path: Path) -> bool:
    return path.read_bytes()[:8] == PNG_MAGIC


def _gif_frames(path: Path) -> int:
    assert path.read_bytes()[:6] in GIF_MAGIC
    with Image.open(path) as im:
        assert im.format == "GIF"
        return im.n_frames


def test_interaction_map(analysis: ModalAnalysis, tmp_path: Path) -> None:
    fig = plot_interaction_map(analysis)
    assert isinstance(fig, Figure)
    ax = fig.axes[0]
    image = ax.get_images()[0]
    np.testing.assert_array_equal(image.get_array(), analysis.participation)
    assert image.get_clim() == (0.0, 1.0)
    assert [t.get_text() for t in ax.get_yticklabels()] == analysis.dof_names
    xlabels = [t.get_text() for t in ax.get_xticklabels()]
    assert len(xlabels) == analysis.shapes.shape[1]
    assert xlabels[0] == "1 · rigid" and xlabels[6] == "7 · 0.258 Hz"
    assert "interaction map" in ax.get_title().lower()
    assert len(fig.axes) == 2  # the map and its colour bar
    fig.savefig(tmp_path / "map.png")
    assert _is_png(tmp_path / "map.png")


def test_interaction_map_into_given_axes(analysis: ModalAnalysis) -> None:
    fig = Figure()
    ax = fig.add_subplot()
    assert plot_interaction_map(analysis, ax=ax) is fig


def test_frequencies(analysis: ModalAnalysis, tmp_path: Path) -> None:
    fig = plot_frequencies(analysis)
    ax = fig.axes[0]
    assert ax.get_yscale() == "log"
    labels = [t.get_text() for t in ax.get_xticklabels()]
    assert len(labels) == 12  # the flexible modes
    assert labels[0] == "7 · flapping · sym. · → hub z"
    assert labels[3] == "10 · torsion · antisym. · hub at rest"
    fig.savefig(tmp_path / "freq.png")
    assert _is_png(tmp_path / "freq.png")


def test_amplitude_gives_15_percent_of_the_panel(analysis: ModalAnalysis) -> None:
    plant = analysis.plant
    rest = satellite_geometry(plant)
    for k in (1, 4, 7, 11, 12):  # rigid modes too
        a = mode_amplitude(analysis, k)
        moved = satellite_geometry(plant, a * analysis.shapes[:, k - 1])
        peak = np.linalg.norm(moved.panels - rest.panels, axis=-1).max()
        assert peak == pytest.approx(0.15 * 4.5, rel=2e-3), k


def test_animate_mode_writes_a_gif_with_the_frames(analysis: ModalAnalysis, tmp_path: Path) -> None:
    path = animate_mode(analysis, 7, tmp_path / "m7.gif", frames=4, fps=10)
    assert path == tmp_path / "m7.gif"
    assert _gif_frames(path) == 4
    with Image.open(path) as im:
        assert im.info["duration"] == 100
        im.seek(1)
        assert im.convert("RGB").getextrema() != ((255, 255), (255, 255), (255, 255))


def test_animate_rigid_mode_and_explicit_amplitude(analysis: ModalAnalysis, tmp_path: Path) -> None:
    path = animate_mode(analysis, 6, tmp_path / "rigid.gif", amplitude=0.5, frames=3)
    assert _gif_frames(path) == 3


def test_animate_mode_rejects_bad_input(analysis: ModalAnalysis, tmp_path: Path) -> None:
    with pytest.raises(ValueError, match="1-based"):
        animate_mode(analysis, 0, tmp_path / "x.gif")
    with pytest.raises(ValueError, match="1-based"):
        animate_mode(analysis, 19, tmp_path / "x.gif")
    with pytest.raises(ValueError, match="frames"):
        animate_mode(analysis, 7, tmp_path / "x.gif", frames=1)


def test_default_modes_are_flexible_and_drive_the_hub(analysis: ModalAnalysis) -> None:
    chosen = default_animated_modes(analysis)
    assert chosen == [7, 8, 9, 11, 12, 14]
    for k in chosen:
        mode = analysis.modes[k - 1]
        assert mode.kind != "rigid" and mode.hub_dof is not None


def test_write_modal_figures(analysis: ModalAnalysis, tmp_path: Path) -> None:
    out = tmp_path / "new" / "figures"
    written = write_modal_figures(analysis, out, mode_indices=[9, 12], frames=3)
    assert [p.name for p in written] == [
        "interaction_map.png", "frequencies.png", "mode_9.png", "mode_9.gif", "mode_12.png",
        "mode_12.gif",
    ]  # fmt: skip
    assert all(p.parent == out and p.is_file() for p in written)
    assert _is_png(written[0]) and _is_png(written[1]) and _is_png(written[2])
    assert _gif_frames(written[3]) == 3 and _gif_frames(written[5]) == 3


def test_the_still_and_the_first_frame_show_the_peak_deformation(
    analysis: ModalAnalysis, tmp_path: Path
) -> None:
    # q = a phi cos(2 pi k / 4): frame 0 is the peak, frame 1 the undeformed satellite.
    from PIL import Image, ImageSequence

    gif = animate_mode(analysis, 7, tmp_path / "m7.gif", frames=4, still=tmp_path / "m7.png")
    with Image.open(gif) as movie:
        frames = [np.asarray(f.convert("L"), dtype=float) for f in ImageSequence.Iterator(movie)]
    with Image.open(tmp_path / "m7.png") as still:
        still_px = np.asarray(still.convert("L"), dtype=float)
    assert still_px.shape == frames[0].shape
    # The GIF's shared palette moves grey levels by up to 3 units out of 255 (white is
    # 252): the still matches frame 0 within that, and the undeformed frame 1 not.
    to_first = np.abs(still_px - frames[0])
    assert np.percentile(to_first, 99) <= 4.0
    assert (np.abs(still_px - frames[1]) > 40.0).mean() > 20 * (to_first > 40.0).mean() + 1e-3
    with pytest.raises(ValueError, match="1-based"):
        write_modal_figures(analysis, tmp_path / "bad", mode_indices=[99])
    assert not (tmp_path / "bad" / "interaction_map.png").exists()


def test_plots_need_no_pyplot_nor_a_display(tmp_path: Path) -> None:
    # Importing pyplot would pick (and possibly require) a GUI backend; the library
    # renders through Agg directly, so a figure and a GIF never pull it in.
    code = (
        "import sys, flexsat.config\n"
        "from flexsat.analysis.modal import modal_analysis\n"
        "from flexsat.dynamics.plant import Plant\n"
        "from flexsat.plots import animate_mode, plot_frequencies\n"
        "a = modal_analysis(Plant.from_config(flexsat.config.nominal()))\n"
        f"plot_frequencies(a).savefig({str(tmp_path / 'f.png')!r})\n"
        f"animate_mode(a, 7, {str(tmp_path / 'm.gif')!r}, frames=2)\n"
        "assert 'matplotlib.pyplot' not in sys.modules, 'pyplot imported'\n"
    )
    subprocess.run([sys.executable, "-c", code], check=True, timeout=120)
    assert _is_png(tmp_path / "f.png") and _gif_frames(tmp_path / "m.gif") == 2
