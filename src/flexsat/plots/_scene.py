"""Pieces shared by the 3-D satellite animations (mode shapes and simulated runs).

- :class:`SatelliteDrawing`: the artists of one :class:`SatelliteGeometry` on 3-D
  axes, created once and moved frame by frame (blitting).
- :func:`frame_view`: fixed limits, one scale on X, Y and Z, labels and view.
- :class:`CanvasPillowWriter` / :class:`CanvasFFMpegWriter`: movie writers that take
  each frame from the Agg canvas as the caller rendered it (no full redraw), or as
  RGBA bytes rendered elsewhere (``add_rgba``).

Private to :mod:`flexsat.plots`.
"""

from __future__ import annotations

import numpy as np
from matplotlib.animation import FFMpegWriter, PillowWriter
from matplotlib.ticker import MaxNLocator
from mpl_toolkits.mplot3d.art3d import Poly3DCollection
from PIL import Image

from flexsat.plots.geometry import SatelliteGeometry

__all__ = [
    "AXIS_COLOURS",
    "CanvasFFMpegWriter",
    "CanvasPillowWriter",
    "SatelliteDrawing",
    "closed",
    "frame_view",
]

AXIS_COLOURS = ("tab:red", "tab:green", "tab:blue")
_ARROW_HEAD = (0.16, 0.06)  # arrowhead length and half-width, fractions of the axis length
_LABEL_OFFSET = 0.14  # axis label beyond the arrow tip, fraction of the axis length


def closed(corners: np.ndarray) -> np.ndarray:
    """The polygon ``corners`` (k, 3) with its first point repeated at the end."""
    return np.concatenate([corners, corners[:1]])


def arrow_path(origin: np.ndarray, frame: np.ndarray, k: int, length: float) -> np.ndarray:
    """Polyline of a 3-D arrow along column ``k`` of the rotation ``frame``, shape (10, 3).

    The shaft runs from ``origin`` to ``origin + length frame[:, k]``; the head is
    four barbs from the tip back towards the two other columns of ``frame``, so it
    reads as an arrow from any viewpoint. Metres.
    """
    along, across = _ARROW_HEAD[0] * length, _ARROW_HEAD[1] * length
    tip = origin + length * frame[:, k]
    back = tip - along * frame[:, k]
    points = [origin, tip]
    for j in (j for j in range(3) if j != k):
        for sign in (1.0, -1.0):
            points += [back + sign * across * frame[:, j], tip]
    return np.array(points)


def hub_faces(geom: SatelliteGeometry) -> list[np.ndarray]:
    """Filled faces of the hub: top, bottom and the side quads between them (frame N, m).

    The first two hub polylines of :func:`~flexsat.plots.geometry.hub_outline` are the
    top and bottom loops (closed, same point order) for both hub kinds.
    """
    top, bottom = geom.hub_lines[0], geom.hub_lines[1]
    sides = [np.array([top[k], top[k + 1], bottom[k + 1], bottom[k]]) for k in range(len(top) - 1)]
    return [top[:-1], bottom[:-1], *sides]


class SatelliteDrawing:
    """Artists of a :class:`SatelliteGeometry` on 3-D axes, updatable per frame.

    Lines for the hub outline, the arms and the panel edges; optionally the panels
    filled (``fill``) and the hub faces filled (``hub_fill``), both in one
    :class:`Poly3DCollection` so the faces are depth-sorted together; optionally the
    hub body axes X_B, Y_B, Z_B in red, green, blue (``body_axes``, ``axis_scale``
    times the length of :attr:`SatelliteGeometry.axes`), as arrows with labels when
    ``axis_arrows`` is set.
    """

    def __init__(self, ax, geom: SatelliteGeometry, *, colour: str, linestyle: str = "-",
                 linewidth: float = 1.4, fill: str | None = None, fill_alpha: float = 0.4,
                 hub_fill: str | None = None, body_axes: bool = False,
                 axis_arrows: bool = False, axis_scale: float = 1.0,
                 label: str | None = None) -> None:  # fmt: skip
        kw = {"color": colour, "linestyle": linestyle, "linewidth": linewidth}
        self.hub = [ax.plot(*line.T, **kw)[0] for line in geom.hub_lines]
        self.arms = [ax.plot(*arm.T, **kw)[0] for arm in geom.arms]
        self.panels = [ax.plot(*closed(p).T, **kw)[0] for p in geom.panels]
        self.panels[0].set_label(label)
        self._hub_fill = hub_fill is not None
        self.fill = None
        if fill or hub_fill:
            colours = [hub_fill] * len(hub_faces(geom)) if hub_fill else []
            colours += [fill or "none"] * len(geom.panels)
            self.fill = Poly3DCollection(self._faces(geom), facecolor=colours,
                                         alpha=fill_alpha, edgecolor="none")  # fmt: skip
            ax.add_collection3d(self.fill)
        self._arrows, self._axis_scale = axis_arrows, float(axis_scale)
        self.axes = []
        self.labels = []
        if body_axes:
            for k, c in enumerate(AXIS_COLOURS):
                self.axes.append(ax.plot(*self._axis_path(geom, k).T, color=c, linewidth=2.0,
                                         label="XYZ"[k] + "_B")[0])  # fmt: skip
                if axis_arrows:
                    self.labels.append(ax.text(*self._label_at(geom, k), "XYZ"[k] + "_B",
                                               color=c, fontsize=9, fontweight="bold",
                                               ha="center", va="center"))  # fmt: skip

    def _faces(self, geom: SatelliteGeometry) -> list[np.ndarray]:
        hub = hub_faces(geom) if self._hub_fill else []
        return [*hub, *geom.panels]

    def _axis_path(self, geom: SatelliteGeometry, k: int) -> np.ndarray:
        axis = self._axis_scale * geom.axes[k]
        if self._arrows:
            return arrow_path(geom.centre, geom.R_NB, k, float(np.linalg.norm(axis)))
        return np.stack([geom.centre, geom.centre + axis])

    def _label_at(self, geom: SatelliteGeometry, k: int) -> np.ndarray:
        return geom.centre + (1.0 + _LABEL_OFFSET) * self._axis_scale * geom.axes[k]

    def update(self, geom: SatelliteGeometry) -> None:
        for art, line in zip(self.hub, geom.hub_lines, strict=True):
            art.set_data_3d(*line.T)
        for art, arm in zip(self.arms, geom.arms, strict=True):
            art.set_data_3d(*arm.T)
        for art, p in zip(self.panels, geom.panels, strict=True):
            art.set_data_3d(*closed(p).T)
        if self.fill is not None:
            self.fill.set_verts(self._faces(geom))
        for k, art in enumerate(self.axes):
            art.set_data_3d(*self._axis_path(geom, k).T)
        for k, text in enumerate(self.labels):
            text.set_position_3d(self._label_at(geom, k))

    def artists(self) -> list:
        fill = [] if self.fill is None else [self.fill]
        return [*self.hub, *self.arms, *fill, *self.panels, *self.axes, *self.labels]

    def draw(self, ax) -> None:
        """Draw the artists onto the canvas (for blitting; projection as last drawn)."""
        if self.fill is not None:
            self.fill.do_3d_projection()
        for art in self.artists():
            ax.draw_artist(art)


