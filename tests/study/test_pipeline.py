"""The study runs every part, keeps going when one fails, and reports both."""

from __future__ import annotations

import json
import subprocess
import sys

from flexsat.config import preset_path
from flexsat.study import PARTS


def test_quick_study_runs_every_part_but_the_campaigns(quick_study):
    out, manifest = quick_study
    status = {part["name"]: part["status"] for part in manifest["parts"]}
    assert status == {part.name: "skipped" if part.full_only else "ok" for part in PARTS}
    assert json.loads((out / "study.json").read_text())["parts"] == manifest["parts"]
    for part in manifest["parts"]:
        if part["status"] == "ok":
            assert part["wall_time_s"] > 0.0
            assert part["error"] is None


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


def test_a_failed_part_is_reported_and_the_rest_still_written(tmp_path):
    # A joint tuned to 3 kHz makes RK4 at 1 ms diverge (omega dt ~ 19): the open loop
    # and the slews fail for real; the configuration and modal parts do not.
    config = tmp_path / "stiff.toml"
    text = preset_path("nominal").read_text()
    config.write_text(text.replace("translation_x = 50.0", "translation_x = 3000.0"))
    out = tmp_path / "study"
    result = subprocess.run(
        [sys.executable, "-m", "flexsat", "study", "--quick", "--config", str(config),
         "--out", str(out)],
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
    failed = {part["name"]: part for part in manifest["parts"]}
    assert "stopped at t =" in failed["openloop"]["error"]
    assert "needs the slew part" in failed["comparison"]["error"]
    report = (out / "report.html").read_text()
    assert "This part failed: SimulationError" in report
    assert "Traceback (most recent call last)" in report  # the traceback is shown
    assert "Failed parts:" in report
    assert "eq. B.2" in report  # the sections of the parts that ran are there
