"""Nothing flexsat writes inside ``--out`` lands outside it, and a user's text is drawn as written.

Links: every command is run twice. The first run, into a clean folder, lists every
file the command writes; before the second, a symbolic link to a file outside the
output folder (the victim) is put at each of those paths. The second run must
replace each link by its own file and leave the victim's bytes as they were. A
linked folder below the output folder (replays/, a study part) is refused with one
message, exit code 2, and nothing is written into the folder it points to.

Names: the open-loop and slew scenarios are named with ``$``, ``\\``, ``{``, ``}``,
``^`` and ``_`` (two ``$``: mathtext, where ``\\undefinedcommand`` is an error).
Every figure of each run is built in this process and drawn; its title must show the
name as written (matplotlib's own test of mathtext, :func:`matplotlib.cbook.is_math_text`,
and its unescaping of ``\\$``).
"""

from __future__ import annotations

from pathlib import Path

import pytest
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.cbook import is_math_text
from matplotlib.text import Text

from flexsat.plots.results import figure_names, plot_result
from flexsat.simulate.result import Result
from tests.cli.harness import flexsat

NAME = r"cost $x^{ $ and \undefinedcommand_y"
"""A scenario name that is mathtext, and invalid mathtext, for matplotlib."""
VICTIM = b"the victim's own bytes\n"
_LIMIT_S = 600
"""A command still running after this fails (the harness's default, 60 s, is short for a
run with its figures on a loaded machine)."""


def _written(folder: Path) -> list[Path]:
    """Every file below ``folder``, relative to it."""
    return sorted(p.relative_to(folder) for p in folder.rglob("*") if p.is_file())


def _plant_links(folder: Path, relative: list[Path], victim: Path) -> None:
    for rel in relative:
        (folder / rel).parent.mkdir(parents=True, exist_ok=True)
        (folder / rel).symlink_to(victim)


def _victim(root: Path) -> Path:
    victim = root / "victim"
    victim.write_bytes(VICTIM)
    return victim


def _replaced(folder: Path, relative: list[Path]) -> list[Path]:
    """The planted paths still a link after the run (none: each was replaced)."""
    return [rel for rel in relative if (folder / rel).is_symlink()]


def _twice(tmp: Path, capsys, argv: list[str], skip: tuple[str, ...] = ()):
    """Run ``argv`` into ``tmp/first``, then into ``tmp/second`` with a link planted at
    every file the first run wrote (but ``skip``); return (second folder, planted
    paths, victim)."""
    first, second = tmp / "first", tmp / "second"
    _first_run(tmp, argv, capsys)
    planted = [p for p in _written(first) if str(p) not in skip]
    assert planted, "the command wrote nothing"
    victim = _victim(tmp)
    _plant_links(second, planted, victim)
    outcome = flexsat([*argv, "--out", str(second)], capsys, _LIMIT_S)
    assert outcome.code == 0, outcome.stderr
    return second, planted, victim


def _first_run(tmp: Path, argv: list[str], capsys) -> Path:
    """``argv`` run once into ``tmp/first`` (a module's tests share it)."""
    first = tmp / "first"
    if not first.exists():
        outcome = flexsat([*argv, "--out", str(first)], capsys, _LIMIT_S)
        assert outcome.code == 0, outcome.stderr
    return first


def _rendered_titles(figure) -> list[str]:
    """The texts of ``figure`` as matplotlib draws them (after drawing it)."""
    FigureCanvasAgg(figure).draw()  # mathtext errors are raised while drawing
    texts = []
    for text in figure.findobj(Text):
        raw = text.get_text()
        # matplotlib draws a text as mathtext iff is_math_text; otherwise \$ as $
        texts.append(raw if is_math_text(raw) else raw.replace(r"\$", "$"))
    return texts


