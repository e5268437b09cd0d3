"""A diverging open-loop run keeps its history and its metrics, with either solver."""

from __future__ import annotations

import json
import math

import pytest

from flexsat.config import validate_config
from flexsat.simulate import OpenLoopScenario
from flexsat.simulate.result import Result
from flexsat.study.outputs import fly_openloop

# 1 MN m about Z from t = 0: the joints' elastic state overflows near t = 10.17 s at 1 ms.
_HUGE_TORQUE = {"duration_s": 11.0, "torque": [{"start_s": 0.0, "torque_nm": [0, 0, 1e6]}]}
# 5 deg/s of pitch from 88 deg: through the ZYX pitch pole at t = 2 deg / 5 deg/s = 0.4 s.
_TO_THE_POLE = {
    "duration_s": 2.0, "torque": [],
    "initial": {"attitude_deg": [0.0, 88.0, 0.0], "rate_deg_s": [0.0, 5.0, 0.0]},
}  # fmt: skip


def _fly(nominal_plant, tmp_path, settings: dict):
    scenario = validate_config(settings, model=OpenLoopScenario)
    result, metrics = fly_openloop(nominal_plant, scenario, tmp_path, progress=False)
    stored = json.loads((tmp_path / "metrics.json").read_text())
    history = Result.from_netcdf(tmp_path / "result.nc").dataset
    return result, stored, history


def _all_finite(metrics: dict) -> bool:
    numbers = []
    for value in metrics.values():
        numbers += value if isinstance(value, list) else [value]
    return all(math.isfinite(v) for v in numbers if isinstance(v, float))


def test_a_huge_torque_diverges_and_keeps_its_history(nominal_plant, tmp_path):
    result, metrics, history = _fly(nominal_plant, tmp_path, _HUGE_TORQUE)
    assert not result.ok and "non-finite" in result.message
    # The state overflows between 10.1 and 10.2 s (10.172 s on the thesis plant at 1 ms).
    assert 10.1 < metrics["finite_until_s"] <= float(history["time"][-1]) < 10.2
    assert history.sizes["time"] > 1000  # every record up to the failure (1018 at 10 ms)
    assert metrics["status"] == "failed"
    assert _all_finite(metrics)


@pytest.mark.parametrize("solver", ["rk4", "dop853"])
def test_the_pitch_pole_stops_neither_solver(nominal_plant, tmp_path, solver):
    # The attitude is re-based before the pole (docs/model.md, 'Attitude
    # parametrization'): the run goes on to its end, through pitch 90 deg at 0.4 s,
    # and its metrics stay finite.
    result, metrics, history = _fly(nominal_plant, tmp_path, {**_TO_THE_POLE, "solver": solver})
    assert result.ok, result.message
    assert float(history["time"][-1]) == pytest.approx(2.0)
    # 88 + 5 t deg about the body pitch axis: 98 deg at 2 s, which ZYX angles write
    # as pitch 82 deg with roll and yaw 180 deg (1e-9 deg: round-off of the angles).
    pitch = history["euler_deg"].values[:, 1]
    assert pitch.max() > 89.99
    assert pitch[-1] == pytest.approx(82.0, abs=1e-9)
    assert _all_finite(metrics)


# 1 MN m of constant environment torque on every axis against a 1e7 N m actuator:
# the PD law cannot hold it and the state overflows within the first 0.1 s.
_HUGE_DISTURBANCE = {
    "duration_s": 20.0, "controller": {"kind": "pd"}, "actuator": {"t_max_nm": 1e7},
    "disturbances": {"environment_nm": [1e6, 1e6, 1e6]},
}  # fmt: skip


