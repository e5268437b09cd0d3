"""R1/R2 verdicts over the observation window, and the ECSS APE/RPE pointing figures."""

from __future__ import annotations

import numpy as np
import pytest
import xarray as xr
from pydantic import ValidationError

from flexsat.analysis import (
    Requirements,
    absolute_performance_error,
    error_rotation_vector,
    relative_performance_error,
    slew_metrics,
)
from flexsat.analysis.requirements import residual_rate_verdict, unjudged_reason
from flexsat.control.quaternion import quaternion_error, target_quaternion
from flexsat.errors import ConfigError
from flexsat.simulate import SlewScenario, load_slew, run_slew

RECORD_DT = 0.01  # [s] the slew's default record interval
TARGET = target_quaternion((45.0, 45.0, 45.0))


def _about_x(angle_deg: np.ndarray) -> np.ndarray:
    """Attitudes off the target by ``angle_deg`` about body x (q = q_d (x) q_x)."""
    half = np.radians(angle_deg) / 2.0
    q_x = np.column_stack([np.cos(half), np.sin(half), 0 * half, 0 * half])
    d0, dv = TARGET[0], TARGET[1:]
    w = d0 * q_x[:, 0] - q_x[:, 1:] @ dv
    v = d0 * q_x[:, 1:] + q_x[:, :1] * dv + np.cross(dv, q_x[:, 1:])
    return np.column_stack([w, v])


def synthetic_slew(pointing_deg, rate_deg_s, duration_s=120.0, **requirements) -> xr.Dataset:
    """A closed-loop dataset with the given error histories (a function of t each)."""
    t = np.round(np.arange(0.0, duration_s + 0.5 * RECORD_DT, RECORD_DT), 10)
    pointing, rate = pointing_deg(t), rate_deg_s(t)
    zeros3 = np.zeros((t.size, 3))
    scenario = SlewScenario.model_validate({"duration_s": duration_s, "requirements": requirements})
    return xr.Dataset(
        {
            "pointing_error_deg": ("time", pointing),
            "rate_error_deg_s": ("time", rate),
            "quaternion": (("time", "quat"), _about_x(pointing)),
            "lambda_act": ("time", np.full(t.size, 0.2)),
            "tau_applied": (("time", "axis"), zeros3 + 0.5),
            "tau_cmd": (("time", "axis"), zeros3 + 0.5),
            "tau_flex": (("time", "axis"), zeros3),
            "euler_deg": (("time", "euler"), zeros3 + 45.0),
            "tip_displacement": (("time", "appendage", "axis"), np.zeros((t.size, 2, 3))),
        },
        coords={"time": t},
        attrs={
            "scenario": scenario.model_dump_json(),
            "target_quaternion": TARGET.tolist(),
            "controller": "asmc",
            "wall_time_s": 0.0,
            "steps": round(duration_s / 1e-3),
            "status": "ok",
            "message": "",
        },
    )


def settles(t):
    """Decays from 45 deg, inside R1 (0.05 deg) from about 36 s, 2e-3 deg at the end."""
    return 45.0 * np.exp(-t / 5.0) + 2e-3


def quiet(t):
    return 1e-3 * np.exp(-(t - 40.0) / 5.0).clip(max=50.0) + 1e-5


def test_a_run_that_stays_in_the_bands_passes():
    metrics = slew_metrics(synthetic_slew(settles, quiet))
    assert metrics["r1_pass"] and metrics["r2_pass"]
    assert metrics["observation_window_s"] == [90.0, 120.0]  # default deadline to the end


def test_a_pointing_excursion_after_the_deadline_fails_r1():
    # Out of the R1 band for 0.5 s at 100 s, back at 2e-3 deg by the end: the last
    # sample alone would pass.
    def dips(t):
        return settles(t) + np.where((t >= 100.0) & (t < 100.5), 0.08, 0.0)

    metrics = slew_metrics(synthetic_slew(dips, quiet))
    assert metrics["final_pointing_error_deg"] < 0.05
    assert not metrics["r1_pass"] and metrics["r2_pass"]
    assert metrics["ape_deg"] == pytest.approx(0.08 + settles(100.0), rel=1e-12)  # the dip


