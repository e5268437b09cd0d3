"""The summary of a stored campaign: what it counts after a resume, its worst cases per
requirement, and where its cases come from."""

from __future__ import annotations

import json
import math

import pytest

from flexsat.campaigns import CampaignStore, load_campaign, run_campaign, summarize
from flexsat.campaigns.definition import CaseStream, describe_counts
from flexsat.campaigns.runner import SUMMARY_ROWS, WORST_CASES
from flexsat.config import nominal

from .test_campaigns import _short


def test_a_resumed_campaign_counts_its_stored_cases_and_their_time(tmp_path):
    # Three runs into one store of 2 cases (1 s slews): both computed; one case file
    # removed, so the second run computes it and resumes the other; the third resumes
    # both. Its summary counts the 2 stored cases, not the 0 it computed, and its
    # times are the campaign's, not the run's: the CPU time is the stored cases' own,
    # summed, the wall time every run's.
    from flexsat.study.outputs import fly_campaign

    definition = _short("montecarlo-random", 1.0)
    options = {"workers": 1, "n_random": 1, "progress": False}
    first = run_campaign(definition, nominal(), tmp_path, **options)
    assert (first["ran"], first["resumed"]) == (2, 0)
    (tmp_path / "cases" / "random-00000.json").unlink()
    second = run_campaign(definition, nominal(), tmp_path, resume=True, **options)
    assert (second["ran"], second["resumed"]) == (1, 1)
    third = fly_campaign(definition, nominal(), tmp_path, resume=True, **options)

    stored = [json.loads(p.read_text()) for p in (tmp_path / "cases").glob("*.json")]
    assert third["cases"] == len(stored) == 2
    assert (third["computed_this_run"], third["resumed_this_run"]) == (0, 2)
    cpu = [row["case_cpu_time_s"] for row in stored]
    assert all(c > 0.0 for c in cpu)  # each case was flown, by some process
    # a sum of the same two floats: equal to rounding (1e-12 relative)
    assert third["cpu_time_s"] == pytest.approx(sum(cpu), rel=1e-12)
    own = [row["case_wall_time_s"] for row in stored]
    assert third["case_wall_time_s"] == pytest.approx(sum(own), rel=1e-12)
    walls = [first["wall_time_s"], second["wall_time_s"], third["run_wall_time_s"]]
    assert third["runs"] == 3
    assert third["campaign_wall_time_s"] == pytest.approx(sum(walls), rel=1e-12)
    assert third["campaign_wall_time_s"] > third["run_wall_time_s"]
    runs = json.loads((tmp_path / "campaign.json").read_text())["runs"]
    assert [(r["computed"], r["resumed"]) for r in runs] == [(2, 0), (1, 1), (0, 2)]
    # the file the study's report reads says the same (a later resume rewrites it whole)
    written = json.loads((tmp_path / "summary.json").read_text())
    for key, _ in SUMMARY_ROWS:
        assert written[key] == third[key]
    assert "ran" not in written and "wall_time_s" not in written


def _row(case_id: str, r1: bool, r2: bool, ape: float, rate: float, torque: list[float],
         pointing: float, status: str = "ok") -> dict:  # fmt: skip
    metrics = {} if status != "ok" else {
        "r1_pass": r1, "r2_pass": r2, "r3_pass": max(torque) <= 2.0, "ape_deg": ape,
        "max_rate_error_deg_s": rate, "max_commanded_torque_nm": torque,
        "final_pointing_error_deg": pointing,
    }  # fmt: skip
    return {"case_id": case_id, "status": status, "metrics": metrics, "inputs_digest": "x",
            "case_cpu_time_s": 0.0}  # fmt: skip


def test_the_worst_cases_are_listed_per_requirement(tmp_path):
    # 100 stored cases, 10 of which fail R2 alone with the smallest pointing errors:
    # a ranking by pointing error alone would name none of them. R2's list
    # holds its 5 failing cases of the largest residual rate; R3's ranks by the
    # largest axis of the commanded torque; a case that failed to run is in every
    # verdict's failing count.
    store = CampaignStore(tmp_path)
    store.cases_dir.mkdir(parents=True)
    for k in range(100):
        jitter = 10 <= k < 20  # fails R2: rate 1.1e-3 .. 2.0e-3 deg/s, the bound 1e-3
        rate = (1.0 + (k - 9) * 0.1) * 1e-3 if jitter else 1e-5 * (k + 1)
        store.write_case(
            _row(
                f"c{k:03d}",
                True,
                not jitter,
                0.01 + 1e-4 * k,
                rate,
                [1.0, 0.5 + 0.01 * k, 0.2],
                1e-6 if jitter else 1e-3 + 1e-5 * k,
            )
        )
    store.write_case(_row("crashed", False, False, 0.0, 0.0, [0.0], 0.0, status="failed"))
    summary = summarize(tmp_path)
    worst = {g["requirement"]: g for g in summary["worst_by_requirement"]}
    assert set(worst) == {"R1", "R2", "R3", "pointing"}
    assert summary["r2_pass_rate"] == pytest.approx(90 / 101, rel=1e-15)
    r2 = worst["R2"]
    assert (r2["metric"], r2["unit"], r2["failing"]) == ("max_rate_error_deg_s", "deg/s", 11)
    # the 5 failing cases of largest rate, largest first; the crashed case has no value
    assert [c["case_id"] for c in r2["cases"]] == ["c019", "c018", "c017", "c016", "c015"]
    assert all(c["passes"] is False for c in r2["cases"])
    assert r2["cases"][0]["value"] == pytest.approx(2.0e-3, rel=1e-12)
    # R1 fails only in the crashed case: it comes first, then the largest APE that passes
    assert [c["case_id"] for c in worst["R1"]["cases"][:2]] == ["crashed", "c099"]
    assert worst["R1"]["failing"] == 1
    # R3 by the largest axis of each case's commanded torque (here the y axis, 0.5 + 0.01 k)
    assert worst["R3"]["cases"][0] == {"case_id": "crashed", "value": None, "passes": False}
    assert worst["R3"]["cases"][1] == {"case_id": "c099", "value": pytest.approx(1.49, rel=1e-12),
                                       "passes": True}  # fmt: skip
    pointing = [c["case_id"] for c in worst["pointing"]["cases"]]
    assert pointing == ["c099", "c098", "c097", "c096", "c095"]
    assert len(pointing) == WORST_CASES
    assert [w["case_id"] for w in summary["worst_cases"]] == pointing  # the figure's list
    assert math.isclose(summary["worst_final_pointing_error_deg"], 1e-3 + 99e-5)


@pytest.mark.parametrize(
    ("name", "n_random", "text"),
    [("montecarlo-random", 100, "101 cases: 100 drawn + the nominal"),
     ("sensitivity", None, "12 cases: 11 listed + the nominal"),
     ("montecarlo-critical", None, "25 cases: 24 from the grid + the nominal"),
     ("deployment-shock", None, "32 cases: 32 from the grid")],
)  # fmt: skip
def test_the_case_count_says_where_the_cases_come_from(name, n_random, text):
    stream = CaseStream(load_campaign(name), nominal(), n_random)
    assert describe_counts(stream.counts()) == text
    assert int(text.split()[0]) == len(stream)


def test_the_cases_option_says_the_nominal_comes_on_top():
    import typer.main

    from flexsat.cli.main import app

    command = typer.main.get_command(app).commands["campaign"]
    (option,) = [p for p in command.params if p.name == "cases"]
    assert "--cases 100 runs 101 cases" in option.help
