"""Pointing indices and their statistical interpretations against closed forms.

Synthetic signals with known answers: a bias, a sinusoid, white noise and a random
walk. Tolerances are stated next to each assertion. Random signals use a fixed seed,
printed; their statistics are checked against the order-statistic confidence
interval the module itself computes (99.9 %: a closed form outside it would be a
one-in-a-thousand draw for a correct estimator, or a wrong estimator).
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.spatial.transform import Rotation
from scipy.stats import norm

from flexsat.analysis.pointing import (
    axis_errors,
    index_samples,
    interpret,
    knowledge_error,
    line_of_sight_error,
    order_statistic,
    uniform_record,
)
from flexsat.errors import ConfigError

SEED = 20261207
DT = 1e-3  # [s]
A = 2.0  # sinusoid amplitude [u]
T = 1.0  # sinusoid period [s]
GAMMA = 0.999  # confidence of the intervals the random statistics are checked against


def _z(p: float) -> float:
    """P-quantile of |N(0, 1)|."""
    return float(norm.ppf(0.5 * (1.0 + p)))


@pytest.fixture(scope="module")
def sinusoid():
    t = np.arange(10_000) * DT  # ten whole periods
    return t, A * np.sin(2.0 * np.pi * t / T)


def test_a_bias_is_all_absolute_and_mean_error_and_no_relative_one():
    t = np.arange(5000) * DT
    e = np.tile([0.01, -0.02, 0.0], (t.size, 1))
    # cumulative sums over 5000 records: round-off ~ n eps |e| ~ 2e-14, hence 1e-12
    for axis, expected in (("x", 0.01), ("y", 0.02), ("total", math.hypot(0.01, 0.02))):
        signal = axis_errors(e)[axis]
        assert index_samples(t, signal, "APE")[1].max() == pytest.approx(expected, rel=1e-12)
        means = index_samples(t, signal, "MPE", 0.5)[1]
        np.testing.assert_allclose(means, expected, rtol=1e-12)
        for index, sep in (("RPE", None), ("PDE", 1.0), ("PRE", 2.0)):
            assert index_samples(t, signal, index, 0.5, sep)[1].max() < 1e-12 * expected


def test_sinusoid_worst_cases_match_the_sinc_forms(sinusoid):
    t, e = sinusoid
    # The moving mean of a sampled sinusoid is the Dirichlet kernel, not sinc: their
    # ratio differs by (pi dt / T)^2 / 6 = 1.6e-6, and the worst window on the record
    # grid misses the peak by at most dt / 2: 1 - cos(pi dt / T) = 4.9e-6; hence 1e-5.
    assert index_samples(t, e, "APE")[1].max() == pytest.approx(A, rel=1e-12)
    assert index_samples(t, e, "MPE", 0.5)[1].max() == pytest.approx(2 * A / np.pi, rel=1e-5)
    # RPE: an even window (500 records) has its centre record dt / 2 off the window's
    # middle, which adds D (pi dt / T)^2 / (2 (1 - D)) = 8.6e-6 of A (D = 2 / pi): 1e-5 A
    assert index_samples(t, e, "RPE", 0.5)[1].max() == pytest.approx(
        A * (1 - 2 / np.pi), abs=1e-5 * A
    )
    assert index_samples(t, e, "PDE", 0.5, 0.5)[1].max() == pytest.approx(4 * A / np.pi, rel=1e-5)
    # a window of one period averages the sinusoid out: MPE 0 and RPE the signal itself
    assert index_samples(t, e, "MPE", 1.0)[1].max() < 1e-12 * A
    assert index_samples(t, e, "RPE", 1.0)[1].max() == pytest.approx(A, rel=1e-12)
    # windows one period apart see the same mean: PRE 0 (round-off of the sums only)
    assert index_samples(t, e, "PRE", 0.5, 1.0)[1].max() < 1e-12 * A


@pytest.mark.parametrize("p", [0.5, 0.95, 0.9973])
def test_sinusoid_temporal_quantile_is_the_arcsine_one(sinusoid, p):
    # |A sin| over whole periods: P(|e| <= q) = (2 / pi) asin(q / A), q_P = A sin(pi P / 2).
    # A sample of a uniform phase grid is off by at most the signal's change over one
    # record, 2 pi A dt / T.
    t, e = sinusoid
    tolerance = 2 * np.pi * A * DT / T
    stat = interpret([index_samples(t, e, "APE")], "temporal", p)
    assert stat.value == pytest.approx(A * np.sin(np.pi * p / 2), abs=tolerance)
    # RPE over one-period windows is the signal again: the same quantile
    rpe = interpret([index_samples(t, e, "RPE", 1.0)], "temporal", p)
    assert rpe.value == pytest.approx(A * np.sin(np.pi * p / 2), abs=tolerance)
    # mixed over copies of one run is the temporal value of that run, exactly
    runs = [index_samples(t, e, "APE")] * 3
    assert interpret(runs, "mixed", p).value == stat.value


@pytest.mark.parametrize("p", [0.95, 0.9973])
def test_white_noise_absolute_error_quantile(p):
    rng = np.random.default_rng(SEED)
    print(f"seed {SEED}")
    sigma, n = 3e-3, 400_000
    t = np.arange(n) * DT
    e = rng.normal(0.0, sigma, n)
    stat = interpret([index_samples(t, e, "APE")], "temporal", p, interval=GAMMA)
    expected = sigma * _z(p)
    assert stat.low <= expected <= stat.high, (stat, expected)
    # its width is the asymptotic one, 2 z_gamma sqrt(P (1 - P) / n) / f(q_P), with
    # f = 2 phi(q / sigma) / sigma the density of |e|; within 15 % (the ranks are whole
    # numbers and the density varies across the interval)
    density = 2.0 * norm.pdf(_z(p)) / sigma
    width = 2.0 * norm.ppf(0.5 * (1 + GAMMA)) * math.sqrt(p * (1 - p) / n) / density
    assert stat.high - stat.low == pytest.approx(width, rel=0.15)


def _one_window_runs(rng, make, runs: int, records: int, sigma: float):
    """Runs exactly one window (and its separation) long: one sample each, independent."""
    t = np.arange(records) * DT
    return t, [make(rng.normal(0.0, sigma, records)) for _ in range(runs)]


@pytest.mark.parametrize("p", [0.95, 0.9973])
def test_white_noise_window_indices_over_an_ensemble(p):
    # One window per run, 20000 runs: the ensemble's samples are independent, so
    # the order-statistic interval is exact. With n = 10 records a window:
    # MPE ~ |N(0, sigma^2 / n)|, RPE ~ |N(0, sigma^2 (1 - 1/n))| (the centre record is
    # in its window), PDE over disjoint windows ~ |N(0, 2 sigma^2 / n)|.
    rng = np.random.default_rng(SEED)
    print(f"seed {SEED}")
    sigma, n, runs = 1.0, 10, 20_000
    window = n * DT
    cases = {
        "MPE": (n, None, sigma / math.sqrt(n)),
        "RPE": (n, None, sigma * math.sqrt(1 - 1 / n)),
        "PDE": (2 * n, window, sigma * math.sqrt(2 / n)),
    }
    for index, (records, sep, scale) in cases.items():
        t, signals = _one_window_runs(rng, lambda x: x, runs, records, sigma)
        samples = [index_samples(t, x, index, window, sep) for x in signals]
        assert all(s[1].size == 1 for s in samples)
        stat = interpret(samples, "ensemble", p, interval=GAMMA)
        expected = scale * _z(p)
        assert stat.low <= expected <= stat.high, (index, stat, expected)


def _walk_sigma(index: str, n: int, s: int) -> float:
    """Standard deviation of an index of a unit random walk e_k = w_0 + ... + w_k,
    from the weight each increment w_j carries (variance = sum of squared weights)."""
    weights = []
    for j in range(n + s):
        first = sum(1 for i in range(n) if i >= j) / n  # increments in window 1's mean
        if index == "MPE":
            weights.append(first)
        elif index == "RPE":
            weights.append((1.0 if n // 2 >= j else 0.0) - first)
        else:  # PDE: the window s records later minus the first
            weights.append(sum(1 for i in range(s, s + n) if i >= j) / n - first)
    return math.sqrt(sum(w * w for w in weights))


@pytest.mark.parametrize("index", ["MPE", "RPE", "PDE"])
def test_random_walk_indices_over_an_ensemble(index):
    rng = np.random.default_rng(SEED + 1)
    print(f"seed {SEED + 1}")
    n, s, runs, p = 20, 30, 20_000, 0.95
    records = n + (s if index == "PDE" else 0)
    sep = s * DT if index == "PDE" else None
    t = np.arange(records) * DT
    samples = [
        index_samples(t, np.cumsum(rng.normal(0.0, 1.0, records)), index, n * DT, sep)
        for _ in range(runs)
    ]
    stat = interpret(samples, "ensemble", p, interval=GAMMA)
    expected = _walk_sigma(index, n, s if index == "PDE" else 0) * _z(p)
    assert stat.low <= expected <= stat.high, (stat, expected)


def test_random_biases_across_an_ensemble():
    # each run a constant bias b_j ~ N(0, sigma): the ensemble's P-quantile at any
    # time is that of |b| (sigma z_P); the temporal one, the worst run's |b_j| exactly;
    # the mixed one pools copies of each |b_j|: the same order statistic as the ensemble's
    rng = np.random.default_rng(SEED + 2)
    print(f"seed {SEED + 2}")
    sigma, runs, p = 1e-2, 4000, 0.95
    biases = rng.normal(0.0, sigma, runs)
    t = np.arange(50) * DT
    samples = [index_samples(t, np.full(t.size, b), "APE") for b in biases]
    ensemble = interpret(samples, "ensemble", p, interval=GAMMA)
    assert ensemble.low <= sigma * _z(p) <= ensemble.high
    temporal = interpret(samples, "temporal", p)
    assert temporal.value == np.abs(biases).max()
    assert temporal.where == float(np.argmax(np.abs(biases)))
    assert interpret(samples, "mixed", p).value == ensemble.value


def test_order_statistic_interval_is_binomial():
    # 100 samples 1..100, P = 0.5, gamma = 0.95: B(100, 0.5)'s 2.5 % and 97.5 %
    # quantiles are 40 and 60, so the interval is [x_(40), x_(61)]; estimate x_(50)
    stat = order_statistic(np.arange(1.0, 101.0), 0.5, 0.95)
    assert (stat.value, stat.low, stat.high) == (50.0, 40.0, 61.0)
    # P = 0.99 from 100 samples: the upper end lies beyond the sample
    assert order_statistic(np.arange(1.0, 101.0), 0.99, 0.95).high == np.inf


def test_line_of_sight_error_is_the_boresight_angle():
    b = [0.0, 0.0, 1.0]
    theta = 0.3  # [rad], no small-angle approximation is made
    about_z = line_of_sight_error(np.array([[0.0, 0.0, theta]]), b)
    assert np.linalg.norm(about_z) == 0.0  # a roll about the boresight moves it not
    for alpha in (0.0, 0.7, 2.0):
        rotation = theta * np.array([[np.cos(alpha), np.sin(alpha), 0.0]])
        assert np.linalg.norm(line_of_sight_error(rotation, b)) == pytest.approx(theta, rel=1e-14)
    # about k = (1, 0, 1)/sqrt(2): cos(angle) = cos(theta) + (1 - cos(theta)) (k . b)^2
    k = np.array([1.0, 0.0, 1.0]) / math.sqrt(2.0)
    expected = math.acos(math.cos(theta) + (1 - math.cos(theta)) / 2)
    los = line_of_sight_error(theta * k[None, :], b)
    assert np.linalg.norm(los) == pytest.approx(expected, rel=1e-12)
    moved = Rotation.from_rotvec(theta * k).apply(b)
    assert np.linalg.norm(los) == pytest.approx(math.acos(moved[2]), rel=1e-12)


def test_knowledge_indices_are_the_performance_ones_on_the_estimation_error():
    import xarray as xr

    rng = np.random.default_rng(SEED + 3)
    print(f"seed {SEED + 3}")
    t = np.arange(2000) * DT
    error = rng.normal(0.0, 1e-5, (t.size, 3))
    ds = xr.Dataset({"estimation_error": (("time", "axis"), error)}, coords={"time": t})
    known = knowledge_error(ds)
    for ape, ake in (("APE", "AKE"), ("RPE", "RKE"), ("MPE", "MKE")):
        np.testing.assert_array_equal(
            index_samples(t, known, ape, 0.1)[1], index_samples(t, known, ake, 0.1)[1]
        )
    assert knowledge_error(xr.Dataset(coords={"time": t})) is None


def test_an_uneven_record_is_resampled():
    t = np.array([0.0, 0.1, 0.25, 0.3, 0.4])
    dt, grid, e = uniform_record(t, 2.0 * t)
    assert dt == pytest.approx(0.1)
    np.testing.assert_allclose(e, 2.0 * grid, rtol=1e-12)  # a line is interpolated exactly


def test_bad_windows_and_names_are_refused_naming_the_field():
    t = np.arange(100) * DT  # 0.1 s
    e = np.zeros(t.size)
    with pytest.raises(ConfigError, match=r"RPE.window_s: 0.5 s is longer than the record"):
        index_samples(t, e, "RPE", 0.5)
    with pytest.raises(ConfigError, match=r"PDE.stability_s: 0.08 s is longer"):
        index_samples(t, e, "PDE", 0.05, 0.08)
    with pytest.raises(ConfigError, match=r"MPE.window_s: 0.0004 s is shorter than the record's"):
        index_samples(t, e, "MPE", 0.0004)  # 0.4 records of 1 ms
    with pytest.raises(ConfigError, match="index: unknown index 'XPE'"):
        index_samples(t, e, "XPE", 0.05)
    with pytest.raises(ConfigError, match=r"confidence: must be in \(0, 1\]"):
        interpret([index_samples(t, e, "APE")], "temporal", 1.5)
    with pytest.raises(ConfigError, match="interpretation: 'ensemble' needs a campaign"):
        interpret([index_samples(t, e, "APE")], "ensemble", 0.9)