def test_a_diverging_slew_keeps_its_history_and_metrics_of_its_finite_part(nominal_plant, tmp_path):
    from flexsat.simulate import SlewScenario
    from flexsat.study.outputs import fly_slew

    scenario = validate_config(_HUGE_DISTURBANCE, model=SlewScenario)
    result, metrics = fly_slew(nominal_plant, scenario, tmp_path, progress=False)
    stored = json.loads((tmp_path / "metrics.json").read_text())
    history = Result.from_netcdf(tmp_path / "result.nc").dataset
    assert not result.ok and "non-finite" in result.message
    assert stored["status"] == "failed" and stored["finite_until_s"] <= history["time"][-1]
    assert 0.0 < stored["finite_until_s"] < 0.1
    assert not stored["r1_pass"] and not stored["r2_pass"]  # stopped before the window
    # NaN is a quantity that does not exist (a settling time, the APE of a window the run
    # never reached); nothing is infinite: the metrics read the finite records only.
    numbers = [
        v
        for value in metrics.values()
        for v in (value if isinstance(value, list) else [value])
        if isinstance(v, float)
    ]
    assert not any(math.isinf(v) for v in numbers)
    assert math.isnan(metrics["ape_deg"]) and math.isnan(metrics["settling_time_s"])


# DOP853 on a diverging run: the child process builds the plant and compiles first
# (its "ready" line), then flies 1e9, 1e12 and 1e200 N m about Z; the adaptive steps
# shrink as the hub spins up until they fall below 1e-2 dt_s (1e9, 1e12) or the first
# step fails (1e200). It must stop with its history instead of stepping on (it ran
# past 60 s at 1e9 and 120 s at 1e12 before) or raising (1e200).
_DOP853_CHILD = """
import json, sys
from flexsat import Plant, load_config
from flexsat.config import validate_config
from flexsat.simulate import OpenLoopScenario
from flexsat.simulate.openloop import run_openloop

plant = Plant.from_config(load_config())
def scenario(torque, duration):
    return validate_config({"solver": "dop853", "duration_s": duration,
                            "torque": [{"start_s": 0.0, "torque_nm": [0, 0, torque]}]},
                           model=OpenLoopScenario)
run_openloop(plant, scenario(1.0, 0.05), progress=False)  # compile and warm up
print("ready", flush=True)
out = []
for torque in (1e9, 1e12, 1e200):
    ds = run_openloop(plant, scenario(torque, 20.0), progress=False).dataset
    out.append({"torque": torque, "status": ds.attrs["status"], "message": ds.attrs["message"],
                "failure_time_s": ds.attrs["failure_time_s"], "records": ds.sizes["time"],
                "t_last": float(ds["time"].values[-1])})
print(json.dumps(out), flush=True)
"""


def test_dop853_stops_a_diverging_run_with_its_history():
    import select
    import subprocess
    import sys

    child = subprocess.Popen([sys.executable, "-c", _DOP853_CHILD], stdout=subprocess.PIPE,
                             stderr=subprocess.PIPE, text=True)  # fmt: skip
    try:
        ready, _, _ = select.select([child.stdout], [], [], 600)  # start-up: compile, load
        assert ready and child.stdout.readline().strip() == "ready", child.stderr.read()
        # The bound of the three diverging runs: a hang is a failure, not a slow pass.
        out, err = child.communicate(timeout=10)
    except subprocess.TimeoutExpired:
        child.kill()
        child.communicate()
        pytest.fail("DOP853 on a diverging run did not stop within 10 s")
    assert child.returncode == 0, err
    for run in json.loads(out):
        assert run["status"] == "failed", run
        t_fail = run["failure_time_s"]
        assert 0.0 <= t_fail < 20.0 and f"stopped at t = {t_fail:.6g} s" in run["message"], run
        assert run["records"] >= 1 and run["t_last"] == pytest.approx(t_fail), run
    stopped = {run["torque"]: run["message"] for run in json.loads(out)}
    assert "adaptive step fell below 1e-2 of dt_s" in stopped[1e9]
    assert "adaptive step fell below 1e-2 of dt_s" in stopped[1e12]
    assert "non-finite" in stopped[1e200]
