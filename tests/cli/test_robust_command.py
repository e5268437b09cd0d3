"""``flexsat robust analyze``: the printed tables, mu.json and mu.png of the PD loop."""

from __future__ import annotations

import json

import numpy as np
import pytest

from flexsat.cli.tables import format_number
from tests.cli.harness import flexsat


def test_robust_analyze_tables_and_files(capsys, tmp_path):
    """The PD loop over the thesis's box: the known k_max = 1 at zero damping.

    docs/linear.md, 'Robust stability: mu' says why (a passive collocated loop; the
    antisymmetric panel modes grow for zeta < 0 whatever the law).
    """
    outcome = flexsat(["robust", "analyze", "--points", "8", "--out", str(tmp_path)], capsys,
                      timeout_s=900)  # fmt: skip
    assert outcome.code == 0, outcome.stderr
    summary = json.loads((tmp_path / "mu.json").read_text())
    # The lower bound's bisection stops within 1e-6 in alpha.
    assert abs(summary["lower"] - 1.0) <= 1e-5
    assert abs(summary["worst_factors"]["damping"]) <= 1e-5
    assert summary["peak_upper"] == max(summary["mu_upper"]) >= summary["lower"]
    assert summary["k_max_lower"] == 1.0 / summary["peak_upper"]
    f = np.array(summary["frequencies_hz"])
    # 8 log-spaced points over 1e-3 ... 200 Hz, the closed loop's modes added.
    assert np.all(np.isin(np.logspace(-3, np.log10(200.0), 8), f)) and f.size > 8
    assert [p["block_size"] for p in summary["parameters"]] == [18, 12, 3, 36]
    assert (tmp_path / "mu.png").stat().st_size > 0
    for text in ("Robust stability, PD loop", "k_max, certified", "Worst case", "damping"):
        assert text in outcome.stdout
    assert format_number(float(summary["peak_upper"])) in outcome.stdout


def test_unknown_bound_is_refused_with_one_message(capsys):
    outcome = flexsat(["robust", "analyze", "--bound", "full"], capsys)
    assert outcome.code != 0
    assert "--bound: one of diagonal, lmi, got 'full'" in outcome.stderr
    assert "Traceback" not in outcome.stderr


def test_lmi_bound_on_the_69_channel_loop_is_refused_with_one_message(capsys):
    """The nominal box's LFT has 69 channels: the LMI bound refuses it (docs/linear.md)."""
    pytest.importorskip("cvxpy")
    outcome = flexsat(["robust", "analyze", "--bound", "lmi", "--points", "8"], capsys,
                      timeout_s=300)  # fmt: skip
    assert outcome.code != 0
    assert "bound: the LMI bound takes at most 40 channels, this model has 69" in outcome.stderr
    assert "Traceback" not in outcome.stderr
