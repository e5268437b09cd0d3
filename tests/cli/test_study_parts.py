"""``flexsat study --parts``: some parts run, the others are shown as not run."""

from __future__ import annotations

import html
import json
import re
import subprocess
import sys

from flexsat.study import PARTS
from flexsat.study.pipeline import NOT_RUN, chosen_parts
from flexsat.study.report import SECTIONS

FLEXSAT = [sys.executable, "-m", "flexsat"]
EVERY_PART = ", ".join(part.name for part in PARTS)


def run(*args: str) -> subprocess.CompletedProcess:
    return subprocess.run([*FLEXSAT, *args], capture_output=True, text=True, timeout=300)


def test_an_unknown_part_is_refused_with_the_parts_named(tmp_path):
    out = tmp_path / "study"
    result = run("study", "--quick", "--parts", "modal,gyro", "--out", str(out))
    assert result.returncode == 2
    assert "Traceback" not in result.stderr
    message = " ".join(result.stderr.split())
    assert f"--parts: unknown part 'gyro': the study's parts are {EVERY_PART}" in message
    assert not out.exists()  # refused before any work


def test_no_part_named_is_refused(tmp_path):
    result = run("study", "--parts", " , ", "--out", str(tmp_path / "study"))
    assert result.returncode == 2
    assert "Traceback" not in result.stderr
    assert f"--parts: no part named: name one or more of {EVERY_PART}" in " ".join(
        result.stderr.split()
    )


def test_the_help_names_every_part():
    result = run("study", "--help")
    assert result.returncode == 0
    text = " ".join(result.stdout.split())
    assert f"With --parts, only the parts named ({EVERY_PART})" in text


def test_a_part_brings_the_parts_it_reads():
    # The comparison and the animation read the nominal slew's result (its NetCDF file):
    # asked for alone, each runs after it; the others read no part.
    assert chosen_parts(["animation"]) == {"animation", "slew"}
    assert chosen_parts(["comparison", "modal"]) == {"comparison", "slew", "modal"}
    assert chosen_parts(["pointing"]) == {"pointing"}


def _summary_rows(report: str) -> dict[str, tuple[str, str, str]]:
    """The report's parts table: part name -> (status, wall time, estimate) as shown."""
    table = report.split("<caption>Parts of the study</caption>")[1].split("</table>")[0]
    rows = re.findall(
        r"<tr><td><a href='#([a-z]+)'>.*?</a></td><td><span class='badge [a-z]+'>([a-z ]+)"
        r"</span></td><td>([^<]*)</td><td>([^<]*)</td></tr>",
        table,
    )
    return {name: (status, wall, html.unescape(said)) for name, status, wall, said in rows}


def test_a_study_of_two_parts_runs_them_and_shows_the_others_not_run(tmp_path):
    # Two cheap parts (no run flown: the configuration's file and the pointing budget's
    # frequency-domain jitter), through the command line.
    out = tmp_path / "study"
    result = run("study", "--quick", "--parts", "pointing, configuration", "--out", str(out))
    assert result.returncode == 0, result.stderr
    manifest = json.loads((out / "study.json").read_text())
    assert manifest["chosen_parts"] == ["configuration", "pointing"]
    status = {entry["name"]: entry["status"] for entry in manifest["parts"]}
    chosen = {"configuration", "pointing"}
    assert status == {part.name: "ok" if part.name in chosen else NOT_RUN for part in PARTS}
    for entry in manifest["parts"]:
        if entry["name"] not in chosen:
            assert entry["wall_time_s"] == 0.0 and entry["outputs"] == {}
            assert not (out / entry["name"]).exists()  # nothing written for it
    # only the parts that run are estimated
    assert set(manifest["estimate"]["parts"]) == chosen
    # The report's table shows each part's status, its wall time and its estimate as
    # study.json has them (one decimal), a dash where none was made.
    report = (out / "report.html").read_text()
    rows = _summary_rows(report)
    assert set(rows) == {part.name for part in PARTS}
    estimated = manifest["estimate"]["parts"]
    for entry in manifest["parts"]:
        said = estimated.get(entry["name"])
        assert rows[entry["name"]] == (
            entry["status"],
            f"{entry['wall_time_s']:.1f}",
            "—" if said is None else f"{said:.1f}",
        ), entry["name"]
    # the badge in the table's rows and in each section of a part not run
    sections = sum((s.part or s.name) not in chosen for s in SECTIONS)
    assert report.count(f"<span class='badge notrun'>{NOT_RUN}</span>") == (
        len(PARTS) - len(chosen) + sections
    )
    total = f"<td>total</td><td></td><td>{manifest['total_wall_time_s']:.1f}</td>"
    assert total + f"<td>{manifest['estimate']['total_s']:.1f}</td>" in report
    assert "Failed parts" not in report
