"""The super-twisting and integral sliding modes fly the thesis slew and campaigns.

Both are registered built-ins: the compiled loop, ``flexsat slew --controller``,
the comparison of ``--controller all`` and the campaigns find them by name.
"""

from __future__ import annotations

import json
import subprocess
import sys

import numpy as np
import pandas as pd
import pytest

from flexsat import nominal
from flexsat.analysis.requirements import slew_metrics
from flexsat.campaigns import load_campaign
from flexsat.campaigns.definition import CampaignDefinition
from flexsat.campaigns.runner import run_campaign, summarize
from flexsat.config import validate_config
from flexsat.control import target_quaternion
from flexsat.control.laws import CompiledLaw
from flexsat.simulate import SlewScenario, design_inertia, run_slew

FLEXSAT = [sys.executable, "-m", "flexsat"]
NEW_LAWS = ("stsmc", "ismc")


def _flexsat(*args: str) -> subprocess.CompletedProcess:
    return subprocess.run([*FLEXSAT, *args], capture_output=True, text=True, timeout=300)


@pytest.mark.parametrize(
    ("kind", "settling_s", "final_deg"),
    # Measured on the nominal case (120 s, RK4 1 ms): R1 from 30.95 s (STSMC) and
    # 62.50 s (ISMC), final errors 5.9e-7 and 2.7e-5 deg; the bounds leave 10 % on
    # the settling times and a decade on the errors (R1 is 0.05 deg).
    [("stsmc", 34.0, 1e-5), ("ismc", 69.0, 3e-4)],
)
def test_law_flies_the_thesis_slew_in_the_compiled_loop(nominal_plant, kind, settling_s,
                                                        final_deg):  # fmt: skip
    scenario = SlewScenario.model_validate({"controller": {"kind": kind}})
    ds = run_slew(nominal_plant, scenario).dataset
    assert ds.attrs["status"] == "ok" and ds.attrs["controller"] == kind
    metrics = slew_metrics(ds)
    assert metrics["r1_pass"] and metrics["r2_pass"] and metrics["r3_pass"]
    assert metrics["settling_time_s"] < settling_s
    assert metrics["final_pointing_error_deg"] < final_deg
    assert ds["sliding_variable"].attrs["units"] == "rad/s"
    assert ds.attrs["surface_lambda_min_rad_s"] == scenario.controller.lambda_


def test_cli_flies_each_new_law_and_compares_them_with_all(tmp_path):
    short = tmp_path / "short.toml"  # a 2 s run holds its observation window
    short.write_text("duration_s = 2.0\n[requirements]\nsettling_deadline_s = 1.0\n")
    for kind in NEW_LAWS:
        result = _flexsat("slew", "--scenario", str(short), "--controller", kind, "--json")
        assert result.returncode == 0, result.stderr
        assert json.loads(result.stdout)["controller"] == kind
    result = _flexsat("slew", "--scenario", str(short), "--controller", "all", "--json")
    assert result.returncode == 0, result.stderr
    assert set(NEW_LAWS) <= set(json.loads(result.stdout))


def test_cli_refuses_a_gain_that_breaks_the_lyapunov_condition(tmp_path):
    path = tmp_path / "slew.toml"
    path.write_text('[controller]\nkind = "stsmc"\nc1 = 1.0\nc2 = 2.5\n')
    result = _flexsat("slew", "--scenario", str(path), "--duration", "1")
    assert result.returncode == 2
    assert "c2 must be > 1 + 2 / c1^2 = 3" in result.stderr
    assert "Traceback" not in result.stderr and len(result.stderr.strip().splitlines()) == 1


@pytest.mark.parametrize("kind", NEW_LAWS)
def test_law_meets_r1_r2_r3_in_the_sensitivity_campaign(tmp_path, kind):
    # The thesis's sensitivity campaign (sec. 5.2.1), each case cut to 95 s: both
    # laws have settled by the window's start, 90 s, in every case (the slowest, ISMC,
    # meets R2 from 77 s on the nominal case), and R1 and R2 are judged over 90-95 s
    # (a run ending at 90 s would leave the window empty: not judged). Full-length
    # pass rates are in docs/control.md.
    data = load_campaign("sensitivity").model_dump(mode="json")
    data["base"] = {**data["base"], "duration_s": 95.0, "controller": {"kind": kind}}
    definition = validate_config(data, source=kind, model=CampaignDefinition)
    run_campaign(definition, nominal(), tmp_path, workers=2, progress=False)
    summary = summarize(tmp_path)
    assert summary["cases"] == 12 and summary["failed"] == 0
    assert summary["r1_not_judged"] == summary["r2_not_judged"] == 0
    assert (summary["r1_pass_rate"], summary["r2_pass_rate"], summary["r3_pass_rate"]) == (
        1.0, 1.0, 1.0,
    )  # fmt: skip
    assert np.isfinite(summary["worst_final_pointing_error_deg"])


def test_stsmc_meets_r2_after_the_deployment_shock(tmp_path):
    # Thesis section 5.3: the ASMC never meets R2 within 120 s after the shock (here
    # 24 of 32 cases by the last sample, R2 held from 45.5-120 s). The STSMC holds R2
    # from 40.6-44.3 s in all 32 (measured); bound 60 s, a third of margin.
    data = load_campaign("deployment-shock").model_dump(mode="json")
    data["base"] = {**data["base"], "controller": {"kind": "stsmc"}}
    definition = validate_config(data, source="stsmc", model=CampaignDefinition)
    stored = run_campaign(definition, nominal(), tmp_path, workers=2, progress=False)
    summary = summarize(tmp_path)
    assert summary["cases"] == 32 and summary["failed"] == 0
    assert summary["r1_pass_rate"] == summary["r2_pass_rate"] == summary["r3_pass_rate"] == 1.0
    rows = pd.read_parquet(stored["parquet"])
    assert rows["metrics.r2_settling_time_s"].max() < 60.0


@pytest.mark.parametrize("kind", NEW_LAWS)
def test_python_callback_path_reproduces_the_compiled_loop(nominal_plant, kind):
    # The same compiled step called from Python (CompiledLaw) keeps its own state
    # between calls as the loop does: the same slew to round-off.
    scenario = SlewScenario.model_validate({"duration_s": 5.0, "controller": {"kind": kind}})
    compiled = run_slew(nominal_plant, scenario).dataset
    law = CompiledLaw(
        scenario.controller,
        scenario.actuator,
        design_inertia(),
        target_quaternion(scenario.target_euler_deg),
        scenario.control_dt_s,
    )
    python = run_slew(nominal_plant, scenario, controller=law).dataset  # fmt: skip
    np.testing.assert_allclose(python["q"].values, compiled["q"].values, rtol=0, atol=1e-12)
