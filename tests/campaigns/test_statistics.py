"""Campaign statistics: exact intervals, cases needed, percentiles, parameters."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest
from scipy.stats import binomtest

from flexsat.campaigns import load_campaign
from flexsat.campaigns.definition import CaseStream
from flexsat.campaigns.statistics import (
    cases_needed,
    metric_statistics,
    parameter_table,
    pass_rate_interval,
    percentile_envelope,
    rank_correlations,
    requirement_statistics,
)
from flexsat.config import nominal


@pytest.mark.parametrize("confidence", [0.9, 0.95, 0.9973])
@pytest.mark.parametrize(("passes", "cases"), [(0, 10), (1, 10), (19, 32), (69, 69), (997, 1000)])
def test_clopper_pearson_matches_scipy_binomtest(passes, cases, confidence):
    # Reference: scipy.stats.binomtest(k, n).proportion_ci(method="exact"), an
    # independent implementation of the same beta quantiles; 1e-12 absolute
    # (quantiles are computed to ~1e-15; the solvers differ).
    ci = binomtest(passes, cases).proportion_ci(confidence_level=confidence, method="exact")
    low, high = pass_rate_interval(passes, cases, confidence)
    assert low == pytest.approx(ci.low, abs=1e-12)
    assert high == pytest.approx(ci.high, abs=1e-12)


@pytest.mark.parametrize(
    ("probability", "confidence", "failures"),
    [(0.9973, 0.95, 0), (0.99, 0.95, 0), (0.9973, 0.95, 2), (0.95, 0.99, 1)],
)
def test_cases_needed_is_the_smallest_count_whose_exact_bound_reaches_the_claim(
    probability, confidence, failures
):
    # The one-sided lower bound at c is the lower end of the two-sided 1 - 2 (1 - c)
    # interval (scipy's exact interval, as reference): reached at n, not at n - 1.
    n = cases_needed(probability, confidence, failures)

    def low(cases: int) -> float:
        ci = binomtest(cases - failures, cases).proportion_ci(
            confidence_level=1 - 2 * (1 - confidence), method="exact"
        )
        return ci.low

    assert low(n) >= probability > low(n - 1)


def test_cases_needed_for_three_sigma_at_95_percent_is_the_textbook_1108_or_so():
    # No failure: n >= ln(1 - c) / ln(p) = ln 0.05 / ln 0.9973 = 1108.03 -> 1109.
    assert cases_needed(0.9973, 0.95) == 1109


def _table() -> pd.DataFrame:
    return pd.DataFrame({
        "case_id": ["a", "b", "c", "d"],
        "status": ["ok", "ok", "ok", "failed"],
        "metrics.r1_pass": [True, False, True, None],
        "metrics.r2_pass": [True, True, True, None],
        "metrics.final_pointing_error_deg": [1.0, 2.0, 3.0, np.nan],
    })  # fmt: skip


def test_requirements_list_their_failing_cases_and_a_failed_run_fails_all():
    table = requirement_statistics(_table()).set_index("requirement")
    assert table.loc["r1_pass", "failing"] == ["b", "d"]
    assert table.loc["r2_pass", "failing"] == ["d"]
    assert table.loc["r1_pass", "passes"] == 2 and table.loc["r1_pass", "cases"] == 4
    bounds = (table.loc["r1_pass", "ci_low"], table.loc["r1_pass", "ci_high"])
    assert bounds == pass_rate_interval(2, 4)


def test_a_case_not_judged_is_neither_a_pass_nor_a_failure():
    # c's run ended before its window (a reason, a null verdict): out of the rate; d
    # failed before it had metrics: it still fails every requirement.
    table = _table()
    table["metrics.r1_pass"] = pd.array([True, False, None, None], dtype="boolean")
    table["metrics.not_judged_reason"] = ["", "", "the run ends at 60 s, ...", np.nan]
    row = requirement_statistics(table).set_index("requirement").loc["r1_pass"]
    assert (row["passes"], row["cases"], row["not_judged"]) == (1, 3, 1)
    assert row["failing"] == ["b", "d"] and row["pass_rate"] == 1 / 3
    assert (row["ci_low"], row["ci_high"]) == pass_rate_interval(1, 3)


def test_a_campaign_of_cases_not_judged_has_no_pass_rate():
    table = _table().iloc[:3].copy()
    table["metrics.r1_pass"] = pd.array([None] * 3, dtype="boolean")
    table["metrics.not_judged_reason"] = ["the run ends at 60 s, ..."] * 3
    row = requirement_statistics(table).set_index("requirement").loc["r1_pass"]
    assert (row["cases"], row["not_judged"], row["failing"]) == (0, 3, [])
    assert np.isnan(row["pass_rate"]) and np.isnan(row["ci_low"])


def test_metric_percentiles_beside_min_and_max():
    # numpy's linear percentiles of [1, 2, 3]: 5 % -> 1.1, 50 % -> 2, 95 % -> 2.9.
    row = metric_statistics(_table()).set_index("metric").loc["final_pointing_error_deg"]
    assert (row["min"], row["max"], row["cases"]) == (1.0, 3.0, 3)
    assert row[["p5", "p50", "p95"]].tolist() == pytest.approx([1.1, 2.0, 2.9], abs=1e-12)


def test_percentile_envelope_is_per_sample():
    values = np.arange(20.0).reshape(10, 2)  # column 0: 0, 2, ..., 18
    envelope = percentile_envelope(values, (0.0, 50.0, 100.0))
    assert envelope[:, 0].tolist() == [0.0, 9.0, 18.0]


def test_parameter_columns_give_physical_values_beside_factors():
    # The nominal flapping target is 0.25 Hz (thesis table 3.1): a case's physical
    # target is 0.25 x its factor; the SADM angle is set, a physical value only.
    stream = CaseStream(load_campaign("montecarlo-random"), nominal(), n_random=3)
    rows = [{"case_id": c.case_id, "parameters": c.parameters,
             "inputs": {"plant": c.plant, "scenario": c.scenario}} for c in stream]  # fmt: skip
    table = parameter_table(rows).set_index("case_id")
    path = "appendages[0].target_frequencies_hz.flapping"
    case = table.loc["random-00001"]
    factor, hz = case[f"{path} [factor]"], case[f"{path} [Hz]"]
    assert hz == pytest.approx(0.25 * factor, rel=1e-15)
    assert "appendages[0].sadm_angle_deg [deg]" in table
    assert "appendages[0].sadm_angle_deg [factor]" not in table
    assert "hub.inertia [factor]" in table  # derived: no physical column


def test_rank_correlations_find_the_monotone_parameter():
    x = pd.DataFrame({"p": [1.0, 2.0, 3.0, 4.0], "q": [1.0, -1.0, 1.0, -1.0]})
    y = pd.DataFrame({"m": [10.0, 20.0, 30.0, 40.0]})
    table = rank_correlations(x, y)
    assert table.loc["p", "m"] == pytest.approx(1.0)
    assert abs(table.loc["q", "m"]) < 0.5


def test_a_chains_parameter_columns_say_which_values_are_factors():
    # On a chain the thesis's paths are derived (its joints, beam and mount change):
    # the damping ratio and the SADM angle are set values, physical columns in their
    # units; a frequency factor scales beam stiffnesses and keeps a factor column only.
    from flexsat.config import load_config, preset_path

    stream = CaseStream(load_campaign("montecarlo-random"), load_config(preset_path("chain")),
                        n_random=3)  # fmt: skip
    cases = list(stream)
    rows = [{"case_id": c.case_id, "parameters": c.parameters,
             "inputs": {"plant": c.plant, "scenario": c.scenario}} for c in cases]  # fmt: skip
    table = parameter_table(rows).set_index("case_id")
    path = "appendages[0]"
    assert f"{path}.damping_ratio [-]" in table and f"{path}.damping_ratio [factor]" not in table
    assert f"{path}.sadm_angle_deg [deg]" in table
    assert f"{path}.target_frequencies_hz.flapping [factor]" in table
    assert f"{path}.target_frequencies_hz.flapping [Hz]" not in table
    case = cases[1]
    assert table.loc[case.case_id, f"{path}.damping_ratio [-]"] == (
        case.plant["appendages"][0]["joint"]["damping_ratio"])  # fmt: skip
