"""Worst-case search: seeded differential evolution over the dispersion box."""

from __future__ import annotations

import json

import pytest

from flexsat.campaigns import replay_case, run_campaign
from flexsat.campaigns.definition import CampaignDefinition
from flexsat.config import nominal, validate_config


def _search(**search) -> CampaignDefinition:
    return validate_config({
        "name": "worst", "base": {"duration_s": 0.5},
        "worst_case": {"metric": "final_pointing_error_deg", "seed": 3, "maxiter": 2,
                       "popsize": 3, "parameters": [
                           {"path": "hub.mass_kg", "bounds": [120.0, 180.0]},
                           {"path": "appendages[*].sadm_angle_deg", "bounds": [0.0, 90.0]}],
                       **search},
    }, model=CampaignDefinition)  # fmt: skip


def test_the_search_stores_every_evaluation_finds_the_largest_and_replays_it(tmp_path):
    summary = run_campaign(_search(), nominal(), tmp_path, workers=1, progress=False)
    # population popsize x D = 6, evaluated for the initial generation and each of
    # the (at most) 2 generations
    assert summary["cases"] == summary["ran"] and 6 <= summary["cases"] <= 18
    rows = {p.stem: json.loads(p.read_text()) for p in (tmp_path / "cases").glob("*.json")}
    assert len(rows) == summary["cases"]
    largest = max(rows, key=lambda c: rows[c]["metrics"]["final_pointing_error_deg"])
    # the metrics a search may name (checked at load) are numbers of every row (None:
    # NaN stored, e.g. the window metrics of a run shorter than the window)
    from flexsat.campaigns.definition import SEARCH_METRICS

    for row in rows.values():
        assert all(isinstance(row["metrics"][key], float | None) for key in SEARCH_METRICS)
        assert isinstance(row["metrics"]["final_pointing_error_deg"], float)
    assert summary["case_id"] == largest
    assert json.loads((tmp_path / "worst_case.json").read_text())["case_id"] == largest
    # replay: the same inputs give the same number (the same compiled run)
    replayed = replay_case(tmp_path, largest).dataset
    from flexsat.analysis.requirements import slew_metrics

    assert slew_metrics(replayed)["final_pointing_error_deg"] == summary["value"]


def test_a_resumed_search_recomputes_nothing(tmp_path):
    first = run_campaign(_search(), nominal(), tmp_path, workers=1, progress=False)
    again = run_campaign(_search(), nominal(), tmp_path, workers=1, resume=True,
                         progress=False)  # fmt: skip
    assert again["ran"] == 0 and again["case_id"] == first["case_id"]


def test_the_ensemble_runner_gives_the_search_of_the_pool(tmp_path):
    # Every backend stores the same rows bit for bit, so the optimizer sees the same
    # values and takes the same path: the same evaluations and the same worst case.
    pool = run_campaign(_search(), nominal(), tmp_path / "pool", workers=1, progress=False)
    ensemble = run_campaign(_search(), nominal(), tmp_path / "ensemble", workers=2,
                            runner="ensemble", progress=False)  # fmt: skip
    keys = ("case_id", "value", "parameters", "cases", "generations")
    assert {k: ensemble[k] for k in keys} == {k: pool[k] for k in keys}


def test_a_search_runs_alone():
    with pytest.raises(ValueError, match="runs alone"):
        validate_config({**_search().model_dump(mode="json"), "random": {"n": 3}},
                        model=CampaignDefinition)  # fmt: skip


def test_a_window_metric_of_runs_that_end_before_the_window_is_explained(tmp_path):
    # 0.5 s runs end long before the 90-120 s observation window: ape_deg is NaN in
    # every evaluation, and the message says why instead of suggesting ape_deg.
    from flexsat.errors import ConfigError

    with pytest.raises(ConfigError, match="need runs that reach the end of the requirements"):
        run_campaign(_search(metric="ape_deg", maxiter=1), nominal(), tmp_path, workers=1,
                     progress=False)  # fmt: skip
