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
    # The rate: each case at the calibrated rate times CASE_FACTOR, on two workers, and
    # each of the three campaigns' summary and figures (exact but for the order of the
    # products: rel 1e-12).
    expected = (estimate.CASE_FACTOR * 120.0 * cases * REFERENCE.wall_per_sim_s / 2
                + 3 * estimate.CAMPAIGN_OVERHEAD_S)  # fmt: skip
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
    assert "basis: a 10 s slew flown now took 0.03 s (2.9 ms per simulated second" in text
    assert "1.00 x a quiet 2-core reference" in text


def test_the_quick_study_estimate_recomputed_from_its_counts():
    # Independent recomputation, part by part, from the quick study's counts written out
    # here (docs/results.md, the quick study): a machine 1.5 times slower than the
    # reference, two processes side by side. Runs at the calibrated rate r (campaign
    # cases times CASE_FACTOR), divided among the processes that fly them; overheads
    # times the speed r / REFERENCE_WALL_PER_SIM_S. Slews and the open loop 120 s, the
    # robust part's two flights 60 s. The avionics part flies the ideal and avionics
    # slews, 4 delays, 3 gains around the margin, the delay at the margin and the solar
    # arrays twice (12 slews); the law comparison the first case of the 2 distinct
    # campaign openings (the nominal opens two of the three) for each of the 5 laws and
    # the damped ASMC (12 cases). Exact arithmetic but for the order of the products:
    # rel 1e-12.
    r = 1.5 * estimate.REFERENCE_WALL_PER_SIM_S
    basis = estimate.Basis(r, workers=2, side_by_side=2)
    speed = r / estimate.REFERENCE_WALL_PER_SIM_S
    overhead = {name: seconds * speed for name, seconds in estimate.QUICK_OVERHEAD_S.items()}
    assert len(law_names()) == 5  # the counts below are the five built-in laws'
    expected = {
        "configuration": overhead["configuration"],
        "modal": overhead["modal"],
        "openloop": 120.0 * r + overhead["openloop"],
        "slew": 120.0 * r + overhead["slew"],
        "frequency": overhead["frequency"],
        "robust": 2 * 60.0 * r + overhead["robust"],
        "pointing": overhead["pointing"],
        "comparison": 4 * 120.0 * r / 2 + overhead["comparison"],
        "animation": overhead["animation"],
        "avionics": 12 * 120.0 * r / 2 + overhead["avionics"],
        "laws": 12 * 120.0 * r * estimate.CASE_FACTOR / 2 + overhead["laws"],
    }
    ctx = pipeline.StudyContext(nominal(), Path("unused"), quick=True)
    rows = estimate.study_estimate(ctx, PARTS, basis)
    got = {name: seconds for name, _, seconds in rows}
    assert set(got) == set(expected)
    for name, seconds in expected.items():
        assert got[name] == pytest.approx(seconds, rel=1e-12), name
    # the total: the longer lane's sum (lane 1: open loop, slew, frequency, comparison,
    # animation; lane 0 the rest)
    lane1 = {"openloop", "slew", "frequency", "comparison", "animation"}
    assert {part.name for part in PARTS if part.lane == 1} == lane1
    lanes = (sum(s for n, s in expected.items() if n not in lane1),
             sum(s for n, s in expected.items() if n in lane1))  # fmt: skip
    total = estimate.total_s(rows, {part.name: part.lane for part in PARTS})
    assert total == pytest.approx(max(lanes), rel=1e-12)


FULL_STUDY_S = 106.1
"""The full study of the nominal case, warm, whole process, on a quiet 2-core machine
(``bench/bench_study.py --repeats 1``, load 0.9-2.0; CHANGELOG.md, 2026-12-07) [s]."""


def test_the_full_study_estimate_on_the_reference_is_near_its_measured_time():
    # The constants measured again (estimate.py's docstrings) on the machine of the
    # reference rate: the full study's estimate against its measured wall time. 10 %:
    # the measurement is the whole process, about 3.5 s (3 %) of it outside the parts
    # (kernels loaded, the calibration, the report), and the parts' constants are
    # rounded to 0.1 s; the old constants (reference 8 ms per simulated second) gave
    # 87 s on this machine's rate, 18 % low.
    lanes = {part.name: part.lane for part in PARTS}
    ctx = pipeline.StudyContext(nominal(), Path("unused"), quick=False)
    total = estimate.total_s(estimate.study_estimate(ctx, PARTS, REFERENCE), lanes)
    print(f"full study: estimate {total:.1f} s against {FULL_STUDY_S} s measured")
    assert total == pytest.approx(FULL_STUDY_S, rel=0.10)


def test_the_quiet_quick_study_the_overheads_came_from_is_given_back():
    # The warm quick study of 2026-12-07 at load 0.7-1.3 (QUICK_OVERHEAD_S's docstring):
    # its calibration slew took 2.706 ms per simulated second, its parts 18.5 s (lane
    # 0). The overheads were rounded to 0.1 s: 5 % covers the five of lane 0 (0.25 s
    # at most, 1.4 %) and the case factor's rounding.
    basis = estimate.Basis(0.0027065, workers=2, side_by_side=2)
    ctx = pipeline.StudyContext(nominal(), Path("unused"), quick=True)
    rows = estimate.study_estimate(ctx, PARTS, basis)
    total = estimate.total_s(rows, {part.name: part.lane for part in PARTS})
    assert total == pytest.approx(18.5, rel=0.05)
