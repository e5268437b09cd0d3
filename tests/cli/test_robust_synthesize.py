"""flexsat robust synthesize: an H-infinity controller file the statespace law reads."""

from __future__ import annotations

import itertools
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


def test_unknown_method_and_iterations_are_refused_with_one_message(tmp_path, capsys):
    out = tmp_path / "k.npz"
    outcome = flexsat(["robust", "synthesize", "--out", str(out), "--method", "lqg"], capsys)
    assert outcome.code != 0
    assert "--method: hinf or dk, got 'lqg'" in outcome.stderr
    assert "Traceback" not in outcome.stderr and not out.exists()
    outcome = flexsat(["robust", "synthesize", "--out", str(out), "--method", "dk",
                       "--iterations", "0"], capsys)  # fmt: skip
    assert outcome.code != 0 and "--iterations: must be in 1 ... 10, got 0" in outcome.stderr
    outcome = flexsat(["robust", "synthesize", "--out", str(out), "--method", "dk",
                       "--points", "7"], capsys)  # fmt: skip
    assert outcome.code != 0 and "--points: must be in 8 ... 200, got 7" in outcome.stderr
    assert "Traceback" not in outcome.stderr and not out.exists()


def test_dk_writes_a_controller_with_its_mu_history(tmp_path, capsys):
    """One D-K step: mu never rises; the file is the reduced 6-state controller.

    The robust-performance mu cannot fall below the H-infinity noise floor gamma
    (5.73, the attitude noise: docs/control.md); the first design sits near twice it.
    On 12 frequencies instead of the default 30 (``--points``; 24 s against 60 s): the
    mu history was 11.357 then 5.7291 against 5.7293 on 30.
    """
    pytest.importorskip("dkpy")
    out = tmp_path / "dk.npz"
    outcome = flexsat(["robust", "synthesize", "--out", str(out), "--method", "dk",
                       "--iterations", "1", "--points", "12", "--json"], capsys,
                      timeout_s=900)  # fmt: skip
    assert outcome.code == 0, outcome.stderr
    summary = json.loads(outcome.stdout)
    mus = summary["mu_history"]
    assert summary["method"] == "dk" and 1 <= len(mus) <= 2
    assert all(b <= a for a, b in itertools.pairwise(mus)) and summary["mu"] == mus[-1]
    # mu >= its H-infinity bound's floor (robust performance contains nominal performance)
    assert summary["mu"] >= 1e-4 * 50 / 8.726646259971648e-4 * (1 - 1e-3)
    assert summary["input_uncertainty"] == pytest.approx(0.25, rel=1e-8)
    assert load_controller(out).order == 6 == summary["order"]
