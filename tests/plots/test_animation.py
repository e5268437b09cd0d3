"""Run animations: real GIF files, frames picked evenly, attitude and magnification as drawn."""

from __future__ import annotations

import itertools
import json
import re
import sys
from pathlib import Path

import matplotlib as mpl
import numpy as np
import pytest
import xarray as xr
from PIL import Image, ImageChops
from scipy.spatial.transform import Rotation

from flexsat.dynamics.plant import Plant
from flexsat.errors import FlexsatError
from flexsat.plots import auto_magnification, run_frames, satellite_geometry, write_animation
from flexsat.plots._scene import CanvasFFMpegWriter
from flexsat.simulate import OpenLoopScenario, Result, SlewScenario, run_openloop, run_slew

GIF_MAGIC = (b"GIF89a", b"GIF87a")
PANEL_LENGTH = 4.5  # nominal panels [m]
# The picture without the texts (title, clock, angles, footer) of a 640 x 512 frame.
PLOT_BOX = (60, 120, 600, 490)


@pytest.fixture(scope="module")
def openloop(nominal_plant: Plant) -> Result:
    """3 s of the thesis's yaw pulse: panels ringing, the hub starting to turn."""
    return run_openloop(nominal_plant, OpenLoopScenario(duration_s=3.0))


@pytest.fixture(scope="module")
def slew(nominal_plant: Plant) -> Result:
    """The first 20 s of the thesis's slew: tens of degrees on every axis."""
    return run_slew(nominal_plant, SlewScenario(duration_s=20.0, record_dt_s=0.05))


def _frames(path: Path) -> list[Image.Image]:
    assert path.read_bytes()[:6] in GIF_MAGIC
    with Image.open(path) as im:
        assert im.format == "GIF"
        out = []
        for k in range(im.n_frames):
            im.seek(k)
            out.append(im.convert("RGB"))
        return out


def _comment(path: Path) -> str:
    with Image.open(path) as im:
        return im.info["comment"].decode()


def _changed_fraction(a: Image.Image, b: Image.Image, box=PLOT_BOX) -> float:
    diff = np.asarray(ImageChops.difference(a.crop(box), b.crop(box))).max(axis=-1)
    return float(np.mean(diff > 0))


def test_gif_frames_fps_and_stated_magnification(openloop: Result, tmp_path: Path) -> None:
    path = write_animation(openloop, tmp_path / "run.gif", magnification=50.0, fps=10,
                           max_frames=12)  # fmt: skip
    assert path == tmp_path / "run.gif"
    frames = _frames(path)
    assert len(frames) == 12
    assert frames[0].size == (640, 512)
    with Image.open(path) as im:
        assert im.info["duration"] == 100  # ms per frame at 10 frames/s
    assert "deformation x50," in _comment(path)
    assert "12 frames, t = 0..3 s" in _comment(path)


def test_the_body_moves_between_frames(slew: Result, tmp_path: Path) -> None:
    frames = _frames(write_animation(slew, tmp_path / "slew.gif", max_frames=8))
    assert len(frames) == 8
    # The satellite itself (texts cropped out) differs between every two frames...
    for a, b in itertools.pairwise(frames):
        assert _changed_fraction(a, b) > 1e-3
    # ... and a lot between t = 0 and t = 20 s (about 35 deg on each axis).
    assert _changed_fraction(frames[0], frames[-1]) > 0.01


def test_frames_are_picked_evenly_in_time(openloop: Result) -> None:
    time = openloop.time
    frames = run_frames(openloop, max_frames=7, magnification=1.0)
    assert len(frames) == 7
    np.testing.assert_allclose(frames.time, np.linspace(0.0, 3.0, 7), atol=0.5 * 0.01)
    np.testing.assert_array_equal(frames.time, time[frames.index])
    np.testing.assert_array_equal(frames.q, openloop.dataset["q"].values[frames.index])
    # fps x playback caps the count; a short run gives all its records at most.
    assert len(run_frames(openloop, max_frames=100, fps=10, playback_s=2.0)) == 20
    assert len(run_frames(openloop, max_frames=10_000)) == time.size


def test_body_axes_follow_the_recorded_attitude(slew: Result) -> None:
    frames = run_frames(slew, max_frames=9)
    quaternion = slew.dataset["quaternion"].values[frames.index]  # scalar first
    turned = 0.0
    for k in range(len(frames)):
        geom = frames.geometry(k)
        R = Rotation.from_quat(quaternion[k][[1, 2, 3, 0]])  # scipy: scalar last
        x_tip = geom.centre + geom.axes[0]  # the drawn tip of X_B, frame N
        direction = (x_tip - geom.centre) / np.linalg.norm(x_tip - geom.centre)
        np.testing.assert_allclose(direction, R.apply([1.0, 0.0, 0.0]), atol=1e-9)
        for j in (1, 2):
            unit = geom.axes[j] / np.linalg.norm(geom.axes[j])
            np.testing.assert_allclose(unit, R.apply(np.eye(3)[j]), atol=1e-9)
        np.testing.assert_allclose(geom.centre, slew.dataset["q"].values[frames.index[k], :3])
        turned = max(turned, R.magnitude())
    assert np.degrees(turned) > 30.0  # a large rotation, shown as such


