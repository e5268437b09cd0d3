"""Campaigns: the thesis's conclusions, backends, interruption, failures, bad input."""

from __future__ import annotations

import json
import signal
import subprocess
import sys
import time

import pandas as pd
import pytest

from flexsat.campaigns import (
    CAMPAIGN_PRESETS,
    CampaignDefinition,
    CampaignStore,
    load_campaign,
    resolve_cases,
    run_campaign,
    summarize,
)
from flexsat.cli.tables import format_number
from flexsat.config import nominal, validate_config
from flexsat.errors import ConfigError

# Columns that legitimately differ between two runs of the same case.
TIMING = ["case_wall_time_s", "case_cpu_time_s"]


def _table(store):
    return pd.read_parquet(store / "results.parquet").drop(columns=TIMING)


def _short(name: str, duration: float) -> CampaignDefinition:
    data = load_campaign(name).model_dump(mode="json")
    data["base"] = {**data["base"], "duration_s": duration}
    return validate_config(data, model=CampaignDefinition)


@pytest.mark.parametrize(
    ("name", "count"),
    [("sensitivity", 12), ("montecarlo-critical", 25), ("deployment-shock", 32)],
)
def test_presets_expand_to_the_thesis_case_counts(name, count):
    # docs/campaigns.md: 11 one-at-a-time cases + nominal; 24 crossed corners + nominal
    # ('The critical-case set'); 8 rate vectors x 4 deformations ('The deployment-shock set').
    assert len(resolve_cases(load_campaign(name), nominal())) == count


def test_every_case_keeps_the_base_configurations_design_model():
    # Uncertainty cases perturb the truth plant only: the controller of every case
    # is designed for the base configuration (its rigidized J_tot), stated in the
    # case's scenario so a replay uses it too.
    from flexsat.simulate import design_inertia

    cases = resolve_cases(load_campaign("sensitivity"), nominal())
    plants = {json.dumps(case.plant, sort_keys=True) for case in cases}
    assert len(plants) == len(cases)  # every case is another truth plant
    for case in cases:
        assert case.scenario["design_inertia_kg_m2"] == design_inertia(nominal()).tolist()


def test_random_campaign_is_seeded_and_sized_from_the_cli():
    a = resolve_cases(load_campaign("montecarlo-random"), nominal(), n_random=4)
    b = resolve_cases(load_campaign("montecarlo-random"), nominal(), n_random=6)
    assert len(a) == 5 and len(b) == 7  # plus the nominal
    # per-case streams: the first cases do not depend on how many are drawn
    assert [c.parameters for c in a] == [c.parameters for c in b[:5]]
    assert a[1].parameters != a[2].parameters
    for case in a[1:]:
        factor = case.parameters["appendages[0].target_frequencies_hz.flapping"]
        assert 0.8 <= factor <= 1.2  # truncated normal bounds


@pytest.fixture(scope="module")
def thesis_campaigns(tmp_path_factory):
    """The three thesis campaigns at full length (120 s each case), 2 local workers."""
    stores = {}
    for name in ("sensitivity", "montecarlo-critical", "deployment-shock"):
        store = tmp_path_factory.mktemp(name)
        run_campaign(load_campaign(name), nominal(), store, workers=2, progress=False)
        stores[name] = store
    return stores


@pytest.mark.parametrize("name", ["sensitivity", "montecarlo-critical"])
def test_parametric_uncertainty_cases_meet_r1_and_r2(thesis_campaigns, name):
    # Thesis sections 5.2.1-5.2.2: every case reaches the target within R1 and R2.
    summary = summarize(thesis_campaigns[name])
    assert summary["failed"] == 0
    assert summary["r1_pass_rate"] == 1.0
    assert summary["r2_pass_rate"] == 1.0
    assert summary["r3_pass_rate"] == 1.0


def test_deployment_shock_stays_stable_and_meets_r1(thesis_campaigns):
    # Thesis section 5.3: no case goes unstable and R1 is met; R2 "is not satisfied
    # during the first 120 seconds" there. Judged over the 90-120 s window, 13 of
    # the 32 cases meet R2 (24 would, judged on the last sample alone); we report
    # the rate rather than assert it (docs/control.md).
    summary = summarize(thesis_campaigns["deployment-shock"])
    assert summary["failed"] == 0
    assert summary["r1_pass_rate"] == 1.0
    assert summary["r3_pass_rate"] == 1.0
    assert 0.0 <= summary["r2_pass_rate"] <= 1.0


