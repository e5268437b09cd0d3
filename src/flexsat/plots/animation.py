"""3-D animation of a simulated run: the satellite turning and its panels deforming.

:func:`write_animation` takes a :class:`~flexsat.simulate.result.Result` (open-loop
or slew), rebuilds the satellite from the config stored in its attributes and
writes a GIF (or an MP4 with ffmpeg) of the whole run in the inertial frame N:

- the hub (filled, with its outline) and the panels (filled polygons), drawn by
  the exact kinematics of :func:`~flexsat.plots.geometry.satellite_geometry`, so a
  slew of tens of degrees shows as such;
- the joint deformation (root rotations and translations) magnified by a stated
  factor, by default chosen from the run so the peak tip displacement shows as
  15 % of the panel length (:func:`auto_magnification`); the hub motion (attitude
  and position) is never magnified;
- the hub body axes X_B, Y_B, Z_B as red, green, blue arrows with labels, and the
  inertial axes X_N, Y_N, Z_N faint and dashed;
- a title naming the run and the magnification ("deformation ×N") and, in each
  frame, the time "t = 12.3 s" and the hub Euler angles.

Frames are recorded states picked evenly in time (:func:`run_frames`), at most
``max_frames`` of them. Rendering uses Agg only (no display, no pyplot, the global
backend untouched), blits the moving artists over a background drawn once, and is
deterministic: the same result and options give the same bytes.
"""

from __future__ import annotations

import json
import math
import mmap
import subprocess
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure

from flexsat.dynamics.plant import Plant
from flexsat.errors import FlexsatError
from flexsat.files import ensure_dir, replacing_name
from flexsat.parallel import figure_workers, forked_map
from flexsat.plots._scene import (
    AXIS_COLOURS,
    CanvasFFMpegWriter,
    CanvasPillowWriter,
    SatelliteDrawing,
    frame_view,
)
from flexsat.plots.geometry import SatelliteGeometry, satellite_geometry
from flexsat.plots.modal import DEFAULT_PEAK_FRACTION
from flexsat.plots.style import literal
from flexsat.simulate.result import Result

__all__ = [
    "DEFAULT_FPS",
    "DEFAULT_MAX_FRAMES",
    "RunFrames",
    "auto_magnification",
    "result_plant",
    "run_frames",
    "write_animation",
]

DEFAULT_MAX_FRAMES = 150
"""Most frames in an animation: a 120 s run plays 7.5 s at 20 frames/s."""
DEFAULT_FPS = 20
"""Playback rate of an animation [frames/s]."""

_SUFFIXES = (".gif", ".mp4")
_FIGSIZE_IN, _DPI = (8.0, 6.4), 80  # 640 x 512 px (even sides, as H.264 wants)
_BODY_AXIS_SCALE = 1.6  # body axes, in units of SatelliteGeometry.axes (2 hub half-sizes)
_INERTIAL_SCALE = 1.4  # inertial axes, in units of the drawn body-axis length
_HUB_FILL, _PANEL_FILL = "silver", "goldenrod"


# -- reading a result ------------------------------------------------------------------


def result_plant(result: Result) -> Plant:
    """Rebuild the simulated :class:`Plant` from the config stored in a result.

    Parameters
    ----------
    result : Result
        A flexsat run (``attrs["config"]`` holds the satellite config as JSON).

    Returns
    -------
    Plant

    Raises
    ------
    FlexsatError
        The dataset is not a flexsat result (no stored config, no ``q`` variable) or
        its config is refused (:class:`~flexsat.errors.ConfigError`).
    """
    from flexsat.config.load import validate_config

    ds = result.dataset
    text = ds.attrs.get("config")
    if not isinstance(text, str) or "q" not in ds.variables or "time" not in ds.coords:
        raise FlexsatError(
            "not a flexsat simulation result (no satellite config or generalized coordinates)"
        )
    try:
        data = json.loads(text)
    except json.JSONDecodeError as exc:
        raise FlexsatError(f"the stored satellite config is not valid JSON ({exc})") from None
    plant = Plant.from_config(validate_config(data, source="stored config"))
    if ds["q"].shape[-1] != plant.n_dof:
        raise FlexsatError(
            f"the result has {ds['q'].shape[-1]} generalized coordinates but its stored "
            f"config has {plant.n_dof}"
        )
    return plant


