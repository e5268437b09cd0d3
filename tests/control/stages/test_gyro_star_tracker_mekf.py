"""Gyro and star tracker statistics, seeded noise, the MEKF's consistency on the
thesis slew, and bad stage configurations refused with one message (exit code 2)."""

from __future__ import annotations

import numpy as np
import pytest
from numba import njit

from flexsat.control.stages.gyro import GyroConfig, gyro_step
from flexsat.control.stages.star_tracker import StarTrackerConfig, star_tracker_step
from flexsat.simulate import SlewScenario, run_slew
from tests.cli.harness import flexsat

N_DOF = 6  # any: the stages read the hub's attitude and rate at fixed offsets of x
DEG_H = np.pi / 180.0 / 3600.0  # [rad/s per deg/h]


@njit(cache=True)
def _static_samples(step, params, state_size, n, every):
    """Call a sensor stage ``n`` times on a satellite at rest; the sample instants'
    measured rate and attitude and its records."""
    x = np.zeros(2 * N_DOF + 2)
    state, record = np.zeros(state_size), np.zeros(8)
    q, w = np.zeros(4), np.zeros(3)
    rates, quats = np.empty((n // every, 3)), np.empty((n // every, 4))
    records = np.empty((n // every, 8))
    for k in range(n):
        step[0](x, N_DOF, k * 0.01, params, state, q, w, record)
        if k % every == 0:
            rates[k // every], quats[k // every], records[k // every] = w, q, record
    return rates, quats, records


def _scenario(**fields) -> SlewScenario:
    return SlewScenario.model_validate(
        {"duration_s": 3600.0, "dt_s": 0.01, "control_dt_s": 0.01, "record_dt_s": 1.0, **fields}
    )


def _gyro(config: GyroConfig, seconds: float = 3600.0) -> np.ndarray:
    params = config.packed(_scenario())
    return _static_samples((gyro_step,), params, 14, round(seconds / 0.01), 1)[0]


def _allan_deviation(rate: np.ndarray, fs: float, m: int) -> np.ndarray:
    """Overlapping Allan deviation at tau = m / fs of a rate series (IEEE Std 952)."""
    theta = np.cumsum(rate, axis=0) / fs
    d = theta[2 * m :] - 2.0 * theta[m:-m] + theta[: -2 * m]
    return np.sqrt((d**2).mean(axis=0) / 2.0) / (m / fs)


def test_allan_deviation_recovers_arw_and_bias_instability():
    # A MEMS-grade gyro: B = 10 deg/h with T_c = 10 s, N = 0.0833 deg/sqrt(h)
    # (0.5 B sqrt(s)); one hour at 100 Hz, at rest.
    B, N = 10.0, 0.5 * 10.0 / 60.0
    rate = _gyro(GyroConfig(sample_dt_s=0.01, arw_deg_rt_h=N, bias_instability_deg_h=B,
                            bias_correlation_s=10.0, seed=11))  # fmt: skip
    # ARW: sigma(tau) sqrt(tau) at tau = 0.1 s, where the bias adds 0.3 % in quadrature.
    arw = _allan_deviation(rate, 100.0, 10) * np.sqrt(0.1)
    np.testing.assert_allclose(arw, N * np.pi / 180.0 / 60.0, rtol=0.10)
    # B: the bias plateau of the Allan deviation is 0.664 B (IEEE Std 952), with the
    # shape g of a Gauss-Markov bias of the configured T_c; B fitted by least squares
    # to the Allan variance over tau = 5..60 s (the plateau's top at 1.89 T_c = 19 s)
    # once the fitted ARW is removed, the three axes pooled: one number from the
    # whole plateau rather than its noisy maximum (one hour holds ~190 independent
    # 19 s intervals per axis).
    m = np.unique(np.geomspace(500, 6000, 12).astype(int))
    tau = m / 100.0
    avar = np.array([_allan_deviation(rate, 100.0, k) for k in m]) ** 2 - arw**2 / tau[:, None]
    x = tau / 10.0
    g = (2.0 * (x - 1.0 + np.exp(-x)) - (1.0 - np.exp(-x)) ** 2) / x**2 * (0.664 / 0.6174) ** 2
    B_fit = np.sqrt((avar * g[:, None]).sum() / (3.0 * (g**2).sum()))
    assert B_fit == pytest.approx(B * DEG_H, rel=0.10)


def test_same_seed_gives_identical_noise_and_another_seed_other_noise():
    config = GyroConfig(arw_deg_rt_h=0.1, bias_instability_deg_h=1.0, seed=5)
    a, b = _gyro(config, 10.0), _gyro(config, 10.0)
    np.testing.assert_array_equal(a, b)
    c = _gyro(config.model_copy(update={"seed": 6}), 10.0)
    assert np.abs(np.corrcoef(a[:, 0], c[:, 0])[0, 1]) < 0.05  # 1000 samples: 1.6 sigma


def test_star_tracker_noise_has_the_configured_std_per_axis():
    config = StarTrackerConfig(sample_dt_s=0.1, noise_arcsec=(5.0, 5.0, 30.0), seed=3)
    params = config.packed(_scenario())
    n = 200_000  # control instants: 20 000 samples
    _, quats, records = _static_samples((star_tracker_step,), params, 11, n, 10)
    # The measured attitude of a satellite at rest (identity) is the noise itself:
    # 2 vec(q) = dtheta / |[1, dtheta / 2]|, equal to (dtheta / 2)^2 < 1e-7 relative.
    error = 2.0 * quats[:, 1:4] * np.sign(quats[:, :1])
    np.testing.assert_allclose(error, records[:, :3], rtol=1e-7)
    sigma = np.array(config.noise_arcsec) * np.pi / 180.0 / 3600.0
    # 20 000 samples: the sample std scatters by 1 / sqrt(2 n) = 0.5 %; 3 %.
    np.testing.assert_allclose(error.std(axis=0), sigma, rtol=0.03)
    assert np.all(np.abs(error.mean(axis=0)) < 4.0 * sigma / np.sqrt(error.shape[0]))


def test_mekf_attitude_error_is_consistent_with_its_covariance(nominal_plant):
    # The thesis's 45/45/45 ASMC slew flown on the MEKF's estimate: gyro at 100 Hz
    # with a turn-on bias, star tracker at 10 Hz (5, 5, 30 arcsec).
    scenario = SlewScenario.model_validate({"sensor_stages": [
        {"kind": "gyro", "bias_deg_h": [0.05, -0.03, 0.02]}, {"kind": "star_tracker"},
        {"kind": "mekf", "initial_bias_std_deg_h": 0.05},
    ]})  # fmt: skip
    ds = run_slew(nominal_plant, scenario).dataset
    assert ds.attrs["status"] == "ok"
    nees = ds["estimation_nees"].values
    # A consistent filter's attitude NEES is chi-square with 3 degrees of freedom: 95 %
    # of the records inside its two-sided 95 % interval [0.216, 9.348]. The records
    # are correlated over the 1200 star-tracker updates (binomial scatter 0.6 %):
    # at least 93 %. Mean within [2, 4]: a covariance 1.5 times off either way fails.
    # Measured: 95.9 %, mean 2.3 (the random-walk model of the Gauss-Markov bias is
    # slightly conservative).
    inside = (nees > 0.2158) & (nees < 9.348)
    assert inside.mean() >= 0.93
    assert 2.0 <= nees.mean() <= 4.0


def test_mekf_records_its_bias_estimate_inside_its_3_sigma(nominal_plant):
    # The bias's sqrt(diag P) starts at initial_bias_std_deg_h (0.05 deg/h; the record
    # at t = 0 precedes the filter's first step and is zero) and grows by the bias's
    # random walk between updates (measured +1.2e-4 relative over the first 10 ms:
    # bound 1e-3). The estimate's error against the gyro's true bias stays inside
    # +-3 sigma at every record after the first (measured: all of them; a consistent
    # filter leaves 0.3 % of independent records outside, and these are correlated).
    scenario = SlewScenario.model_validate({"duration_s": 30.0, "sensor_stages": [
        {"kind": "gyro", "bias_deg_h": [0.05, -0.03, 0.02]}, {"kind": "star_tracker"},
        {"kind": "mekf", "initial_bias_std_deg_h": 0.05},
    ]})  # fmt: skip
    ds = run_slew(nominal_plant, scenario).dataset
    sigma = ds["estimated_gyro_bias_sigma"]
    assert sigma.attrs["units"] == "rad/s" and sigma.dims == ("time", "axis")
    sigma = sigma.values[1:] / DEG_H
    np.testing.assert_allclose(sigma[0], 0.05, rtol=1e-3)
    error = (ds["estimated_gyro_bias"].values - ds["gyro_bias"].values)[1:] / DEG_H
    assert np.all(np.abs(error) <= 3.0 * sigma)


BAD = [
    (
        "wheel axes",
        '[actuator]\nkind = "wheels"\naxes = [[1, 0, 0], [0, 1, 0], [1, 1, 0]]\n',
        "actuator: axes: the spin axes must span 3D",
    ),
    (
        "negative noise",
        '[[sensor_stages]]\nkind = "gyro"\narw_deg_rt_h = -0.1\n',
        "sensor_stages[0].arw_deg_rt_h: Input should be greater than or equal to 0",
    ),
    (
        "negative star tracker noise",
        '[[sensor_stages]]\nkind = "star_tracker"\nnoise_arcsec = [5, -5, 30]\n',
        "sensor_stages[0].noise_arcsec[1]: Input should be greater than or equal to 0",
    ),
    (
        "delay longer than the run",
        'duration_s = 1.0\ncontrol_dt_s = 0.01\n[[actuator_stages]]\nkind = "delay"\n'
        "periods = 200\n",
        "actuator_stages[0].periods: a delay of 200 control periods",
    ),
    (
        "gyro rate not a multiple",
        '[[sensor_stages]]\nkind = "gyro"\nsample_dt_s = 0.0025\n',
        "sensor_stages[0].sample_dt_s must be a whole multiple of control_dt_s",
    ),
    (
        "limitless final actuator",
        '[actuator]\nkind = "delay"\n',
        "can only be one of the actuator_stages",
    ),
]


@pytest.mark.parametrize(("body", "fragment"), [b[1:] for b in BAD], ids=[b[0] for b in BAD])
def test_a_bad_stage_config_gives_one_message_naming_the_field(body, fragment, tmp_path, capsys):
    path = tmp_path / "s.toml"
    path.write_text(body)
    outcome = flexsat(["slew", "--scenario", str(path), "--out", str(tmp_path / "o")], capsys)
    assert outcome.code == 2, outcome.stderr
    assert fragment in outcome.stderr, outcome.stderr
    assert "Traceback" not in outcome.stderr


def test_the_avionics_template_is_a_valid_slew_scenario():
    from importlib import resources

    from flexsat.simulate.scenario import load_slew

    path = resources.files("flexsat.config") / "presets" / "avionics-slew.toml"
    scenario = load_slew(str(path))
    assert [s.kind for _, s in scenario.stage_chain()] == [
        "ideal", "gyro", "star_tracker", "mekf", "wheels"]  # fmt: skip
