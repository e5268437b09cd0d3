"""The pointing budget: contributions, the two summations, verdicts, the requirement file.

The statistical sum is checked against a Monte Carlo of the same contributors
(fixed, printed seed) within the order-statistic interval of the Monte Carlo's
quantile; each periodic contribution against the index measured on the sinusoid it
stands for; the rest against closed forms.
"""

from __future__ import annotations

import csv
import io
import math

import numpy as np
import pytest
import xarray as xr
from scipy.stats import norm

from flexsat.analysis.budget import (
    IndexRequirement,
    PointingRequirements,
    budget_rows,
    contribution,
    evaluate,
    gaussian_factor,
    load_requirements,
    summed,
    to_csv,
)
from flexsat.analysis.pointing import index_samples, interpret, order_statistic
from flexsat.errors import ConfigError

SEED = 20261207


def _requirements(contributors, **indices) -> PointingRequirements:
    return PointingRequirements.model_validate(
        {
            "indices": {k: {"bound_deg": 1.0, **v} for k, v in indices.items()},
            "contributors": contributors,
        }
    )


MIXED = [
    {"name": "alignment", "kind": "bias", "sigma_deg": [1e-3, 1e-3, 2e-3]},
    {"name": "sensor noise", "kind": "random", "sigma_deg": [2e-3, 2e-3, 1e-3]},
    {
        "name": "panel mode",
        "kind": "periodic",
        "amplitude_deg": [5e-4, 5e-4, 0.0],
        "period_s": 3.0,
    },
    {
        "name": "thermal",
        "kind": "bias",
        "distribution": "uniform",
        "bound_deg": [5e-4, 5e-4, 1e-3],
    },
]


@pytest.mark.parametrize("p", [0.95, 0.9973])
def test_statistical_sum_matches_a_monte_carlo_of_the_contributors(p):
    # Draw each contributor as its class and distribution say (the bias once per
    # draw, the random error, the sinusoid at a uniform phase, the uniform bias) and
    # sum them: the P-quantile of |sum| over 10^6 draws, with its 99.9 % order-
    # statistic interval, must hold the statistical sum n_P sqrt(sum sigma_i^2)
    # (zero means), and stay below the worst-case sum. The statistical sum takes the
    # total as Gaussian; the sinusoid's and the uniform's excess kurtosis (-1.5, -1.2)
    # move the true quantile by the Cornish-Fisher term (z^3 - 3 z) / 24 gamma_2 sigma,
    # asserted below a third of the interval's half-width, so that the check is sharp.
    rng = np.random.default_rng(SEED)
    print(f"seed {SEED}")
    rows = budget_rows(_requirements(MIXED, APE={"confidence": p}))
    n = 1_000_000
    for k, row in enumerate(rows):
        draws = (
            rng.normal(0.0, MIXED[0]["sigma_deg"][k], n)
            + rng.normal(0.0, MIXED[1]["sigma_deg"][k], n)
            + MIXED[2]["amplitude_deg"][k] * np.sin(rng.uniform(0.0, 2 * np.pi, n))
            + rng.uniform(-1.0, 1.0, n) * MIXED[3]["bound_deg"][k]
        )
        stat = order_statistic(np.abs(draws), p, 0.999)
        sine, box = MIXED[2]["amplitude_deg"][k] ** 2 / 2, MIXED[3]["bound_deg"][k] ** 2 / 3
        gamma_2 = (-1.5 * sine**2 - 1.2 * box**2) / row["sigma_deg"] ** 4
        z = gaussian_factor(p)
        shift = abs((z**3 - 3 * z) / 24 * gamma_2) * row["sigma_deg"]
        assert shift < (stat.high - stat.low) / 6, (shift, stat)
        assert stat.low <= row["statistical_deg"] <= stat.high, (row, stat)
        assert stat.high <= row["worst_case_deg"], (row, stat)
        # the total's sigma: sqrt(sigma_b^2 + sigma_r^2 + A^2 / 2 + B^2 / 3)
        variance = (
            MIXED[0]["sigma_deg"][k] ** 2
            + MIXED[1]["sigma_deg"][k] ** 2
            + MIXED[2]["amplitude_deg"][k] ** 2 / 2
            + MIXED[3]["bound_deg"][k] ** 2 / 3
        )
        assert row["sigma_deg"] == pytest.approx(math.sqrt(variance), rel=1e-14)


