"""Microvibration jitter: the frequency-domain path against time-domain runs of the same
wheels, a resonance the speed sweep finds, the PSD, the window and the SADM stepper."""

from __future__ import annotations

import numpy as np
import pytest

from flexsat.analysis.pointing import error_rotation, index_samples, line_of_sight_error
from flexsat.control.laws.pd import PDConfig
from flexsat.control.stages.wheels import WheelsConfig
from flexsat.dynamics.plant import Plant
from flexsat.errors import ConfigError
from flexsat.linear.jitter import (
    Lines,
    StepperConfig,
    closed_loop,
    jitter_psd,
    jitter_rms,
    line_response,
    los_rows,
    speed_sweep,
    stepper_lines,
    wheel_lines,
    window_gain,
)
from flexsat.simulate import SlewScenario, run_slew
from tests.conftest import config_from, variant

SEED = 7
QUIET = {"environment_nm": [0, 0, 0], "sloshing_ratio": 0.0, "residual_nm": [0, 0, 0]}
POSITIONS = [[0.5, 0.5, 0.2], [-0.5, 0.5, 0.2], [-0.5, -0.5, 0.2], [0.5, -0.5, 0.2]]
# wheel 1 alone vibrates: the other wheels' speeds drift apart by ~0.5 rpm under the
# law's torque, and lines of nearly equal frequency would beat over the record
VIBRATION = {
    "static_imbalance_kg_m": 2e-5, "dynamic_imbalance_kg_m2": 2e-5,
    "radial_force": [{"number": 2.0, "coefficient": 5e-6}],
    "axial_force": [{"number": 1.0, "coefficient": 1e-5}],
    "positions_m": POSITIONS, "seed": SEED, "wheels": [1],
}  # fmt: skip
FRICTIONLESS = {"kind": "wheels", "viscous_nm_s_rad": 0.0, "coulomb_nm": 0.0}


def _run(plant, wheels: dict, duration_s: float):
    print(f"microvibration phase seed {wheels['microvibration']['seed']}")
    scenario = SlewScenario.model_validate({
        "duration_s": duration_s, "target_euler_deg": [0, 0, 0], "record_dt_s": 1e-3,
        "controller": {"kind": "pd"}, "actuator": wheels, "disturbances": QUIET,
    })  # fmt: skip
    ds = run_slew(plant, scenario).dataset
    model = closed_loop(
        plant, PDConfig(), ds["wheel_momentum_B"].values.mean(axis=0),
        actuator_time_constant_s=scenario.actuator.motor_time_constant_s,
    )  # fmt: skip
    return ds, scenario.actuator, model


def test_time_and_frequency_domain_rms_jitter_agree(plant):
    # Wheel 1 of the pyramid at 2000 rpm: imbalances (33.3 Hz), a second radial
    # harmonic (66.7 Hz) and an axial one, on the nominal satellite under the PD law.
    wheels = {**FRICTIONLESS, "initial_speed_rpm": 2000.0, "microvibration": VIBRATION}
    ds, config, model = _run(plant, wheels, duration_s=10.0)
    t, theta = ds["time"].values, error_rotation(ds)
    window_s = 0.3
    predicted = jitter_rms(model, wheel_lines(config, 2000.0), window_s=window_s)
    for axis in range(3):
        times, rpe = index_samples(t, theta[:, axis], "RPE", window_s)
        measured = np.sqrt(np.mean(rpe[times >= 3.0] ** 2))
        # The start of the disturbance excites the rigid loop and the 0.26-1.2 Hz panel
        # modes (0.5 % damping: they ring through the run); the RPE's window keeps
        # 1 - sinc(f 0.3 s) < 4 % of them, and the 7 s kept are 233 periods of the
        # first line. The wheel's speed drifts by < 0.5 rpm under the law's torque and
        # the law acts through the sampled loop (the model takes it continuous).
        # Measured within 1.1 %; acceptance 5 %.
        assert measured == pytest.approx(predicted[axis], rel=0.05)
        assert predicted[axis] > 5e-8  # a jitter, not round-off


