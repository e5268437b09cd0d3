"""The avionics study part on a 40 s horizon (the slew settles at 37 s; the 90-120 s
requirement window is beyond it, so R1/R2 and the windowed metrics are absent), and
its delay sweep in the quick study's report (120 s runs)."""

from __future__ import annotations

import json
from html.parser import HTMLParser

import pytest

from flexsat.config import nominal
from flexsat.dynamics.plant import Plant
from flexsat.study.avionics import (
    AVIONICS_FIGURES,
    NO_DRIVE,
    SADM_RATE_DEG_S,
    avionics_study,
    bracket_delays,
    render_avionics,
)

HORIZON_S = 40.0


@pytest.fixture(scope="module")
def study(tmp_path_factory):
    out = tmp_path_factory.mktemp("avionics")
    written = avionics_study(Plant.from_config(nominal()), out, quick=True, duration_s=HORIZON_S)
    return out, written, json.loads(written["json"].read_text())


def test_the_realistic_chain_settles_beside_the_ideal_loop(study):
    # Both settle (the report's settling time, 37.0 s ideal, measured) and end within
    # 0.05 deg of the target (measured 0.010 and 0.014 deg at 40 s): the sensors'
    # noise (5-30 arcsec star tracker, MEKF) and the 10 ms wheel motors only delay
    # settling by a fraction of a second (measured 0.4 s; bound 2 s).
    # R3: both hold it; the min-max allocation asks every wheel for 82 % of its motor's
    # limit where the pseudo-inverse alone asked one for 123 %
    # (tests/control/stages/test_wheels.py).
    _, _, data = study
    ideal, avionics = data["side_by_side"]["ideal"], data["side_by_side"]["avionics"]
    assert ideal["r3_pass"] and avionics["r3_pass"]
    for run in (ideal, avionics):
        assert run["status"] == "ok"
        assert run["final_pointing_error_deg"] < 0.05
        assert run["ape_deg"] is None  # the window starts at 90 s
    assert 30.0 < ideal["settling_time_s"] < HORIZON_S
    assert 0.0 <= avionics["settling_time_s"] - ideal["settling_time_s"] < 2.0


def test_the_delay_sweep_is_refined_around_the_linear_margin(study):
    # The ASMC's linear loop about rest has its smallest delay margin on Z, 0.0754 s
    # at 3.29 Hz (the frequency section's; measured). The quick sweep adds the
    # control periods just below and above it and 1.04 and 1.1 times it (75, 76, 78
    # and 83 ms) to its own 0.05, 0.1, 0.2 and 0.5 s.
    _, _, data = study
    margin = data["linear_delay_margin"]
    assert (margin["law"], margin["axis"]) == ("asmc", "z")
    assert margin["margin_s"] == pytest.approx(0.0754, abs=5e-5)
    delays = [row["delay_s"] for row in data["delay_sweep"]]
    assert delays == pytest.approx([0.05, 0.075, 0.076, 0.078, 0.083, 0.1, 0.2, 0.5])
    assert bracket_delays(margin["margin_s"], 1e-3, (1.0,)) == [75, 76]


def test_a_shortened_sweep_is_judged_on_its_last_quarter(study):
    # 40 s runs do not reach the 90-120 s window: each is judged over 30-40 s, where
    # the slew is still ending (1.15 deg/s at 30 s). 50 ms of delay leaves the slew as
    # it was (measured 4e-4 deg from the ideal's end point; bound 0.005 deg) and its
    # envelope decays (measured 0.08 of the first half's); with 0.5 s the loop is in
    # a limit cycle of 15.8 deg/s, its envelope neither decaying nor growing
    # (measured 1.02). A verdict near the margin needs the 120 s runs (the report's,
    # tests of the quick study below).
    _, _, data = study
    rows = {round(row["delay_s"], 6): row for row in data["delay_sweep"]}
    short, long = rows[0.05], rows[0.5]
    assert short["span_s"] == long["span_s"] == [30.0, 40.0]
    ideal = data["side_by_side"]["ideal"]["final_pointing_error_deg"]
    assert abs(short["final_pointing_error_deg"] - ideal) < 0.005
    assert short["verdict"] == "stable" and not short["unstable"]
    assert long["verdict"] == "limit cycle" and long["unstable"]
    assert long["envelope_last_deg_s"] > 10.0


