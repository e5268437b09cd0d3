"""The HTML report shows the numbers of the study's JSON outputs, and only those."""

from __future__ import annotations

import json
import re
import subprocess
import sys
from html.parser import HTMLParser

import pytest

from flexsat.study import PARTS, format_value, pipeline


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


def _shown(value, path: str) -> str:
    """What a cell shows: :func:`format_value`, and "not judged" for a verdict that is
    null (a run planned to end before its observation window)."""
    from flexsat.study.report import _VERDICTS

    return "not judged" if value is None and path.split("/")[-1] in _VERDICTS else (
        format_value(value))  # fmt: skip


def test_every_number_is_the_one_its_json_file_holds(report):
    out, _, parser = report
    assert len(parser.cells) > 300  # config 45, M(0) blocks 180, modes 60, metrics of 4 runs
    sources = set()
    for cell in parser.cells:
        held = _lookup(json.loads((out / cell["data-source"]).read_text()), cell["data-path"])
        assert json.loads(cell["data-value"]) == held, cell
        assert cell["text"] == _shown(held, cell["data-path"]), cell
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


# -- satellites of several appendage models -------------------------------------------


def _mixed_satellite(kind: str):
    """The nominal satellite with its first plate replaced, by its twin as a chain
    (``"chain + plate"``) or by its modal export, 3 modes (``"modal + plate"``): the
    second plate stays beside it."""
    from flexsat import Plant
    from flexsat.config import validate_config
    from flexsat.linear.export import modal_satellite
    from tests.conftest import nominal_dict
    from tests.dynamics.chain_satellites import plate_as_chain

    data = nominal_dict()
    if kind == "chain + plate":
        data["appendages"][0] = plate_as_chain(data["appendages"][0])
    else:
        exported = modal_satellite(Plant.from_config(validate_config(data)), n_modes=3)
        data["appendages"][0] = exported.model_dump(mode="json")["appendages"][0]
    return validate_config(data)


def _configuration_report(config, out) -> tuple[str, dict]:
    """The configuration part of the study on ``config`` and its report: (html, the
    manifest as the report left it)."""
    from flexsat.study.report import write_report

    out.mkdir()
    part = next(p for p in PARTS if p.name == "configuration")
    entry = pipeline._run_part(part, pipeline.StudyContext(config, out))
    manifest = {"flexsat_version": "test", "created_utc": "now", "config_name": config.name,
                "config_source": "a test", "quick": True, "parts": [entry]}  # fmt: skip
    (out / "study.json").write_text(json.dumps(manifest))
    write_report(out)
    return (out / "report.html").read_text(), json.loads((out / "study.json").read_text())


@pytest.mark.parametrize("kind", ["chain + plate", "modal + plate"])
def test_the_configuration_of_mixed_appendage_models_is_drawn(tmp_path, kind):
    # A parameter one model has and the other lacks (the chain's segment count, the modal
    # appendage's mode-shape data) is a row with the value where the model has it and
    # "—" where it does not; every value shown is the one configuration.json holds.
    config = _mixed_satellite(kind)
    text, manifest = _configuration_report(config, tmp_path / "study")
    assert "could not be drawn" not in text and "This part failed" not in text
    assert manifest["parts"][0]["status"] == "ok"
    parser = _Cells()
    parser.feed(text)
    data = json.loads((tmp_path / "study" / "configuration" / "configuration.json").read_text())
    first, second = data["config"]["appendages"]
    only_first = sorted(set(first) - set(second))
    assert only_first  # the two models have parameters of their own
    shown = {c["data-path"] for c in parser.cells}
    for key in only_first:
        rows = [p for p in shown if p.startswith(f"config/appendages/0/{key}")]
        assert rows, key  # the first appendage's own parameters are shown ...
        assert not any(p.startswith(f"config/appendages/1/{key}") for p in shown)
    assert "<td class='absent'>—</td>" in text  # ... and marked absent for the plate
    for cell in parser.cells:
        assert json.loads(cell["data-value"]) == _lookup(data, cell["data-path"]), cell


