"""``flexsat campaign --controller``: every case flown by the chosen law, and the stored
histories carry that law's declared diagnostics, named and with their units."""

from __future__ import annotations

import json

import pytest

from flexsat.campaigns.store import CampaignStore
from flexsat.control.laws import get_law
from tests.cli.harness import flexsat

CAMPAIGN = """name = "two-cases"
include_nominal = true
[base]
duration_s = 2.0
[[cases]]
id = "heavier"
plant = [{ path = "hub.mass_kg", value = 180.0 }]
"""


@pytest.mark.parametrize("law", ["stsmc", "asmc"])
def test_campaign_flies_the_chosen_law_and_stores_its_diagnostics(tmp_path, capsys, law):
    (tmp_path / "k.toml").write_text(CAMPAIGN)
    store = tmp_path / "store"
    out = flexsat(["campaign", str(tmp_path / "k.toml"), "--controller", law, "--out",
                   str(store), "--workers", "1", "--json"], capsys, timeout_s=600)  # fmt: skip
    assert out.code == 0, out.stderr
    summary = json.loads(out.stdout)
    assert summary["cases"] == 2 and summary["failed"] == 0
    rows = CampaignStore(store).rows()
    assert {row["metrics"]["controller"] for row in rows} == {law}
    spec = get_law(law)
    for ds in CampaignStore(store).histories().values():
        for channel in spec.diagnostics:
            assert ds[channel.name].attrs["units"] == channel.units
            assert ds[channel.name].dims == (("time", "axis") if channel.per_axis else ("time",))
        other = {"lambda_act", "twisting_integral"} - {c.name for c in spec.diagnostics}
        assert not other & set(ds.data_vars)