def _nice_floor(x: float) -> float:
    """``x`` > 0 rounded down to two significant digits (347.2 -> 340, 3.47 -> 3.4)."""
    step = 10.0 ** (math.floor(math.log10(x)) - 1)
    return math.floor(x / step + 1e-9) * step


def auto_magnification(
    result: Result, plant: Plant | None = None, fraction: float = DEFAULT_PEAK_FRACTION
) -> float:
    """Deformation magnification that makes the run's peak tip displacement visible.

    Chosen so the largest tip displacement of any panel over the whole run (the
    recorded ``tip_displacement``, mount frame) shows as about ``fraction`` of that
    panel's length: ``fraction * L_i / peak_i`` for the panel where ``peak_i / L_i``
    is largest, rounded down to two significant digits, and never below 1 (a run
    that deforms more than that is shown at true scale). A run whose panels do not
    deform (or would need a factor above a million) gets 1.

    Parameters
    ----------
    result : Result
        A recorded run.
    plant : Plant, optional
        The run's plant; by default rebuilt with :func:`result_plant`.
    fraction : float
        Target peak tip displacement over panel length [-].

    Returns
    -------
    float
        The magnification [-], >= 1.
    """
    plant = result_plant(result) if plant is None else plant
    peak, length = _peak_tip(result, plant)
    ratio = peak / length
    if ratio <= 0.0 or ratio * 1e6 < fraction:  # rigid, or nothing visible at any scale
        return 1.0
    return max(1.0, _nice_floor(fraction / ratio))


def _peak_tip(result: Result, plant: Plant) -> tuple[float, float]:
    """Peak tip displacement over the run [m] of the panel where it is largest relative
    to the panel length, and that panel's length [m]."""
    ds = result.dataset
    lengths = np.array([m.extent(a) for a, m in zip(plant.config.appendages, plant.models,
                                                    strict=True)])  # fmt: skip
    if "tip_displacement" in ds.variables:
        tips = np.asarray(ds["tip_displacement"].values, dtype=float)
    else:
        q = np.asarray(ds["q"].values, dtype=float)
        tips = np.array([plant.tip_displacement(qk) for qk in q if np.all(np.isfinite(qk))])
    with np.errstate(invalid="ignore", over="ignore"):
        norms = np.linalg.norm(tips.reshape(-1, lengths.size, 3), axis=-1)
    norms = np.where(np.isfinite(norms), norms, 0.0)
    if norms.size == 0:
        return 0.0, float(lengths[0])
    peaks = np.where(lengths > 0.0, norms.max(axis=0), 0.0)  # a rigid body has no tip motion
    worst = int(np.argmax(peaks / np.where(lengths > 0.0, lengths, 1.0)))
    return float(peaks[worst]), float(lengths[worst])


# -- frames ----------------------------------------------------------------------------


@dataclass(frozen=True)
class RunFrames:
    """The recorded states an animation shows, and how it shows them.

    Attributes
    ----------
    plant : Plant
        The simulated satellite.
    time : ndarray, shape (k,)
        Frame times [s], recorded times picked evenly over the run.
    index : ndarray of int, shape (k,)
        Their record indices in the result [-].
    q : ndarray, shape (k, n_dof)
        Recorded generalized coordinates at those times [m, rad].
    magnification : float
        Factor applied to the joint coordinates (root translations and rotations)
        when drawing [-]; the hub position and attitude are drawn as recorded.
    """

    plant: Plant
    time: np.ndarray
    index: np.ndarray
    q: np.ndarray
    magnification: float

    def __len__(self) -> int:
        return int(self.time.size)

    def drawn_q(self, k: int) -> np.ndarray:
        """Coordinates drawn in frame ``k``: the joint ones magnified, shape (n_dof,)."""
        q = self.q[k].copy()
        q[6:] *= self.magnification
        return q

    def geometry(self, k: int) -> SatelliteGeometry:
        """Drawable satellite of frame ``k`` in the inertial frame N [m].

        Its ``R_NB`` and ``axes`` (hub body axes, rows X_B, Y_B, Z_B) follow the
        recorded attitude exactly; only the panel deformation is magnified.
        """
        return satellite_geometry(self.plant, self.drawn_q(k))