def test_a_rate_excursion_after_the_deadline_fails_r2():
    def kicks(t):
        return quiet(t) + np.where((t >= 100.0) & (t < 100.2), 5e-3, 0.0)

    metrics = slew_metrics(synthetic_slew(settles, kicks))
    assert metrics["final_rate_error_deg_s"] < 1e-3
    assert metrics["r1_pass"] and not metrics["r2_pass"]
    assert metrics["max_rate_error_deg_s"] > 5e-3


def test_an_excursion_before_the_deadline_does_not_count():
    # The window starts at the deadline: a transient at 80 s is part of the slew.
    def late_transient(t):
        return settles(t) + np.where((t >= 80.0) & (t < 81.0), 0.3, 0.0)

    metrics = slew_metrics(synthetic_slew(late_transient, quiet))
    assert metrics["r1_pass"]
    assert metrics["settling_time_s"] == pytest.approx(81.0)


def test_the_window_comes_from_the_stored_requirements():
    ds = synthetic_slew(settles, quiet, settling_deadline_s=30.0, window_end_s=100.0)
    metrics = slew_metrics(ds)
    assert metrics["observation_window_s"] == [30.0, 100.0]
    assert not metrics["r1_pass"]  # at 30 s the error is still 45 e^-6 = 0.11 deg


def test_a_run_planned_to_end_before_the_deadline_is_not_judged():
    # 80 s planned, the window opens at 90 s: never observed, so neither pass nor fail
    metrics = slew_metrics(synthetic_slew(settles, quiet, duration_s=80.0))
    assert metrics["observation_window_s"] == [90.0, 80.0]
    assert metrics["r1_pass"] is None and metrics["r2_pass"] is None
    assert metrics["not_judged_reason"] == (
        "the run ends at 80 s, before the observation window starts at 90 s "
        "(requirements.settling_deadline_s)"
    )
    for key in ("ape_deg", "rpe_deg", "max_rate_error_deg_s"):
        assert np.isnan(metrics[key]), key
    assert metrics["r3_pass"] is True  # R3 is judged on every record of any run


def test_a_run_planned_to_end_before_its_stated_window_end_is_not_judged():
    # the window is 90-110 s, the run planned to 100 s: it never meant to observe it all
    metrics = slew_metrics(synthetic_slew(settles, quiet, duration_s=100.0, window_end_s=110.0))
    assert metrics["r1_pass"] is None and metrics["r2_pass"] is None
    assert "before the observation window ends at 110 s" in metrics["not_judged_reason"]
    assert np.isnan(metrics["ape_deg"])


def test_a_run_planned_to_cover_the_window_that_stops_early_fails():
    # Planned to 120 s, records to 100 s (a run stopped by a fault): judged, and failed,
    # although every record it has is inside both bands.
    ds = synthetic_slew(settles, quiet).sel(time=slice(0.0, 100.0))
    metrics = slew_metrics(ds)
    assert metrics["r1_pass"] is False and metrics["r2_pass"] is False
    assert metrics["not_judged_reason"] == ""
    # the APE is over the records it has: the largest, at 90 s (settles decreases);
    # the same float64 expression on the same record time, so round-off only
    assert metrics["ape_deg"] == pytest.approx(settles(90.0), rel=1e-12)


@pytest.mark.parametrize(
    ("duration_s", "fields", "judged"),
    [
        (90.0, {}, False),  # the window [90, 90] is empty
        (90.5, {}, True),
        (100.0, {"window_end_s": 110.0}, False),
        (110.0, {"window_end_s": 110.0}, True),
        (120.0, {"settling_deadline_s": 30.0, "window_end_s": 100.0}, True),
    ],
)
def test_unjudged_reason_says_whether_the_planned_run_covers_the_window(duration_s, fields, judged):
    reason = unjudged_reason(Requirements(**fields), duration_s)
    assert (reason == "") is judged


