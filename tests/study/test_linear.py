"""Loop margins written for the CLI, and over a campaign's cases."""

from __future__ import annotations

import json

import numpy as np
import pytest

from flexsat.config import nominal
from flexsat.dynamics.plant import Plant
from flexsat.errors import ConfigError
from flexsat.study.linear import family_margins, parse_about, parse_reduction, write_margins


@pytest.fixture(scope="module")
def plant() -> Plant:
    return Plant.from_config(nominal())


def test_margins_over_a_campaign_show_what_undamping_costs(plant, tmp_path):
    campaign = tmp_path / "undamped.toml"
    campaign.write_text(
        'name = "undamped"\n'
        "[[cases]]\n"
        'id = "zeta0"\n'
        'plant = [{ path = "appendages[*].damping_ratio", value = 0.0 }]\n'
    )
    family = family_margins(plant, campaign, out=tmp_path)
    nominal_margins = write_margins(plant)["axes"]
    assert set(family["cases"]) == {"nominal", "zeta0"}
    for axis in "xyz":  # the nominal case is the nominal loop, to round-off
        assert family["cases"]["nominal"][axis]["delay_margin_s"] == pytest.approx(
            nominal_margins[axis]["delay_margin_s"], rel=1e-9
        )
    # Without damping the ~100 Hz root-translation peaks are infinite and cross 0 dB
    # with the phase of a collocated mode, +-90 deg: the delay margin collapses to
    # about a quarter period of that mode, 1 / (4 f_c), within 5 % (the exact phase
    # at the crossing is within a few degrees of 90).
    for axis in "xz":
        m = family["cases"]["zeta0"][axis]
        assert m["delay_crossover_hz"] > 90.0
        assert m["delay_margin_s"] == pytest.approx(1 / (4 * m["delay_crossover_hz"]), rel=0.05)
    saved = json.loads((tmp_path / "margins_family.json").read_text())
    assert (
        saved["cases"]["zeta0"]["x"]["delay_margin_s"]
        == family["cases"]["zeta0"]["x"]["delay_margin_s"]
    )
    assert (tmp_path / "loop_family.png").stat().st_size > 0


def test_parsers_accept_the_documented_forms_and_refuse_others():
    assert parse_about("rest") == "rest"
    np.testing.assert_array_equal(parse_about("spin:0.1,0,-0.2"), [0.1, 0.0, -0.2])
    assert parse_reduction("balanced:16") == ("balanced", 16)
    assert parse_reduction(None) is None
    for bad in ("spin:1,2", "spin", "spin:a,b,c", "rotating:1,2,3"):
        with pytest.raises(ConfigError, match="--about"):
            parse_about(bad)
    for bad in ("balanced", "balanced:-3", "hankel:4"):
        with pytest.raises(ConfigError, match="--reduce"):
            parse_reduction(bad)
