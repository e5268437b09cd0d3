"""The truncated-normal draws of campaign modifiers."""

from __future__ import annotations

import numpy as np
import pytest
from scipy import stats

from flexsat.campaigns.modifiers import truncnormal_ppf


def test_truncated_normal_quantiles_match_scipys_truncnorm():
    # Independent formulation: scipy.stats.truncnorm.ppf (log-space tails). Same
    # quantile through ndtr/ndtri: rounding apart, measured at most 7e-15 std over
    # these 4000 draws (the inverse CDF's slope 1/phi magnifies the rounding of
    # Phi(a) + u (Phi(b) - Phi(a)) where phi is small). Bound: 1e-12 std.
    rng = np.random.default_rng(7)
    worst = 0.0
    for _ in range(4000):
        mean, std = rng.normal(), rng.uniform(0.01, 2.0)
        a = rng.uniform(-10.0, 6.0)  # intervals below, across and above the mean
        b = a + rng.uniform(0.01, 8.0)
        u = rng.uniform()
        got = truncnormal_ppf(u, mean, std, mean + a * std, mean + b * std)
        expected = stats.truncnorm.ppf(u, a, b, loc=mean, scale=std)
        worst = max(worst, abs(got - expected) / std)
        assert mean + a * std <= got <= mean + b * std
    assert worst <= 1e-12


@pytest.mark.parametrize(("u", "bound"), [(0.0, "low"), (1.0, "high")])
def test_the_extreme_quantiles_are_the_bounds(u, bound):
    low, high = 0.8, 1.2
    assert truncnormal_ppf(u, 1.0, 0.1, low, high) == pytest.approx(
        {"low": low, "high": high}[bound], abs=1e-15
    )


def test_the_modified_copy_is_a_deep_copy_of_the_config():
    # apply_modifiers copies the base config before writing into it. The copy must be
    # what copy.deepcopy gives (equal, no dict or list shared with the base), or one
    # case's values would leak into the next case's base.
    import copy

    from flexsat.campaigns.definition import CampaignDefinition, CaseStream, Reduced
    from flexsat.campaigns.modifiers import _copied
    from flexsat.config import nominal

    definition = CampaignDefinition(name="copy", reduced=Reduced())
    stream = CaseStream(definition, nominal())
    for base in (stream._plant_base, stream._scenario_base):
        copied = _copied(base)
        assert copied == copy.deepcopy(base)
        originals = {id(node) for node in _containers(base)}
        assert not originals & {id(node) for node in _containers(copied)}


def _containers(node):
    """Every dict and list inside ``node``, itself included."""
    if isinstance(node, dict | list):
        yield node
        for value in node.values() if isinstance(node, dict) else node:
            yield from _containers(value)


def test_a_derived_path_takes_only_its_op_and_an_unknown_path_lists_what_there_is():
    # A chain's damping_ratio sets every joint's ratio (a set value); scaling it has no
    # meaning and is refused by name. A path the appendage lacks lists the fields and
    # derived paths its model offers, so the user sees what to write instead.
    import tomllib

    from flexsat.campaigns.modifiers import Modifier, apply_modifiers
    from flexsat.config import preset_path

    data = tomllib.loads(preset_path("chain").read_text())
    rng = np.random.default_rng(0)
    with pytest.raises(KeyError, match=r"appendages\[0\]\.damping_ratio takes op = 'set'"):
        apply_modifiers(data, [Modifier(path="appendages[*].damping_ratio", op="scale",
                                        value=2.0)], rng, {})  # fmt: skip
    with pytest.raises(KeyError) as error:
        apply_modifiers(data, [Modifier(path="appendages[0].stiffness_scale", value=2.0)],
                        rng, {})  # fmt: skip
    message = error.value.args[0]
    assert "a 'chain' appendage" in message
    for offered in (
        "beam.EI_flap_N_m2",
        "joint.damping_ratio",
        "mount_yaw_deg",
        "damping_ratio",
        "target_frequencies_hz.torsion",
        "sadm_angle_deg",
    ):
        assert offered in message  # fmt: skip
