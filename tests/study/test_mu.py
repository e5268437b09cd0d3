"""The thesis's 24 critical cases against the mu analysis of their loop, in the linear model.

The critical set (``montecarlo-critical``: zeta = 0, frequencies, hub and panel
inertias +-20 % at their corners, SADM angle 0, 45, 90 deg) mapped to the LFT's
normalized deltas (:func:`flexsat.study.mu.case_factors`); the mapping is checked
against each case's own satellite, linearized. Each SADM angle is its own LFT (the
angle is not pulled out), analysed on its own.
"""

from __future__ import annotations

import dataclasses
import json

import numpy as np
import pytest
import xarray as xr

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
MAXITER = 100
"""L-BFGS-B iterations of the upper bound's scalings per frequency, as in the quick
study's robust part, whose peak refinement (up to 12 more bounds near the peak) is left
out here: every scaling gives a valid upper bound, so the peak on the grid alone can
only be lower than the refined one, never invalid, and the claims below rest on the
lower bound (the worst case and its alpha, which refinement does not touch) and on
k_max[0] < 1. At SADM 0 deg the refinement did not raise the peak (8.504 with and
without, with the full eigendecomposition; the peak of the diagonal bound moves with
its eigensolver's round-off, docs/linear.md); it took a quarter of the analysis (72 s
against 54 s at load 16-21)."""
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
            mu = analyze(lft, controller, frequencies_hz=GRID_HZ, maxiter=MAXITER, refine=False)
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


# -- the study's robustness part, alone ------------------------------------------------------


@pytest.fixture(scope="module")
def robust_part(quick_study, tmp_path_factory):
    """The robustness part of the quick study on the nominal satellite, and its report.

    The part as the suite's one quick study ran it (``tests/study/conftest.py``: the
    same ``run_study(nominal(), quick=True)``), not a second run of it: its folder
    and manifest entry copied into a study of that part alone, whose report is written
    here.
    """
    import shutil

    from flexsat.study.report import write_report

    src, study = quick_study
    entry = next(part for part in study["parts"] if part["name"] == "robust")
    out = tmp_path_factory.mktemp("robust_study")
    shutil.copytree(src / "robust", out / "robust")
    manifest = {"flexsat_version": "test", "created_utc": "now", "config_name": "nominal",
                "config_source": "a test", "quick": True, "parts": [entry]}  # fmt: skip
    (out / "study.json").write_text(json.dumps(manifest))
    write_report(out)
    return out, json.loads((out / "study.json").read_text())["parts"][0]


def test_the_robust_part_states_its_bounds_and_worst_cases(robust_part):
    """mu.json and robust.json hold what the section shows; their relations hold."""
    out, entry = robust_part
    assert entry["status"] == "ok", entry["error"]
    mu = json.loads((out / entry["outputs"]["mu"]).read_text())
    rob = json.loads((out / entry["outputs"]["json"]).read_text())
    # A valid upper bound is never below a lower bound: at the lower bound's frequency
    # (evaluated there) and at the peak; the peak is the curve's largest value.
    assert rob["upper_at_lower_frequency"] >= mu["lower"]
    assert mu["peak_upper"] >= mu["lower"] and mu["peak_upper"] == max(mu["mu_upper"])
    assert mu["k_max_lower"] == pytest.approx(1.0 / mu["peak_upper"], rel=1e-12)
    assert mu["k_max_upper"] == pytest.approx(1.0 / mu["lower"], rel=1e-12)
    # The sampling check passed: nothing unstable in the certified box, nothing in the
    # full box further right than the mu worst case.
    assert rob["certified_unstable"] == 0 and rob["certified_max_real_1_s"] < 0.0
    assert rob["box_max_real_1_s"] <= rob["cases"]["mu_worst"]["max_real_1_s"]
    # Each flown case's record is the perturbed satellite the factors make.
    for case in rob["cases"].values():
        ds = xr.load_dataset(out / "robust" / case["result"])
        flown = json.loads(ds.attrs["config"])
        ref = nominal().model_dump(mode="json")
        for app, base in zip(flown["appendages"], ref["appendages"], strict=True):
            ratio = (
                app["target_frequencies_hz"]["flapping"] / base["target_frequencies_hz"]["flapping"]
            )
            assert ratio == pytest.approx(case["factors"]["frequency"], rel=1e-12)
            assert app["damping_ratio"] == pytest.approx(
                case["factors"]["damping"] * base["damping_ratio"], rel=1e-12, abs=1e-15
            )
    text = (out / "report.html").read_text()
    for caption in ("μ bounds and k_max of the ASMC loop", "Worst-case parameter combination",
                    "Sampling check in the linear model",
                    "Worst cases flown in the nonlinear simulator"):  # fmt: skip
        assert caption in text
    print(f"mu upper {mu['peak_upper']:.4g} at {mu['peak_frequency_hz']:.4g} Hz, lower "
          f"{mu['lower']:.6g} at {mu['lower_frequency_hz']:.4g} Hz; decay rates: mu worst "
          f"{rob['cases']['mu_worst']['decay_rate_1_s']:.3g}, sampled worst "
          f"{rob['cases']['sampled_worst']['decay_rate_1_s']:.3g} 1/s")  # fmt: skip


def test_a_robust_section_that_cannot_be_drawn_fails_its_part(robust_part, tmp_path):
    """robust.json without its sampling check: the part is failed, never 'ok'."""
    import shutil

    from flexsat.study.report import write_report

    src, _ = robust_part
    out = tmp_path / "study"
    shutil.copytree(src, out)
    path = out / "robust" / "robust.json"
    data = json.loads(path.read_text())
    del data["certified_unstable"]
    path.write_text(json.dumps(data))
    write_report(out)
    entry = json.loads((out / "study.json").read_text())["parts"][0]
    assert entry["status"] == "failed" and entry["report_failed"]
    assert "robust section could not be drawn: KeyError('certified_unstable')" in entry["error"]
    assert "Failed parts: Robust stability" in (out / "report.html").read_text()


def test_the_robust_part_is_skipped_for_a_satellite_without_an_uncertain_model(tmp_path):
    """A chain appendage has no LFT: the part is skipped, naming why."""
    from flexsat.config import validate_config
    from flexsat.study import pipeline
    from tests.conftest import nominal_dict
    from tests.dynamics.chain_satellites import plate_as_chain

    data = nominal_dict()
    data["appendages"][0] = plate_as_chain(data["appendages"][0])
    part = next(p for p in pipeline.PARTS if p.name == "robust")
    entry = pipeline._run_part(part, pipeline.StudyContext(validate_config(data), tmp_path))
    assert entry["status"] == "skipped"
    assert entry["error"].startswith("not applicable: appendages[0]: an uncertain model is built")