def test_a_section_that_cannot_be_drawn_fails_its_part(tmp_path):
    # The configuration's JSON without its derived hub inertia: the section cannot be
    # drawn, so the part is failed, in the report (badge, banner, error) and in
    # study.json (status, error, traceback), never listed "ok".
    from flexsat.study.report import write_report

    config = _mixed_satellite("modal + plate")
    out = tmp_path / "study"
    _configuration_report(config, out)
    path = out / "configuration" / "configuration.json"
    data = json.loads(path.read_text())
    del data["hub_inertia_kg_m2"]
    path.write_text(json.dumps(data))
    write_report(out)
    entry = json.loads((out / "study.json").read_text())["parts"][0]
    assert entry["status"] == "failed" and entry["report_failed"]
    assert (
        "configuration section could not be drawn: KeyError('hub_inertia_kg_m2')"
        in (entry["error"])
    )
    assert "Traceback (most recent call last)" in entry["traceback"]
    text = (out / "report.html").read_text()
    assert "Failed parts: Configuration." in text
    assert "<span class='badge failed'>failed</span>" in text
    # Once the output is readable again, the part is drawn and ok again.
    path.write_text(json.dumps({**data, "hub_inertia_kg_m2": [[1.0, 0, 0], [0, 1, 0], [0, 0, 1]]}))
    write_report(out)
    entry = json.loads((out / "study.json").read_text())["parts"][0]
    assert entry["status"] == "ok" and entry["error"] is None and "report_failed" not in entry


def test_the_margins_table_lists_every_crossover_and_flexible_peak(tmp_path):
    from flexsat.config import nominal
    from flexsat.dynamics.plant import Plant
    from flexsat.simulate import SlewScenario
    from flexsat.study import report as report_module
    from flexsat.study.linear import write_margins

    # The study's frequency part: the nominal slew's law (ASMC) about rest.
    summary = write_margins(Plant.from_config(nominal()), SlewScenario())
    (tmp_path / "frequency").mkdir()
    (tmp_path / "frequency" / "margins.json").write_text(json.dumps(summary))
    section = report_module._frequency(tmp_path, {"json": "frequency/margins.json",
                                                  "figures": []}, {})  # fmt: skip
    parser = _Cells()
    parser.feed(section)
    shown = {cell["data-path"]: json.loads(cell["data-value"]) for cell in parser.cells}
    for axis, m in summary["axes"].items():
        assert m["crossovers"] and m["flexible_peaks"]
        for k, crossing in enumerate(m["crossovers"]):
            for key in ("frequency_hz", "phase_margin_deg", "delay_margin_s"):
                assert shown[f"axes/{axis}/crossovers/{k}/{key}"] == crossing[key]
        for k, peak in enumerate(m["flexible_peaks"]):
            for key in ("mode_hz", "peak_hz", "peak_gain_db", "stabilized"):
                assert shown[f"axes/{axis}/flexible_peaks/{k}/{key}"] == peak[key]
    # One row per crossover names the one that sets its axis's delay margin.
    assert section.count("<td>sets the delay margin</td>") == 3
    assert "gain-stabilized" in section and "phase-stabilized" in section


