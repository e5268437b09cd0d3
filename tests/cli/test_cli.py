"""The flexsat command, run as a user runs it: in a subprocess."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import time

import numpy as np
import pytest

from flexsat.control.laws import law_names

FLEXSAT = [sys.executable, "-m", "flexsat"]


def run(*args: str) -> subprocess.CompletedProcess:
    return subprocess.run([*FLEXSAT, *args], capture_output=True, text=True, timeout=300)


def test_help_reads_well():
    result = run("--help")
    assert result.returncode == 0
    for command in ("modal", "config", "equations"):
        assert command in result.stdout


def test_slew_help_names_every_built_in_law():
    # --controller's help lists the laws flexsat registers itself (it had missed the
    # two beyond the thesis): no user's law is registered in this process.
    result = run("slew", "--help")
    assert result.returncode == 0
    text = " ".join(result.stdout.split())
    listed = text.split("built in:")[1].split(")")[0]
    assert sorted(name.strip() for name in listed.split(",")) == sorted(law_names())


def test_modal_json_has_the_documented_keys():
    result = run("modal", "--json")
    assert result.returncode == 0, result.stderr
    summary = json.loads(result.stdout)
    for key in ("mass_matrix", "stiffness_diag", "frequencies_hz", "modes", "rigid_inertia"):
        assert key in summary
    assert len(summary["frequencies_hz"]) == 18
    # Thesis table 3.3: the yaw-coupled antisymmetric in-plane mode at 1.23 Hz.
    mode_12 = summary["modes"][11]
    assert mode_12["frequency_hz"] == pytest.approx(1.23, abs=0.005)
    assert (mode_12["kind"], mode_12["symmetry"]) == ("in_plane", "antisymmetric")


@pytest.mark.parametrize(
    ("content", "fragment"),
    [
        ("[hub]\nmass_kg = -1\n", "hub.mass_kg"),
        ("colour = 1\n", "unknown key 'colour'"),
        ("[hub\n", "not valid TOML"),
    ],
)
def test_bad_config_exits_2_with_one_message(tmp_path, content, fragment):
    path = tmp_path / "bad.toml"
    path.write_text(content)
    result = run("modal", "--config", str(path))
    assert result.returncode == 2
    assert fragment in result.stderr
    assert "Traceback" not in result.stderr


def test_missing_config_file_exits_2(tmp_path):
    result = run("modal", "--config", str(tmp_path / "absent.toml"))
    assert result.returncode == 2
    assert "not found" in result.stderr
    assert "Traceback" not in result.stderr


def test_preset_copy_round_trips(tmp_path):
    target = tmp_path / "mine.toml"
    assert run("config", "preset", "nominal", "-o", str(target)).returncode == 0
    shown = run("config", "show", "--config", str(target), "--json")
    assert shown.returncode == 0, shown.stderr
    payload = json.loads(shown.stdout)
    assert payload["config"]["name"] == "nominal"
    assert payload["derived"]["appendages"][0]["mass_kg"] == pytest.approx(6.75)
    again = run("config", "preset", "nominal", "-o", str(target))
    assert again.returncode == 2 and "exists" in again.stderr


def test_openloop_json_has_the_documented_keys():
    result = run("openloop", "--duration", "12", "--json")
    assert result.returncode == 0, result.stderr
    metrics = json.loads(result.stdout)
    for key in (
        "final_angular_momentum_nms", "final_rate_deg_s", "total_energy_j",
        "peak_elastic_energy_j", "dissipated_energy_j", "peak_flex_torque_nm",
        "peak_tip_displacement_m", "dominant_frequency_hz", "energy_balance_error_j",
        "wall_time_s", "steps",
    ):  # fmt: skip
        assert key in metrics
    # 1 N m about Z for 10 s: H_z = 10 N m s (round-off).
    assert metrics["final_angular_momentum_nms"][2] == pytest.approx(10.0, abs=1e-9)
    assert metrics["steps"] == 12000


def test_openloop_divergence_exits_1_and_keeps_the_partial_result(tmp_path):
    config = tmp_path / "stiff.toml"
    from flexsat.config import preset_path

    text = preset_path("nominal").read_text()
    text = text.replace("translation_x = 50.0", "translation_x = 3000.0")
    config.write_text(text)
    out = tmp_path / "run"
    result = run(
        "openloop", "--config", str(config), "--dt", "0.01", "--duration", "30", "--out", str(out)
    )
    assert result.returncode == 1
    assert "stopped at t =" in result.stderr
    assert "Traceback" not in result.stderr
    import xarray as xr

    with xr.open_dataset(out / "result.nc") as ds:
        assert ds.attrs["status"] == "failed"
        assert ds["time"].size > 1


def test_openloop_bad_option_exits_2():
    result = run("openloop", "--dt", "0.5")
    assert result.returncode == 2
    assert "dt_s" in result.stderr


def test_slew_json_reports_the_requirements():
    result = run("slew", "--json")
    assert result.returncode == 0, result.stderr
    metrics = json.loads(result.stdout)
    for key in ("final_pointing_error_deg", "r1_pass", "r2_pass", "r3_pass", "settling_time_s",
                "ape_deg", "rpe_deg", "rpe_window_s", "max_rate_error_deg_s"):  # fmt: skip
        assert key in metrics
    # R1 and R2 are judged over the stated window: the default deadline to the end.
    assert metrics["observation_window_s"] == [90.0, 120.0]
    assert metrics["r1_pass"] and metrics["r2_pass"] and metrics["r3_pass"]


def _short_slew(tmp_path, deadline_s: float) -> str:
    """A scenario file whose observation window opens at ``deadline_s``: a run shorter
    than the default 90 s must hold its window (tests/cli/test_bad_inputs.py)."""
    path = tmp_path / "short.toml"
    path.write_text(f"[requirements]\nsettling_deadline_s = {deadline_s}\n")
    return str(path)


def test_slew_shorter_than_its_window_is_judged_over_the_window_it_holds(tmp_path):
    # A 60 s run with the window opening at 50 s: R1 and R2 are judged over [50, 60]
    # (a 60 s run with the default 90 s window is refused: test_bad_inputs.py).
    short = _short_slew(tmp_path, 50.0)
    metrics = json.loads(run("slew", "--scenario", short, "--duration", "60", "--json").stdout)
    assert metrics["observation_window_s"] == [50.0, 60.0]
    assert metrics["r1_pass"] and metrics["r2_pass"]  # inside both bands from 45.5 s


def test_slew_design_inertia_is_the_configs(tmp_path):
    # A 300 kg hub: the controller is designed for that satellite (its rigidized
    # J_tot), not for the thesis's; the thesis slew keeps the nominal J_tot.
    from flexsat.config import load_config, preset_path
    from flexsat.simulate import design_inertia

    heavy = tmp_path / "heavy.toml"
    text = preset_path("nominal").read_text()
    heavy.write_text(text.replace("mass_kg = 150.0", "mass_kg = 300.0", 1))
    short = _short_slew(tmp_path, 0.5)
    result = run("slew", "--config", str(heavy), "--scenario", short, "--duration", "1",
                 "--json")  # fmt: skip
    assert result.returncode == 0, result.stderr
    reported = np.array(json.loads(result.stdout)["design_inertia_kg_m2"])
    np.testing.assert_allclose(reported, design_inertia(load_config(heavy)), rtol=1e-15)
    # the hub's J_xx doubles (41.6 -> 83.3 kg m^2): J_tot,xx grows by ~41.6
    assert reported[0, 0] == pytest.approx(189.99 + 41.6, abs=0.1)
    nominal = run("slew", "--scenario", short, "--duration", "1", "--json")
    J = np.array(json.loads(nominal.stdout)["design_inertia_kg_m2"])
    # J_tot of the thesis satellite (section 3.1, appendix B), to the printed digits
    np.testing.assert_allclose(np.diag(J), [189.99, 44.16, 177.90], atol=0.006)


def test_slew_unknown_controller_exits_2():
    result = run("slew", "--controller", "lqr")
    assert result.returncode == 2
    assert "controller.kind: must be one of" in result.stderr


def test_study_unknown_controller_exits_2(tmp_path):
    result = run("study", "--controller", "asmc,lqr", "--out", str(tmp_path))
    assert result.returncode == 2
    assert "--controller: unknown control law 'lqr': must be one of asmc, smc, pd" in result.stderr


def test_slew_compares_all_controllers(tmp_path):
    short = _short_slew(tmp_path, 5.0)
    result = run("slew", "--scenario", short, "--controller", "all", "--duration", "10", "--json")
    assert result.returncode == 0, result.stderr
    metrics = json.loads(result.stdout)
    assert set(metrics) == set(law_names())  # every registered law, the built-ins here
    for fields in metrics.values():
        for key in ("settling_time_s", "max_abs_torque_nm", "lambda_switch_time_s", "wall_time_s"):
            assert key in fields


def test_slew_target_option(tmp_path):
    short = _short_slew(tmp_path, 50.0)
    result = run("slew", "--scenario", short, "--target-euler-deg", "10,0,-20", "--duration",
                 "60", "--json")  # fmt: skip
    assert result.returncode == 0, result.stderr
    final = json.loads(result.stdout)["final_euler_deg"]
    assert final == pytest.approx([10.0, 0.0, -20.0], abs=0.05)
    bad = run("slew", "--target-euler-deg", "10,0")
    assert bad.returncode == 2 and "three comma-separated numbers" in bad.stderr


_ANNOUNCE = (
    "import sys; from pathlib import Path; from flexsat.dynamics import kernels; "
    "from flexsat.cli.main import _announce_compilation; "
    "cache = Path(kernels.accelerations._cache._cache_path); "
    "cache.mkdir(parents=True, exist_ok=True); "
    "sys.argv[1:] and (cache / 'kernels.accelerations-1.py311.nbi').touch(); "
    "_announce_compilation(); print(cache)"
)


def _announce(env: dict, *extra: str) -> subprocess.CompletedProcess:
    command = [sys.executable, "-c", _ANNOUNCE, *extra]
    return subprocess.run(command, env=env, capture_output=True, text=True, check=True)


def test_the_first_run_notice_looks_where_numba_caches(tmp_path):
    # With NUMBA_CACHE_DIR set (or read-only sources), numba caches elsewhere than
    # beside the sources: an empty cache there is announced, a filled one is not.
    env = {**os.environ, "NUMBA_CACHE_DIR": str(tmp_path / "numba")}
    empty, filled = _announce(env), _announce(env, "filled")
    assert empty.stdout.strip().startswith(str(tmp_path / "numba"))
    assert "compiling the dynamics kernels" in empty.stderr
    assert "compiling" not in filled.stderr


def test_the_command_exits_without_a_last_collection_and_its_files_are_whole(tmp_path):
    # The command freezes the heap at exit, so the interpreter's last collection walks
    # nothing (a handler registered before main runs after main's: atexit is last in,
    # first out). What the command wrote is closed and complete: the written preset
    # loads back.
    out = tmp_path / "hub.toml"
    code = ("import atexit, gc, sys\n"
            "atexit.register(lambda: print('frozen', gc.get_freeze_count() > 0))\n"
            f"sys.argv = ['flexsat', 'config', 'preset', 'nominal', '-o', {str(out)!r}]\n"
            "from flexsat.cli.main import main\n"
            "main()\n")  # fmt: skip
    result = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                            timeout=300)  # fmt: skip
    assert result.returncode == 0, result.stderr
    assert result.stdout.splitlines()[-1] == "frozen True"
    assert run("config", "show", "--config", str(out)).returncode == 0


def test_ctrl_c_ends_a_command_with_one_line_and_code_130(tmp_path):
    # typer turns Ctrl-C into a silent exit 130; the command says why it stopped. The
    # study makes its output folder once it has started: SIGINT then lands in it.
    out = tmp_path / "study"
    command = [*FLEXSAT, "study", "--quick", "--out", str(out)]
    process = subprocess.Popen(command, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    deadline = time.monotonic() + 120
    while not out.exists():
        assert time.monotonic() < deadline, "the study did not start"
        time.sleep(0.01)
    process.send_signal(signal.SIGINT)
    _, stderr = process.communicate(timeout=60)
    assert process.returncode == 130
    assert stderr.endswith("error: interrupted\n")
    assert "Traceback" not in stderr


def test_campaign_prints_what_a_worst_case_search_found(tmp_path):
    # The summary's worst-case lines rank the final pointing error; a search also
    # prints its own result, by the metric it searched, as worst_case.json holds it.
    path = tmp_path / "worst.toml"
    path.write_text(
        'name = "worst"\n[base]\nduration_s = 0.5\n'
        '[worst_case]\nmetric = "peak_tip_displacement_m"\nseed = 3\nmaxiter = 1\n'
        'popsize = 3\nparameters = [{ path = "hub.mass_kg", bounds = [120.0, 180.0] }]\n'
    )
    result = run("campaign", str(path), "--workers", "1", "--out", str(tmp_path / "s"))
    found = json.loads((tmp_path / "s" / "worst_case.json").read_text())
    assert result.returncode == 0, result.stderr
    line = f"worst-case search: {found['case_id']}  {found['metric']} = {found['value']:.4g}"
    assert line in " ".join(result.stdout.split("\n"))
