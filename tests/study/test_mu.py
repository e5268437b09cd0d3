"""The thesis's 24 critical cases against the mu analysis of their loop, in the linear model.

The critical set (``montecarlo-critical``: zeta = 0, frequencies, hub and panel
inertias +-20 % at their corners, SADM angle 0, 45, 90 deg) mapped to the LFT's
normalized deltas (:func:`flexsat.study.mu.case_factors`); the mapping is checked
against each case's own satellite, linearized. Each SADM angle is its own LFT (the
angle is not pulled out), analysed on its own.
"""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from flexsat.campaigns import load_campaign, resolve_cases
from flexsat.config import nominal
from flexsat.config.models import SatelliteConfig
from flexsat.dynamics.plant import Plant
from flexsat.errors import ConfigError
from flexsat.linear import linearize
from flexsat.linear.frequency import law_gains
from flexsat.linear.mu import LinearController, analyze, closed_loop
from flexsat.linear.uncertain import uncertain_model, with_sadm_angle
from flexsat.simulate import SlewScenario
from flexsat.study.mu import case_factors

# A coarse log grid; analyze adds the closed loop's modal frequencies, where the peaks are.
GRID_HZ = np.logspace(-3, np.log10(200.0), 8)
ROUND_OFF_RE = 1e-9
"""Absolute tolerance [1/s] on a closed-loop pole's real part: with zeta = 0 the panels'
antisymmetric modes (which do not move the hub) are undamped whatever the law, so the
rightmost pole of every critical case, and of the mu worst case, sits on the imaginary
axis; numpy's eigenvalues of the 30-state closed loop (norm ~4e5: the 100 Hz joint modes
squared) carry eps * norm ~ 1e-10 of round-off (measured below 1e-12)."""


def _max_real(lft, loop, delta) -> float:
    A, B, C, D = loop
    Dl = lft.delta_matrix(delta)
    X = np.linalg.solve(np.eye(D.shape[0]) - Dl @ D, Dl)
    return float(np.max(np.linalg.eigvals(A + B @ X @ C).real))


@pytest.fixture(scope="module")
def critical():
    """Per SADM angle: the LFT, the loop, its mu analysis and its cases (id, deltas, plant)."""
    config = nominal()
    cases = [c for c in resolve_cases(load_campaign("montecarlo-critical"), config)
             if c.case_id != "nominal"]  # fmt: skip
    # The campaign's law (its base scenario's), designed on the base satellite: the
    # design model is never perturbed (docs/campaigns.md).
    law = SlewScenario.model_validate(cases[0].scenario).controller
    controller = LinearController.static(law_gains(Plant.from_config(config), law))
    out = {}
    for case in cases:
        factors, angle = case_factors(case, config)
        if angle not in out:
            lft = uncertain_model(with_sadm_angle(config, angle))
            loop = closed_loop(lft, controller)
            mu = analyze(lft, controller, frequencies_hz=GRID_HZ, maxiter=100)
            out[angle] = {"lft": lft, "loop": loop, "mu": mu, "cases": []}
        entry = out[angle]
        out[angle]["cases"].append((case, entry["lft"].deltas(factors)))
    return out


def test_the_critical_set_is_24_corners_at_three_sadm_angles(critical):
    """zeta = 0 is delta_damping = -1; the other parameters at +-1: every case a corner."""
    assert sorted(critical) == [0.0, 45.0, 90.0]
    deltas = np.array([d for entry in critical.values() for _, d in entry["cases"]])
    assert deltas.shape == (24, 4)
    # The factors 0.8, 1.2 and 0 map to -1, +1 and -1 exactly (up to the ratio's rounding).
    np.testing.assert_allclose(np.abs(deltas), 1.0, atol=1e-12)
    assert np.all(deltas[:, 1] == -1.0)
    assert len({tuple(d) for d in deltas}) == 8


def test_the_deltas_are_each_cases_own_satellite(critical):
    """The LFT at a case's deltas is the linearization of the case's satellite (the
    campaign modifiers applied to the nominal one): 1e-6 relative, as in
    tests/linear/test_uncertain.py (the LFT is exact algebra, measured ~1e-15)."""
    worst = 0.0
    for entry in critical.values():
        for case, delta in entry["cases"]:
            ref = linearize(Plant.from_config(SatelliteConfig.model_validate(case.plant)),
                            outputs=("attitude", "rate"))  # fmt: skip
            m = entry["lft"].evaluate(delta)
            err = np.max(np.abs(m.A - ref.A)) / np.max(np.abs(ref.A))
            worst = max(worst, err)
            assert err <= 1e-6, case.case_id
            assert np.max(np.abs(m.B - ref.B)) <= 1e-6 * np.max(np.abs(ref.B)), case.case_id
    print(f"largest relative difference of A: {worst:.2g}")


def test_no_critical_case_is_worse_than_the_mu_worst_case(critical):
    """Inside the mu-certified box (max |delta_i| <= k_max[0]) no case is unstable; no
    case has a closed-loop pole further right than the mu worst case of its angle."""
    for angle, entry in critical.items():
        mu, lft, loop = entry["mu"], entry["lft"], entry["loop"]
        worst = _max_real(lft, loop, mu.worst_delta)
        inside, rightmost = [], -np.inf
        for case, delta in entry["cases"]:
            re = _max_real(lft, loop, delta)
            rightmost = max(rightmost, re)
            if np.max(np.abs(delta)) <= mu.k_max[0]:
                inside.append(case.case_id)
                assert re < 0.0, case.case_id
            assert re <= worst + ROUND_OFF_RE, (case.case_id, re, worst)
        # Every case is a corner (max |delta| = 1) and the certified k_max is below 1:
        # none lies inside the certified box.
        assert mu.k_max[0] < 1.0 and inside == []
        # The loop loses stability where the damping reaches 0 (tests/linear/test_mu.py):
        # the worst case is zeta = 0, the boundary every critical case sits on.
        assert abs(mu.k_max[1] - 1.0) <= 1e-5 and abs(mu.worst_factors["damping"]) <= 1e-5
        assert abs(worst) <= ROUND_OFF_RE and abs(rightmost) <= ROUND_OFF_RE
        print(f"SADM {angle:g} deg: mu upper {mu.peak_upper:.4g} at {mu.peak_frequency_hz:.4g} "
              f"Hz (certified k_max {mu.k_max[0]:.4g}), lower {mu.lower:.6g} at "
              f"{mu.lower_frequency_hz:.4g} Hz, worst factors "
              f"{ {k: round(v, 4) for k, v in mu.worst_factors.items()} }; rightmost pole of "
              f"the 8 cases {rightmost:.3g} 1/s, mu worst case {worst:.3g} 1/s; inside the "
              f"certified box: {inside or 'none'}")  # fmt: skip


def test_a_case_the_lft_does_not_model_is_refused(critical):
    """A case that changes a parameter outside the LFT is named, not silently dropped."""
    case, _ = critical[0.0]["cases"][0]
    odd = dataclasses.replace(case, parameters={**case.parameters, "hub.mass_kg": 9.0})
    with pytest.raises(ConfigError, match=r"'hub\.mass_kg' is not a parameter of the uncertain"):
        case_factors(odd, nominal())
