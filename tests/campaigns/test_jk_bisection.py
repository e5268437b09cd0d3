"""The JK_min bisection (flexsat.campaigns.jk_bisection) at reduced size: three of the
critical cases on the reduced model, three halvings, against the analytical estimate.

The full run (24 cases, full model, eight halvings) is bench/bench_jk_min.py."""

from __future__ import annotations

import numpy as np
import pytest

from flexsat.analysis.requirements import NotJudgedWarning
from flexsat.campaigns import CampaignStore, resolve_cases
from flexsat.campaigns.definition import CampaignDefinition, Reduced
from flexsat.campaigns.jk_bisection import bisect_jk_min, with_jk_min
from flexsat.config import nominal, validate_config
from flexsat.config.models import SatelliteConfig
from flexsat.errors import ConfigError
from flexsat.simulate import SlewScenario
from flexsat.simulate.robustness_gain import jk_min_estimate

# The three critical corners whose R2 settling is slowest (hub +20 %, panel -20 %,
# frequencies -20 %, zeta = 0; docs/control.md, 'The minimum robustness gain JK_min'),
# one per SADM angle, 120 s slews (R2's window starts at 90 s).
THREE = {
    "name": "jk-three",
    "include_nominal": False,
    "base": {"duration_s": 120.0},
    "reduced": Reduced().model_dump(mode="json"),
    "grid": {
        "common": {"label": "zeta0", "plant": [
            {"path": "appendages[*].damping_ratio", "value": 0.0},
            {"path": "hub.inertia", "value": 1.2},
            {"path": "appendages[*].inertia", "value": 0.8},
            {"path": "appendages[*].target_frequencies_hz.flapping", "op": "scale", "value": 0.8},
            {"path": "appendages[*].target_frequencies_hz.in_plane", "op": "scale", "value": 0.8},
            {"path": "appendages[*].target_frequencies_hz.torsion", "op": "scale", "value": 0.8},
        ]},
        "axes": [{"name": "sadm", "levels": [
            {"label": f"sadm{a}", "plant": [{"path": "appendages[*].sadm_angle_deg", "value": a}]}
            for a in (0, 45, 90)]}],
    },
}  # fmt: skip
LOW, HIGH, STEPS = 0.01, 0.8925, 3


@pytest.fixture(scope="module")
def three() -> CampaignDefinition:
    return validate_config(THREE, model=CampaignDefinition)


@pytest.fixture(scope="module")
def stores(tmp_path_factory):
    return tmp_path_factory.mktemp("jk")


@pytest.fixture(scope="module")
def bisection(three, stores):
    return bisect_jk_min(three, nominal(), stores, LOW, HIGH, STEPS)


def test_bisection_brackets_the_first_passing_gain(bisection):
    assert bisection.found
    assert len(bisection.steps) == 2 + STEPS  # the two ends, then one campaign per halving
    assert [s.cases for s in bisection.steps] == [3] * (2 + STEPS)
    high, low = bisection.steps[:2]
    assert high.jk_min_nm == HIGH and high.passed  # the thesis's 0.8925 N m holds them
    assert low.jk_min_nm == LOW and not low.passed
    # Each halving keeps the bracket: what passed is at or above its top, what failed
    # at or below its bottom, and it ends (HIGH - LOW) / 2^STEPS wide (exact: halvings).
    for step in bisection.steps:
        assert step.jk_min_nm >= bisection.high_nm if step.passed else (
            step.jk_min_nm <= bisection.low_nm)  # fmt: skip
    assert bisection.high_nm - bisection.low_nm == pytest.approx((HIGH - LOW) / 2**STEPS,
                                                                 rel=1e-12)  # fmt: skip
    assert bisection.jk_min_nm == bisection.high_nm


def test_failing_steps_miss_r2_only(bisection, stores):
    # Every failing step's cases keep R1 and R3 and miss R2 (the residual rate of the
    # undamped panels is not below 1e-3 deg/s by 90 s): the requirement that binds.
    failed = [step for step in bisection.steps if not step.passed]
    assert failed
    for step in failed:
        rows = {r["case_id"]: r for r in CampaignStore(stores / f"jk-{step.jk_min_nm:.6f}").rows()}
        for case_id in step.failing:
            metrics = rows[case_id]["metrics"]
            assert rows[case_id]["status"] == "ok"
            assert metrics["r1_pass"] and metrics["r3_pass"] and not metrics["r2_pass"]


