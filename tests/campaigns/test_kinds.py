"""Campaign kinds: the registry the definition, the runner and the summary look up."""

from __future__ import annotations

import pytest

from flexsat.campaigns import kind_names, load_campaign, run_campaign, summarize
from flexsat.campaigns.definition import CaseStream, describe_counts
from flexsat.campaigns.kinds import KINDS, CampaignKind, register_kind
from flexsat.config import nominal
from flexsat.errors import ConfigError

TOY = """
name = "corners-toy"
include_nominal = false
base = {duration_s = 0.2}

[corners]
parameters = [
  {path = "hub.mass_kg", bounds = [120.0, 180.0]},
  {path = "appendages[*].sadm_angle_deg", bounds = [0.0, 90.0]},
]
"""


@pytest.fixture
def corners_kind():
    """The toy kind of tests/campaigns/corners_kind.py, registered for one test."""
    from tests.campaigns import corners_kind

    register_kind(corners_kind.CORNERS)  # the import registered it; again after a test
    yield corners_kind
    KINDS.unregister("corners")


def test_the_built_in_kinds_are_registered_in_order():
    # Registration order is the order the cases stream in: fixed kinds, then drawn ones.
    assert kind_names()[:5] == ("cases", "grid", "random", "sobol", "worst_case")


def test_a_kind_from_its_own_module_loads_and_runs_a_tiny_campaign(tmp_path, corners_kind):
    path = tmp_path / "corners.toml"
    path.write_text(TOY)
    definition = load_campaign(path)
    assert list(definition.tables()) == ["corners"]
    stream = CaseStream(definition, nominal())
    assert stream.counts()["corners"] == 4
    assert describe_counts(stream.counts()) == "4 cases: 4 corners"
    # corner 2 = 0b10: the hub mass at its low bound, the SADM angle at its high one
    corner = stream.head[2]
    assert corner.case_id == "corner-00002"
    assert corner.plant["hub"]["mass_kg"] == 120.0
    assert [a["sadm_angle_deg"] for a in corner.plant["appendages"]] == [90.0, 90.0]

    run = run_campaign(definition, nominal(), tmp_path / "store", workers=1, progress=False)
    assert run["cases"] == run["ran"] == 4 and run["case_counts"]["corners"] == 4
    summary = summarize(tmp_path / "store", definition)
    assert summary["cases"] == 4 and summary["corners"] == {"corners": 4}
    assert "corners" not in summarize(tmp_path / "store")  # the store alone: the common part


def test_an_unregistered_kind_table_is_refused(tmp_path):
    path = tmp_path / "corners.toml"
    path.write_text(TOY)
    with pytest.raises(ConfigError, match="corners"):
        load_campaign(path)


def test_a_search_runs_alone_whatever_kinds_are_registered():
    from flexsat.campaigns.definition import CampaignDefinition
    from flexsat.config import validate_config

    with pytest.raises(ConfigError, match="a worst_case search runs alone: no cases, grid"):
        validate_config({"name": "x", "grid": {"axes": [{"name": "a", "levels": [
            {"label": "l"}]}]}, "worst_case": {"parameters": [
            {"path": "hub.mass_kg", "bounds": [120.0, 180.0]}]}},
            model=CampaignDefinition)  # fmt: skip


def test_a_kind_must_generate_or_search():
    from flexsat.campaigns.definition import RandomCases

    with pytest.raises(ValueError, match="exactly one of cases and search"):
        register_kind(CampaignKind("nothing", RandomCases))
    with pytest.raises(ValueError, match="needs an id_prefix"):
        register_kind(CampaignKind("drawn", RandomCases, cases=lambda t, n: None, streamed=True))
    assert "nothing" not in kind_names() and "drawn" not in kind_names()


def test_a_bad_table_of_a_registered_kind_names_the_kind_and_its_field(tmp_path, corners_kind):
    path = tmp_path / "corners.toml"
    path.write_text(TOY.replace("parameters =", "parmeters ="))
    with pytest.raises(ConfigError, match=r"\[corners\]: .*unknown key 'parmeters'"):
        load_campaign(path)
