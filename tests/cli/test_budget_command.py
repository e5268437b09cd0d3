"""``flexsat budget`` on a real short slew's result.nc and on a campaign store."""

from __future__ import annotations

import csv
import json
import math

import numpy as np
import pytest
import xarray as xr

from flexsat.campaigns.store import CampaignStore
from flexsat.simulate import SlewScenario, run_slew
from tests.cli.harness import flexsat

START_S = 6.0  # [s] the judged span opens here: the 12 s slew's second half
REQUIREMENTS = f"""
[pointing]
confidence = 0.95
start_s = {START_S}
boresight = [0.0, 0.0, 1.0]

[pointing.indices.APE]
bound_deg = 60.0
[pointing.indices.RPE]
bound_deg = 0.5
window_s = 1.0
[pointing.indices.PDE]
bound_deg = 30.0
window_s = 1.0
stability_s = 2.0
[pointing.indices.AKE]
bound_deg = 0.01
[pointing.indices.RKE]
bound_deg = 0.01
window_s = 0.5

[[pointing.contributors]]
name = "star tracker"
kind = "random"
knowledge = true
sigma_deg = [0.0014, 0.0014, 0.0083]
"""


@pytest.fixture(scope="module")
def slew_nc(nominal_plant, tmp_path_factory):
    """A 12 s slew flown on the MEKF's estimate (gyro and star tracker), stored."""
    scenario = SlewScenario.model_validate({
        "duration_s": 12.0,
        "requirements": {"settling_deadline_s": START_S},
        "sensor_stages": [{"kind": "gyro", "sample_dt_s": 0.01},
                          {"kind": "star_tracker", "sample_dt_s": 0.1}, {"kind": "mekf"}],
    })  # fmt: skip
    folder = tmp_path_factory.mktemp("budget")
    path = run_slew(nominal_plant, scenario).to_netcdf(folder / "result.nc")
    (folder / "req.toml").write_text(REQUIREMENTS)
    return path, folder / "req.toml"


def _quantile(values: np.ndarray, p: float) -> float:
    """Order statistic ceil(p n) of the values, the estimate's definition."""
    ordered = np.sort(values)
    return float(ordered[math.ceil(p * ordered.size) - 1])


def test_budget_json_measures_the_slew(slew_nc, capsys):
    path, req = slew_nc
    outcome = flexsat(["budget", str(path), "--requirements", str(req), "--json"], capsys)
    assert outcome.code == 0, outcome.stderr
    report = json.loads(outcome.stdout)
    rows = {(r["index"], r["axis"]): r for r in report["measured"]}
    with xr.open_dataset(path) as ds:
        t = ds["time"].values
        keep = t >= START_S
        pointing = ds["pointing_error_deg"].values[keep]
        known = np.degrees(ds["estimation_error"].values[keep])
    # APE about the total axis: the stored 2 asin |q_v,e| against 2 atan2 of the same
    # quaternion, equal to round-off (1e-9 deg is 1e4 times the rounding of either)
    assert rows["APE", "total"]["value_deg"] == pytest.approx(_quantile(pointing, 0.95), abs=1e-9)
    # AKE: the MEKF's record itself; the same arithmetic, hence 1e-12 relative
    assert rows["AKE", "total"]["value_deg"] == pytest.approx(
        _quantile(np.linalg.norm(known, axis=1), 0.95), rel=1e-12
    )
    # RKE about x, window 0.5 s = 50 records: a loop over every record against the mean
    # of the window centred on it (records k - 25 .. k + 24), the vectorised sums'
    # round-off ~ n eps: 1e-9 relative
    n, x = 50, known[:, 0]
    loop = [
        abs(x[k] - x[k - n // 2 : k - n // 2 + n].mean())
        for k in range(n // 2, x.size - n // 2 + 1)
    ]
    assert rows["RKE", "x"]["value_deg"] == pytest.approx(_quantile(np.array(loop), 0.95), rel=1e-9)
    assert rows["RKE", "x"]["samples"] == len(loop)
    # the line of sight about +z: no larger than the total angle
    assert rows["APE", "los"]["value_deg"] <= rows["APE", "total"]["value_deg"] + 1e-12
    # the budget: the star tracker alone, n_0.95 sigma = 1.95996 x 0.0083 deg about z
    budget = {(r["index"], r["axis"]): r for r in report["budget"]}
    assert budget["AKE", "z"]["statistical_deg"] == pytest.approx(1.959964 * 0.0083, rel=1e-6)
    assert budget["AKE", "z"]["pass"] is False and budget["AKE", "x"]["pass"] is True
    assert budget["APE", "x"]["statistical_deg"] == 0.0  # no performance contributor
    assert report["pass"] is False


def test_budget_prints_tables_and_writes_json_and_csv(slew_nc, capsys, tmp_path):
    path, req = slew_nc
    out = tmp_path / "budget"
    outcome = flexsat(["budget", str(path), "--requirements", str(req), "--out", str(out)], capsys)
    assert outcome.code == 0, outcome.stderr
    assert "Measured on 1 run(s)" in outcome.stdout and "Budget at P = 0.95" in outcome.stdout
    assert "pointing requirements: FAIL" in outcome.stdout
    report = json.loads((out / "budget.json").read_text())
    with (out / "budget.csv").open() as handle:
        rows = list(csv.DictReader(handle))
    assert len(rows) == len(report["measured"]) + len(report["budget"])
    # 5 axes x 3 performance indices, 5 x 2 knowledge ones; 3 hub axes x 5 in the budget
    assert (len(report["measured"]), len(report["budget"])) == (25, 15)


def test_budget_on_a_campaign_store(tmp_path, capsys):
    # three stored cases at constant pointing errors 0.01, 0.02, 0.03 deg: the
    # ensemble's median (order statistic ceil(0.5 x 3) = 2) is 0.02 deg; the temporal
    # interpretation's worst run is the third, 0.03 deg
    store = CampaignStore(tmp_path / "store")
    t = np.arange(100) * 0.1
    for k, value in enumerate((0.01, 0.02, 0.03)):
        store.write_history(f"case{k}", {"time": t, "pointing_error_deg": np.full(t.size, value)})
    (store.root / "campaign.json").write_text(json.dumps({"name": "k"}))
    for interpretation, expected in (("ensemble", 0.02), ("temporal", 0.03), ("mixed", 0.02)):
        req = tmp_path / f"{interpretation}.toml"
        req.write_text(
            f'[pointing]\nconfidence = 0.5\ninterpretation = "{interpretation}"\n'
            "[pointing.indices.APE]\nbound_deg = 0.025\n"
        )
        outcome = flexsat(["budget", str(store.root), "--requirements", str(req), "--json"], capsys)
        assert outcome.code == 0, outcome.stderr
        (row,) = json.loads(outcome.stdout)["measured"]
        assert (row["axis"], row["value_deg"]) == ("total", expected)
        assert row["pass"] is (expected <= 0.025)