def _pick(time: np.ndarray, n: int) -> np.ndarray:
    """Indices of ``n`` records nearest to evenly spaced times over ``time`` (sorted)."""
    if n >= time.size:
        return np.arange(time.size)
    targets = np.linspace(time[0], time[-1], n)
    right = np.clip(np.searchsorted(time, targets), 1, time.size - 1)
    left = right - 1
    nearest = np.where(targets - time[left] <= time[right] - targets, left, right)
    return np.unique(nearest)


def run_frames(
    result: Result,
    *,
    magnification: float | None = None,
    max_frames: int = DEFAULT_MAX_FRAMES,
    fps: int = DEFAULT_FPS,
    playback_s: float | None = None,
    plant: Plant | None = None,
) -> RunFrames:
    """Choose the frames of an animation: times, states and magnification.

    Parameters
    ----------
    result : Result
        A flexsat run; a failed run is shown up to its last finite state.
    magnification : float, optional
        Joint-deformation magnification [-] (>= 0; 1 is true scale); by default
        :func:`auto_magnification`.
    max_frames : int
        Most frames (>= 2); fewer when the run has fewer records.
    fps : int
        Playback rate [frames/s] (> 0); with ``playback_s`` sets the frame count.
    playback_s : float, optional
        Length of the animation on screen [s]: at most ``fps * playback_s`` frames
        (still at most ``max_frames``); by default ``max_frames`` frames.
    plant : Plant, optional
        The run's plant; by default rebuilt with :func:`result_plant`.

    Returns
    -------
    RunFrames
    """
    if int(max_frames) < 2:
        raise ValueError(f"max_frames must be at least 2, got {max_frames}")
    if int(fps) <= 0:
        raise ValueError(f"fps must be positive, got {fps}")
    if magnification is not None and not (np.isfinite(magnification) and magnification >= 0):
        raise ValueError(f"magnification must be finite and >= 0, got {magnification}")
    if playback_s is not None and not (np.isfinite(playback_s) and playback_s > 0):
        raise ValueError(f"playback_s must be positive, got {playback_s}")
    plant = result_plant(result) if plant is None else plant
    time = np.asarray(result.dataset["time"].values, dtype=float)
    q = np.asarray(result.dataset["q"].values, dtype=float)
    finite = np.flatnonzero(np.all(np.isfinite(q), axis=1) & np.isfinite(time))
    if finite.size == 0:
        raise FlexsatError("the result has no finite state to draw")
    n = int(max_frames)
    if playback_s is not None:
        n = max(2, min(n, round(int(fps) * float(playback_s))))
    index = finite[_pick(time[finite], n)]
    if magnification is None:
        magnification = auto_magnification(result, plant)
    return RunFrames(plant, time[index], index, q[index], float(magnification))


# -- drawing ---------------------------------------------------------------------------


def _shown(x: float) -> str:
    """A magnification as printed: 19 -> '19', 3.4 -> '3.4', 1250 -> '1250'."""
    return f"{x:.0f}" if x >= 10.0 or float(x).is_integer() else f"{x:.3g}"


def _title(result: Result, frames: RunFrames) -> str:
    attrs = result.dataset.attrs
    head = literal(str(attrs.get("title", "flexsat run")).removeprefix("flexsat "))
    head = head[:1].upper() + head[1:]
    if attrs.get("controller"):
        head += f", {literal(attrs.get('controller_label', str(attrs['controller']).upper()))}"
    head += f", {frames.time[-1] - frames.time[0]:.4g} s"
    if attrs.get("status", "ok") != "ok":
        head += f" (run failed at t = {float(attrs.get('failure_time_s', frames.time[-1])):.4g} s)"
    peak, length = _peak_tip(result, frames.plant)
    detail = ""
    if peak > 0.0:
        amount = f"{1e3 * peak:.3g} mm" if peak < 1.0 else f"{peak:.3g} m"
        shown = 100.0 * frames.magnification * peak / length
        detail = (
            f" (peak tip displacement {amount} on the {length:.3g} m panel, "
            f"shown as {shown:.2g} % of its length)"
        )
    scale = " = true scale" if frames.magnification == 1.0 else ""
    return f"{head}\ndeformation ×{_shown(frames.magnification)}{scale}{detail}"