def test_a_wheel_speed_on_a_flexible_mode_shows_the_predicted_resonance():
    # Panels stiffened and damped (5 Hz flapping, 2 %): the ringing of the start dies
    # within the run (time constant 1 / (zeta omega) < 1.6 s).
    plant = Plant.from_config(config_from(variant(
        damping_ratio=0.02,
        target_frequencies_hz={"flapping": 5.0, "in_plane": 8.0, "torsion": 12.0,
                               "translation_x": 50.0, "translation_y": 50.0,
                               "translation_z": 50.0},
    )))  # fmt: skip
    vibration = {"dynamic_imbalance_kg_m2": 1e-4, "wheels": [1], "seed": SEED}
    wheels = {**FRICTIONLESS, "microvibration": vibration}
    sweep = speed_sweep(
        closed_loop(plant, PDConfig(), actuator_time_constant_s=0.01),
        WheelsConfig.model_validate(wheels), np.linspace(60.0, 1200.0, 200),
    )  # fmt: skip
    rpm = float(sweep.worst_rpm[0])
    mode_hz = sweep.modes_hz[np.argmin(np.abs(sweep.modes_hz - rpm / 60.0))]
    # the worst speed puts the imbalance (h = 1) on a flexible mode: the peak of a
    # 2 %-damped resonance lies within zeta^2 of its natural frequency
    assert rpm / 60.0 == pytest.approx(mode_hz, rel=0.01)
    assert sweep.worst_rms[0] > 3.0 * np.median(sweep.total)  # a peak, not the floor

    ds, config, model = _run(plant, {**wheels, "initial_speed_rpm": rpm}, duration_s=12.0)
    freqs, Y = line_response(model, wheel_lines(config, rpm))
    t, theta = ds["time"].values, error_rotation(ds)
    keep = t >= 7.0  # past 4 time constants of the ringing
    x = theta[keep] - theta[keep].mean(axis=0)
    hann = np.hanning(x.shape[0])
    n_fft = 16 * x.shape[0]
    spectrum = np.fft.rfft(x * hann[:, None], n=n_fft, axis=0) * 2.0 / hann.sum()
    f = np.fft.rfftfreq(n_fft, 1e-3)
    peak = np.argmax(np.where(f > 2.0, np.linalg.norm(spectrum, axis=1), 0.0))
    # frequency: the Hann spectrum over 5 s, zero-padded 16 times, resolves 0.0125 Hz
    # (0.06 % of the line); acceptance 1 %. Measured 0.03 %.
    assert f[peak] == pytest.approx(freqs[0], rel=0.01)
    # amplitude: the Hann window's scalloping is below 0.1 % at this padding and the
    # residual ringing e^-4.4 ~ 1 %; acceptance 10 %. Measured within 0.7 %.
    np.testing.assert_allclose(np.abs(spectrum[peak]), np.abs(Y[0]), rtol=0.10)


def test_the_psd_integrates_to_the_mean_square_and_drops_lines_off_the_grid(plant):
    model = closed_loop(plant, PDConfig())
    config = WheelsConfig.model_validate({**FRICTIONLESS, "microvibration": VIBRATION})
    lines = wheel_lines(config, 3000.0)  # 50 Hz and 100 Hz lines
    f = np.arange(0.0, 200.0, 0.25)
    psd = jitter_psd(model, lines, f)
    # each line's power lands whole in one bin: exact up to round-off
    np.testing.assert_allclose(np.sqrt(psd.sum(axis=0) * 0.25), jitter_rms(model, lines),
                               rtol=1e-12)  # fmt: skip
    low = jitter_psd(model, lines, np.arange(0.0, 75.0, 0.25))
    below = lines.frequency_hz < 75.0
    first = jitter_rms(model, Lines(lines.frequency_hz[below], lines.amplitude[below], ()))
    np.testing.assert_allclose(np.sqrt(low.sum(axis=0) * 0.25), first, rtol=1e-12)
    with pytest.raises(ConfigError, match="frequency_hz"):
        jitter_psd(model, lines, np.array([0.0, 1.0, 3.0]))


def test_window_gain_is_the_rpe_of_a_sinusoid():
    # The RPE of A sin(2 pi f t) over a window of n records: its RMS is
    # A / sqrt(2) |1 - sinc(f n dt)| up to the discrete mean (records, not an integral).
    dt, f, A = 1e-3, 7.3, 2.0
    t = np.arange(0.0, 20.0, dt)
    for window_s in (0.051, 0.301, 1.001):  # odd record counts: centred windows
        _, rpe = index_samples(t, A * np.sin(2 * np.pi * f * t), "RPE", window_s)
        expected = A / np.sqrt(2.0) * window_gain(np.array([f]), window_s)[0]
        # the discrete window mean differs from sinc by O((f dt)^2) = 5e-5 relative,
        # the record's finite length by one window of partial periods: 2e-3
        assert np.sqrt(np.mean(rpe**2)) == pytest.approx(expected, rel=2e-3)
    assert window_gain(np.array([3.0]), None)[0] == 1.0
    with pytest.raises(ConfigError, match="window_s"):
        window_gain(np.array([1.0]), -0.5)


