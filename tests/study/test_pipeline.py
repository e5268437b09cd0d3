"""The study runs every part, keeps going when one fails, and reports both."""

from __future__ import annotations

import json
import os
import subprocess
import sys
import time
from pathlib import Path

import psutil
import pytest

from flexsat.config import nominal, preset_path
from flexsat.parallel import figure_workers
from flexsat.study import PARTS, pipeline


def test_quick_study_runs_every_part_but_the_campaigns(quick_study):
    out, manifest = quick_study
    status = {part["name"]: part["status"] for part in manifest["parts"]}
    assert status == {part.name: "skipped" if part.full_only else "ok" for part in PARTS}
    assert json.loads((out / "study.json").read_text())["parts"] == manifest["parts"]
    for part in manifest["parts"]:
        if part["status"] == "ok":
            assert part["wall_time_s"] > 0.0
            assert part["error"] is None


def test_the_study_states_its_estimate_per_part(quick_study):
    # Said before the first part (and kept in study.json): the estimated wall time of
    # every part that runs, the longer lane's sum and the basis it rests on.
    _, manifest = quick_study
    estimate = manifest["estimate"]
    ran = {part["name"] for part in manifest["parts"] if part["status"] != "skipped"}
    assert set(estimate["parts"]) == ran
    assert all(seconds >= 0.0 for seconds in estimate["parts"].values())
    lanes = {part.name: part.lane for part in PARTS}
    longer = max(sum(s for name, s in estimate["parts"].items() if lanes[name] == lane)
                 for lane in (0, 1))  # fmt: skip
    # the longer lane's sum; on one core (one lane), every part's
    assert estimate["total_s"] == pytest.approx(
        longer if figure_workers() > 1 else sum(estimate["parts"].values()), rel=1e-12
    )
    assert estimate["basis"].startswith("basis: a 10 s slew flown now took")


def test_the_total_wall_time_is_the_longer_lanes_parts(quick_study):
    # The report's "total" row: the parts of the lane that took longer, one after
    # another (each lane's own kernel loading is in compilation_s), recomputed here
    # from the parts' entries; on one core, every part's.
    _, manifest = quick_study
    lanes = {part.name: part.lane for part in PARTS}
    walls = {part["name"]: part["wall_time_s"] for part in manifest["parts"]}
    per_lane = [sum(w for name, w in walls.items() if lanes[name] == lane) for lane in (0, 1)]
    expected = max(per_lane) if figure_workers() > 1 else sum(walls.values())
    assert manifest["total_wall_time_s"] == pytest.approx(expected, rel=1e-12)
    assert manifest["total_wall_time_s"] >= max(walls.values())


def test_a_lane_still_loading_does_not_shorten_the_total():
    # Lane 0 loads its kernels for 40 s, then runs a 3 s part; lane 1 runs 25 s of
    # parts meanwhile. The elapsed 43 s less the 40 s of loading would say 3 s; the
    # total is the longer lane's parts, 25 s (28 s in one lane).
    entries = [{"name": part.name, "wall_time_s": 0.0} for part in PARTS]
    lane_1 = [entry for entry, part in zip(entries, PARTS, strict=True) if part.lane == 1]
    for entry, seconds in zip(lane_1, (10.0, 15.0), strict=False):
        entry["wall_time_s"] = seconds
    entries[0]["wall_time_s"] = 3.0  # a lane-0 part
    assert PARTS[0].lane == 0
    assert pipeline.parts_wall_time(entries, lanes=2) == 25.0
    assert pipeline.parts_wall_time(entries, lanes=1) == 28.0
    assert pipeline.parts_wall_time([], lanes=2) == 0.0


def test_every_output_the_manifest_names_exists(quick_study):
    out, manifest = quick_study

    def paths(node):
        if isinstance(node, dict):
            for value in node.values():
                yield from paths(value)
        elif isinstance(node, list):
            for value in node:
                yield from paths(value)
        else:
            yield node

    named = [p for part in manifest["parts"] for p in paths(part["outputs"])]
    assert len(named) > 30  # configuration, modal, open loop, three slews, animation
    for relative in named:
        assert (out / relative).stat().st_size > 0, relative
    figures = {p for p in named if p.endswith((".png", ".gif"))}
    assert "slew/asmc/animation.gif" in figures
    assert "comparison/comparison.png" in figures


