"""A campaign whose runs end before their observation window: R1 and R2 "not judged".

Flown by the real command (a subprocess, as a user runs it), with ``--duration``
shorter than the default 90 s settling deadline. One case moves its own window inside
its run, so the campaign holds a judged case (which fails: at 0.2-0.5 s the slew has
barely started) beside one that is not judged (docs/control.md, 'How R1 and R2 are
judged'; docs/campaigns.md, 'Cases not judged').
"""

from __future__ import annotations

import json
import os
import subprocess
import sys

import pandas as pd
import pytest

CAMPAIGN = """name = "mixed"
include_nominal = true
[base]
duration_s = 120.0
[[cases]]
id = "early-window"
scenario = [{ path = "requirements.settling_deadline_s", value = 0.2 }]
"""


@pytest.fixture(scope="module")
def flown(tmp_path_factory):
    """The command's output and the store of the campaign flown 0.5 s per case."""
    folder = tmp_path_factory.mktemp("not-judged")
    (folder / "mixed.toml").write_text(CAMPAIGN)
    store = folder / "store"
    result = subprocess.run(
        [sys.executable, "-m", "flexsat", "campaign", str(folder / "mixed.toml"),
         "--duration", "0.5", "--workers", "1", "--out", str(store)],
        capture_output=True, text=True, timeout=600, env={**os.environ, "COLUMNS": "200"},
    )  # fmt: skip
    assert result.returncode == 0, result.stderr
    return result, store


def test_the_command_says_before_flying_that_r1_and_r2_are_not_judged(flown):
    result, _ = flown
    assert (
        "campaign mixed: R1 and R2 are not judged in 1 of the first 2 cases: the run ends at "
        "0.5 s, before the observation window starts at 90 s "
        "(requirements.settling_deadline_s)"
    ) in " ".join(result.stderr.split())


def test_the_store_keeps_not_judged_as_null(flown):
    _, store = flown
    table = pd.read_parquet(store / "results.parquet").set_index("case_id")
    for key in ("metrics.r1_pass", "metrics.r2_pass"):
        assert str(table[key].dtype) == "boolean"  # pandas' nullable bool, from Parquet
        assert table[key].isna().tolist() == [False, True]  # nominal: null, not False
        assert not table.loc["early-window", key]  # judged, and failed
    assert table.loc["nominal", "metrics.not_judged_reason"].startswith("the run ends at 0.5 s")
    assert table.loc["early-window", "metrics.not_judged_reason"] == ""
    assert pd.isna(table.loc["nominal", "metrics.ape_deg"])  # no window observed: no APE


def test_the_summary_rates_the_judged_cases_and_counts_the_others(flown):
    _, store = flown
    summary = json.loads((store / "summary.json").read_text())
    # one judged case, failing R1 and R2 (the slew's first half second): 0 of 1
    assert (summary["r1_pass_rate"], summary["r2_pass_rate"]) == (0.0, 0.0)
    assert (summary["r1_not_judged"], summary["r2_not_judged"]) == (1, 1)
    assert summary["r3_pass_rate"] == 1.0  # R3 is judged on every record of every run
    assert "before the observation window starts at 90 s" in summary["not_judged_reason"]
    r1 = next(r for r in summary["requirements"] if r["requirement"] == "r1_pass")
    assert (r1["cases"], r1["not_judged"], r1["passes"], r1["failing"]) == (
        1, 1, 0, ["early-window"])  # fmt: skip
    for group in summary["worst_by_requirement"][:2]:  # R1, R2: nominal is no failure
        assert group["failing"] == 1
        assert all(c["case_id"] != "nominal" or c["passes"] is None for c in group["cases"])


def test_the_table_fails_only_the_judged_case(flown):
    result, _ = flown
    # early-window fails R1 and R2 (its worst lines); nominal reads FAIL nowhere
    assert result.stdout.count("FAIL") == 2
    lines = [line for line in result.stdout.splitlines() if "FAIL" in line]
    assert all("nominal" not in line and "early-window" in line for line in lines), lines
    assert "R1 not judged" in result.stdout