def test_explicit_bands_override_the_stored_ones():
    ds = synthetic_slew(settles, quiet)
    tight = Requirements(pointing_deg=1e-3)
    assert not slew_metrics(ds, requirements=tight)["r1_pass"]  # 2e-3 deg is outside 1e-3 deg
    assert slew_metrics(ds, requirements=Requirements(settling_deadline_s=10.0))[
        "observation_window_s"
    ] == [10.0, 120.0]


def test_ape_and_rpe_of_a_bias_plus_a_ripple():
    # e(t) = b + a sin(2 pi f t) on one axis, 1 Hz ripple, 1 s RPE windows holding
    # whole periods: the window mean is b, so RPE = a and APE = b + a. Sampled at
    # 10 ms, the samples hit the ripple's peak exactly (t = 0.25 s + k).
    b, a = 0.01, 0.002  # [deg]
    t = np.round(np.arange(60.0, 120.0, RECORD_DT), 10)
    error = np.zeros((t.size, 3))
    error[:, 0] = b + a * np.sin(2 * np.pi * t)
    assert absolute_performance_error(error) == pytest.approx(b + a, rel=1e-12)
    # Round-off only: the window mean of a sampled whole-period sine is b to 1e-15.
    assert relative_performance_error(t, error, 1.0) == pytest.approx(a, rel=1e-9)
    # A 0.5 s window holds one hump of the ripple: its mean is b + 2a/pi (or
    # b - 2a/pi), the hump's ends are farthest from it, RPE = 2a/pi. The sum over 50
    # samples is the trapezoidal rule of the hump (it vanishes at both ends):
    # relative error (pi/50)^2/12 = 3e-4, hence rel=1e-3.
    assert relative_performance_error(t, error, 0.5) == pytest.approx(2 * a / np.pi, rel=1e-3)


def test_rpe_is_the_window_by_window_definition():
    # Independent formulation: each window's records picked by a mask, its mean and
    # the records' distances from it, window after window. Uneven record times and
    # window lengths, a window holding a NaN (passed over); 1e-14 relative: the two
    # sum the same records in another order.
    rng = np.random.default_rng(11)
    for trial in range(60):
        n = int(rng.integers(1, 300))
        t = np.sort(rng.uniform(0.0, 30.0, n))
        error = rng.normal(size=(n, 3))
        if trial % 6 == 0:
            error[rng.integers(n)] = np.nan
        duration = rng.uniform(0.05, 40.0)
        index = np.floor((t - t[0]) / duration + 1e-6).astype(int)  # edge tolerance as in flexsat
        expected = 0.0
        for k in np.unique(index):
            inside = error[index == k]
            distance = np.linalg.norm(inside - inside.mean(axis=0), axis=1).max()
            expected = distance if distance > expected else expected
        if np.bincount(index).max() < 2:  # no window holds two records: not measured
            expected = np.nan
        assert relative_performance_error(t, error, duration) == pytest.approx(
            expected, rel=1e-14, abs=0.0, nan_ok=True
        )


def test_rpe_is_not_measured_when_every_window_holds_one_record():
    # Records 1 s apart and 1 s windows: each window's mean is its lone record, whose
    # distance from it is 0 whatever the error does. That is no stability measured:
    # NaN (reported as not measured), where 2 s windows see the 1 deg step.
    t = np.arange(0.0, 10.0, 1.0)
    error = np.zeros((t.size, 3))
    error[1::2, 0] = 1.0  # [deg]
    assert np.isnan(relative_performance_error(t, error, 1.0))
    assert relative_performance_error(t, error, 2.0) == pytest.approx(0.5, rel=1e-15)


def test_error_rotation_vector_is_the_error_quaternion_angle():
    rng = np.random.default_rng(7)
    q = rng.normal(size=(50, 4))
    q /= np.linalg.norm(q, axis=1, keepdims=True)
    vectors = error_rotation_vector(q, TARGET)
    for k in range(q.shape[0]):
        e = np.array(quaternion_error(tuple(TARGET), tuple(q[k])))
        angle = 2.0 * np.arcsin(min(np.linalg.norm(e[1:]), 1.0))
        # Same rotation both ways, to round-off.
        assert np.linalg.norm(vectors[k]) == pytest.approx(angle, abs=1e-12)
        np.testing.assert_allclose(vectors[k] * np.linalg.norm(e[1:]), angle * e[1:], atol=1e-12)
    assert np.all(error_rotation_vector(TARGET[None, :], TARGET) == 0.0)