def test_estimate_is_above_the_bisected_gain(three, bisection):
    # The estimate bounds the lumped disturbance for s^T J s_dot < 0 at every instant
    # (sufficient); the bisection finds what R1-R3 need: the estimate must not be below
    # it, on every axis.
    satellite = nominal()
    truth = [validate_config(c.plant, model=SatelliteConfig)
             for c in resolve_cases(three, satellite)]  # fmt: skip
    estimate = jk_min_estimate(satellite, SlewScenario(), truth)
    assert np.all(estimate.jk_min_nm >= bisection.jk_min_nm)


def test_refusals(three, tmp_path):
    with pytest.raises(ConfigError, match="low_nm"):
        bisect_jk_min(three, nominal(), tmp_path, 0.5, 0.4)
    with pytest.raises(ConfigError, match="steps"):
        bisect_jk_min(three, nominal(), tmp_path, 0.1, 0.4, steps=-1)
    with pytest.raises(ConfigError, match="jk_min_nm"):
        with_jk_min(three, 0.0)
    pd = validate_config({**THREE, "base": {"controller": {"kind": "pd"}}},
                         model=CampaignDefinition)  # fmt: skip
    with pytest.raises(ConfigError, match=r"base\.controller\.kind"):
        with_jk_min(pd, 0.3)
    flown = with_jk_min(three, 0.3)
    assert flown.base["controller"] == {"kind": "asmc", "jk_min_nm": 0.3}
    assert flown.grid == three.grid and flown.reduced == three.reduced


def test_a_kind_registered_outside_flexsat_keeps_its_cases(tmp_path):
    # The copy keeps the table of a kind registered by a user's module (other_kinds,
    # which a dump of the definition leaves out): the same cases, another gain.
    from flexsat.campaigns import load_campaign
    from flexsat.campaigns.definition import CaseStream
    from flexsat.campaigns.kinds import KINDS, register_kind
    from tests.campaigns import corners_kind

    register_kind(corners_kind.CORNERS)
    try:
        path = tmp_path / "corners.toml"
        path.write_text('name = "corners-jk"\ninclude_nominal = false\n[corners]\nparameters = '
                        '[{path = "hub.mass_kg", bounds = [120.0, 180.0]}]\n')  # fmt: skip
        definition = load_campaign(path)
        flown = with_jk_min(definition, 0.3)
        assert flown.tables() == definition.tables() and list(flown.tables()) == ["corners"]
        cases = list(CaseStream(flown, nominal()))
        assert len(cases) == 2
        assert {c.scenario["controller"]["jk_min_nm"] for c in cases} == {0.3}
    finally:
        KINDS.unregister("corners")


def test_a_campaign_not_judged_is_refused_before_it_flies(three, tmp_path):
    # 60 s runs end before the 90 s window opens: no verdict to bisect on
    short = three.model_copy(update={"base": {"duration_s": 60.0}})
    with pytest.raises(ConfigError) as refused:
        bisect_jk_min(short, nominal(), tmp_path / "out", LOW, HIGH, 0)
    assert str(refused.value) == (
        "duration_s: R1 and R2 are not judged in every case: the run ends at 60 s, before "
        "the observation window starts at 90 s (requirements.settling_deadline_s); the "
        "JK_min bisection needs judged runs: give duration_s past the end of the "
        "observation window (requirements.settling_deadline_s, window_end_s)"
    )
    assert not (tmp_path / "out").exists()  # refused before any campaign ran


def test_a_case_not_judged_is_refused_once_flown(tmp_path):
    # The base is judged (window 0.2-0.5 s); one case's own deadline, 1 s, is after
    # its 0.5 s run: the first campaign flown shows it, and the bisection stops there.
    data = {"name": "jk-late", "base": {"duration_s": 0.5,
                                        "requirements": {"settling_deadline_s": 0.2}},
            "reduced": Reduced().model_dump(mode="json"),
            "cases": [{"id": "late", "scenario": [
                {"path": "requirements.settling_deadline_s", "value": 1.0}]}]}  # fmt: skip
    definition = validate_config(data, model=CampaignDefinition)
    refused = pytest.raises(
        ConfigError,
        match=r"R1 and R2 are not judged in case 'late': the "
        r"run ends at 0.5 s, before the observation window starts at 1 s",
    )
    with refused, pytest.warns(NotJudgedWarning, match="not judged in 1 of the first 2 cases"):
        bisect_jk_min(definition, nominal(), tmp_path, LOW, HIGH, 0)
