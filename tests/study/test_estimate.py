"""The study's estimate counts the work each part does, and says its basis."""

from __future__ import annotations

from pathlib import Path

import pytest
from rich.console import Console

from flexsat.config import nominal
from flexsat.control.laws import law_names
from flexsat.study import PARTS, estimate, pipeline

# At the reference rate, two processes side by side (the 2-core machine of the basis).
REFERENCE = estimate.Basis(estimate.REFERENCE_WALL_PER_SIM_S, workers=2, side_by_side=2)


def _study(quick: bool, config=None) -> dict:
    ctx = pipeline.StudyContext(config or nominal(), Path("unused"), quick=quick)
    return {name: (work, seconds) for name, work, seconds in
            estimate.study_estimate(ctx, PARTS, REFERENCE)}  # fmt: skip


def test_the_campaigns_are_counted_case_by_case():
    # Independent count: every case the three campaigns resolve to on the nominal
    # satellite, each of its base scenario's duration (120 s); the law comparison of
    # the full study flies them again for each variant but the default law's (its
    # stores are the campaigns part's): the other registered laws and the ASMC with
    # hybrid damping; the campaigns of slews from rest fly every variant, the default
    # law's too, on the reduced model, each case REDUCED_SHARE of a full one, but the
    # laws of FULL_MODEL_LAWS (the STSMC), on the full model.
    from flexsat.campaigns import load_campaign, resolve_cases
    from flexsat.study.laws import FULL_MODEL_LAWS, REDUCED_CAMPAIGNS

    count = {name: len(resolve_cases(load_campaign(name), nominal()))
             for name in pipeline.CAMPAIGNS}  # fmt: skip
    cases = sum(count.values())
    full = _study(quick=False)
    campaigns, _ = full["campaigns"]
    assert (campaigns.runs, campaigns.simulated_s) == (cases, 120.0 * cases)
    variants = len(law_names())  # the other laws (n - 1) and the damped ASMC
    reduced = sum(count[name] for name in REDUCED_CAMPAIGNS)
    on_full = sum(law in FULL_MODEL_LAWS for law in law_names())  # not the default law
    assert on_full == 1 and law_names()[0] not in FULL_MODEL_LAWS
    laws, _ = full["laws"]
    assert laws.runs == variants * (cases - reduced) + (variants + 1) * reduced
    simulated = 120.0 * (variants * (cases - reduced) + on_full * reduced
                         + (variants + 1 - on_full) * reduced * estimate.REDUCED_SHARE)  # fmt: skip
    assert laws.simulated_s == pytest.approx(simulated, rel=1e-12)
    # The rate: each case at the calibrated rate times CASE_FACTOR, on two workers
    # (exact: the same product in the same order).
    expected = estimate.CASE_FACTOR * 120.0 * cases * REFERENCE.wall_per_sim_s / 2
    assert full["campaigns"][1] == pytest.approx(expected, rel=1e-12)


def test_the_quick_study_leaves_out_the_campaigns_and_flies_one_case_of_each():
    # The quick law comparison: the first case of each campaign for each variant, the
    # nominal shared by the sensitivity and critical-case sets (flown once).
    quick = _study(quick=True)
    assert "campaigns" not in quick
    variants = len(law_names()) + 1
    assert quick["laws"][0].runs == variants * 2
    # the other parts count the same runs in both studies
    full = _study(quick=False)
    for name in ("openloop", "slew", "comparison"):
        assert quick[name][0].simulated_s == full[name][0].simulated_s, name


def test_a_slower_machine_scales_every_part_alike():
    # Twice the calibrated wall time per simulated second: every part's estimate
    # doubles (runs at the rate, overheads by the speed against the reference).
    slower = estimate.Basis(2 * REFERENCE.wall_per_sim_s, workers=2, side_by_side=2)
    ctx = pipeline.StudyContext(nominal(), Path("unused"), quick=False)
    for name, work, seconds in estimate.study_estimate(ctx, PARTS, REFERENCE):
        assert work.wall_s(slower) == pytest.approx(2 * seconds, rel=1e-12), name


def test_parts_the_satellite_cannot_run_are_not_estimated():
    from flexsat import Plant
    from flexsat.linear.export import modal_satellite

    modal = modal_satellite(Plant.from_config(nominal()), n_modes=3)
    skipped = _study(quick=True, config=modal)
    assert "laws" not in skipped
    assert "robust" not in skipped  # a modal appendage has no uncertain model


def test_the_robust_part_counts_its_two_flights_and_its_larger_full_grid():
    # Independent count: the mu worst case and the sampled worst case, each held 60 s
    # (docs/linear.md, 'In the study report'), one after the other; the full study's
    # mu grid costs FULL_OVERHEAD_FACTOR times the quick one's.
    quick, full = _study(quick=True)["robust"], _study(quick=False)["robust"]
    for work, _ in (quick, full):
        assert (work.runs, work.simulated_s, work.parallel) == (2, 120.0, 1)
    ratio = estimate.FULL_OVERHEAD_FACTOR["robust"]
    assert full[0].overhead_s == pytest.approx(ratio * quick[0].overhead_s, rel=1e-12)
    assert "2 runs of 60 s" in quick[0].what and "mu on 8 frequencies" in quick[0].what


def test_the_estimate_is_printed_with_its_basis_before_the_parts():
    console = Console(record=True, width=200)
    rows = estimate.study_estimate(pipeline.StudyContext(nominal(), Path("unused"), quick=True),
                                   PARTS, REFERENCE)  # fmt: skip
    lanes = {part.name: part.lane for part in PARTS}
    total = estimate.total_s(rows, lanes)
    # the longer lane's sum: the lanes run side by side
    assert total == max(sum(s for n, _, s in rows if lanes[n] == lane) for lane in (0, 1))
    estimate.print_estimate(console, rows, REFERENCE, {p.name: p.title for p in PARTS}, total)
    text = console.export_text()
    for part in PARTS:
        if not part.full_only:
            assert part.title in text
    assert "basis: a 10 s slew flown now took 0.08 s (8.0 ms per simulated second" in text
    assert "1.00 x a quiet 2-core reference" in text
