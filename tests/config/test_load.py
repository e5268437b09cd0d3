"""Unknown-key messages list the keys allowed where the mistake is, tagged unions too."""

from __future__ import annotations

import pytest

from flexsat.config import validate_config
from flexsat.errors import ConfigError
from flexsat.simulate import SlewScenario


@pytest.mark.parametrize(
    ("section", "fragment"),
    [
        ({"controller": {"kind": "asmc", "lamda_max": 4.0}},
         "did you mean 'lambda_max'? (allowed here: include_lambda_dot, jk_min_nm, kind, "
         "lambda_adaptation, lambda_max,"),
        ({"controller": {"kind": "pd", "k_p": 1.0}}, "(allowed here: "),
        ({"initial": {"appendages": [{"name": "panel_1", "rho_dg": [0, 0, 0]}]}},
         "did you mean 'rho_deg'?"),
        ({"requirements": {"deadline_s": 50.0}}, "settling_deadline_s"),
    ],
)  # fmt: skip
def test_a_misspelt_key_names_the_allowed_ones(section, fragment):
    with pytest.raises(ConfigError) as raised:
        validate_config(section, source="slew.toml", model=SlewScenario)
    message = str(raised.value)
    assert fragment in message
    assert "(allowed here: )" not in message


def test_a_template_file_is_listed_and_copied_with_no_other_edit(tmp_path, monkeypatch, capsys):
    # The templates are the folder's files: a new one needs no entry anywhere else
    # (its header comment's first line says what it is).
    import shutil

    from flexsat.config import TEMPLATES, load, preset_path, templates
    from tests.cli.harness import flexsat

    folder = tmp_path / "presets"
    shutil.copytree(load.TEMPLATES_DIR, folder)
    (folder / "my-template.toml").write_text("# my own slew\n# second line\n")
    monkeypatch.setattr(load, "TEMPLATES_DIR", folder)
    listed = templates()
    assert list(listed)[: len(TEMPLATES)] == list(TEMPLATES)  # the curated ones first
    assert listed["my-template"] == "my own slew"
    assert preset_path("my-template") == folder / "my-template.toml"
    outcome = flexsat(["config", "preset", "--list"], capsys)
    assert outcome.code == 0 and "my-template" in outcome.stdout
