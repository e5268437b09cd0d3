"""``flexsat robust jk-min``: the JK_min estimate's terms, printed and as JSON."""

from __future__ import annotations

import json

import numpy as np

from flexsat.cli.tables import format_number
from tests.cli.harness import flexsat, to_toml

TERMS = ("actuator", "sloshing", "environment", "residual", "inertia", "gyroscopic", "flexible")


def test_the_json_adds_up_and_the_table_prints_it(capsys):
    """Recomputed here: the disturbance is the seven terms' sum and JK_min (1 + margin)
    times it (1e-12 relative: the same sums in another order); the design satellite
    alone has no inertia or gyroscopic mismatch; the table prints every JK_min."""
    outcome = flexsat(["robust", "jk-min", "--margin", "0.1", "--json"], capsys, timeout_s=300)
    assert outcome.code == 0, outcome.stderr
    summary = json.loads(outcome.stdout)
    total = np.sum([summary[f"{term}_nm"] for term in TERMS], axis=0)
    assert np.allclose(summary["disturbance_nm"], total, rtol=1e-12)
    assert np.allclose(summary["jk_min_nm"], 1.1 * total, rtol=1e-12)
    assert summary["inertia_nm"] == [0.0, 0.0, 0.0] and summary["gyroscopic_nm"] == [0.0] * 3
    assert summary["truth_plants"] == 1 and summary["margin"] == 0.1
    assert summary["feasible"] == bool(np.all(1.1 * total <= summary["budget_nm"]))
    printed = flexsat(["robust", "jk-min", "--margin", "0.1"], capsys, timeout_s=300)
    assert printed.code == 0, printed.stderr
    for value in summary["jk_min_nm"]:
        assert format_number(value) in printed.stdout


def test_bad_margin_and_a_law_without_jk_are_refused_with_one_message(capsys, tmp_path):
    outcome = flexsat(["robust", "jk-min", "--margin", "2"], capsys)
    assert outcome.code != 0 and "margin: must be within [0, 1], got 2" in outcome.stderr
    assert "Traceback" not in outcome.stderr
    scenario = tmp_path / "pd.toml"
    scenario.write_text(to_toml({"controller": {"kind": "pd"}}))
    outcome = flexsat(["robust", "jk-min", "--scenario", str(scenario)], capsys)
    assert outcome.code != 0 and "Traceback" not in outcome.stderr
    assert "asmc" in outcome.stderr.lower()
