"""The shared plot style (flexsat.plots.style): layout, envelopes, writing files."""

from __future__ import annotations

import numpy as np
import pytest
import xarray as xr
from matplotlib.backends.backend_agg import FigureCanvasAgg

from flexsat.plots import style

PNG_MAGIC = b"\x89PNG\r\n\x1a\n"


def test_envelope_keeps_every_peak_of_a_fast_oscillation():
    t = np.linspace(0.0, 10.0, 200_001)
    y = np.sin(2.0 * np.pi * 37.0 * t) * np.exp(-0.1 * t)
    tt, yy = style.envelope(t, y, max_points=2000)
    assert tt.size <= 2200  # about max_points (pairs of min/max plus the tail)
    assert np.all(np.diff(tt) >= 0.0)  # still a time series
    # Striding to 2000 points would miss the extremes; min/max buckets keep them exactly.
    assert yy.max() == y.max() and yy.min() == y.min()
    short_t, short_y = style.envelope(t[:100], y[:100])
    assert np.array_equal(short_t, t[:100]) and np.array_equal(short_y, y[:100])  # untouched


def test_positive_masks_what_a_log_axis_cannot_show():
    out = style.positive([1.0, 0.0, -2.0, 3.0])
    assert np.array_equal(np.isnan(out), [False, True, True, False])


def test_time_axis_and_title():
    ds = xr.Dataset(coords={"time": [0.0, 0.5, 1.0]}, attrs={"title": "run A"})
    t = style.time_s(ds)
    fig, axes = style.figure(2, 3)
    assert axes.shape == (2, 3)
    style.finish_time_axis(axes, t)
    assert axes[0, 0].get_xlim() == (0.0, 1.0)
    assert axes[1, 2].get_xlabel() == "time t [s]" and axes[0, 2].get_xlabel() == ""
    style.suptitle(fig, ds.assign_attrs(status="failed", message="diverged"), "What")
    assert fig._suptitle.get_text() == "What\nrun A  —  FAILED: diverged"


@pytest.mark.parametrize(("shape", "size", "sharex"),
                         [((3, 1), (11.0, 9.0), True), ((2, 3), (14.0, 7.0), True),
                          ((2, 3), (15.0, 9.5), False), ((1, 1), (9.0, 5.5), True)])  # fmt: skip
def test_fixed_layout_keeps_labels_titles_and_legend_apart(shape, size, sharex):
    # Reference: the figure's own extents. Every axes' box with its tick labels, labels
    # and title must lie inside the figure and clear of its neighbours and the legend
    # (1 px of slack for anti-aliased text edges).
    ds = xr.Dataset(coords={"time": np.linspace(0.0, 120.0, 50)}, attrs={"title": "run A"})
    t = style.time_s(ds)
    fig, axes = style.figure(*shape, size=size, sharex=sharex)
    for k, ax in enumerate(axes.ravel()):
        ax.semilogy(t, 1e-6 + np.exp(-t / 10.0), label=f"curve {k}")
        ax.set_ylabel("pointing error [deg]")
        ax.set_title(f"axis {k}: near the target (t ≥ 93.25 s)", fontsize=10)
        if not sharex:
            ax.set_xlabel("q_v,e [-]")
    style.finish_time_axis(axes, t)
    handles = [ax.get_lines()[0] for ax in axes.ravel()]
    style.figure_legend(fig, handles, [h.get_label() for h in handles], ncols=4)
    style.suptitle(fig, ds, "What the figure shows")
    renderer = FigureCanvasAgg(fig).get_renderer()
    fig.draw(renderer)
    page = fig.bbox
    boxes = [ax.get_tightbbox(renderer) for ax in axes.ravel()]
    legend = fig.legends[0].get_window_extent(renderer)
    title = fig._suptitle.get_window_extent(renderer)
    for box in [*boxes, legend, title]:
        assert box.x0 >= page.x0 - 1 and box.x1 <= page.x1 + 1
        assert box.y0 >= page.y0 - 1 and box.y1 <= page.y1 + 1
    for i, a in enumerate(boxes):
        assert not a.padded(-1).overlaps(legend)
        assert not a.padded(-1).overlaps(title)
        for b in boxes[i + 1 :]:
            assert not a.padded(-1).overlaps(b.padded(-1))


def test_write_figures_writes_in_order_and_creates_the_folder(tmp_path):
    drawn = []

    def draw(name):
        drawn.append(name)
        fig, axes = style.figure(1, 1, size=(2.0, 2.0))
        style.line(axes[0, 0], np.arange(3.0), np.arange(3.0))
        return fig

    out = tmp_path / "a" / "b"
    written = style.write_figures(out, ("second", "first"), draw, dpi=20, workers=1)
    assert drawn == ["second", "first"]  # drawn here, in order
    assert written == [out / "second.png", out / "first.png"]
    assert all(p.read_bytes().startswith(PNG_MAGIC) for p in written)
    assert style.write_figures(tmp_path / "empty", (), draw, dpi=20) == []
    assert (tmp_path / "empty").is_dir()  # the folder exists even with nothing to draw


