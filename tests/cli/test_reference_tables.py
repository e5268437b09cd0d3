"""The slew TOML's [reference] and [joint_actuator] tables, through the command line."""

from __future__ import annotations

import json

from tests.cli.harness import flexsat

SCENARIO = """duration_s = 5.0
[requirements]
settling_deadline_s = 4.0
[reference]
kind = "eigenaxis"
profile = "polynomial"
duration_s = 4.0
[reference.shaper]
kind = "zv"
frequencies_hz = [0.52]
[joint_actuator]
kind = "rate_feedback"
coordinates = ["eta_rx", "eta_ry", "eta_rz"]
gain = 10.0
limit = 0.1
"""


def test_a_shaped_damped_slew_from_toml(tmp_path, capsys):
    (tmp_path / "s.toml").write_text(SCENARIO)
    out = flexsat(["slew", "--scenario", str(tmp_path / "s.toml"), "--json"], capsys,
                  timeout_s=600)  # fmt: skip
    assert out.code == 0, out.stderr
    metrics = json.loads(out.stdout)
    assert metrics["status"] == "ok"
    assert metrics["r3_pass"]