def test_a_campaign_table_says_what_it_counts_and_names_each_requirements_worst(tmp_path):
    # A store of 3 cases, one failing R2 with the smallest pointing error: the report's
    # campaign section labels its counts and times by what they count and names that
    # case among R2's worst (ranked by pointing error only, it was not named).
    from flexsat.campaigns import CampaignStore, summarize
    from flexsat.study import report

    store = CampaignStore(tmp_path / "campaigns" / "mc")
    store.cases_dir.mkdir(parents=True)
    for case_id, r2, rate, pointing in (("nominal", True, 1e-5, 0.02),
                                        ("random-00000", False, 2e-3, 0.001),
                                        ("random-00001", True, 5e-5, 0.03)):  # fmt: skip
        metrics = {"r1_pass": True, "r2_pass": r2, "r3_pass": True, "ape_deg": 0.01,
                   "max_rate_error_deg_s": rate, "max_commanded_torque_nm": [1.0, 1.0, 1.0],
                   "final_pointing_error_deg": pointing}  # fmt: skip
        store.write_case({"case_id": case_id, "status": "ok", "metrics": metrics,
                          "inputs_digest": "x", "case_cpu_time_s": 2.0})  # fmt: skip
    summary = {**summarize(store.root), "computed_this_run": 0, "resumed_this_run": 3,
               "run_wall_time_s": 0.04, "cases_text": "3 cases: 2 drawn + the nominal"}  # fmt: skip
    (store.root / "summary.json").write_text(json.dumps(summary))
    outputs = {"summaries": {"mc": "campaigns/mc/summary.json"}, "figures": []}
    html = report._campaigns(tmp_path, outputs, {})
    for label in ("cases stored", "computed by this run", "resumed from the store by this run",
                  "CPU time of the stored cases [s]", "wall time of every run into the store [s]",
                  "wall time of this run [s]", "3 cases: 2 drawn + the nominal",
                  "Worst cases per requirement"):  # fmt: skip
        assert label in html
    assert ">ran<" not in html and ">wall_time_s<" not in html
    cells = _Cells()
    cells.feed(html)
    shown = {c["data-path"]: json.loads(c["data-value"]) for c in cells.cells}
    assert shown["cpu_time_s"] == 6.0  # 3 cases of 2.0 s, summed exactly
    assert shown["resumed_this_run"] == 3 and shown["computed_this_run"] == 0
    r2 = [g["requirement"] for g in summary["worst_by_requirement"]].index("R2")
    assert shown[f"worst_by_requirement/{r2}/cases/0/passes"] is False
    assert "random-00000" in html.split("Worst cases per requirement")[1]


def test_a_campaign_not_judged_reads_so_in_the_report(tmp_path):
    # Two cases whose runs ended before their observation window: R1 and R2 null with
    # the reason. The report says "not judged" where a pass rate or verdict would be,
    # and counts them; no cell reads "fail" for them.
    from flexsat.campaigns import CampaignStore, summarize
    from flexsat.strict_json import dumps
    from flexsat.study import report

    store = CampaignStore(tmp_path / "campaigns" / "short")
    store.cases_dir.mkdir(parents=True)
    reason = "the run ends at 60 s, before the observation window starts at 90 s"
    for case_id in ("nominal", "random-00000"):
        metrics = {"r1_pass": None, "r2_pass": None, "r3_pass": True, "ape_deg": None,
                   "max_rate_error_deg_s": None, "max_commanded_torque_nm": [1.0, 1.0, 1.0],
                   "final_pointing_error_deg": 0.5, "not_judged_reason": reason}  # fmt: skip
        store.write_case({"case_id": case_id, "status": "ok", "metrics": metrics,
                          "inputs_digest": "x", "case_cpu_time_s": 2.0})  # fmt: skip
    summary = {**summarize(store.root), "computed_this_run": 2, "resumed_this_run": 0,
               "run_wall_time_s": 0.04}  # fmt: skip
    (store.root / "summary.json").write_text(dumps(summary))  # NaN rates as null
    outputs = {"summaries": {"short": "campaigns/short/summary.json"}, "figures": []}
    cells = _Cells()
    cells.feed(report._campaigns(tmp_path, outputs, {}))
    shown = {(c["data-source"].split("/")[-1], c["data-path"]): c["text"] for c in cells.cells}
    totals = {path: text for (source, path), text in shown.items() if source == "summary.json"}
    assert totals["r1_pass_rate"] == totals["r2_pass_rate"] == "not judged"
    assert totals["r1_not_judged"] == totals["r2_not_judged"] == "2"
    assert totals["r3_pass_rate"] == "1"
    for case in ("nominal.json", "random-00000.json"):
        assert shown[case, "metrics/r1_pass"] == shown[case, "metrics/r2_pass"] == "not judged"
    assert "fail" not in shown.values()
