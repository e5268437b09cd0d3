"""The HTML report shows the numbers of the study's JSON outputs, and only those."""

from __future__ import annotations

import json
import re
import subprocess
import sys
from html.parser import HTMLParser

import pytest

from flexsat.study import PARTS, format_value


class _Cells(HTMLParser):
    """Every element with a data-source attribute: (source, path, value JSON, text)."""

    def __init__(self) -> None:
        super().__init__()
        self.cells: list[dict] = []
        self.images: list[str] = []
        self._open: dict | None = None

    def handle_starttag(self, tag, attrs):
        attrs = dict(attrs)
        if tag == "img":
            self.images.append(attrs.get("src", ""))
        if "data-source" in attrs:
            self._open = {**attrs, "text": ""}

    def handle_data(self, data):
        if self._open is not None:
            self._open["text"] += data

    def handle_endtag(self, tag):
        if self._open is not None and tag in ("td", "th"):
            self.cells.append(self._open)
            self._open = None


@pytest.fixture(scope="module")
def report(quick_study):
    out, _ = quick_study
    parser = _Cells()
    text = (out / "report.html").read_text()
    parser.feed(text)
    return out, text, parser


def _lookup(data, path: str):
    for key in path.split("/"):
        data = data[int(key)] if isinstance(data, list) else data[key]
    return data


def test_every_number_is_the_one_its_json_file_holds(report):
    out, _, parser = report
    assert len(parser.cells) > 300  # config 45, M(0) blocks 180, modes 60, metrics of 4 runs
    sources = set()
    for cell in parser.cells:
        held = _lookup(json.loads((out / cell["data-source"]).read_text()), cell["data-path"])
        assert json.loads(cell["data-value"]) == held, cell
        assert cell["text"] == format_value(held), cell
        sources.add(cell["data-source"])
    assert {"openloop/metrics.json", "slew/asmc/metrics.json", "slew/pd/metrics.json",
            "slew/smc/metrics.json", "modal/modal.json",
            "configuration/configuration.json"} <= sources  # fmt: skip


def test_the_json_files_are_what_the_commands_print(quick_study):
    # One source of truth: `flexsat openloop --json` prints the metrics the study
    # wrote (same scenario, same compiled engine: bit for bit but the wall time).
    out, _ = quick_study
    result = subprocess.run([sys.executable, "-m", "flexsat", "openloop", "--json"],
                            capture_output=True, text=True, timeout=300)  # fmt: skip
    assert result.returncode == 0, result.stderr
    printed = json.loads(result.stdout)
    written = json.loads((out / "openloop" / "metrics.json").read_text())
    for key in set(printed) - {"wall_time_s", "files"}:
        assert printed[key] == written[key], key


def test_every_section_is_filled(report):
    _, text, _ = report
    for part in PARTS:
        assert f'<section id="{part.name}">' in text
    assert '<section id="model">' in text
    assert "This part failed" not in text
    # Beside the thesis: table 3.3, the open-loop and slew numbers with their sources.
    assert "thesis f [Hz]" in text and "fig. 3.14" in text and "section 5.1.3" in text
    assert "skipped with --quick" in text  # the campaigns say why they are empty


def test_the_report_is_self_contained(report, quick_study):
    _, text, parser = report
    _, manifest = quick_study
    figures = [f for part in manifest["parts"] for f in part["outputs"].get("figures", [])]
    assert len(parser.images) == len(figures)
    assert all(src.startswith(("data:image/png;base64,", "data:image/gif;base64,"))
               for src in parser.images)  # fmt: skip
    assert not re.search(r"""(src|href)=["']?(https?:|//|file:)""", text)
    assert "flexsat " + manifest["flexsat_version"] in text


def test_the_slew_states_how_r1_and_r2_are_judged(report):
    # The verdicts are over a stated window; its bounds are a cell of the slew's JSON.
    _, text, parser = report
    assert "R1 and R2 are judged over an observation window" in text
    shown = {(c["data-source"], c["data-path"]) for c in parser.cells}
    for key in ("observation_window_s", "ape_deg", "rpe_deg", "rpe_window_s"):
        assert ("slew/asmc/metrics.json", key) in shown, key