# The parts test_a_failed_part_is_reported_and_the_rest_still_written reads, run with
# --parts: configuration and modal in lane 0, open loop, slew and the two parts that
# need the slew in lane 1, the full-only campaigns. The other parts (frequency domain,
# robust stability, pointing, avionics, law comparison), whose outcome this test does
# not read, took most of the run: the test took 413 s with every part, 65 s with these
# (load 12-19). The quick study of every part is
# test_quick_study_runs_every_part_but_the_campaigns'.
_SOME_PARTS = ("configuration", "modal", "openloop", "slew", "comparison", "animation",
               "campaigns")  # fmt: skip


def test_a_failed_part_is_reported_and_the_rest_still_written(tmp_path):
    # A joint tuned to 3 kHz makes RK4 at 1 ms diverge (omega dt ~ 19): the open loop
    # and the slews fail for real; the configuration and modal parts do not. The study
    # runs the parts this test reads (_SOME_PARTS), through the command line.
    config = tmp_path / "stiff.toml"
    text = preset_path("nominal").read_text()
    config.write_text(text.replace("translation_x = 50.0", "translation_x = 3000.0"))
    out = tmp_path / "study"
    result = subprocess.run(
        [sys.executable, "-m", "flexsat", "study", "--quick", "--config", str(config),
         "--out", str(out), "--parts", ",".join(_SOME_PARTS)],
        capture_output=True, text=True, timeout=600,
    )  # fmt: skip
    assert result.returncode == 1
    assert "Traceback" not in result.stderr
    assert "failed parts:" in result.stderr
    manifest = json.loads((out / "study.json").read_text())
    status = {part["name"]: part["status"] for part in manifest["parts"]}
    assert status["configuration"] == status["modal"] == "ok"
    assert status["openloop"] == status["slew"] == "failed"
    assert status["comparison"] == status["animation"] == "failed"  # they need the slew
    assert status["campaigns"] == "skipped"
    assert {name for name, value in status.items() if value == "not run"} == {
        part.name for part in PARTS if part.name not in _SOME_PARTS
    }
    failed = {part["name"]: part for part in manifest["parts"]}
    assert "stopped at t =" in failed["openloop"]["error"]
    assert "needs the slew part" in failed["comparison"]["error"]
    report = (out / "report.html").read_text()
    assert "This part failed: SimulationError" in report
    assert "Traceback (most recent call last)" in report  # the traceback is shown
    assert "Failed parts:" in report
    assert "eq. B.2" in report  # the sections of the parts that ran are there


def test_every_part_reads_only_parts_of_its_own_lane():
    # A part's inputs come from its own process: a need in the other lane would be
    # missing in the forked lane (or read before it is written in this one).
    lane = {part.name: part.lane for part in PARTS}
    for part in PARTS:
        assert part.lane in range(pipeline.LANES), part.name
        assert all(lane[need] == part.lane for need in part.needs), part.name


def _part(name: str, lane: int, run, needs: tuple[str, ...] = ()) -> pipeline.Part:
    return pipeline.Part(name, name.title(), run, needs=needs, lane=lane)


def _two_lanes(parts, monkeypatch) -> dict:
    monkeypatch.setattr(pipeline, "PARTS", parts)
    ctx = pipeline.StudyContext(nominal(), Path("."), quick=True, progress=False)
    recorded: dict[str, dict] = {}
    pipeline._run_parts(ctx, lambda part, entry: recorded.update({part.name: entry}), lanes=2)
    return recorded


def test_two_lanes_run_every_part_once_and_pass_outputs_along_a_lane(monkeypatch):
    parts = (
        _part("first", 0, lambda ctx: {"pid": os.getpid()}),
        _part("second", 1, lambda ctx: {"pid": os.getpid()}),
        _part("third", 1, lambda ctx: {"read": ctx.results["second"]["pid"]},
              needs=("second",)),
        _part("fourth", 0, lambda ctx: {"pid": os.getpid()}),
    )  # fmt: skip
    recorded = _two_lanes(parts, monkeypatch)
    assert set(recorded) == {"first", "second", "third", "fourth"}
    assert all(entry["status"] == "ok" for entry in recorded.values())
    outputs = {name: entry["outputs"] for name, entry in recorded.items()}
    assert outputs["first"]["pid"] == outputs["fourth"]["pid"] == os.getpid()
    assert outputs["second"]["pid"] != os.getpid()  # lane 1 ran in the forked process
    assert outputs["third"]["read"] == outputs["second"]["pid"]