def test_rows_carry_the_verdicts_over_the_window(thesis_campaigns):
    # Each row states its observation window and its APE/RPE, and its R2 verdict
    # is the residual rate's maximum over that window, not its last sample.
    rows = CampaignStore(thesis_campaigns["deployment-shock"]).rows()
    rates = summarize(thesis_campaigns["deployment-shock"])["r2_pass_rate"]
    assert rates == sum(r["metrics"]["max_rate_error_deg_s"] < 1e-3 for r in rows) / len(rows)
    for row in rows:
        metrics = row["metrics"]
        assert metrics["observation_window_s"] == [90.0, 120.0]
        assert metrics["ape_deg"] >= metrics["final_pointing_error_deg"]
        assert metrics["rpe_deg"] >= 0.0
        assert metrics["r1_pass"] == (metrics["ape_deg"] < 0.05)


def test_serial_pool_ensemble_and_dask_give_identical_rows(tmp_path):
    # Bit for bit: the ensemble (threads, one compiled call per batch; every Dask task
    # is one) flies the same compiled chunks as a case alone.
    definition = _short("sensitivity", 5.0)
    run_campaign(definition, nominal(), tmp_path / "local", workers=2, progress=False)
    run_campaign(definition, nominal(), tmp_path / "serial", workers=1, progress=False)
    run_campaign(definition, nominal(), tmp_path / "ensemble", workers=2, runner="ensemble",
                 progress=False)  # fmt: skip
    run_campaign(definition, nominal(), tmp_path / "dask", dask_local=2, progress=False)
    local = _table(tmp_path / "local")
    pd.testing.assert_frame_equal(local, _table(tmp_path / "serial"))
    pd.testing.assert_frame_equal(local, _table(tmp_path / "ensemble"))
    pd.testing.assert_frame_equal(local, _table(tmp_path / "dask"))
    with pytest.raises(ConfigError, match="runner: 'threads' is not one of pool, ensemble"):
        run_campaign(definition, nominal(), tmp_path / "bad", runner="threads", progress=False)


