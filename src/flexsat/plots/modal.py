"""Figures of a modal analysis: interaction map, frequency summary, mode animations.

Every figure is a :class:`matplotlib.figure.Figure` created directly (no pyplot),
so nothing here needs a display or changes the global matplotlib backend; PNG
and GIF output is rendered with Agg.

- :func:`plot_interaction_map`: heat map of the normalized mass-weighted modal
  amplitudes, DOF x mode (thesis fig. 3.2).
- :func:`plot_frequencies`: the flexible-mode frequencies on a log scale, each
  labelled with its kind, mirror symmetry and coupled hub DOF (thesis table 3.3).
- :func:`animate_mode`: a GIF of one mode shape oscillating over one period.
- :func:`write_modal_figures`: all of the above into a folder.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
from matplotlib.axes import Axes
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure
from matplotlib.lines import Line2D
from PIL import Image

from flexsat.analysis.modal import ModalAnalysis, Mode
from flexsat.dynamics.plant import Plant
from flexsat.files import ensure_dir, replacing, replacing_name
from flexsat.plots import style
from flexsat.plots._scene import CanvasPillowWriter, SatelliteDrawing, frame_view
from flexsat.plots.geometry import SatelliteGeometry, satellite_geometry

__all__ = [
    "DEFAULT_PEAK_FRACTION",
    "animate_mode",
    "default_animated_modes",
    "mode_amplitude",
    "plot_frequencies",
    "plot_interaction_map",
    "write_modal_figures",
]

DEFAULT_PEAK_FRACTION = 0.15
"""Largest panel displacement of an animated mode, as a fraction of the panel length."""

_MAX_DEFAULT_ANIMATIONS = 6
_AMPLITUDE_ITERATIONS = 8
_KIND_LABEL = {
    "rigid": "rigid body",
    "flapping": "flapping",
    "in_plane": "in-plane bending",
    "torsion": "torsion",
    "translation": "root translation",
}
_KIND_COLOUR = {
    "flapping": "tab:blue",
    "in_plane": "tab:orange",
    "torsion": "tab:green",
    "translation": "tab:purple",
}
_SYMMETRY_MARKER = {"symmetric": "o", "antisymmetric": "s", "none": "^"}
_SYMMETRY_SHORT = {"symmetric": "sym.", "antisymmetric": "antisym.", "none": "no parity"}


# -- interaction map -------------------------------------------------------------------


def plot_interaction_map(analysis: ModalAnalysis, ax: Axes | None = None) -> Figure:
    """Heat map of the modal interaction map (thesis fig. 3.2).

    Cell (j, k) is ``analysis.participation[j, k]``: the mass-weighted amplitude
    ``|phi_jk| sqrt(M_jj)`` of generalized coordinate j in mode k, each mode
    scaled to a maximum of 1 (dimensionless, 0-1). DOFs run down the vertical
    axis (hub first, then each appendage, separated by rules); modes run along the
    horizontal axis labelled with their 1-based index and natural frequency [Hz],
    the six rigid-body modes first. Values are printed in the cells for up to 30
    DOFs; fonts shrink with the number of DOFs.

    Parameters
    ----------
    analysis : ModalAnalysis
        The modes (:func:`flexsat.analysis.modal_analysis`).
    ax : matplotlib.axes.Axes, optional
        Axes to draw into (the colour bar is added to its figure); by default a new
        figure sized to the number of DOFs.

    Returns
    -------
    matplotlib.figure.Figure
    """
    data = np.asarray(analysis.participation, dtype=float)
    n_dof, n_modes = data.shape
    names = list(analysis.dof_names) or [str(j) for j in range(n_dof)]
    font = _font_size(max(n_dof, n_modes))
    if ax is None:
        side = float(np.clip(4.0 + 0.3 * max(n_dof, n_modes), 7.0, 20.0))
        fig = Figure(figsize=(side + 1.2, side), layout="constrained")
        ax = fig.add_subplot()
    else:
        fig = ax.figure

    image = ax.imshow(data, cmap="Blues", vmin=0.0, vmax=1.0, aspect="auto",
                      interpolation="nearest")  # fmt: skip
    ax.set_yticks(np.arange(n_dof), names, fontsize=font)
    ax.set_xticks(np.arange(n_modes), [_mode_tick(m) for m in analysis.modes[:n_modes]],
                  rotation=90, fontsize=font)  # fmt: skip
    ax.tick_params(length=2)
    ax.set_xticks(np.arange(n_modes + 1) - 0.5, minor=True)
    ax.set_yticks(np.arange(n_dof + 1) - 0.5, minor=True)
    ax.grid(which="minor", color="0.85", linewidth=0.4)
    ax.tick_params(which="minor", length=0)
    for j in range(6, n_dof, 6):  # hub | appendage 1 | appendage 2 ...
        ax.axhline(j - 0.5, color="0.25", linewidth=0.9)
    n_rigid = sum(m.kind == "rigid" for m in analysis.modes)
    if 0 < n_rigid < n_modes:
        ax.axvline(n_rigid - 0.5, color="0.25", linewidth=0.9)
    if n_dof <= 30:
        for j, k in zip(*np.nonzero(data >= 0.05), strict=True):
            ax.text(k, j, f"{data[j, k]:.2f}".lstrip("0"), ha="center", va="center",
                    fontsize=font - 1.5, color="white" if data[j, k] > 0.6 else "0.15")  # fmt: skip

    ax.set_xlabel("mode (index · natural frequency)", fontsize=font + 1)
    ax.set_ylabel("generalized coordinate", fontsize=font + 1)
    n_app = analysis.plant.n_appendages
    ax.set_title(
        f"Modal interaction map — {style.literal(analysis.plant.config.name)} "
        f"({n_app} appendage{'s' if n_app != 1 else ''}, {n_dof} DOF)",
        fontsize=font + 3,
    )
    bar = fig.colorbar(image, ax=ax, fraction=0.04, pad=0.02)
    bar.set_label("normalized mass-weighted amplitude |φ_jk|·√M_jj  [-]", fontsize=font + 1)
    bar.ax.tick_params(labelsize=font)
    return fig


def _mode_tick(mode: Mode) -> str:
    if mode.kind == "rigid":
        return f"{mode.index} · rigid"
    return f"{mode.index} · {mode.frequency_hz:.3g} Hz"


def _font_size(n: int) -> float:
    """Tick font size [pt] for n rows or columns: 9 up to ~20, down to 5 at ~60."""
    return float(np.clip(9.0 - 4.0 * (n - 20) / 40.0, 5.0, 9.0))


# -- frequency summary -----------------------------------------------------------------


def plot_frequencies(analysis: ModalAnalysis, ax: Axes | None = None) -> Figure:
    """Stem chart of the flexible-mode natural frequencies (table-3.3-style summary).

    One stem per flexible mode at its 1-based index, height = natural frequency
    [Hz] on a logarithmic axis; colour = mode kind (dominant strain energy),
    marker = mirror symmetry. Each mode is labelled with its frequency and, above
    the plot, with its kind, symmetry and the hub DOF it drives (``-> psi``) or
    ``no hub`` when it leaves the hub at rest. Dotted lines mark the appendages'
    clamped-root (cantilever) target frequencies. The six rigid-body modes (0 Hz)
    are counted in a note, not drawn.

    Parameters
    ----------
    analysis : ModalAnalysis
        The modes (:func:`flexsat.analysis.modal_analysis`).
    ax : matplotlib.axes.Axes, optional
        Axes to draw into; by default a new figure sized to the number of modes.

    Returns
    -------
    matplotlib.figure.Figure
    """
    flexible = [m for m in analysis.modes if m.kind != "rigid" and m.frequency_hz > 0.0]
    n_rigid = len(analysis.modes) - len(flexible)
    n = len(flexible)
    font = _font_size(n)
    if ax is None:
        width = float(np.clip(3.0 + 0.42 * n, 7.0, 22.0))
        fig = Figure(figsize=(width, 7.5), layout="constrained")
        ax = fig.add_subplot()
    else:
        fig = ax.figure
    if not flexible:
        ax.text(0.5, 0.5, "no flexible modes", ha="center", va="center", transform=ax.transAxes)
        return fig

    idx = np.array([m.index for m in flexible])
    freq = np.array([m.frequency_hz for m in flexible])
    low, high = freq.min() / 3.0, freq.max() * 3.0
    ax.set_yscale("log")
    ax.set_ylim(low, high)
    ax.set_xlim(idx.min() - 0.7, idx.max() + 0.7)
    for m in flexible:
        colour = _KIND_COLOUR.get(m.kind, "0.3")
        ax.vlines(m.index, low, m.frequency_hz, color=colour, linewidth=2.0, alpha=0.8)
        ax.plot(m.index, m.frequency_hz, _SYMMETRY_MARKER.get(m.symmetry, "o"), color=colour,
                markersize=8, markeredgecolor="black", markeredgewidth=0.6)  # fmt: skip
        ax.annotate(f"{m.frequency_hz:.3g}", (m.index, m.frequency_hz), xytext=(0, 7),
                    textcoords="offset points", ha="center", va="bottom", fontsize=font,
                    rotation=90 if n > 16 else 0)  # fmt: skip

    for value, labels in _cantilever_targets(analysis.plant).items():
        if low < value < high:
            ax.axhline(value, color="0.55", linestyle=":", linewidth=0.9, zorder=0)
            ax.annotate(f"cantilever {', '.join(labels)}: {value:.3g} Hz", (1.0, value),
                        xycoords=("axes fraction", "data"), xytext=(-3, 2),
                        textcoords="offset points", ha="right", va="bottom",
                        fontsize=font - 1, color="0.45")  # fmt: skip

    # The x tick labels are the table: index, kind, symmetry, hub DOF driven.
    ax.set_xticks(idx, [_frequency_tick(m) for m in flexible], rotation=90, fontsize=font)
    for label, m in zip(ax.get_xticklabels(), flexible, strict=True):
        label.set_color(_KIND_COLOUR.get(m.kind, "0.3"))
    ax.tick_params(axis="y", labelsize=font)
    ax.set_xlabel("mode: index · kind · mirror symmetry · hub DOF driven", fontsize=font + 1)
    ax.set_ylabel("natural frequency [Hz]", fontsize=font + 1)
    ax.grid(axis="y", which="both", color="0.9", linewidth=0.5)
    handles = [Line2D([], [], color=c, linewidth=3, label=_KIND_LABEL[k])
               for k, c in _KIND_COLOUR.items() if any(m.kind == k for m in flexible)]  # fmt: skip
    handles += [Line2D([], [], linestyle="none", marker=mk, color="0.6", markeredgecolor="black",
                       label=s) for s, mk in _SYMMETRY_MARKER.items()
                if any(m.symmetry == s for m in flexible)]  # fmt: skip
    ax.legend(handles=handles, loc="upper left", fontsize=font, framealpha=0.9)
    ax.set_title(
        f"Natural frequencies of the flexible modes — {style.literal(analysis.plant.config.name)}\n"
        f"{n} flexible modes; {n_rigid} rigid-body modes at 0 Hz not shown",
        fontsize=font + 3,
    )
    return fig


def _frequency_tick(mode: Mode) -> str:
    hub = f"→ hub {mode.hub_dof}" if mode.hub_dof else "hub at rest"
    kind = _KIND_LABEL.get(mode.kind, mode.kind)
    return f"{mode.index} · {kind} · {_SYMMETRY_SHORT.get(mode.symmetry, mode.symmetry)} · {hub}"


def _cantilever_targets(plant: Plant) -> dict[float, list[str]]:
    """Distinct clamped-root target frequencies [Hz] -> the joint DOFs that use them."""
    targets: dict[float, list[str]] = {}
    for app, model in zip(plant.config.appendages, plant.models, strict=True):
        for label, value in model.target_frequencies(app):
            names = targets.setdefault(round(float(value), 9), [])
            if label not in names:
                names.append(label)
    for names in targets.values():
        moved = [x for x in names if x.startswith("translation ")]
        if len(moved) == 3:
            names[names.index(moved[0])] = "translation"
            for x in moved[1:]:
                names.remove(x)
    return dict(sorted(targets.items()))


# -- mode animation --------------------------------------------------------------------


def _panel_lengths(plant: Plant) -> np.ndarray:
    """Length of the appendage each drawn quadrilateral belongs to, (k,) [m]."""
    rows = zip(plant.config.appendages, plant.models, plant.params, plant.layout.blocks,
               strict=True)  # fmt: skip
    return np.concatenate([np.full(len(m.outlines(a, p, np.zeros(b.count))), m.extent(a))
                           for a, m, p, b in rows])  # fmt: skip


def _panel_displacement(plant: Plant, q: np.ndarray, rest: SatelliteGeometry) -> np.ndarray:
    """Largest displacement of each drawn quadrilateral from ``rest`` (at a corner), (k,) [m]."""
    moved = satellite_geometry(plant, q).panels - rest.panels
    return np.linalg.norm(moved, axis=-1).max(axis=-1)


def mode_amplitude(
    analysis: ModalAnalysis, mode_index: int, fraction: float = DEFAULT_PEAK_FRACTION
) -> float:
    """Modal amplitude ``a`` that makes q = a phi move a panel by ``fraction`` of its length.

    The largest displacement of any point of any panel (attained at a corner), in N
    and relative to the undeformed satellite (so rigid-body modes count too), is
    set to ``fraction`` times that panel's length: first to first order in ``a``,
    then corrected on the exact (finite-rotation) geometry to within 0.1 %.

    Parameters
    ----------
    analysis : ModalAnalysis
        The modes (:func:`flexsat.analysis.modal_analysis`).
    mode_index : int
        1-based, as in ``analysis.modes``.
    fraction : float
        Target peak panel displacement over panel length [-].

    Returns
    -------
    float
        ``a`` in the units of the mass-normalized shapes (q = a phi) [sqrt(kg) m];
        1.0 for a mode that does not move the panels.
    """
    plant, phi = analysis.plant, _shape(analysis, mode_index)
    eps = 1e-6 / max(float(np.max(np.abs(phi))), 1e-300)
    plus = satellite_geometry(plant, eps * phi).panels
    minus = satellite_geometry(plant, -eps * phi).panels
    rate = np.linalg.norm(plus - minus, axis=-1).max(axis=-1) / (2.0 * eps)  # (n,) m per unit a
    lengths = _panel_lengths(plant)
    ratio = float(np.max(rate / lengths))
    if ratio <= 1e-12:
        return 1.0
    a = fraction / ratio
    # Finite rotations make the displacement slightly nonlinear in a: correct the
    # first-order estimate on the exact geometry (both signs of the oscillation).
    rest = satellite_geometry(plant)
    for _ in range(_AMPLITUDE_ITERATIONS):
        reached = max(
            float(np.max(_panel_displacement(plant, s * a * phi, rest) / lengths))
            for s in (1.0, -1.0)
        )
        if abs(reached - fraction) <= 1e-3 * fraction or reached <= 0.0:
            break
        a *= fraction / reached
    return a


def _shape(analysis: ModalAnalysis, mode_index: int) -> np.ndarray:
    n = analysis.shapes.shape[1]
    if not 1 <= int(mode_index) <= n:
        raise ValueError(f"mode_index must be in 1..{n} (1-based), got {mode_index}")
    return np.asarray(analysis.shapes[:, int(mode_index) - 1], dtype=float)


def animate_mode(
    analysis: ModalAnalysis,
    mode_index: int,
    path: str | Path,
    amplitude: float | None = None,
    frames: int = 48,
    fps: int = 24,
    still: str | Path | None = None,
) -> Path:
    """Write a GIF of one mode shape oscillating over one period.

    The satellite is drawn in 3-D at q(t) = a phi cos(2 pi t / T), t = k T / frames for
    k = 0 .. frames-1, so the first frame (what a viewer that shows no animation, or a
    printed page, shows) is the peak deformation (T = 1 / f; a rigid-body mode, f = 0,
    is shown as the same oscillation with no time scale). The undeformed satellite is
    dashed grey, the deformed one solid with shaded panels, with the hub body axes X_B,
    Y_B, Z_B in red, green, blue. The axes (frame N, metres) have one scale on X, Y and
    Z and limits fixed over the whole period, so the picture does not jump. The title
    gives the mode index, frequency, kind, symmetry, the hub DOF it drives and the
    magnification of the motion; a footer gives the time within the period. Rendered
    with Agg by blitting (560 x 448 px at the default size), written with a
    :class:`matplotlib.animation.PillowWriter` and one shared 255-colour palette.

    Parameters
    ----------
    analysis : ModalAnalysis
        The modes (:func:`flexsat.analysis.modal_analysis`).
    mode_index : int
        1-based, as in ``analysis.modes``.
    path : str or Path
        Output GIF file; its folder must exist.
    amplitude : float, optional
        Modal amplitude ``a`` applied to the mass-normalized shape [sqrt(kg) m]; by
        default :func:`mode_amplitude`, so the largest panel displacement is 15 %
        of the panel length.
    frames : int
        Frames per period (at least 2).
    fps : int
        Playback rate [frames/s]; one period lasts ``frames / fps`` seconds on
        screen whatever the mode's real period.
    still : str or Path, optional
        Also write the first frame, the peak deformation, as this PNG.

    Returns
    -------
    Path
        The GIF written.
    """
    if frames < 2:
        raise ValueError(f"frames must be at least 2, got {frames}")
    if fps <= 0:
        raise ValueError(f"fps must be positive, got {fps}")
    path = Path(path)
    plant = analysis.plant
    phi = _shape(analysis, mode_index)
    mode = analysis.modes[int(mode_index) - 1]
    a = mode_amplitude(analysis, mode_index) if amplitude is None else float(amplitude)

    rest = satellite_geometry(plant)
    phases = np.cos(2.0 * np.pi * np.arange(frames) / frames)  # frame 0: the peak
    shots = [satellite_geometry(plant, a * s * phi) for s in phases]
    peaks = [_panel_displacement(plant, sign * a * phi, rest) for sign in (1.0, -1.0)]
    peak = np.maximum(*peaks)
    worst = int(np.argmax(peak / _panel_lengths(plant)))
    length = _panel_lengths(plant)[worst]

    fig = Figure(figsize=(7.0, 5.6), dpi=80)
    canvas = FigureCanvasAgg(fig)
    ax = fig.add_axes((0.0, 0.04, 1.0, 0.82), projection="3d")
    lo, hi = rest.bounds()
    for g in shots:
        glo, ghi = g.bounds()
        lo, hi = np.minimum(lo, glo), np.maximum(hi, ghi)
    # Same scale on every axis (1 m is 1 m), limits fixed over the period; a flat
    # satellite keeps some depth so out-of-plane motion stays visible.
    frame_view(ax, lo, hi, min_depth=0.3)

    SatelliteDrawing(ax, rest, colour="0.6", linestyle="--", linewidth=0.9,
                     label="undeformed")  # fmt: skip
    moving = SatelliteDrawing(ax, shots[0], colour="0.1", fill="goldenrod", body_axes=True,
                              label="mode shape (magnified)")  # fmt: skip
    ax.legend(loc="upper left", fontsize=7, framealpha=0.8)
    fig.suptitle(_animation_title(mode, a, float(peak[worst]), length), fontsize=9, y=0.985)
    clock = fig.text(0.01, 0.015, "", fontsize=8, color="0.3", animated=True)
    period = 1.0 / mode.frequency_hz if mode.frequency_hz > 0.0 else None

    # Blitting: render the still parts (axes, undeformed outline, titles) once and
    # draw only the moving artists on top of that background in each frame.
    for art in moving.artists():
        art.set_animated(True)
    canvas.draw()
    background = canvas.copy_from_bbox(fig.bbox)
    writer = CanvasPillowWriter(fps=fps)
    # new files moved onto path and still: a link there is replaced, never followed
    with replacing_name(path) as partial, writer.saving(fig, partial, dpi=fig.dpi):
        for k, geom in enumerate(shots):
            canvas.restore_region(background)
            moving.update(geom)
            moving.draw(ax)
            when = f"t = {k}/{frames} T"
            if period is not None:
                when += f" = {k * period / frames:.3g} s of T = {period:.3g} s"
            clock.set_text(f"{when}   (playback {frames / fps:.3g} s per period)")
            fig.draw_artist(clock)
            writer.grab_frame()
            if k == 0 and still is not None:
                image = Image.frombuffer("RGBA", canvas.get_width_height(),
                                         canvas.buffer_rgba(), "raw", "RGBA", 0, 1)  # fmt: skip
                with replacing(still) as handle:
                    image.convert("RGB").save(handle, format="PNG")
    fig.clear()
    return path


def _animation_title(mode: Mode, a: float, peak: float, length: float) -> str:
    if mode.kind == "rigid":
        mainly = f", mainly {mode.dominant_dofs[0]}" if mode.dominant_dofs else ""
        head = f"Mode {mode.index}: rigid-body mode (0 Hz){mainly}"
    else:
        hub = f", drives hub {mode.hub_dof}" if mode.hub_dof else ", hub at rest"
        symmetry = "no mirror parity" if mode.symmetry == "none" else mode.symmetry
        head = (
            f"Mode {mode.index}: {mode.frequency_hz:.4g} Hz, "
            f"{_KIND_LABEL.get(mode.kind, mode.kind)}, {symmetry}{hub}"
        )
    scale = (
        f"motion magnified: largest panel displacement {peak:.3g} m "
        f"= {100.0 * peak / length:.0f} % of the {length:.3g} m panel length\n"
        f"(modal amplitude a = {a:.3g} √kg·m on the mass-normalized shape)"
    )
    return f"{head}\n{scale}"


# -- everything at once ----------------------------------------------------------------


def default_animated_modes(analysis: ModalAnalysis) -> list[int]:
    """Flexible modes that drive a hub DOF, lowest first, at most six (1-based).

    Parameters
    ----------
    analysis : ModalAnalysis
        The modes (:func:`flexsat.analysis.modal_analysis`).

    Returns
    -------
    list of int
        1-based mode indices.
    """
    picked = [m.index for m in analysis.modes if m.kind != "rigid" and m.hub_dof is not None]
    return picked[:_MAX_DEFAULT_ANIMATIONS]


def write_modal_figures(
    analysis: ModalAnalysis,
    out_dir: str | Path,
    mode_indices: list[int] | None = None,
    *,
    frames: int = 48,
    fps: int = 24,
) -> list[Path]:
    """Write the modal figures of an analysis into a folder.

    Files: ``interaction_map.png`` (:func:`plot_interaction_map`),
    ``frequencies.png`` (:func:`plot_frequencies`) and, for each chosen mode,
    ``mode_<k>.png`` (its peak deformation) and ``mode_<k>.gif``
    (:func:`animate_mode`, default amplitude).

    Parameters
    ----------
    analysis : ModalAnalysis
        The modes (:func:`flexsat.analysis.modal_analysis`).
    out_dir : str or Path
        Created if missing; existing files of the same names are replaced.
    mode_indices : list of int, optional
        1-based modes to animate; by default the flexible modes that drive a hub
        DOF (``hub_dof`` is not None), lowest first, at most six.
    frames, fps : int
        Passed to :func:`animate_mode`.

    Returns
    -------
    list of Path
        The files written, in the order above.
    """
    out = ensure_dir(out_dir)
    chosen = default_animated_modes(analysis) if mode_indices is None else list(mode_indices)
    for k in chosen:
        _shape(analysis, k)  # validate every index before writing anything
    static = {"interaction_map": plot_interaction_map, "frequencies": plot_frequencies}
    written = style.write_figures(out, static, lambda name: static[name](analysis), dpi=150)

    def animate(k: int) -> list[Path]:
        still = out / f"mode_{int(k)}.png"
        gif = animate_mode(analysis, int(k), out / f"mode_{int(k)}.gif", frames=frames, fps=fps,
                           still=still)  # fmt: skip
        return [still, gif]

    for pair in style.forked_map(animate, chosen):  # drawn in parallel, listed in order
        written += pair
    return written