def test_line_of_sight_rows_are_the_small_angle_line_of_sight_error():
    rng = np.random.default_rng(SEED)
    print(f"seed {SEED}")
    boresight = [0.3, -0.2, 0.9]
    theta = rng.normal(scale=1e-6, size=(20, 3))
    # exact angle against its small-angle form: they differ at O(theta^2) = 1e-12 rad
    np.testing.assert_allclose(theta @ los_rows(boresight).T,
                               line_of_sight_error(theta, boresight), atol=1e-11)  # fmt: skip
    with pytest.raises(ConfigError, match="boresight"):
        los_rows([0.0, 0.0, 0.0])


def test_wheel_lines_and_speed_sweep_refuse_bad_input(plant):
    model = closed_loop(plant, PDConfig())
    config = WheelsConfig.model_validate({**FRICTIONLESS, "microvibration": VIBRATION})
    with pytest.raises(ConfigError, match="speeds_rpm"):
        speed_sweep(model, config, np.array([-10.0, 100.0]))
    with pytest.raises(ConfigError, match="microvibration"):
        speed_sweep(model, WheelsConfig(), np.array([10.0, 100.0]))
    with pytest.raises(ConfigError, match="actuator_time_constant_s"):
        closed_loop(plant, PDConfig(), actuator_time_constant_s=0.0)
    assert wheel_lines(WheelsConfig(), 1000.0).frequency_hz.size == 0


def test_wheels_at_rest_give_no_line_and_no_jitter(plant):
    # C Omega^2 = 0 at rest: no line (a line at 0 Hz would ask H(0), singular with the
    # hub's free translation), so zero jitter instead of a failed solve.
    model = closed_loop(plant, PDConfig())
    config = WheelsConfig.model_validate(
        {**FRICTIONLESS, "microvibration": {**VIBRATION, "wheels": None}}
    )
    rest = wheel_lines(config, 0.0, model.B.shape[1])
    assert rest.frequency_hz.size == 0 and rest.amplitude.shape == (0, model.B.shape[1])
    np.testing.assert_array_equal(jitter_rms(model, rest), np.zeros(3))
    # wheel 2 at rest among spinning ones: the others' lines only, each unchanged
    mixed = wheel_lines(config, [1500.0, 0.0, 1500.0, 1500.0])
    spinning = wheel_lines(config, 1500.0)
    assert [s for s in spinning.source if not s.startswith("wheel 2 ")] == list(mixed.source)
    keep = [not s.startswith("wheel 2 ") for s in spinning.source]
    np.testing.assert_array_equal(mixed.amplitude, spinning.amplitude[keep])


def test_backwards_spin_gives_the_mirrored_lines():
    # Omega -> -Omega: theta(t) = -|Omega| t, so each line is the conjugate, same power.
    config = WheelsConfig.model_validate({**FRICTIONLESS, "microvibration": VIBRATION})
    forward, backward = wheel_lines(config, 1500.0), wheel_lines(config, -1500.0)
    np.testing.assert_array_equal(forward.frequency_hz, backward.frequency_hz)
    np.testing.assert_allclose(backward.amplitude, np.conj(forward.amplitude), rtol=1e-15)


def test_stepper_lines_sit_at_the_step_rate_harmonics(plant):
    stepper = StepperConfig.model_validate({
        "coordinate": "panel_1.eta_ry", "rate_deg_s": 0.06, "step_angle_deg": 0.0036,
        "harmonics": [{"number": 1.0, "amplitude_nm": 0.01},
                      {"number": 4.0, "amplitude_nm": 0.002}], "seed": SEED,
    })  # fmt: skip
    model = closed_loop(plant, PDConfig(), actuated=[stepper.coordinate])
    lines = stepper_lines(stepper, model)
    # 0.06 deg/s over 0.0036 deg per microstep: 16.67 steps per second
    np.testing.assert_allclose(lines.frequency_hz, [16.0 + 2.0 / 3.0, 66.0 + 2.0 / 3.0],
                               rtol=1e-12)  # fmt: skip
    np.testing.assert_allclose(np.abs(lines.amplitude[:, -1]), [0.01, 0.002], rtol=1e-15)
    # The response through python-control's own evaluation of the same state space
    import control

    sys = model.to_statespace()
    G = np.stack([sys(2j * np.pi * f) for f in lines.frequency_hz])
    Y = line_response(model, lines)[1]
    # two LAPACK paths: round-off relative to the largest answer (1e-9 of it)
    np.testing.assert_allclose(Y, np.einsum("fou,fu->fo", G, lines.amplitude), rtol=1e-9,
                               atol=1e-9 * np.abs(Y).max())  # fmt: skip
    assert isinstance(sys, control.StateSpace)
    with pytest.raises(ConfigError, match="coordinate"):
        stepper_lines(stepper, closed_loop(plant, PDConfig()))
