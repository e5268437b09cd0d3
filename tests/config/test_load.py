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
