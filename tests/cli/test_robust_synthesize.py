"""flexsat robust synthesize: an H-infinity controller file the statespace law reads."""

from __future__ import annotations

import json

import pytest

from flexsat.control.laws.statespace import load_controller
from tests.cli.harness import flexsat

pytest.importorskip("slycot")


def test_synthesize_writes_a_controller_of_the_order_asked(tmp_path, capsys):
    out = tmp_path / "hinf.mat"
    outcome = flexsat(["robust", "synthesize", "--out", str(out), "--order", "12", "--modes",
                       "6", "--json"], capsys, timeout_s=600)  # fmt: skip
    assert outcome.code == 0, outcome.stderr
    summary = json.loads(outcome.stdout)
    k = load_controller(out)
    assert (k.order, k.dt) == (12, 1e-3) == (summary["order"], summary["control_dt_s"])
    assert summary["full_order"] == 24  # 6 rigid + 12 modal states + 3 W_p + 3 W_u
    # the attitude noise's floor (docs/control.md): 1e-4 rad x 50 / 0.05 deg
    assert summary["gamma"] == pytest.approx(1e-4 * 50 / 8.726646259971648e-4, rel=1e-5)


def test_the_default_design_is_the_rigid_attitude_reduced_to_6_states(tmp_path, capsys):
    out = tmp_path / "hinf.npz"
    outcome = flexsat(["robust", "synthesize", "--out", str(out), "--json"], capsys, 600)
    assert outcome.code == 0, outcome.stderr
    summary = json.loads(outcome.stdout)
    assert (summary["modes"], summary["full_order"], summary["order"]) == (0, 12, 6)
    assert load_controller(out).order == 6