def test_arrays_turning_at_the_sadm_rate(study):
    # (c): the drive moves the arrays by r T = 0.06 deg/s x 40 s = 2.4 deg, to within
    # the drive's peak tracking error (measured 0.026 deg, during the slew's
    # acceleration); the slew with the arrays turning stays within 0.02 deg of the one
    # with them held (measured 0.008 deg: the arrays' 1.4 kg m^2 about their axis
    # against the satellite's ~100 kg m^2) and settles at the same time.
    _, _, data = study
    sadm = data["sadm"]
    assert sadm["rate_deg_s"] == SADM_RATE_DEG_S
    assert abs(sadm["array_angle_deg"] - SADM_RATE_DEG_S * HORIZON_S) <= (
        sadm["peak_tracking_error_deg"])  # fmt: skip
    assert 0.0 < sadm["peak_tracking_error_deg"] < 0.1
    assert 0.0 < sadm["attitude_difference_deg"] < 0.02
    assert sadm["turning"]["settling_time_s"] == pytest.approx(sadm["holding"]["settling_time_s"],
                                                               abs=0.5)  # fmt: skip
    assert sadm["peak_drive_torque_nm"] > 0.0


def test_report_rows_trace_every_number(study):
    out, written, data = study
    outputs = {"json": written["json"].relative_to(out), "figures": []}
    side, sweep, sadm, sentence = render_avionics(out, outputs, lambda rel, *path: path)
    assert len(sweep) == len(data["delay_sweep"])
    assert ("sadm", "turning", "settling_time_s") in [row[2] for row in sadm]
    assert "0.06 deg/s" in sentence
    assert "smallest delay margin on axis z: 0.0754 s" in sentence
    assert f"a limit cycle from {data['limit_cycle_at_delay_s']:g} s" in sentence
    assert written["figures"][0].exists()


def test_the_avionics_runs_stage_figures_are_written(study):
    # The report shows the avionics run's estimation (MEKF) and wheel figures beside
    # the delay boundary (their content: tests/plots/test_stage_plots.py).
    out, written, _ = study
    names = [path.name for path in written["figures"]]
    assert names == ["delay_boundary.png", *(f"{name}.png" for name in AVIONICS_FIGURES)]
    for path in written["figures"]:
        assert path.parent == out and path.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_a_satellite_without_plates_reports_the_drive_not_applicable(tmp_path):
    # The drive is built for thesis plates; a satellite of chains runs (a) and (b) and
    # says why (c) is absent instead of failing the whole part (its two panels here are
    # the plates as one-segment chains; 1 s runs: only the payload's shape is tested).
    from tests.dynamics.chain_satellites import thesis_chain_config

    written = avionics_study(Plant.from_config(thesis_chain_config()), tmp_path, quick=True,
                             duration_s=1.0)  # fmt: skip
    data = json.loads(written["json"].read_text())
    assert data["sadm"] == {"rate_deg_s": SADM_RATE_DEG_S, "not_applicable": NO_DRIVE}
    assert len(data["delay_sweep"]) >= 4 and data["side_by_side"]["avionics"]["status"] == "ok"
    outputs = {"json": written["json"].relative_to(tmp_path), "figures": []}
    _, _, sadm, sentence = render_avionics(tmp_path, outputs, lambda rel, *path: path)
    assert sadm == [] and sentence.endswith(f"Arrays turning (SADM): {NO_DRIVE}.")