@pytest.mark.parametrize(
    "fields",
    [
        {"settling_deadline_s": -1.0},
        {"settling_deadline_s": float("nan")},
        {"settling_deadline_s": 60.0, "window_end_s": 60.0},
        {"rpe_window_s": 0.0},
    ],
)
def test_bad_windows_are_refused(fields):
    with pytest.raises(ValidationError):
        Requirements.model_validate(fields)


def test_the_thesis_slew_meets_r1_and_r2_over_the_window(nominal_plant):
    # Section 5.1.3: R1 and R2 met. flexsat settles into R1 at 37 s and R2 at
    # 45.5 s, well before the 90 s deadline, and stays in to 120 s.
    metrics = slew_metrics(run_slew(nominal_plant).dataset)
    assert metrics["r1_pass"] and metrics["r2_pass"] and metrics["r3_pass"]
    assert metrics["observation_window_s"] == [90.0, 120.0]
    # The APE over the window bounds the final error and is far inside R1.
    assert metrics["final_pointing_error_deg"] <= metrics["ape_deg"] < 0.01
    assert 0.0 < metrics["rpe_deg"] <= 2.0 * metrics["ape_deg"]
    assert metrics["max_rate_error_deg_s"] < 1e-3


def test_the_window_is_set_in_the_slew_toml(tmp_path):
    path = tmp_path / "slew.toml"
    path.write_text("[requirements]\nsettling_deadline_s = 70.0\nrpe_window_s = 2.0\n")
    requirements = load_slew(path).requirements
    assert (requirements.settling_deadline_s, requirements.rpe_window_s) == (70.0, 2.0)
    path.write_text("[requirements]\nsettling_deadline_s = 100.0\nwindow_end_s = 80.0\n")
    with pytest.raises(ConfigError, match=r"requirements.*window_end_s must be > settling"):
        load_slew(path)


def test_a_law_without_lambda_has_no_switch_time():
    metrics = slew_metrics(synthetic_slew(settles, quiet).drop_vars("lambda_act"))
    assert np.isnan(metrics["lambda_switch_time_s"]) and metrics["r1_pass"]


# --- stability verdict from the residual-rate envelope, and R3 of a unit actuator ---

WINDOW = (90.0, 120.0)
BAND = 1e-3  # [deg/s] R2's jitter band
CYCLE_HZ = 2.45  # [Hz] the delayed ASMC loop's oscillation about Z (docs/guide/avionics.md)


def _rate(amplitude, t):
    """|A(t) sin(2 pi f t)|: a residual rate oscillating at CYCLE_HZ [deg/s]."""
    return np.abs(amplitude(t) * np.sin(2.0 * np.pi * CYCLE_HZ * t))


@pytest.mark.parametrize(
    ("amplitude", "verdict"),
    [
        (lambda t: 0.26 + 0 * t, "limit cycle"),  # constant above the band
        (lambda t: 0.26 * np.exp(-(t - 90.0) / 5.0), "stable"),  # halves every 3.5 s
        (lambda t: 0.26 * np.exp((t - 90.0) / 5.0), "diverges"),  # doubles every 3.5 s
        (lambda t: 5e-4 + 0 * t, "stable"),  # constant inside the band: a forced response
        (lambda t: 1e-9 * np.exp((t - 90.0) / 3.0), "stable"),  # grows to 2e-5, inside the band
    ],
    ids=["constant", "decaying", "growing", "inside the band", "growing inside the band"],
)
def test_the_residual_rate_envelope_classifies_the_loop(amplitude, verdict):
    # 10 ms records, the slew's. The envelope of each half of the 90-120 s window is
    # its peak: for the constant 0.26 deg/s oscillation, 0.26 to the sampling of the
    # sine's crest (2.45 Hz at 100 Hz: within 1 - cos(pi f dt) = 0.3 %).
    t = np.round(np.arange(0.0, 120.0 + 5e-3, RECORD_DT), 10)
    result = residual_rate_verdict(t, _rate(amplitude, t), WINDOW, BAND)
    assert result["verdict"] == verdict
    assert result["span_s"] == [90.0, 120.0]
    if verdict == "limit cycle":
        assert result["envelope_last_deg_s"] == pytest.approx(0.26, rel=3e-3)
        assert result["envelope_ratio"] == pytest.approx(1.0, abs=3e-3)