def test_dask_tasks_batch_cases_but_every_worker_thread_gets_several():
    # At most DASK_BATCH cases per task (a task's overhead paid once per batch), and
    # never so many that a worker thread has fewer than four tasks of the campaign: a
    # worker lost mid-run then loses a task another re-runs, not its whole share (the
    # real cluster's kill test flies 12 cases on two workers: one case per task).
    from flexsat.campaigns.backends import DASK_BATCH, _dask_batch

    assert _dask_batch(1000, 2) == DASK_BATCH == 32
    assert _dask_batch(12, 2) == 1 and _dask_batch(69, 2) == 8 and _dask_batch(0, 4) == 1
    assert all(size // _dask_batch(size, 2) >= 8 for size in range(8, 257))
    # The batches of a 1000-case campaign on two threads, as _dask submits them: full
    # while plenty remain, then shrinking to single cases, so the workers' last tasks
    # end together; every case is submitted once.
    batches, remaining = [], 1000
    while remaining:
        batches.append(_dask_batch(remaining, 2))
        remaining -= batches[-1]
    assert batches[:24] == [32] * 24 and batches[-8:] == [1] * 8
    assert sum(batches) == 1000 and batches == sorted(batches, reverse=True)


def test_kill_and_resume_loses_nothing_and_recomputes_nothing(tmp_path):
    store = tmp_path / "killed"
    command = [
        sys.executable, "-m", "flexsat", "campaign", "sensitivity", "--duration", "20",
        "--workers", "1", "--out", str(store), "--json",
    ]  # fmt: skip
    process = subprocess.Popen(command, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    deadline = time.monotonic() + 240
    cases = store / "cases"
    while time.monotonic() < deadline:
        if cases.exists() and len(list(cases.glob("*.json"))) >= 3:
            break
        time.sleep(0.05)
    process.send_signal(signal.SIGKILL)
    process.wait()
    before = {p.name: p.stat().st_mtime_ns for p in cases.glob("*.json")}
    assert 3 <= len(before) < 12
    assert not list(cases.glob("*.partial"))  # nothing half-written was left as a case
    summary = run_campaign(
        _short("sensitivity", 20.0), nominal(), store, workers=1, resume=True, progress=False
    )
    assert summary["ran"] == 12 - len(before)  # only the missing cases ran
    after = {p.name: p.stat().st_mtime_ns for p in cases.glob("*.json")}
    assert all(after[name] == stamp for name, stamp in before.items())
    reference = tmp_path / "uninterrupted"
    run_campaign(_short("sensitivity", 20.0), nominal(), reference, workers=1, progress=False)
    pd.testing.assert_frame_equal(_table(store), _table(reference))


def test_failed_case_is_recorded_and_the_campaign_finishes(tmp_path):
    path = tmp_path / "stiff.toml"
    path.write_text(
        'name = "with-a-bad-case"\n'
        "[base]\nduration_s = 5.0\ndt_s = 0.002\ncontrol_dt_s = 0.002\n"
        '[[cases]]\nid = "stiff"\n'
        'plant = [{ path = "appendages[*].target_frequencies_hz.translation_x", value = 3000.0 }]\n'
    )
    summary = run_campaign(
        load_campaign(path), nominal(), tmp_path / "s", workers=1, progress=False
    )
    assert summary["cases"] == 2 and summary["failed"] == 1
    rows = {
        r["case_id"]: r
        for r in (json.loads(p.read_text()) for p in (tmp_path / "s" / "cases").glob("*.json"))
    }
    assert rows["stiff"]["status"] == "failed"
    assert "stopped at t =" in rows["stiff"]["error"]
    assert rows["nominal"]["status"] == "ok"


def test_resuming_into_another_campaign_is_refused(tmp_path):
    run_campaign(_short("sensitivity", 1.0), nominal(), tmp_path, workers=1, progress=False)
    with pytest.raises(ConfigError, match="the campaign definition"):
        run_campaign(_short("sensitivity", 2.0), nominal(), tmp_path, resume=True, progress=False)
    with pytest.raises(ConfigError, match="use --resume"):
        run_campaign(_short("sensitivity", 1.0), nominal(), tmp_path, progress=False)


BAD_CAMPAIGNS = [
    ('[[cases]]\nid = "a"\nplant = [{ path = "hub.colour", value = 1.0 }]\n', "no 'colour'"),
    (
        '[[cases]]\nid = "a"\nplant = [{ path = "hub.mass_kg", uniform = [2.0, 2.0] }]\n',
        "low < high",
    ),
    (
        '[[cases]]\nid = "a"\nplant = [{ path = "hub.mass_kg", truncnormal = [1.0, 0.1, 2.0, 1.0] }]\n',
        "low < high",
    ),
    (
        '[[cases]]\nid = "a"\nplant = [{ path = "hub.mass_kg", value = -5.0 }]\n',
        "hub.mass_kg: Input should be greater than or equal to 0.0001",
    ),
    ("[random]\nn = -3\n", "random.n"),
    ("[base]\ndt_s = -1.0\n", "dt_s"),
    # initial states the satellite cannot take, refused before any case flies
    (
        '[[cases]]\nid = "a"\nscenario = [{ path = "initial.appendages", value = [{ name = "boom" }] }]\n',
        "case 'a' (scenario): initial.appendages: ",
    ),
    (
        '[[cases]]\nid = "a"\nplant = [{ path = "appendages[*].locked_dofs", value = ["eta_x"] }]\nscenario = [{ path = "initial.appendages", value = [{ name = "panel_1", eta_rate_m_s = [0.1, 0.0, 0.0] }] }]\n',
        "its initial rate must be 0",
    ),
    # a modifier's value checked against its target before any case runs
    (
        '[[cases]]\nid = "a"\nplant = [{ path = "hub.mass_kg", op = "scale", value = "x" }]\n',
        "hub.mass_kg: op = 'scale' takes a finite number as its factor (value), got 'x'",
    ),
    (
        '[[cases]]\nid = "a"\nplant = [{ path = "hub.inertia", op = "scale", value = "x" }]\n',
        "hub.inertia: op = 'scale' takes a finite number as its factor",
    ),
    (
        '[[cases]]\nid = "a"\nplant = [{ path = "hub.inertia", value = "x" }]\n',
        "modifier 'hub.inertia' (op = 'set'): hub.inertia takes a finite number (a scale factor",
    ),
    (
        '[[cases]]\nid = "a"\nplant = [{ path = "appendages[*].inertia", value = [1.0, 2.0] }]\n',
        "appendages[0].inertia takes a finite number",
    ),
    (
        '[[cases]]\nid = "a"\nplant = [{ path = "hub.mass_kg", uniform = [0.8, inf] }]\n',
        "uniform takes finite numbers",
    ),
    (
        '[[cases]]\nid = "a"\nplant = [{ path = "hub.mass_kg", op = "scale", uniform = [-1e308, 1e308] }]\n',
        "is wider than a float holds: high - low must be <= 1.798e+308",
    ),
    (
        '[[cases]]\nid = "a"\nplant = [{ path = "hub.mass_kg", normal = [1.0, 1e307] }]\n',
        "|mean| + 40 std must be <= 1.798e+308",
    ),
    (
        '[[cases]]\nid = "a"\nplant = [{ path = "appendages[0].name", op = "scale", value = 3 }]\n',
        "appendages[0].name is 'panel_1', not a number or a list of numbers",
    ),
    (
        '[worst_case]\nparameters = [{ path = "hub.mass_kg", bounds = [1.0, inf] }]\n',
        "bounds take finite numbers",
    ),
    # the search's metric at load, not after its cases ran; duplicate ids by name
    (
        '[worst_case]\nmetric = "happiness"\nparameters = [{ path = "hub.mass_kg", bounds = [100.0, 200.0] }]\n',
        "worst_case.metric: 'happiness' is not a numeric slew metric; one of final_pointing_error_deg",
    ),
    ('[[cases]]\nid = "a"\n[[cases]]\nid = "a"\n', "duplicate case ids: 'a'"),
    ('[random]\nn = 3\n[[cases]]\nid = "random-00002"\n', "duplicate case ids: 'random-00002'"),
]


@pytest.mark.parametrize(("body", "fragment"), BAD_CAMPAIGNS)
def test_bad_campaign_files_are_refused_before_any_case_runs(tmp_path, body, fragment):
    path = tmp_path / "bad.toml"
    path.write_text('name = "bad"\n' + body)
    with pytest.raises(ConfigError) as caught:
        resolve_cases(load_campaign(path), nominal())
    assert fragment in str(caught.value)
    assert not (tmp_path / "out").exists()


def test_deployment_shock_on_modal_appendages_is_refused_before_any_case_runs():
    # A modal appendage has no root deformation to set: every deployment-shock case
    # would fail as it starts; the campaign is refused whole, naming the case.
    from flexsat import Plant
    from flexsat.linear.export import modal_satellite

    satellite = modal_satellite(Plant.from_config(nominal()), n_modes=2)
    with pytest.raises(ConfigError, match=r"case '.+' \(scenario\): .*no initial state to set"):
        resolve_cases(load_campaign("deployment-shock"), satellite)


def test_negative_case_count_is_refused():
    with pytest.raises(ConfigError, match="--cases must be >= 1"):
        resolve_cases(load_campaign("montecarlo-random"), nominal(), n_random=-1)


def test_every_preset_is_listed_and_loads():
    for name in CAMPAIGN_PRESETS:
        assert load_campaign(name).name == name


def test_cli_campaign_json(tmp_path):
    result = subprocess.run(
        [sys.executable, "-m", "flexsat", "campaign", "montecarlo-random", "--cases", "2",
         "--duration", "2", "--workers", "1", "--out", str(tmp_path), "--json"],
        capture_output=True, text=True, timeout=300,
    )  # fmt: skip
    assert result.returncode == 0, result.stderr
    summary = json.loads(result.stdout)
    for key in ("cases", "failed", "r1_pass_rate", "r2_pass_rate", "r3_pass_rate",
                "worst_final_pointing_error_deg", "computed_this_run", "resumed_this_run",
                "cpu_time_s", "campaign_wall_time_s", "run_wall_time_s"):  # fmt: skip
        assert key in summary
    assert summary["cases"] == 3
    # --cases 2 of a campaign with the nominal: 3 cases, and the summary says why
    assert summary["cases_text"] == "3 cases: 2 drawn + the nominal"
    replay = subprocess.run(
        [sys.executable, "-m", "flexsat", "campaign", "replay", str(tmp_path), "random-00001"],
        capture_output=True, text=True, timeout=300,
    )  # fmt: skip
    assert replay.returncode == 0, replay.stderr
    assert (tmp_path / "replays" / "random-00001.nc").exists()
    # The replay prints the case's metrics, those the store holds for it.
    stored = json.loads((tmp_path / "cases" / "random-00001.json").read_text())["metrics"]
    assert "r1_pass" in replay.stdout and "final_pointing_error_deg" in replay.stdout
    # (printed as every table prints a number: flexsat.cli.tables.format_number)
    assert format_number(stored["final_pointing_error_deg"]) in replay.stdout
