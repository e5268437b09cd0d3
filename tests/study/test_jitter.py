"""The study's microvibration summary against the jitter recomputed from its definitions
(tests/study/jitter_reference.py), its sweep's worst speeds and its files."""

from __future__ import annotations

import json

import numpy as np
import pytest

from flexsat.config import nominal
from flexsat.dynamics.plant import Plant
from flexsat.errors import ConfigError
from flexsat.linear.jitter import StepperConfig, closed_loop
from flexsat.simulate import SlewScenario
from flexsat.study.jitter import DEFAULT_MICROVIBRATION, jitter_scenario, write_jitter
from tests.study import jitter_reference as ref

# The reference projects sampled sinusoids and solves the loop with numpy; flexsat
# evaluates closed forms through its own frequency response: both are exact up to
# round-off (the lines span 1e-3 to 1 of the largest), so 1e-9 relative.
RTOL = 1e-9
STEPPER = {"coordinate": "panel_1.eta_ry", "rate_deg_s": 0.06, "step_angle_deg": 0.001,
           "harmonics": [{"number": 1.0, "amplitude_nm": 0.01},
                         {"number": 4.0, "amplitude_nm": 0.002}], "seed": 3}  # fmt: skip


@pytest.fixture(scope="module")
def plant():
    return Plant.from_config(nominal())


def _model(plant, scenario, actuated=()):
    wheels = scenario.actuator
    h0 = wheels.spin_inertia_kg_m2 * wheels.initial_speed_rpm * np.pi / 30.0
    return closed_loop(plant, scenario.controller, wheels.spin_axes().sum(axis=0) * h0,
                       actuated, wheels.motor_time_constant_s)  # fmt: skip


def _reference(model, scenario, speed_rpm, rows=None, window_s=None, stepper=None):
    """RMS per output [arcsec] of the wheels at ``speed_rpm`` (and a stepper's lines)."""
    rows = np.eye(3) if rows is None else rows
    torques = ref.wheel_torque_lines(scenario.actuator.spin_axes(), DEFAULT_MICROVIBRATION,
                                     speed_rpm)  # fmt: skip
    pad = np.zeros(model.B.shape[1] - 3)
    lines = {f: np.concatenate([u, pad]) for f, u in torques.items()}
    if stepper is not None:
        column = model.input_names.index(f"Q_{stepper['coordinate']}")
        for f, q in ref.stepper_force_lines(stepper).items():
            lines.setdefault(f, np.zeros(model.B.shape[1], complex))
            lines[f] = lines[f] + np.eye(model.B.shape[1])[column] * q
    outputs = [rows @ ref.response(model, f, u) for f, u in lines.items()]
    gains = None if window_s is None else [ref.rpe_gain(f, window_s) for f in lines]
    return ref.rms_arcsec(outputs, gains), sorted(lines)


def test_the_summary_is_the_jitter_of_the_default_wheels(plant, tmp_path):
    scenario = jitter_scenario()
    speeds = np.linspace(200.0, 4000.0, 40)
    summary = write_jitter(plant, scenario, tmp_path / "j", speeds_rpm=speeds, window_s=0.5)
    model = _model(plant, scenario)
    rms, freqs = _reference(model, scenario, 2000.0)
    rpe, _ = _reference(model, scenario, 2000.0, window_s=0.5)
    print(f"phase seed {DEFAULT_MICROVIBRATION['seed']}: RMS {rms} arcsec, RPE(0.5 s) {rpe}")
    assert summary["speed_rpm"] == 2000.0 and summary["outputs"] == ["x", "y", "z"]
    np.testing.assert_allclose([summary["rms_arcsec"][a] for a in "xyz"], rms, rtol=RTOL)
    np.testing.assert_allclose([summary["rpe_rms_arcsec"][a] for a in "xyz"], rpe, rtol=RTOL)
    # h = 1 (imbalances, axial) at 33.3 Hz and the radial h = 2 at 66.7 Hz
    np.testing.assert_allclose([line["frequency_hz"] for line in summary["lines"]], freqs,
                               rtol=1e-12)  # fmt: skip
    np.testing.assert_allclose(freqs, [2000.0 / 60.0, 4000.0 / 60.0], rtol=1e-12)
    assert min(rms) > 1e-3  # arcsec: a jitter, far above round-off

    # each worst speed's total is the reference's there, and no swept speed beats it
    totals = [np.linalg.norm(_reference(model, scenario, s, window_s=0.5)[0]) for s in speeds]
    worst = summary["worst"]
    assert len(worst) == 3
    for entry in worst:
        at = _reference(model, scenario, entry["speed_rpm"], window_s=0.5)[0]
        assert entry["rms_arcsec"] == pytest.approx(np.linalg.norm(at), rel=RTOL)
    assert worst[0]["rms_arcsec"] >= max(totals) * (1.0 - 1e-12)
    assert [w["rms_arcsec"] for w in worst] == sorted((w["rms_arcsec"] for w in worst),
                                                      reverse=True)  # fmt: skip

    # files: the summary as JSON, the Campbell figure
    written = json.loads((tmp_path / "j" / "jitter.json").read_text())
    assert written["rms_arcsec"] == summary["rms_arcsec"] and written["worst"] == worst
    assert (tmp_path / "j" / "campbell.png").stat().st_size > 10_000


