"""Sobol sensitivity: SALib's estimator on the Ishigami function, and as a campaign kind."""

from __future__ import annotations

import numpy as np
import pytest

from flexsat.campaigns import run_campaign
from flexsat.campaigns.definition import CampaignDefinition, SobolCases, sobol_samples
from flexsat.campaigns.sobol import analyze_sobol, sobol_indices
from flexsat.config import nominal, validate_config
from flexsat.errors import ConfigError

# Ishigami f = sin x1 + 7 sin^2 x2 + 0.1 x3^4 sin x1 on [-pi, pi]^3: the published
# analytic indices (Ishigami & Homma 1990; Saltelli et al., Global Sensitivity
# Analysis: The Primer, 2008): S1 = (0.3139, 0.4424, 0), ST = (0.5576, 0.4424, 0.2437).
ISHIGAMI_S1 = (0.3139, 0.4424, 0.0)
ISHIGAMI_ST = (0.5576, 0.4424, 0.2437)


def test_ishigami_indices_match_the_published_values_within_salibs_error():
    from SALib.test_functions import Ishigami

    sobol = SobolCases(n=4096, seed=18, parameters=[
        {"path": f"x{k}", "bounds": [-np.pi, np.pi]} for k in (1, 2, 3)])  # fmt: skip
    X = sobol_samples(sobol)
    assert X.shape == (4096 * 5, 3)
    indices = analyze_sobol(sobol, Ishigami.evaluate(X), seed=18)
    # Tolerance: SALib's own error estimate, the 95 % bootstrap half-width of each
    # index (S1_conf, ST_conf: 0.01-0.04 at N = 4096), plus 4e-3 for the rounding
    # of the published values and the estimator's O(1/N) bias.
    for k in range(3):
        row = indices.iloc[k]
        assert abs(row["S1"] - ISHIGAMI_S1[k]) <= row["S1_conf"] + 4e-3
        assert abs(row["ST"] - ISHIGAMI_ST[k]) <= row["ST_conf"] + 4e-3


def test_sobol_n_must_be_a_power_of_two():
    with pytest.raises(ValueError, match="power of 2"):
        SobolCases(n=48, parameters=[{"path": "hub.mass_kg", "bounds": [1.0, 2.0]}])


def test_a_sobol_campaign_runs_its_sample_and_gives_indices(tmp_path):
    # 2 parameters, N = 4: 4 (2 + 2) = 16 cases of a 0.5 s slew. Checks the plumbing
    # (cases in sample order, indices per metric), not the values (N far too small).
    definition = validate_config({
        "name": "sobol-small", "include_nominal": False,
        "base": {"duration_s": 0.5},
        "sobol": {"n": 4, "seed": 1, "parameters": [
            {"path": "hub.mass_kg", "bounds": [120.0, 180.0]},
            {"path": "appendages[*].target_frequencies_hz.flapping", "op": "scale",
             "bounds": [0.8, 1.2]},
        ]},
    }, model=CampaignDefinition)  # fmt: skip
    run = run_campaign(definition, nominal(), tmp_path, workers=1, progress=False)
    assert run["cases"] == 16 and run["failed"] == 0
    indices = sobol_indices(tmp_path, definition.sobol)
    assert set(indices["parameter"]) == {
        "hub.mass_kg",
        "appendages[*].target_frequencies_hz.flapping",
    }
    assert "final_pointing_error_deg" in set(indices["metric"])


def test_a_sobol_path_that_does_not_exist_is_refused_before_running(tmp_path):
    definition = validate_config({
        "name": "sobol-bad", "include_nominal": False,
        "sobol": {"n": 4, "parameters": [{"path": "hub.colour", "bounds": [0.0, 1.0]}]},
    }, model=CampaignDefinition)  # fmt: skip
    with pytest.raises(ConfigError, match="no 'colour'"):
        run_campaign(definition, nominal(), tmp_path / "out", workers=1, progress=False)
    assert not (tmp_path / "out").exists()