def frame_view(ax, lo: np.ndarray, hi: np.ndarray, *, min_depth: float = 0.3,
               elev: float = 22.0, azim: float = -38.0, zoom: float = 1.2) -> None:  # fmt: skip
    """Fix the limits of 3-D axes around the box ``lo``..``hi`` (frame N, metres).

    One scale on X, Y and Z (1 m is 1 m on screen) with a 10 % margin; each half
    side is at least ``min_depth`` times the largest (1.0: a cube, for a body that
    turns), so a flat satellite keeps some depth. Axes labelled ``X_N [m]``...
    """
    centre, half = 0.5 * (lo + hi), 0.55 * (hi - lo)
    half = np.maximum(half, min_depth * half.max())
    for k, (setter, axis) in enumerate(((ax.set_xlim, ax.xaxis), (ax.set_ylim, ax.yaxis),
                                        (ax.set_zlim, ax.zaxis))):  # fmt: skip
        setter(centre[k] - half[k], centre[k] + half[k])
        axis.set_major_locator(MaxNLocator(nbins=max(2, int(8 * half[k] / half.max()))))
        axis.set_label_text(f"{'XYZ'[k]}_N [m]", fontsize=8)
    ax.set_box_aspect(tuple(half), zoom=zoom)
    ax.view_init(elev=elev, azim=azim)
    ax.tick_params(labelsize=7)


def _rgba_image(size: tuple[int, int], rgba) -> Image.Image:
    return Image.frombuffer("RGBA", size, rgba, "raw", "RGBA", 0, 1)


class CanvasPillowWriter(PillowWriter):
    """A :class:`PillowWriter` that takes each frame from the Agg canvas as it stands.

    The caller renders the frame (here by blitting); ``grab_frame`` copies the
    canvas buffer instead of redrawing the whole figure through ``savefig``. The
    GIF gets one palette for all frames and, if given, a ``comment``.
    """

    def __init__(self, *args, comment: str | None = None, **kwargs) -> None:
        super().__init__(*args, **kwargs)
        self.comment = comment

    def grab_frame(self, **savefig_kwargs) -> None:
        self.add_rgba(self.fig.canvas.buffer_rgba())

    def add_rgba(self, rgba) -> None:
        """Append a frame rendered elsewhere: RGBA bytes of the figure's size."""
        size = self.fig.canvas.get_width_height(physical=True)
        self._frames.append(_rgba_image(size, rgba).convert("RGB"))

    def finish(self) -> None:
        # One palette for the whole GIF, from a few frames spread over the sequence:
        # much faster than an adaptive palette per frame, and no colour flicker.
        frames = self._frames
        picks = sorted({0, len(frames) // 4, len(frames) // 2, 3 * len(frames) // 4})
        width, height = frames[0].size
        montage = Image.new("RGB", (width, height * len(picks)))
        for row, k in enumerate(picks):
            montage.paste(frames[k], (0, row * height))
        palette = montage.quantize(colors=255, method=Image.Quantize.MEDIANCUT)
        indexed = [f.quantize(palette=palette, dither=Image.Dither.NONE) for f in frames]
        extra = {} if self.comment is None else {"comment": self.comment}
        indexed[0].save(self.outfile, format="GIF", save_all=True, append_images=indexed[1:],
                        duration=int(1000 / self.fps), loop=0, **extra)  # fmt: skip


class CanvasFFMpegWriter(FFMpegWriter):
    """An :class:`FFMpegWriter` fed the raw RGBA Agg canvas as the caller rendered it."""

    def __init__(self, *args, **kwargs) -> None:
        super().__init__(*args, **kwargs)
        self.frame_format = "rgba"

    def grab_frame(self, **savefig_kwargs) -> None:
        self.add_rgba(self.fig.canvas.buffer_rgba())

    def add_rgba(self, rgba) -> None:
        """Pipe a frame rendered elsewhere: RGBA bytes of the figure's size."""
        self._proc.stdin.write(bytes(rgba))