@pytest.mark.parametrize("index", ["APE", "MPE", "RPE", "PDE", "PRE"])
def test_a_periodic_contribution_is_the_index_of_its_sinusoid(index):
    # A sinusoid of amplitude A and period T, sampled every dt: the index measured on
    # it (temporal, P = 0.95) against the budget's worst case for that one contributor,
    # a_index sin(pi P / 2). The record holds a whole number of periods of window
    # positions; an odd window (1001 records) has its centre record in its middle.
    # A sample on a phase grid is off by at most the signal's change over one record,
    # 2 pi A dt / T.
    amplitude, period, dt, p = 1e-3, 1.25, 1e-3, 0.95
    req = IndexRequirement(bound_deg=1.0, window_s=1.001, stability_s=0.5, observation_s=3.0)
    periodic = _requirements(
        [
            {
                "name": "mode",
                "kind": "periodic",
                "amplitude_deg": [amplitude, 0.0, 0.0],
                "period_s": period,
            }
        ],
        **{index: req.model_dump()},
    )
    n = round(req.window_s / dt)
    separation = {"PDE": req.stability_s, "PRE": req.observation_s}.get(index)
    extra = (n - 1 if index != "APE" else 0) + round((separation or 0.0) / dt)
    t = np.arange(8 * round(period / dt) + extra) * dt
    e = amplitude * np.sin(2 * np.pi * t / period)
    measured = interpret([index_samples(t, e, index, req.window_s, separation)], "temporal", p)
    budget = budget_rows(periodic.model_copy(update={"confidence": p}))[0]
    assert budget["worst_case_deg"] == pytest.approx(
        measured.value, abs=2 * np.pi * amplitude * dt / period
    )


def test_closed_forms_of_the_distributions():
    p = 0.9973
    req = IndexRequirement(bound_deg=1.0, window_s=1.0)
    # a Gaussian bias: n_P sigma, n_P = Phi^-1((1 + P) / 2) = 2.99998 (to 1e-5)
    bias = _requirements([{"name": "b", "kind": "bias", "sigma_deg": [1e-3, 0, 0]}], APE={})
    total = summed([contribution(bias.contributors[0], "APE", req)], p)
    assert gaussian_factor(p) == pytest.approx(norm.ppf(0.99865), rel=1e-15)
    assert total["statistical"][0] == pytest.approx(2.99998e-3, abs=1e-8)
    # fixed biases add as numbers, with their signs, in both sums' means
    fixed = [
        {"name": f"f{k}", "kind": "bias", "distribution": "fixed", "mean_deg": [v, 0, 0]}
        for k, v in enumerate((2e-3, -0.5e-3))
    ]
    rows = budget_rows(_requirements(fixed, APE={}, RPE={"window_s": 1.0}))
    assert rows[0]["statistical_deg"] == pytest.approx(1.5e-3, rel=1e-15)
    assert rows[0]["worst_case_deg"] == pytest.approx(2.5e-3, rel=1e-15)
    assert rows[3]["statistical_deg"] == 0.0  # a bias has no relative error
    # a uniform error +-B: sigma B / sqrt(3), own P-quantile P B
    uniform = _requirements(
        [{"name": "u", "kind": "random", "distribution": "uniform", "bound_deg": [3e-3, 0, 0]}],
        APE={},
        MPE={"window_s": 1.0},
    )
    rows = budget_rows(uniform.model_copy(update={"confidence": p}))
    assert rows[0]["sigma_deg"] == pytest.approx(3e-3 / math.sqrt(3.0), rel=1e-15)
    assert rows[0]["worst_case_deg"] == pytest.approx(p * 3e-3, rel=1e-15)
    assert rows[3]["statistical_deg"] == 0.0  # a random error averages out of the mean
    # a random error's own mean is a constant: in the APE and the MPE, not in the RPE
    offset = {"name": "o", "kind": "random", "mean_deg": [1e-3, 0, 0], "sigma_deg": [2e-3, 0, 0]}
    rows = budget_rows(
        _requirements([offset], APE={}, MPE={"window_s": 1.0}, RPE={"window_s": 1.0})
    )
    n_p = gaussian_factor(0.9973)
    assert rows[0]["statistical_deg"] == pytest.approx(1e-3 + n_p * 2e-3, rel=1e-15)
    assert rows[3]["statistical_deg"] == pytest.approx(1e-3, rel=1e-15)
    assert rows[6]["statistical_deg"] == pytest.approx(n_p * 2e-3, rel=1e-15)