def test_a_lane_that_dies_leaves_its_unfinished_parts_failed(monkeypatch):
    parts = (
        _part("survivor", 0, lambda ctx: {}),
        _part("done", 1, lambda ctx: {}),
        _part("killer", 1, lambda ctx: os._exit(7)),
        _part("orphan", 1, lambda ctx: {}),
    )
    recorded = _two_lanes(parts, monkeypatch)
    status = {name: entry["status"] for name, entry in recorded.items()}
    assert status == {"survivor": "ok", "done": "ok", "killer": "failed", "orphan": "failed"}
    assert recorded["orphan"]["error"] == "the process running it stopped (exit code 7)"


_KILLED_STUDY = """
import os, sys, time
from pathlib import Path
from flexsat.config import nominal
from flexsat.study import pipeline

def lane_part(ctx):
    print(os.getpid(), flush=True)  # the lane's process id, for the test
    time.sleep(600)

def main_part(ctx):
    time.sleep(600)  # killed meanwhile

pipeline.PARTS = (pipeline.Part("main", "Main", main_part, lane=0),
                  pipeline.Part("lane", "Lane", lane_part, lane=1))
ctx = pipeline.StudyContext(nominal(), Path("."), quick=True, progress=False)
pipeline._run_parts(ctx, lambda part, entry: None, lanes=2)
"""


def test_the_forked_lane_exits_with_a_killed_study():
    # SIGKILL, as the out-of-memory killer sends: the study cannot stop its lane, which
    # would otherwise run its parts to the end with no one to read them. Linux kills it
    # at once; elsewhere it notices within 0.2 s. 2 s allowed.
    study = subprocess.Popen([sys.executable, "-c", _KILLED_STUDY], stdout=subprocess.PIPE,
                             text=True)  # fmt: skip
    lane = int(study.stdout.readline())
    study.kill()
    study.wait()
    deadline = time.monotonic() + 2.0
    while _alive(lane):
        assert time.monotonic() < deadline, "the lane outlived the study"
        time.sleep(0.02)


def _alive(pid: int) -> bool:
    """Running (an orphan may stay a zombie until its new parent reaps it)."""
    try:
        return psutil.Process(pid).status() != psutil.STATUS_ZOMBIE
    except psutil.NoSuchProcess:
        return False


def test_each_lane_loads_the_loops_only_its_parts_fly():
    ctx = pipeline.StudyContext(nominal(), Path("."), quick=True, progress=False)
    runs = pipeline._compile_runs(ctx)
    shared, per_lane = pipeline._split_runs(runs, lanes=2)
    lane = {part.name: part.lane for part in PARTS}
    for fields, parts in runs:
        lanes = {lane[name] for name in parts}
        if not parts:  # only compiled (the drive's plant): flown by neither
            assert fields not in shared and all(fields not in r for r in per_lane.values())
        elif len(lanes) == 1:  # flown by one lane's parts: loaded there, not before the fork
            assert fields in per_lane[lanes.pop()] and fields not in shared
        else:
            assert fields in shared
    assert "open loop" in per_lane[1]  # the open-loop part's lane
    assert None in per_lane[0]  # the solar-array drive: the avionics part's lane
    assert {"controller": {"kind": ctx.laws[0]}} in shared  # the slew's and law comparison's
    one = pipeline._split_runs(runs, lanes=1)
    assert one == ([fields for fields, parts in runs if parts], {})


def test_the_compiling_processes_take_the_closed_loop_first():
    # The first law's slew builds the plant and compiles the closed loop all other
    # slews load from the disk cache; the runs after it need no closed loop, so the
    # second compiling process is busy with them meanwhile instead of compiling it a
    # second time (the stages first: they need no plate kernels either).
    ctx = pipeline.StudyContext(nominal(), Path("."), quick=True, progress=False)
    order = [fields for fields, _ in pipeline._compile_runs(ctx)]
    assert order[:4] == [{"controller": {"kind": ctx.laws[0]}}, "stages", "drive plant",
                         "open loop"]  # fmt: skip


def test_the_lanes_fly_their_own_short_runs_before_their_parts(monkeypatch):
    # Lane 1 flies its share in the forked process, lane 0 here; the longer lane's time
    # comes back (it is compilation, not the parts' wall time).
    import time

    flown = []

    def fly(ctx, fields):
        time.sleep(fields)
        flown.append((os.getpid(), fields))

    monkeypatch.setattr(pipeline, "_fly_short", fly)
    parts = (_part("first", 0, lambda ctx: {"flown": list(flown)}),
             _part("second", 1, lambda ctx: {"flown": list(flown)}))  # fmt: skip
    monkeypatch.setattr(pipeline, "PARTS", parts)
    ctx = pipeline.StudyContext(nominal(), Path("."), quick=True, progress=False)
    recorded: dict[str, dict] = {}
    prepared = pipeline._run_parts(ctx, lambda part, entry: recorded.update({part.name: entry}),
                                   lanes=2, prepare={0: [0.01], 1: [0.3]})  # fmt: skip
    assert 0.3 <= prepared < 5.0
    assert recorded["first"]["outputs"]["flown"] == [(os.getpid(), 0.01)]
    ((pid, seconds),) = recorded["second"]["outputs"]["flown"]
    assert pid != os.getpid() and seconds == 0.3