@pytest.fixture(scope="module")
def openloop_run(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("openloop")
    scenario = tmp / "s.toml"
    scenario.write_text(f"name = '{NAME}'\nduration_s = 2.0\n")
    return tmp, ["openloop", "--scenario", str(scenario)]


def test_openloop_writes_no_byte_through_a_link(openloop_run, capsys):
    tmp, argv = openloop_run
    second, planted, victim = _twice(tmp, capsys, argv)
    assert {"result.nc", "metrics.json", "attitude.png"} <= {str(p) for p in planted}
    assert victim.read_bytes() == VICTIM
    assert _replaced(second, planted) == []


def test_openloop_figures_show_the_scenario_name_as_written(openloop_run, capsys):
    ds = Result.from_netcdf(_first_run(*openloop_run, capsys) / "result.nc").dataset
    assert NAME in ds.attrs["title"]
    for kind in figure_names(ds):
        texts = _rendered_titles(plot_result(ds, kind))
        assert any(NAME in text for text in texts), (kind, texts)


@pytest.fixture(scope="module")
def slew_run(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("slew")
    scenario = tmp / "s.toml"
    scenario.write_text(
        f"name = '{NAME}'\nduration_s = 4.0\n[requirements]\nsettling_deadline_s = 2.0\n"
    )
    return tmp, ["slew", "--scenario", str(scenario)]


def test_slew_and_plot_write_no_byte_through_a_link(slew_run, capsys):
    tmp, argv = slew_run
    second, planted, victim = _twice(tmp, capsys, argv)
    assert victim.read_bytes() == VICTIM
    assert _replaced(second, planted) == []
    # flexsat plot of that run, into a folder of links at each figure it draws
    plotted = tmp / "plotted"
    figures = [Path(f"{kind}.png") for kind in figure_names(
        Result.from_netcdf(second / "result.nc").dataset)]  # fmt: skip
    _plant_links(plotted, figures, victim)
    outcome = flexsat(["plot", str(second / "result.nc"), "--out", str(plotted)], capsys, _LIMIT_S)
    assert outcome.code == 0, outcome.stderr
    assert victim.read_bytes() == VICTIM
    assert _replaced(plotted, figures) == []


def test_slew_figures_show_the_scenario_name_as_written(slew_run, capsys):
    ds = Result.from_netcdf(_first_run(*slew_run, capsys) / "result.nc").dataset
    for kind in figure_names(ds):
        texts = _rendered_titles(plot_result(ds, kind))
        assert any(NAME in text for text in texts), (kind, texts)


def test_campaign_store_writes_no_byte_through_a_link(tmp_path, capsys):
    campaign = tmp_path / "tiny.toml"
    campaign.write_text('name = "tiny"\n[base]\nduration_s = 0.5\n[[cases]]\nid = "a"\n')
    # Not planted: campaign.json (read first: a link there is a store of another
    # campaign, refused) and campaign.lock (refused: the next test).
    second, planted, victim = _twice(tmp_path, capsys, ["campaign", str(campaign)],
                                     skip=("campaign.json", "campaign.lock"))  # fmt: skip
    names = {str(p) for p in planted}
    assert {"cases/a.json", "histories/a.nc", "results.parquet", "results.csv",
            "summary.json", "figures/envelope_pointing.png"} <= names  # fmt: skip
    assert victim.read_bytes() == VICTIM
    assert _replaced(second, planted) == []


def test_a_linked_campaign_lock_is_refused_and_untouched(tmp_path, capsys):
    campaign = tmp_path / "tiny.toml"
    campaign.write_text('name = "tiny"\n[base]\nduration_s = 0.5\n[[cases]]\nid = "a"\n')
    victim = _victim(tmp_path)
    (tmp_path / "store").mkdir()
    (tmp_path / "store" / "campaign.lock").symlink_to(victim)
    outcome = flexsat(["campaign", str(campaign), "--out", str(tmp_path / "store")], capsys)
    assert outcome.code == 2
    assert "campaign.lock is a symbolic link" in outcome.stderr
    assert victim.read_bytes() == VICTIM


def test_a_replay_writes_no_byte_through_a_link(tmp_path, capsys):
    campaign = tmp_path / "tiny.toml"
    campaign.write_text('name = "tiny"\n[base]\nduration_s = 0.5\n[[cases]]\nid = "a"\n')
    store = tmp_path / "store"
    assert flexsat(["campaign", str(campaign), "--out", str(store)], capsys).code == 0
    victim = _victim(tmp_path)
    _plant_links(store, [Path("replays/a.nc")], victim)
    assert flexsat(["campaign", "replay", str(store), "a"], capsys).code == 0
    assert victim.read_bytes() == VICTIM
    assert not (store / "replays" / "a.nc").is_symlink()
    # a linked replays/ folder is refused: nothing lands in the folder it points to
    outside = tmp_path / "outside"
    outside.mkdir()
    (store / "replays" / "a.nc").unlink()
    (store / "replays").rmdir()
    (store / "replays").symlink_to(outside, target_is_directory=True)
    outcome = flexsat(["campaign", "replay", str(store), "a"], capsys)
    assert outcome.code == 2
    assert "replays is a symbolic link inside the output folder" in outcome.stderr
    assert list(outside.iterdir()) == []


@pytest.mark.parametrize("argv", [["linearize", "--reduce", "balanced:16"], ["margins"]],
                         ids=["linearize", "margins"])  # fmt: skip
def test_linear_exports_write_no_byte_through_a_link(argv, tmp_path, capsys):
    second, planted, victim = _twice(tmp_path, capsys, argv)
    if argv[0] == "linearize":
        assert {"model.npz", "model.mat", "reduced.npz", "reduced.mat", "linear.json"} <= {
            str(p) for p in planted}  # fmt: skip
    assert victim.read_bytes() == VICTIM
    assert _replaced(second, planted) == []


# The study's files at fixed places (the quick study's parts), and one part's folder.
_STUDY_FILES = [
    "report.html", "study.json", "configuration/configuration.json",
    "openloop/attitude.png", "openloop/result.nc", "openloop/metrics.json",
    "modal/frequencies.png", "modal/modal.json",
    "slew/asmc/pointing.png", "slew/asmc/result.nc", "slew/asmc/animation.gif",
    "comparison/comparison.png", "frequency/margins.json", "frequency/loop_gain.png",
]  # fmt: skip
_STUDY_NAME = "wing_set_(v2)#1"
"""The satellite's name: a name holds no $, \\, { or } (refused at load), but _ and #."""


# The parts that write the planted files (_STUDY_FILES) besides the report and the
# manifest: the second run is a study of these parts alone. None of the others' files
# is planted (robust stability, pointing, avionics, law comparison: they write with
# the same helpers, write_json, save_figure and Result.to_netcdf, into folders of
# their own), and they would take over half of the run's time.
_PLANTED_PARTS = {"configuration", "modal", "openloop", "slew", "frequency", "comparison",
                  "animation"}  # fmt: skip


def _study_of_the_planted_parts(monkeypatch) -> None:
    """Restrict the study to :data:`_PLANTED_PARTS` (its up-front compilation too)."""
    from flexsat.study import pipeline

    every_run = pipeline._compile_runs
    parts = tuple(part for part in pipeline.PARTS if part.name in _PLANTED_PARTS)
    assert {part.name for part in parts} == _PLANTED_PARTS
    monkeypatch.setattr(pipeline, "PARTS", parts)
    monkeypatch.setattr(pipeline, "_compile_runs", lambda ctx: [
        (fields, names & _PLANTED_PARTS) for fields, names in every_run(ctx)])  # fmt: skip


def test_the_study_writes_no_byte_through_a_link_and_shows_the_name(tmp_path, capsys, monkeypatch):
    """The first run (every part) is refused before any part runs; the second flies
    the parts that write the planted files (:data:`_PLANTED_PARTS`)."""
    from tests.cli.harness import to_toml
    from tests.conftest import nominal_dict

    data = nominal_dict()
    data["name"] = _STUDY_NAME
    config = tmp_path / "satellite.toml"
    config.write_text(to_toml(data))
    out, outside = tmp_path / "study", tmp_path / "outside"
    outside.mkdir()
    victim = _victim(tmp_path)
    planted = [Path(p) for p in _STUDY_FILES]
    _plant_links(out, planted, victim)
    # A part's folder that is a link: refused before any part runs, nothing written.
    (out / "avionics").symlink_to(outside, target_is_directory=True)
    argv = ["study", "--quick", "--config", str(config), "--out", str(out)]
    outcome = flexsat(argv, capsys, _LIMIT_S)
    assert outcome.code == 2, outcome.stderr
    assert "avionics is a symbolic link inside the output folder" in outcome.stderr
    assert list(outside.iterdir()) == []
    assert _replaced(out, planted) == planted  # not one written
    # Without it, the study replaces every link by its own file.
    (out / "avionics").unlink()
    _study_of_the_planted_parts(monkeypatch)
    outcome = flexsat(argv, capsys, _LIMIT_S)
    assert outcome.code == 0, outcome.stderr
    assert victim.read_bytes() == VICTIM
    assert _replaced(out, planted) == []
    assert _STUDY_NAME in (out / "report.html").read_text()
