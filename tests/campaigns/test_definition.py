"""Campaign presets: found in their folder, listed from there by the CLI and the study."""

from __future__ import annotations

import shutil

from flexsat.campaigns import definition
from flexsat.campaigns.definition import campaign_presets, load_campaign
from flexsat.study.thesis import CAMPAIGNS
from tests.cli.harness import flexsat


def test_a_preset_file_is_listed_and_loads_with_no_other_edit(tmp_path, monkeypatch, capsys):
    folder = tmp_path / "presets"
    shutil.copytree(definition.PRESETS_DIR, folder)
    text = (
        (folder / "sensitivity.toml")
        .read_text()
        .replace('name = "sensitivity"', 'name = "my-preset"')
    )
    (folder / "my-preset.toml").write_text(text)
    monkeypatch.setattr(definition, "PRESETS_DIR", folder)
    assert "my-preset" in campaign_presets()
    assert load_campaign("my-preset").name == "my-preset"
    outcome = flexsat(["config", "preset", "--list"], capsys)
    assert outcome.code == 0 and "my-preset" in outcome.stdout


def test_the_thesis_campaigns_are_shipped_presets():
    assert set(CAMPAIGNS) <= set(campaign_presets())
    assert campaign_presets() == tuple(
        sorted(p.stem for p in definition.PRESETS_DIR.glob("*.toml"))
    )