def test_a_line_of_sight_and_a_stepper_join_the_summary(plant):
    scenario = jitter_scenario(1500.0)
    stepper = StepperConfig.model_validate(STEPPER)
    summary = write_jitter(plant, scenario, speeds_rpm=np.linspace(500.0, 3000.0, 10),
                           boresight=[0.0, 0.0, 2.0], stepper=stepper)  # fmt: skip
    model = _model(plant, scenario, [STEPPER["coordinate"]])
    # boresight +z: u is the hub's x axis, v = z x x = y
    rows = np.array([[1.0, 0, 0], [0, 1.0, 0], [0, 0, 1.0], [1.0, 0, 0], [0, 1.0, 0]])
    rms, freqs = _reference(model, scenario, 1500.0, rows=rows, stepper=STEPPER)
    print(f"stepper phase seed {STEPPER['seed']}: RMS {rms} arcsec at lines {freqs} Hz")
    assert summary["outputs"] == ["x", "y", "z", "los_u", "los_v"]
    np.testing.assert_allclose(list(summary["rms_arcsec"].values()), rms, rtol=RTOL)
    # the stepper alone: 60 steps/s, lines at 60 and 240 Hz on the panel's root rotation
    assert summary["stepper"]["step_rate_hz"] == pytest.approx(60.0, rel=1e-12)
    alone = [rows @ ref.response(model, f, np.eye(model.B.shape[1])[-1] * q)
             for f, q in ref.stepper_force_lines(STEPPER).items()]  # fmt: skip
    np.testing.assert_allclose(list(summary["stepper"]["rms_arcsec"].values()),
                               ref.rms_arcsec(alone), rtol=RTOL, atol=1e-12)  # fmt: skip
    assert summary["stepper"]["rms_arcsec"]["y"] > 1e-5  # the panel's rotation reaches y


def test_a_scenario_without_microvibration_is_refused(plant):
    bare = SlewScenario.model_validate({"actuator": {"kind": "wheels"}})
    with pytest.raises(ConfigError, match=r"actuator\.microvibration: the jitter needs"):
        write_jitter(plant, bare)
    static = SlewScenario.model_validate({})
    with pytest.raises(ConfigError, match='kind = "wheels"'):
        write_jitter(plant, static)


def test_the_lines_are_the_budgets_periodic_contributors(plant, tmp_path):
    from flexsat.analysis.budget import budget_rows, load_requirements

    summary = write_jitter(plant, jitter_scenario(), tmp_path / "j",
                           speeds_rpm=np.linspace(500.0, 3000.0, 5), window_s=1.0)  # fmt: skip
    header = ("[pointing]\n[pointing.indices.APE]\nbound_deg = 0.01\n"
              "[pointing.indices.RPE]\nbound_deg = 0.01\nwindow_s = 1.0\n")  # fmt: skip
    requirements = tmp_path / "req.toml"
    requirements.write_text(header + (tmp_path / "j" / "contributors.toml").read_text())
    rows = budget_rows(load_requirements(requirements))
    sigma = {(r["index"], r["axis"]): r["sigma_deg"] * 3600.0 for r in rows}
    # Each line is a sinusoid per axis: the budget's sigma A / sqrt(2) summed in power
    # is the jitter's RMS, its RPE's A |1 - sinc(dt / T)| the windowed RMS. Both sides
    # are the same sums of the same amplitudes (repr round-trips floats exactly):
    # round-off, 1e-12.
    for axis in "xyz":
        assert sigma["APE", axis] == pytest.approx(summary["rms_arcsec"][axis], rel=1e-12)
        assert sigma["RPE", axis] == pytest.approx(summary["rpe_rms_arcsec"][axis], rel=1e-12)
    assert len(rows) == 6 and sigma["APE", "y"] > 0.01  # arcsec: the lines are all there
