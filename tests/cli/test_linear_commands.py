"""``flexsat linearize`` and ``flexsat margins``, run as a user runs them."""

from __future__ import annotations

import json
import subprocess
import sys

import numpy as np
import pytest

FLEXSAT = [sys.executable, "-m", "flexsat"]


def run(*args: str) -> subprocess.CompletedProcess:
    return subprocess.run([*FLEXSAT, *args], capture_output=True, text=True, timeout=300)


def test_linearize_writes_the_model_files_and_figures(tmp_path):
    from scipy.io import loadmat

    result = run("linearize", "--reduce", "balanced:16", "--json", "--out", str(tmp_path))
    assert result.returncode == 0, result.stderr
    summary = json.loads(result.stdout)
    assert summary["n_states"] == 36 and summary["jacobian"] == "analytic"
    # Thesis table 3.3: first coupled flexible mode 0.258 Hz, zeta = 0.005 (table 3.1).
    first = summary["modes"][0]
    assert first["frequency_hz"] == pytest.approx(0.2581, abs=1e-4)
    assert first["damping_ratio"] == pytest.approx(0.005, rel=0.05)
    assert summary["reduction"]["error_bound"] > 0.0
    mat = loadmat(tmp_path / "model.mat")
    assert mat["A"].shape == (36, 36)
    assert np.load(tmp_path / "reduced.npz")["A"].shape == (16, 16)
    for name in ("bode_rate", "bode_attitude", "singular_values", "pole_zero"):
        assert (tmp_path / f"{name}.png").stat().st_size > 0


def test_linearize_about_a_spin_reports_the_equilibrium():
    result = run("linearize", "--about", "spin:0.5,0,0", "--outputs", "rate", "--json")
    assert result.returncode == 0, result.stderr
    summary = json.loads(result.stdout)
    assert summary["about"] == "spin" and summary["jacobian"] == "richardson"
    assert summary["spin_rad_s"] == [0.5, 0.0, 0.0]
    assert summary["output_names"] == ["omega_x", "omega_y", "omega_z"]


def test_linearize_adds_an_input_per_actuated_coordinate(tmp_path):
    result = run("linearize", "--actuated", "panel_1.eta_rz", "--actuated", "eta_x",
                 "--json", "--out", str(tmp_path))  # fmt: skip
    assert result.returncode == 0, result.stderr
    summary = json.loads(result.stdout)
    assert summary["input_names"] == ["tau_x", "tau_y", "tau_z", "Q_panel_1.eta_rz",
                                      "Q_panel_1.eta_x", "Q_panel_2.eta_x"]  # fmt: skip
    assert summary["input_units"] == ["N m"] * 4 + ["N"] * 2
    model = np.load(tmp_path / "model.npz")
    assert model["B"].shape == (36, 6) and list(model["input_names"])[3] == "Q_panel_1.eta_rz"
    assert (tmp_path / "singular_values.png").stat().st_size > 0  # torque inputs only


def test_margins_table_and_files(tmp_path):
    result = run("margins", "--out", str(tmp_path))
    assert result.returncode == 0, result.stderr
    assert "delay margin" in result.stdout
    summary = json.loads((tmp_path / "margins.json").read_text())
    assert set(summary["axes"]) == {"x", "y", "z"}
    # Every crossover and flexible peak is printed: the x loop's three crossovers and
    # its phase-stabilized 0.521 Hz mode (+28.46 dB; against python-control in
    # tests/linear/test_frequency.py).
    x = summary["axes"]["x"]
    assert [c["frequency_hz"] for c in x["crossovers"]] == x["crossovers_hz"]
    assert len(x["crossovers"]) == 3
    phase = [p for p in x["flexible_peaks"] if p["stabilized"] == "phase"]
    assert [round(p["peak_gain_db"], 2) for p in phase] == [28.46]
    assert "28.46" in result.stdout and "phase" in result.stdout and "sets it" in result.stdout
    assert (tmp_path / "loop_gain.png").exists() and (tmp_path / "nichols.png").exists()


@pytest.mark.parametrize(
    ("args", "fragment"),
    [
        (("linearize", "--about", "spin:0,0,0"), "zero length"),
        (("linearize", "--about", "tumbling"), "--about: expected 'rest' or 'spin:wx,wy,wz'"),
        (("linearize", "--outputs", "rate,tips"), "unknown output 'tips'"),
        (("linearize", "--reduce", "balanced:99"), "order: must be between 12"),
        (("linearize", "--reduce", "hankel:8"), "--reduce: expected"),
        (("linearize", "--actuated", "rho_q"), "actuated: unknown coordinate 'rho_q'"),
    ],
)
def test_bad_requests_exit_2_with_one_message(args, fragment):
    result = run(*args)
    assert result.returncode == 2
    assert fragment in result.stderr
    assert "Traceback" not in result.stderr


def test_margins_of_a_sliding_mode_law_inside_its_boundary_layer(tmp_path):
    scenario = tmp_path / "slew.toml"
    scenario.write_text('[controller]\nkind = "smc"\n')
    result = run("margins", "--scenario", str(scenario), "--json")
    assert result.returncode == 0, result.stderr
    summary = json.loads(result.stdout)
    assert summary["law"] == "smc" and summary["gains"]["lambda"] == 1.0


def test_linearize_json_is_the_state_space_model_of_the_npz(tmp_path):
    import control
    from flexsat.linear.model import statespace_name

    result = run("linearize", "--reduce", "modal:16", "--json", "--out", str(tmp_path))
    assert result.returncode == 0, result.stderr
    summary = json.loads(result.stdout)
    for part, npz_name in ((summary, "model.npz"), (summary["reduction"], "reduced.npz")):
        npz = np.load(tmp_path / npz_name)
        # python-control refuses a dot in a signal name ("panel_1.tip_x"): the
        # mapping LinearModel.to_statespace documents.
        sys = control.ss(part["A"], part["B"], part["C"], part["D"],
                         states=part["state_names"],
                         inputs=[statespace_name(n) for n in part["input_names"]],
                         outputs=[statespace_name(n) for n in part["output_names"]])  # fmt: skip
        # JSON numbers are written with the shortest repr that reads back to the same
        # float64, so the model rebuilt from the JSON is the exported one bit for bit.
        for key in ("A", "B", "C", "D"):
            assert np.array_equal(getattr(sys, key), npz[key]), key
        for key in ("x0", "u0"):
            assert np.array_equal(part[key], npz[key]), key
        assert sys.state_labels == list(npz["state_names"])
        assert sys.input_labels == [statespace_name(n) for n in npz["input_names"]]
        assert sys.output_labels == [statespace_name(n) for n in npz["output_names"]]
        for key in ("state_units", "input_units", "output_units"):
            assert part[key] == list(npz[key]), key
    assert summary["state_units"][:3] == ["m"] * 3 and summary["input_units"] == ["N m"] * 3
