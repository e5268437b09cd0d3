"""``flexsat jitter``: the JSON's numbers recomputed from the wheel model's definitions
(tests/study/jitter_reference.py), and the printed tables."""

from __future__ import annotations

import json

import numpy as np
import pytest

from flexsat.config import nominal
from flexsat.dynamics.plant import Plant
from flexsat.linear.jitter import closed_loop
from flexsat.study.jitter import DEFAULT_MICROVIBRATION, jitter_scenario
from tests.cli.harness import flexsat
from tests.study import jitter_reference as ref

WINDOW_S = 0.4
# boresight +z: the line-of-sight error's u is the hub's x axis, v = z x x = y
LOS = np.array([[1.0, 0.0, 0.0], [0.0, 1.0, 0.0]])


def _los_rpe(model, axes, speed_rpm):
    """The line of sight's RPE RMS over WINDOW_S [arcsec] at one wheel speed."""
    lines = ref.wheel_torque_lines(axes, DEFAULT_MICROVIBRATION, speed_rpm)
    outputs = [LOS @ ref.response(model, f, u) for f, u in lines.items()]
    return ref.rms_arcsec(outputs, [ref.rpe_gain(f, WINDOW_S) for f in lines])


def test_jitter_json_is_the_jitter_recomputed(capsys):
    argv = ["jitter", "--json", "--speeds", "500:3000:20", "--window", str(WINDOW_S),
            "--boresight", "0,0,1"]  # fmt: skip
    outcome = flexsat(argv, capsys)
    assert outcome.code == 0, outcome.stderr
    summary = json.loads(outcome.stdout)
    print(f"phase seed {DEFAULT_MICROVIBRATION['seed']}")

    scenario = jitter_scenario()  # the command's default: ASMC, pyramid at 2000 rpm
    wheels = scenario.actuator
    h0 = wheels.spin_inertia_kg_m2 * 2000.0 * np.pi / 30.0
    model = closed_loop(Plant.from_config(nominal()), scenario.controller,
                        wheels.spin_axes().sum(axis=0) * h0, (),
                        wheels.motor_time_constant_s)  # fmt: skip
    axes = wheels.spin_axes()
    lines = ref.wheel_torque_lines(axes, DEFAULT_MICROVIBRATION, 2000.0)
    hub = [ref.response(model, f, u) for f, u in lines.items()]
    rms = ref.rms_arcsec(hub)
    rpe = ref.rms_arcsec(hub, [ref.rpe_gain(f, WINDOW_S) for f in lines])
    # exact formulas on both sides, evaluated differently: round-off, 1e-9
    assert summary["law"] == "asmc" and summary["window_s"] == WINDOW_S
    assert summary["outputs"] == ["x", "y", "z", "los_u", "los_v"]
    np.testing.assert_allclose(list(summary["rms_arcsec"].values()),
                               [*rms, rms[0], rms[1]], rtol=1e-9)  # fmt: skip
    np.testing.assert_allclose(list(summary["rpe_rms_arcsec"].values()),
                               [*rpe, rpe[0], rpe[1]], rtol=1e-9)  # fmt: skip
    for line, f in zip(summary["lines"], lines, strict=True):
        assert line["frequency_hz"] == pytest.approx(f, rel=1e-12)
    # the sweep on the line of sight: each worst speed's RPE is the recomputed one, and
    # none of the 20 grid speeds is worse than the worst
    worst = summary["worst"]
    for entry in worst:
        expected = np.linalg.norm(_los_rpe(model, axes, entry["speed_rpm"]))
        assert entry["rms_arcsec"] == pytest.approx(expected, rel=1e-9)
        assert 500.0 <= entry["speed_rpm"] <= 3000.0
    grid = [np.linalg.norm(_los_rpe(model, axes, s)) for s in np.linspace(500, 3000, 20)]
    assert worst[0]["rms_arcsec"] >= max(grid) * (1.0 - 1e-12)
    assert min(summary["modes_hz"]) < 1.0 < 50.0 <= max(summary["modes_hz"])  # panels


def test_jitter_prints_its_tables_and_writes_its_files(capsys, tmp_path):
    argv = ["jitter", "--speeds", "500:3000:10", "--out", str(tmp_path / "j")]
    outcome = flexsat(argv, capsys)
    assert outcome.code == 0, outcome.stderr
    assert "Jitter at 2000 rpm, ASMC loop [arcsec]" in outcome.stdout
    assert "Worst wheel" in outcome.stdout  # the title wraps on a narrow console
    written = json.loads((tmp_path / "j" / "jitter.json").read_text())
    # the printed RMS about y is the file's, to the table's 4 significant digits
    assert f"{written['rms_arcsec']['y']:.4g}" in outcome.stdout
    assert (tmp_path / "j" / "campbell.png").stat().st_size > 10_000
    for entry in written["worst"]:
        assert f"{entry['speed_rpm']:.4g}" in outcome.stdout