def test_auto_magnification_shows_the_peak_tip_displacement(openloop: Result) -> None:
    peak = float(np.linalg.norm(openloop.dataset["tip_displacement"].values, axis=-1).max())
    factor = auto_magnification(openloop)
    assert factor >= 1.0
    assert factor == float(f"{factor:.2g}")  # two significant digits
    assert 0.135 <= factor * peak / PANEL_LENGTH <= 0.15
    frames = run_frames(openloop, max_frames=31)
    assert frames.magnification == factor
    # As drawn: the panel tips move from the rigid pose by the factor times the
    # recorded tip displacement (to first order in the small root rotations).
    tips = openloop.dataset["tip_displacement"].values[frames.index]
    for k in range(len(frames)):
        rigid_q = frames.q[k].copy()
        rigid_q[6:] = 0.0
        geom = frames.geometry(k)
        moved_b = (geom.tips - satellite_geometry(frames.plant, rigid_q).tips) @ geom.R_NB
        np.testing.assert_allclose(np.linalg.norm(moved_b, axis=-1),
                                   factor * np.linalg.norm(tips[k], axis=-1),
                                   rtol=0.03, atol=1e-3 * PANEL_LENGTH)  # fmt: skip


def test_auto_magnification_is_never_below_one(openloop: Result) -> None:
    big = openloop.dataset.copy()
    big["tip_displacement"] = big["tip_displacement"] * 1e4
    assert auto_magnification(Result(big)) == 1.0
    rigid = openloop.dataset.copy()
    rigid["tip_displacement"] = rigid["tip_displacement"] * 0.0
    assert auto_magnification(Result(rigid)) == 1.0


def test_stated_magnification_is_the_one_drawn(openloop: Result, tmp_path: Path) -> None:
    path = write_animation(openloop, tmp_path / "m.gif", magnification=7.5, max_frames=3)
    assert "deformation x7.5," in _comment(path)
    auto = write_animation(openloop, tmp_path / "auto.gif", max_frames=3)
    shown = float(re.search(r"deformation x([0-9.]+),", _comment(auto)).group(1))
    assert shown == auto_magnification(openloop)
    frames = run_frames(openloop, magnification=7.5, max_frames=3)
    np.testing.assert_allclose(frames.drawn_q(2)[6:], 7.5 * frames.q[2, 6:])
    np.testing.assert_array_equal(frames.drawn_q(2)[:6], frames.q[2, :6])


def test_animation_is_deterministic(openloop: Result, tmp_path: Path) -> None:
    a = write_animation(openloop, tmp_path / "a.gif", max_frames=4)
    b = write_animation(openloop, tmp_path / "b.gif", max_frames=4)
    assert a.read_bytes() == b.read_bytes()


def test_frames_rendered_by_forked_processes_are_the_same(openloop: Result, tmp_path: Path,
                                                          monkeypatch) -> None:  # fmt: skip
    monkeypatch.setenv("FLEXSAT_FIGURE_WORKERS", "1")
    here = write_animation(openloop, tmp_path / "here.gif", max_frames=5)
    monkeypatch.setenv("FLEXSAT_FIGURE_WORKERS", "2")
    forked = write_animation(openloop, tmp_path / "forked.gif", max_frames=5)
    assert here.read_bytes() == forked.read_bytes()


def test_failed_run_is_drawn_up_to_its_last_finite_state(openloop: Result) -> None:
    ds = openloop.dataset.copy(deep=True)
    ds["q"][-50:, 7] = np.nan
    ds.attrs.update(status="failed", failure_time_s=float(ds["time"][-50]))
    frames = run_frames(Result(ds), max_frames=5, magnification=1.0)
    assert np.all(np.isfinite(frames.q))
    assert frames.time[-1] == pytest.approx(float(ds["time"][-51]))


def test_refusals(openloop: Result, tmp_path: Path, monkeypatch) -> None:
    with pytest.raises(FlexsatError, match="not a flexsat simulation result"):
        write_animation(Result(xr.Dataset({"a": ("x", [1.0])})), tmp_path / "x.gif")
    with pytest.raises(FlexsatError, match=r"\.gif or \.mp4"):
        write_animation(openloop, tmp_path / "x.png")
    monkeypatch.setattr(CanvasFFMpegWriter, "isAvailable", classmethod(lambda cls: False))
    with pytest.raises(FlexsatError, match="needs ffmpeg"):
        write_animation(openloop, tmp_path / "x.mp4", max_frames=2)
    assert not (tmp_path / "x.mp4").exists()
    with pytest.raises(ValueError, match="max_frames"):
        run_frames(openloop, max_frames=1)


FAKE_FFMPEG = """#!{python}
import json, sys
args = sys.argv[1:]
data = sys.stdin.buffer.read()
meta = [a for a in args if a.startswith("comment=")]
with open(args[-1], "w") as out:
    json.dump({{"size": args[args.index("-s") + 1], "pix_fmt": args[args.index("-pix_fmt") + 1],
               "bytes": len(data), "meta": meta}}, out)
"""


def test_mp4_frames_are_piped_to_ffmpeg(openloop: Result, tmp_path: Path, monkeypatch) -> None:
    """A stand-in ffmpeg records what the writer pipes to it: raw RGBA frames."""
    fake = tmp_path / "ffmpeg"
    fake.write_text(FAKE_FFMPEG.format(python=sys.executable))
    fake.chmod(0o755)
    monkeypatch.setitem(mpl.rcParams, "animation.ffmpeg_path", str(fake))
    path = write_animation(openloop, tmp_path / "run.mp4", magnification=20.0, max_frames=6)
    seen = json.loads(path.read_text())
    assert (seen["size"], seen["pix_fmt"]) == ("640x512", "rgba")
    assert seen["bytes"] == 6 * 640 * 512 * 4
    assert any("deformation x20," in m for m in seen["meta"])