def _time_format(frames: RunFrames) -> str:
    step = float(np.min(np.diff(frames.time))) if len(frames) > 1 else 1.0
    decimals = int(np.clip(math.ceil(-math.log10(max(step, 1e-3)) + 1e-9), 1, 3))
    return f"{{:.{decimals}f}}"


def _body_length(shots: list[SatelliteGeometry]) -> float:
    """Drawn length of the hub body axes [m]."""
    return _BODY_AXIS_SCALE * float(np.linalg.norm(shots[0].axes[0]))


def _view_box(shots: list[SatelliteGeometry]) -> tuple[np.ndarray, np.ndarray]:
    """Corners (lo, hi) of the box the view holds: every frame and the inertial axes [m]."""
    inertial = _INERTIAL_SCALE * _body_length(shots)
    lo, hi = np.full(3, -1.1 * inertial), np.full(3, 1.1 * inertial)
    for g in shots:
        glo, ghi = g.bounds()
        lo, hi = np.minimum(lo, glo), np.maximum(hi, ghi)
    return lo, hi


def _draw_inertial_axes(ax, length: float) -> None:
    for k, colour in enumerate(AXIS_COLOURS):
        tip = np.zeros(3)
        tip[k] = length
        ax.plot(*np.stack([np.zeros(3), tip]).T, color=colour, alpha=0.3, linestyle="--",
                linewidth=1.0)  # fmt: skip
        ax.text(*(1.08 * tip), "XYZ"[k] + "_N", color=colour, alpha=0.45, fontsize=8,
                ha="center", va="center")  # fmt: skip


def _writer(path: Path, fps: int, comment: str):
    if path.suffix.lower() == ".gif":
        return CanvasPillowWriter(fps=fps, comment=comment)
    if not CanvasFFMpegWriter.isAvailable():
        raise FlexsatError(
            f"writing {path.name} needs ffmpeg, which was not found; install ffmpeg "
            "or write a .gif instead"
        )
    return CanvasFFMpegWriter(fps=fps, codec="h264", metadata={"comment": comment})