@pytest.mark.skipif(style.figure_workers() < 2, reason="no forked drawing processes here")
def test_figures_drawn_by_forked_processes_are_the_same_files(tmp_path):
    def draw(name):  # a closure: forked workers inherit it, nothing is pickled
        fig, axes = style.figure(1, 1, size=(2.0, 2.0))
        style.line(axes[0, 0], np.arange(3.0), np.arange(3.0) * len(name))
        return fig

    names = ("c", "bb", "a", "dddd")
    here = style.write_figures(tmp_path / "here", names, draw, dpi=20, workers=1)
    forked = style.write_figures(tmp_path / "forked", names, draw, dpi=20, workers=2)
    assert [p.name for p in forked] == [p.name for p in here] == [f"{n}.png" for n in names]
    assert [p.read_bytes() for p in forked] == [p.read_bytes() for p in here]


def test_save_figure_releases_the_figure(tmp_path):
    fig, axes = style.figure(1, 1, size=(2.0, 2.0))
    path = style.save_figure(fig, tmp_path / "sub" / "one.png", dpi=20)
    assert path.read_bytes().startswith(PNG_MAGIC)
    assert not fig.axes  # cleared once written


def test_log_axes_keep_only_the_ticks_in_view_and_draw_the_same_image(tmp_path):
    def draw():
        fig, axes = style.figure(2, 1, size=(6.0, 5.0))  # two axes sharing a log x axis
        f = np.geomspace(1e-3, 200.0, 300)
        for ax in axes[:, 0]:
            ax.loglog(f, 1.0 / (1.0 + f**2))
            ax.grid(True, which="both")
        return fig, axes

    fig, axes = draw()
    fig.savefig(tmp_path / "plain.png", dpi=40)
    fig, axes = draw()
    style._log_ticks_in_view(fig)
    fig.savefig(tmp_path / "in_view.png", dpi=40)
    assert (tmp_path / "in_view.png").read_bytes() == (tmp_path / "plain.png").read_bytes()
    for axis in (axes[0, 0].xaxis, axes[1, 0].xaxis, axes[0, 0].yaxis):
        lo, hi = sorted(axis.get_view_interval())
        for ticks in (axis.get_majorticklocs(), axis.get_minorticklocs()):
            assert ticks.size and np.all((ticks >= lo * (1 - 1e-6)) & (ticks <= hi * (1 + 1e-6)))


# A name that matplotlib would parse as mathtext (two $) and refuse (an unknown command).
_HOSTILE = r"cost $x^{ $ and \undefinedcommand_y"


def _drawn(text) -> tuple[str, bool]:
    """What matplotlib draws for a Text: (string, whether it is parsed as mathtext)."""
    return text._preprocess_math(text.get_text())


@pytest.mark.parametrize("name", [_HOSTILE, r"a\$b", "$", "plain_name {x}"])
def test_literal_text_is_drawn_as_written(name):
    fig, axes = style.figure(1, 1, size=(6.0, 3.0))
    ax = axes[0, 0]
    ax.plot([0.0, 1.0], [0.0, 1.0], label=style.literal(name))
    ax.set_title(style.literal(name))
    legend = ax.legend()
    FigureCanvasAgg(fig).draw()  # an unknown mathtext command would raise here
    assert _drawn(ax.title) == (name, False)
    assert _drawn(legend.get_texts()[0]) == (name, False)


def test_literal_text_beside_the_figures_own_mathtext_stays_literal():
    fig, axes = style.figure(1, 1, size=(6.0, 3.0))
    title = axes[0, 0].set_title(rf"$\omega_z$ of {style.literal('run $1 and $2')}")
    FigureCanvasAgg(fig).draw()
    text, math = _drawn(title)
    assert math  # the figure's own symbol is still mathtext...
    assert text.endswith(r"of run \$1 and \$2")  # ...where \$ is mathtext's literal dollar


def test_a_failed_runs_title_and_message_are_drawn_as_written():
    ds = xr.Dataset(attrs={"title": f"flexsat slew run '{_HOSTILE}'", "status": "failed",
                           "message": "diverged at $t$ = 3 s"})  # fmt: skip
    fig, _ = style.figure(1, 1, size=(6.0, 3.0))
    style.suptitle(fig, ds, "Pointing")
    FigureCanvasAgg(fig).draw()
    text, math = _drawn(fig._suptitle)
    assert not math
    assert text == f"Pointing\nflexsat slew run '{_HOSTILE}'  —  FAILED: diverged at $t$ = 3 s"