class _SweepTable(HTMLParser):
    """The rows of the report's table captioned "Sweep over the computational delay":
    each cell's text and class."""

    def __init__(self) -> None:
        super().__init__()
        self.rows: list[list[dict]] = []
        self.header: list[str] = []
        self._in_table = self._in_caption = False
        self._cell: dict | None = None

    def handle_starttag(self, tag, attrs):
        if tag == "caption":
            self._in_caption = True
        elif self._in_table and tag == "tr":
            self.rows.append([])
        elif self._in_table and tag in ("td", "th"):
            self._cell = {"class": dict(attrs).get("class", ""), "text": ""}

    def handle_data(self, data):
        if self._in_caption and data == "Sweep over the computational delay":
            self._in_table = True
        if self._cell is not None:
            self._cell["text"] += data

    def handle_endtag(self, tag):
        if tag == "caption":
            self._in_caption = False
        elif tag == "table":
            self._in_table = False
        elif self._cell is not None and tag in ("td", "th"):
            self.rows[-1].append(self._cell)
            self._cell = None


def test_the_reports_delay_sweep_says_stable_where_the_loop_is_stable(quick_study):
    # The quick study's report (120 s runs). Its verdict column names what each run
    # does, read from the residual-rate envelope over the 90-120 s window: 50 ms and
    # the two control periods around the 0.0754 s linear margin (75, 76 ms) settle
    # into the disturbances' forced response (3.4e-5 to 3.6e-5 deg/s, inside R2's
    # 1e-3 deg/s); from 78 ms on the loop holds a limit cycle (measured 0.139 deg/s
    # at 78 ms, 0.263 at 0.1 s, 3.43 at 0.2 s, 17.4 at 0.5 s), its envelope steady
    # (second-half over first-half peak 0.97 to 1.0). Before, the column was a
    # boolean "unstable" drawn as pass/fail: the stable 50 ms row read a red "fail".
    out, _ = quick_study
    parser = _SweepTable()
    parser.feed((out / "report.html").read_text())
    header, *rows = parser.rows
    names = [cell["text"] for cell in header]
    delay_col = names.index("delay [s]")
    verdict_col = names.index("stability (residual-rate envelope)")
    envelope_col = names.index("envelope, window's 2nd half [deg/s]")
    verdicts = {float(row[delay_col]["text"]): row[verdict_col] for row in rows}
    for cell in verdicts.values():
        assert cell["text"] in ("stable", "limit cycle", "diverges")
        assert cell["class"] not in ("pass", "fail")  # no pass/fail colour for a verdict
    cycle = "limit cycle"
    assert {d: c["text"] for d, c in verdicts.items()} == {
        0.05: "stable", 0.075: "stable", 0.076: "stable", 0.078: cycle, 0.083: cycle,
        0.1: cycle, 0.2: cycle, 0.5: cycle}  # fmt: skip
    envelope = {float(row[delay_col]["text"]): float(row[envelope_col]["text"]) for row in rows}
    # the limit cycles at 0.1 and 0.2 s: 0.263 and 3.43 deg/s (4 digits shown; the run
    # is deterministic, 1 % covers another platform's rounding)
    assert envelope[0.1] == pytest.approx(0.263, rel=0.01)
    assert envelope[0.2] == pytest.approx(3.43, rel=0.01)
    # The sweep brackets the linear margin with the periods on either side of it, and
    # the time-domain boundary (between the last stable and first limit-cycle delay,
    # 76 and 78 ms) lies within 4 % above the linear prediction (measured 0.8 to 3.4 %).
    data = json.loads((out / "avionics" / "avionics.json").read_text())
    margin = data["linear_delay_margin"]["margin_s"]
    stable, unstable = data["stable_up_to_delay_s"], data["unstable_at_delay_s"]
    assert (stable, unstable) == (pytest.approx(0.076), pytest.approx(0.078))
    assert any(d <= margin for d in verdicts) and any(d > margin for d in verdicts)
    assert margin < stable < unstable < 1.04 * margin