def test_the_envelope_ratio_is_the_halves_peak_ratio():
    # exp(-t/5) over halves of 15 s: the ratio of the halves' peaks (their first
    # records, 90 and 105 s) is exp(-3) = 0.0498, to the crest sampling (0.3 %).
    t = np.round(np.arange(0.0, 120.0 + 5e-3, RECORD_DT), 10)
    rate = 0.26 * np.exp(-(t - 90.0) / 5.0) * (1.0 + 0 * t)
    result = residual_rate_verdict(t, rate, WINDOW, BAND)
    assert result["envelope_first_deg_s"] == pytest.approx(0.26, rel=1e-12)
    assert result["envelope_ratio"] == pytest.approx(np.exp(-3.0), rel=1e-3)
    assert result["verdict"] == "stable"


def test_a_stopped_run_diverges_and_a_short_one_is_judged_on_its_last_quarter():
    t = np.round(np.arange(0.0, 40.0 + 5e-3, RECORD_DT), 10)
    rate = _rate(lambda s: 0.15 + 0 * s, t)
    # a run that stopped (non-finite state) diverges whatever its records show
    assert residual_rate_verdict(t, rate, WINDOW, BAND, stopped=True)["verdict"] == "diverges"
    # a 40 s run does not reach the 90-120 s window (nor does a window past its end,
    # as a shortened scenario gives, (90, 40)): its last quarter, 30-40 s, is judged
    for window in (WINDOW, (90.0, 40.0)):
        result = residual_rate_verdict(t, rate, window, BAND)
        assert result["span_s"] == [30.0, 40.0]
        assert result["verdict"] == "limit cycle"
        assert result["envelope_last_deg_s"] == pytest.approx(0.15, rel=3e-3)


def _wheel_slew(torque_ratio: float, applied_nm: float, saturated: bool = False):
    """A synthetic slew with a wheel cluster's records: the hub torque (motors plus the
    wheels' gyroscopic torque) at ``applied_nm`` on X, the motor torque asked of the
    fullest wheel at ``torque_ratio`` of its limit."""
    ds = synthetic_slew(settles, quiet)
    n = ds.sizes["time"]
    tau = np.zeros((n, 3))
    tau[n // 2, 0] = applied_nm
    return ds.assign(
        tau_applied=(("time", "axis"), tau),
        actuator_torque_ratio=("time", np.full(n, torque_ratio)),
        actuator_saturated=("time", np.where(np.arange(n) == n // 2, float(saturated), 0.0)),
    )


def test_r3_of_a_wheel_cluster_is_judged_on_what_each_wheel_is_asked():
    # 3.1 N m on the hub (the T_max = 2 N m rule's failure, measured on a wheel
    # cluster biased at 3000 rpm: tests/control/stages/test_wheels.py) with each motor asked
    # 99 % of its limit and no wheel at its momentum limit: R3 holds.
    metrics = slew_metrics(_wheel_slew(0.99, 3.1))
    assert metrics["r3_pass"] and metrics["max_abs_torque_nm"][0] == 3.1
    # a motor asked beyond its limit (clipped: the cluster does not deliver), or a
    # wheel at its momentum limit, fails it whatever the hub torque
    assert not slew_metrics(_wheel_slew(1.234, 1.7))["r3_pass"]
    assert not slew_metrics(_wheel_slew(0.5, 1.7, saturated=True))["r3_pass"]
    # an actuator without units keeps the hub-torque rule
    no_units = _wheel_slew(0.99, 3.1).drop_vars(["actuator_torque_ratio"])
    assert not slew_metrics(no_units)["r3_pass"]