def test_knowledge_contributors_feed_only_the_knowledge_indices():
    star = {
        "name": "star tracker",
        "kind": "random",
        "knowledge": True,
        "sigma_deg": [1e-3, 1e-3, 5e-3],
    }
    rows = budget_rows(_requirements([star], APE={}, AKE={}, RKE={"window_s": 1.0}))
    by = {(r["index"], r["axis"]): r for r in rows}
    assert by["APE", "z"]["statistical_deg"] == 0.0
    factor = gaussian_factor(0.9973)  # the default confidence
    assert by["AKE", "z"]["statistical_deg"] == pytest.approx(factor * 5e-3, rel=1e-15)
    assert by["RKE", "x"]["statistical_deg"] == pytest.approx(factor * 1e-3, rel=1e-15)


def _history(t, value):
    return xr.Dataset({"pointing_error_deg": ("time", np.full(t.size, value))}, coords={"time": t})


def test_evaluate_a_campaign_gives_measured_and_budget_verdicts():
    # three stored cases with constant pointing errors 0.01, 0.02, 0.03 deg: the
    # ensemble's median (P = 0.5, order statistic ceil(1.5) = 2) is 0.02 deg at any
    # time; bound 0.025 passes it, the budget (a 0.01 deg Gaussian bias, 3 sigma
    # 0.03 deg) fails it
    t = np.arange(200) * 0.1
    cases = [_history(t, v) for v in (0.01, 0.02, 0.03)]
    req = PointingRequirements.model_validate(
        {
            "confidence": 0.5,
            "interpretation": "ensemble",
            "indices": {"APE": {"bound_deg": 0.025, "confidence": 0.5}},
            "contributors": [{"name": "b", "kind": "bias", "sigma_deg": [0.01, 0.01, 0.01]}],
        }
    )
    report = evaluate(cases, req)
    (row,) = report["measured"]
    assert (row["axis"], row["value_deg"], row["pass"]) == ("total", 0.02, True)
    assert [r["pass"] for r in report["budget"]] == [True] * 3  # n_0.5 = 0.674: 0.0067 deg
    strict = req.model_copy(update={"summation": "worst_case"})
    assert evaluate(cases, strict)["budget"][0]["worst_case_deg"] == pytest.approx(
        norm.ppf(0.75) * 0.01, rel=1e-12
    )
    text = to_csv(report["measured"] + report["budget"])
    assert len(list(csv.DictReader(io.StringIO(text)))) == 4


@pytest.mark.parametrize(
    ("body", "fragment"),
    [
        ("confidence = 1.0", "pointing.confidence: Input should be less than 1"),
        ("[pointing.indices.XPE]\nbound_deg = 1.0", "pointing: indices.XPE: unknown index"),
        ("[pointing.indices.RPE]\nbound_deg = 1.0", "indices.RPE.window_s: RPE needs a window"),
        ('[[pointing.contributors]]\nname = "m"\nkind = "periodic"', "period_s: a periodic"),
        (
            '[[pointing.contributors]]\nname = "m"\nkind = "random"\ndistribution = "fixed"',
            "distribution: a random contributor is gaussian or uniform",
        ),
    ],
)
def test_a_bad_requirement_file_names_the_field(tmp_path, body, fragment):
    path = tmp_path / "req.toml"
    path.write_text(f"[pointing]\n{body}\n")
    with pytest.raises(ConfigError, match=fragment.replace(".", r"\.")):
        load_requirements(path)


def test_a_window_longer_than_the_run_names_the_field():
    t = np.arange(100) * 0.1  # 10 s
    req = PointingRequirements.model_validate(
        {"indices": {"RPE": {"bound_deg": 1.0, "window_s": 60.0}}}
    )
    with pytest.raises(ConfigError, match=r"pointing\.indices\.RPE\.window_s: 60 s is longer"):
        evaluate([_history(t, 0.01)], req)