def test_the_stages_run_compiles_every_other_slews_stages_without_a_plant():
    # It runs beside the plant's compilation: it must not build the plant, and it must
    # reach every stage kind the other runs fly (the drive's joint actuator included).
    from flexsat.control.stages import JOINT_ACTUATORS

    ctx = pipeline.StudyContext(nominal(), Path("."), quick=True, progress=False)
    drive = JOINT_ACTUATORS.get("sadm_drive").step
    pipeline._fly_short(ctx, "stages")
    assert "plant" not in ctx.results
    assert drive.signatures  # compiled (or loaded from the disk cache) by this process


def test_parts_the_campaigns_cannot_fly_are_skipped_with_the_reason(tmp_path):
    # A modal appendage has no target frequencies and no initial joint state: the
    # thesis's campaigns vary both, so neither the campaigns nor the law comparison over
    # them can fly it. Both are skipped, saying which campaign and why (the quick study
    # of such a satellite then exits 0, not 1); on the nominal satellite both run.
    from flexsat import Plant
    from flexsat.linear.export import modal_satellite

    modal = modal_satellite(Plant.from_config(nominal()), n_modes=3)
    parts = {part.name: part for part in PARTS}
    ctx = pipeline.StudyContext(modal, tmp_path, quick=True)
    entry = pipeline._run_part(parts["laws"], ctx)
    assert entry["status"] == "skipped", entry
    assert entry["error"].startswith("not applicable: the sensitivity campaign cannot fly")
    assert "target_frequencies_hz" in entry["error"]
    full = pipeline.StudyContext(modal, tmp_path, quick=False)
    assert pipeline._run_part(parts["campaigns"], full)["error"] == entry["error"]
    assert pipeline._campaigns_fly(pipeline.StudyContext(nominal(), tmp_path)) is None


def test_a_study_of_some_parts_loads_only_their_loops_and_the_calibrations():
    # A study of the pointing budget flies no loop of its own: of the runs compiled up
    # front only the first law's slew is left, which the estimate's calibration flies
    # in this process before the lanes start (else its 10 s would time the loading of
    # the loop: 0.19 s instead of 0.03 s measured). A study of the slew (lane 1) still
    # loads that loop in this process, not in the lane.
    ctx = pipeline.StudyContext(nominal(), Path("."), quick=True, progress=False,
                                only=pipeline.chosen_parts(["pointing"]))  # fmt: skip
    first = {"controller": {"kind": ctx.laws[0]}}
    runs = pipeline._compile_runs(ctx)
    assert [fields for fields, parts in runs if parts] == []
    assert runs[0] == (first, frozenset())
    assert pipeline._split_runs(runs, lanes=2) == ([first], {0: [], 1: []})
    assert pipeline._split_runs(runs, lanes=1) == ([first], {})
    ctx.only = pipeline.chosen_parts(["slew", "openloop"])
    shared, per_lane = pipeline._split_runs(pipeline._compile_runs(ctx), lanes=2)
    assert shared == [first] and per_lane[0] == [] and "open loop" in per_lane[1]
    assert first not in per_lane[1]
    ctx.only = pipeline.chosen_parts(["modal", "avionics"])
    shared, per_lane = pipeline._split_runs(pipeline._compile_runs(ctx), lanes=2)
    assert shared == [first] and first not in per_lane[0] and None in per_lane[0]


def test_an_unknown_part_is_refused_before_any_work(tmp_path):
    from flexsat.errors import ConfigError

    out = tmp_path / "study"
    with pytest.raises(ConfigError, match="unknown part 'gyro': the study's parts are "
                                          "configuration, modal, openloop"):  # fmt: skip
        pipeline.run_study(nominal(), out, quick=True, parts=["slew", "gyro"])
    assert not out.exists()
    with pytest.raises(ConfigError, match="no part named"):
        pipeline.run_study(nominal(), out, quick=True, parts=[])
    assert pipeline.chosen_parts("animation") == {"animation", "slew"}  # one name