def write_animation(
    result: Result,
    path: str | Path,
    *,
    magnification: float | None = None,
    fps: int = DEFAULT_FPS,
    playback_s: float | None = None,
    max_frames: int = DEFAULT_MAX_FRAMES,
) -> Path:
    """Write a 3-D animation of a simulated run (GIF, or MP4 with ffmpeg).

    The satellite is rebuilt from the config stored in the result and drawn in the
    inertial frame N at recorded states picked evenly in time (see
    :func:`run_frames`): hub and panels filled, joint deformation magnified by a
    stated factor, hub body axes as coloured labelled arrows, inertial axes faint.
    The axes (metres) have one scale on X, Y and Z and limits fixed over the whole
    run. The title names the run and gives ``deformation ×N``; each frame shows
    ``t = ... s`` and the hub Euler angles. 640 x 512 px, Agg, deterministic (the
    frames are rendered by :func:`~flexsat.parallel.figure_workers` forked processes,
    the same pixels as in one). A GIF
    gets one shared 255-colour palette and a comment
    ``"flexsat animation: deformation xN, K frames, t = t0..t1 s"`` (an MP4 the same
    as its ``comment`` metadata), so a file tells the magnification it shows.

    Parameters
    ----------
    result : Result
        A flexsat open-loop or slew run (a failed one shows its history).
    path : str or Path
        Output file, ``.gif`` or ``.mp4``; missing folders are created.
    magnification : float, optional
        Joint-deformation magnification [-] (>= 0; 1 is true scale); by default
        :func:`auto_magnification`: the peak tip displacement shows as 15 % of the
        panel length, never below 1.
    fps : int
        Playback rate [frames/s].
    playback_s : float, optional
        Length of the animation on screen [s]; caps the frames at ``fps * playback_s``.
    max_frames : int
        Most frames; a 120 s run at the default 150 plays 7.5 s at 20 frames/s.

    Returns
    -------
    Path
        The file written.

    Raises
    ------
    FlexsatError
        Not a flexsat result, a suffix other than ``.gif``/``.mp4``, or an MP4
        requested without ffmpeg.

    Notes
    -----
    The frames sample the run every ``duration / (frames - 1)`` seconds of
    simulated time (0.8 s for a 120 s run in 150 frames): panel vibration faster
    than half that sampling rate is shown aliased, slower than it is. The
    magnification and peak are taken from every record, not only the frames.
    """
    path = Path(path)
    if path.suffix.lower() not in _SUFFIXES:
        raise FlexsatError(f"animation file must end in .gif or .mp4, got {path.name!r}")
    frames = run_frames(result, magnification=magnification, max_frames=max_frames, fps=fps,
                        playback_s=playback_s)  # fmt: skip
    comment = (
        f"flexsat animation: deformation x{_shown(frames.magnification)}, {len(frames)} frames, "
        f"t = {frames.time[0]:.6g}..{frames.time[-1]:.6g} s"
    )
    writer = _writer(path, int(fps), comment)
    ensure_dir(path.parent)

    shots = [frames.geometry(k) for k in range(len(frames))]
    width, height = round(_FIGSIZE_IN[0] * _DPI), round(_FIGSIZE_IN[1] * _DPI)
    # The frames are rendered by forked processes (figure_workers), each a contiguous
    # run of them, into one anonymous shared mapping (RGBA rows, one per frame): no
    # frame is pickled, and the writer takes them in order here.
    shared = mmap.mmap(-1, len(shots) * height * width * 4)
    movie = np.frombuffer(shared, dtype=np.uint8).reshape(len(shots), -1)
    lo, hi = _view_box(shots)

    def render(chunk: np.ndarray) -> None:
        fig = Figure(figsize=_FIGSIZE_IN, dpi=_DPI)
        canvas = FigureCanvasAgg(fig)
        ax = fig.add_axes((0.0, 0.04, 1.0, 0.84), projection="3d")
        frame_view(ax, lo, hi, min_depth=1.0, zoom=1.1)  # a cube: the body turns
        _draw_inertial_axes(ax, _INERTIAL_SCALE * _body_length(shots))
        moving = SatelliteDrawing(ax, shots[0], colour="0.15", linewidth=1.2,
                                  fill=_PANEL_FILL, fill_alpha=0.75, hub_fill=_HUB_FILL,
                                  body_axes=True, axis_arrows=True,
                                  axis_scale=_BODY_AXIS_SCALE)  # fmt: skip
        for line in moving.hub:
            line.set_linewidth(0.7)
        fig.suptitle(_title(result, frames), fontsize=9, y=0.985)
        clock = fig.text(0.02, 0.85, "", fontsize=12, fontweight="bold", animated=True)
        angles = fig.text(0.02, 0.815, "", fontsize=8, color="0.3", animated=True)
        span = frames.time[-1] - frames.time[0]
        speed = span / (len(frames) / int(fps)) if span > 0 else 0.0
        fig.text(0.98, 0.85, f"{len(frames)} frames, playback {speed:.3g}× real time",
                 fontsize=7, color="0.45", ha="right")  # fmt: skip
        when = _time_format(frames)
        euler = np.degrees(frames.q[:, 3:6])
        for art in moving.artists():
            art.set_animated(True)
        canvas.draw()
        background = canvas.copy_from_bbox(fig.bbox)
        for k in chunk:
            canvas.restore_region(background)
            moving.update(shots[k])
            moving.draw(ax)
            clock.set_text(f"t = {when.format(frames.time[k])} s")
            roll, pitch, yaw = euler[k]
            angles.set_text(f"roll {roll:+.1f}°  pitch {pitch:+.1f}°  yaw {yaw:+.1f}°")
            fig.draw_artist(clock)
            fig.draw_artist(angles)
            movie[k] = np.frombuffer(canvas.buffer_rgba(), dtype=np.uint8).ravel()
        fig.clear()

    workers = min(figure_workers(), len(shots))
    forked_map(render, np.array_split(np.arange(len(shots)), workers), workers)
    sheet = Figure(figsize=_FIGSIZE_IN, dpi=_DPI)  # what the writer sizes the movie by
    FigureCanvasAgg(sheet)
    try:
        # a new file moved onto path: a link there is replaced, never followed
        with replacing_name(path, keep_suffix=True) as partial, \
                writer.saving(sheet, partial, dpi=_DPI):  # fmt: skip
            for rgba in movie:
                writer.add_rgba(rgba)
    except (OSError, subprocess.CalledProcessError) as exc:  # ffmpeg failed, the pipe broke
        if path.suffix.lower() == ".gif":
            raise
        raise FlexsatError(f"ffmpeg could not write {path.name}: {exc}") from None
    return path
