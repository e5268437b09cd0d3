"""What the study will cost, said before it starts: per part, from its runs and the rest.

Each part of :data:`flexsat.study.pipeline.PARTS` is counted in the work it does
(:func:`part_work`): the runs it flies, their simulated seconds (the scenarios'
durations times the runs, the campaigns' case counts included) and how many fly
side by side, and its overhead, the figures, files and analyses besides the runs.
One slew flown on this machine just before the parts start (:func:`calibrate`)
gives the wall time a simulated second takes now: the runs are counted at that
rate, and the overheads, known on a quiet 2-core reference machine
(:data:`QUICK_OVERHEAD_S`), are scaled by the same speed against the reference
(:data:`REFERENCE_WALL_PER_SIM_S`). A campaign case costs about its simulated time
at that rate, times :data:`CASE_FACTOR` for its records and store (a reduced-model
case :data:`REDUCED_SHARE` of a full one), and each campaign of the campaigns part
:data:`CAMPAIGN_OVERHEAD_S` more for its summary and figures.

The constants were measured again on 2026-12-07 (docs/results.md, 'The study
report'): on the reference the quick study is estimated at 19.8 s and the full study
at 106.2 s (106.1 s measured, whole process, by ``bench/bench_study.py`` on a quiet
machine); the quiet warm quick study the overheads were measured on, whose
calibration gave 0.93 times the reference, took 18.5 s in its parts (22.3 s as a
whole process), which the constants give back.

The estimate is an estimate: a part whose runs stop early takes less, and a
machine whose load changes during the study, or whose load slows its files and
figures more than its arithmetic, takes more or less than said.
"""

from __future__ import annotations

import time
from dataclasses import dataclass

__all__ = [
    "CAMPAIGN_OVERHEAD_S",
    "CASE_FACTOR",
    "QUICK_OVERHEAD_S",
    "REDUCED_SHARE",
    "REFERENCE_WALL_PER_SIM_S",
    "Basis",
    "PartWork",
    "calibrate",
    "part_work",
    "study_estimate",
]

CALIBRATION_S = 10.0
"""Simulated seconds of the calibration slew [s]."""
REFERENCE_WALL_PER_SIM_S = 0.0029
"""Wall time per simulated second of the calibration slew on the reference machine
(the quiet 2-core machine the overheads were measured on) [s/s]. Measured 2026-12-07:
2.9 ms in the calibration of a warm quick study at load 0.4-0.5 and again in two at
load 1.7-2.7 (the 10 s slew takes 0.03 s: it gets a core even then), 2.7 ms in two
at load 0.7-1.5 and 3.7 ms in one at load 1.8-3.4;
:func:`calibrate` seven times in one process at load 3.4, 2.84-3.52 ms, median 2.87.
It was 0.008 before the loop's steps grew faster: the overheads, scaled by the speed
against it, then counted about a third of their time (a quick study estimated at
12.5 s)."""
CASE_FACTOR = 1.14
"""A campaign case's wall time against its simulated time at the calibrated rate [-]:
its records, metrics and stored files besides the run. Measured 2026-12-07 from the
full study on a quiet machine (``bench/bench_study.py``, load 0.9-2.0): its law
comparison took 43.1 s for 197 full-model and 185 reduced-model cases of 120 s on two
workers; less its 0.9 s overhead (:data:`QUICK_OVERHEAD_S`), with
:data:`REDUCED_SHARE`, that is 1.14 times 120 s at the reference rate a full case on
each core. ``run_case`` alone (``bench/bench_case_cost.py --cases 5``, load 2.9-4.6)
takes 0.336-0.338 CPU-s a full case, 0.97 times 120 s at that rate: the rest is the
campaign's store and its workers."""
REDUCED_SHARE = 0.09
"""A reduced-model campaign case's wall time against a full-model one's [-]. Measured
2026-12-07 with ``bench/bench_case_cost.py --cases 5``: 0.0287 against 0.3375 CPU-s
(load 2.9) and 0.0331 against 0.3357 (load 4.6), 0.085 and 0.099."""
CAMPAIGN_OVERHEAD_S = 3.3
"""What each thesis campaign of the full study's campaigns part does besides its cases
(its summary, its figures, starting its workers) on the reference machine [s]: the
part took 23.7 s for 69 cases of 120 s in the full study of 2026-12-07 (quiet,
``bench/bench_study.py``), of which 13.7 s its cases at :data:`CASE_FACTOR` on two
workers; the other 10.0 s shared among its three campaigns."""
QUICK_OVERHEAD_S = {
    "configuration": 0.0, "modal": 3.4, "openloop": 2.9, "slew": 2.4, "frequency": 3.1,
    "comparison": 1.3, "animation": 2.9, "avionics": 3.6, "laws": 0.9, "pointing": 0.5,
    "robust": 6.6,
}  # fmt: skip
"""What each part of the quick study does besides flying its runs (figures, files,
analyses) on the reference machine [s]. Measured 2026-12-07 in a warm quick study of
the nominal case at load 0.7-1.3 (its own processes, nothing else running): each
part's wall time less its runs at the rate its calibration measured (2.7 ms per
simulated second, 0.93 times the reference), divided by that 0.93. The parts took
modal 3.15 s, open loop 3.07, slew 2.54, frequency 2.91, comparison 1.86, animation
2.73 (lane 1, 13.1 s); robustness 6.52, pointing 0.49, avionics 5.31, law comparison
3.03 (lane 0, 18.5 s: the study's parts); the whole process 22.3 s, of which 1.5 s
loading the kernels. A second run minutes later, with another process starting
beside it (load 1.1-1.5), took 23.9 s in its parts."""
FULL_OVERHEAD_FACTOR = {
    "modal": 3.0, "comparison": 13.0, "animation": 2.5, "avionics": 1.4, "robust": 3.0,
}  # fmt: skip
"""The full study's overhead against the quick one's, per part [-]: three times the
mode GIFs (6 against 2), each compared law's 13 figures (against the one comparison
figure), 150 animation frames against 60, the longer delay sweep, the mu grid of 60
log-spaced frequencies at 200 iterations each against 8 at 100 (72 against 20 with the
modal ones): measured 2026-12-07, the full study's robustness part took 20.3 s on a
quiet machine (``bench/bench_study.py``, load 0.9-2.0), 3.0 times the quick one's
overhead with its two 60 s flights at the reference rate."""


@dataclass(frozen=True)
class Basis:
    """What turns work into wall time.

    Parameters
    ----------
    wall_per_sim_s : float
        Wall time per simulated second of the nominal slew, measured now [s/s].
    workers : int
        Processes the campaigns' cases share.
    side_by_side : int
        Processes a part's runs share (:func:`flexsat.parallel.figure_workers`).
    """

    wall_per_sim_s: float
    workers: int
    side_by_side: int

    @property
    def speed(self) -> float:
        """This machine now against the reference: > 1 is slower [-]."""
        return self.wall_per_sim_s / REFERENCE_WALL_PER_SIM_S

    def describe(self) -> str:
        """One sentence: the basis of the estimate."""
        return (
            f"basis: a {CALIBRATION_S:g} s slew flown now took "
            f"{self.wall_per_sim_s * CALIBRATION_S:.2f} s ({self.wall_per_sim_s * 1e3:.1f} ms "
            f"per simulated second, {self.speed:.2f} x a quiet 2-core reference); every run "
            f"counted at that rate, {self.side_by_side} side by side (campaign cases "
            f"{self.workers}); figures and files as the parts took on the reference, "
            f"scaled alike"
        )


@dataclass(frozen=True)
class PartWork:
    """The work of one part, before it is turned into wall time.

    Parameters
    ----------
    runs : int
        Simulations flown.
    simulated_s : float
        Their simulated time, summed [s].
    parallel : int
        How many of them fly side by side.
    overhead_s : float
        Everything else (figures, files, analyses) on the reference machine [s].
    what : str
        The work in words.
    factor : float
        Wall time of a run against its simulated time at the calibrated rate [-].
    """

    runs: int = 0
    simulated_s: float = 0.0
    parallel: int = 1
    overhead_s: float = 0.0
    what: str = "no run"
    factor: float = 1.0

    def wall_s(self, basis: Basis) -> float:
        """The estimated wall time [s]: the runs at the measured rate (times ``factor``,
        :data:`CASE_FACTOR` for campaign cases), side by side, and the overhead scaled
        by the machine's speed against the reference."""
        runs = self.factor * self.simulated_s * basis.wall_per_sim_s / max(self.parallel, 1)
        return runs + self.overhead_s * basis.speed


def calibrate(plant, workers: int | None = None) -> Basis:
    """Fly :data:`CALIBRATION_S` of the nominal slew of ``plant`` and time it.

    Parameters
    ----------
    plant : Plant
        The study's satellite (its kernels already compiled or loaded).
    workers : int, optional
        The campaigns' worker processes (default: every core).

    Returns
    -------
    Basis
    """
    import os

    from flexsat.parallel import figure_workers
    from flexsat.simulate import SlewScenario, run_slew

    scenario = SlewScenario.model_validate({"duration_s": CALIBRATION_S, "record_dt_s": 0.1})
    start = time.perf_counter()
    run_slew(plant, scenario, progress=False)
    elapsed = time.perf_counter() - start
    return Basis(elapsed / CALIBRATION_S, workers or os.cpu_count() or 1, figure_workers())


def _cases(ctx) -> dict[str, tuple[int, float]]:
    """Per thesis campaign: (its cases, their duration [s])."""
    from flexsat.campaigns import load_campaign
    from flexsat.campaigns.definition import CaseStream
    from flexsat.simulate import SlewScenario
    from flexsat.study.thesis import CAMPAIGNS

    out = {}
    for name in CAMPAIGNS:
        definition = load_campaign(name)
        duration = definition.base.get("duration_s", SlewScenario().duration_s)
        out[name] = (len(CaseStream(definition, ctx.config)), float(duration))
    return out


def part_work(name: str, ctx, side_by_side: int = 2) -> PartWork:
    """The work of the part called ``name`` in the study ``ctx``.

    Parameters
    ----------
    name : str
        A part of :data:`flexsat.study.pipeline.PARTS`.
    ctx : StudyContext
        The study (its satellite, quick or full, its laws).
    side_by_side : int
        Processes a part's runs share.

    Returns
    -------
    PartWork
    """
    from flexsat.simulate import OpenLoopScenario, SlewScenario
    from flexsat.study import avionics, laws

    slew_s = SlewScenario().duration_s
    quick = ctx.quick
    others = len(ctx.laws) - 1
    overhead = QUICK_OVERHEAD_S.get(name, 0.0) * (
        1.0 if quick else FULL_OVERHEAD_FACTOR.get(name, 1.0)
    )
    if name == "openloop":
        duration = OpenLoopScenario().duration_s
        return PartWork(1, duration, 1, overhead, f"1 open-loop run of {duration:g} s")
    if name == "slew":
        return PartWork(1, slew_s, 1, overhead, f"1 slew of {slew_s:g} s")
    if name == "comparison":
        return PartWork(others, others * slew_s, side_by_side, overhead,
                        f"{others} slews of {slew_s:g} s")  # fmt: skip
    if name == "avionics":
        delays = len(avionics.QUICK_DELAYS_S if quick else avionics.DELAYS_S)
        around = len(avionics.QUICK_MARGIN_FACTORS if quick else avionics.MARGIN_FACTORS)
        runs = 2 + delays + around + 1 + 2  # ideal and avionics, the sweep, the arrays x2
        return PartWork(runs, runs * slew_s, side_by_side, overhead,
                        f"about {runs} slews of {slew_s:g} s")  # fmt: skip
    if name == "robust":
        from flexsat.study import mu

        points = mu.QUICK_POINTS if quick else mu.STUDY_POINTS
        return PartWork(2, 2 * mu.FLIGHT_S, 1, overhead,
                        f"mu on {points} frequencies and the modal ones, {2 * mu.SAMPLES} "
                        f"linear cases, 2 runs of {mu.FLIGHT_S:g} s")  # fmt: skip
    if name in ("campaigns", "laws"):
        cases = _cases(ctx)
        every = sum(c for c, _ in cases.values())
        flown = sum(c * d for c, d in cases.values())
        if name == "campaigns":
            listed = ", ".join(f"{k} {c}" for k, (c, _) in cases.items())
            overhead += CAMPAIGN_OVERHEAD_S * len(cases)  # summaries and figures
            return PartWork(every, flown, ctx.workers or side_by_side, overhead,
                            f"{every} cases ({listed})", CASE_FACTOR)  # fmt: skip
        variants = others + 2  # the laws and the ASMC with hybrid damping
        if quick:  # the first case of each campaign and variant, each distinct case once:
            # the nominal opens both the sensitivity and the critical-case sets
            n = variants * laws.QUICK_CASES * (len(cases) - 1)
            first = max(d for _, d in cases.values())
            what = f"{n} cases ({variants} variants, the first case of each campaign)"
            return PartWork(n, n * first, side_by_side, overhead, what, CASE_FACTOR)
        # a full-model default law's stores are the campaigns part's own; a reduced
        # campaign flies every variant on the reduced model (laws.REDUCED_CAMPAIGNS)
        # but those of laws.FULL_MODEL_LAWS, on the full one (the default law's store
        # again the campaigns part's)
        full_model = [law in laws.FULL_MODEL_LAWS for law in ctx.laws]
        n = simulated = 0.0
        for campaign, (count, duration) in cases.items():
            if campaign in laws.REDUCED_CAMPAIGNS:
                on_full = sum(full_model[1:])
                on_reduced = variants - on_full - full_model[0]
            else:
                on_full, on_reduced = variants - 1, 0
            n += (on_full + on_reduced) * count
            simulated += (on_full + on_reduced * REDUCED_SHARE) * count * duration
        what = (f"{int(n)} cases ({variants - 1} variants besides the default law; "
                f"{', '.join(laws.REDUCED_CAMPAIGNS)} on the reduced model)")  # fmt: skip
        return PartWork(int(n), simulated, ctx.workers or side_by_side, overhead, what,
                        CASE_FACTOR)  # fmt: skip
    return PartWork(overhead_s=overhead, what="figures and analysis" if overhead else "no run")


def study_estimate(ctx, parts, basis: Basis) -> list[tuple[str, PartWork, float]]:
    """Per part that will run: (name, its work, its estimated wall time [s]).

    Parameters
    ----------
    ctx : StudyContext
        The study.
    parts : sequence of Part
        The parts (:data:`flexsat.study.pipeline.PARTS`).
    basis : Basis
        From :func:`calibrate`.

    Returns
    -------
    list of tuple
        Parts that will be skipped (``full_only`` in a quick study, or not
        applicable to the satellite) are left out.
    """
    rows = []
    for part in parts:
        if part.full_only and ctx.quick:
            continue
        if part.applies is not None and part.applies(ctx) is not None:
            continue  # skipped on this satellite
        work = part_work(part.name, ctx, basis.side_by_side)
        rows.append((part.name, work, work.wall_s(basis)))
    return rows


def total_s(rows: list[tuple[str, PartWork, float]], lane_of: dict[str, int]) -> float:
    """The study's estimated wall time [s]: the longer lane's sum (the lanes run side
    by side; ``lane_of`` maps a part to its lane, one lane: every part to 0)."""
    lanes: dict[int, float] = {}
    for name, _, seconds in rows:
        lanes[lane_of.get(name, 0)] = lanes.get(lane_of.get(name, 0), 0.0) + seconds
    return max(lanes.values(), default=0.0)


def print_estimate(console, rows, basis: Basis, titles: dict[str, str], total: float) -> None:
    """Print the estimate: a table of the parts (work, estimated wall time), the total
    and the basis.

    Parameters
    ----------
    console : rich.console.Console
        Where.
    rows : list of tuple
        From :func:`study_estimate`.
    basis : Basis
        From :func:`calibrate`.
    titles : dict
        Part name -> its title.
    total : float
        From :func:`total_s` [s].
    """
    from rich.table import Table

    table = Table(title=f"Estimate: about {_duration(total)} (compilation excluded)",
                  title_justify="left", box=None, pad_edge=False)  # fmt: skip
    for column, justify in (("part", "left"), ("work", "left"), ("estimate", "right")):
        table.add_column(column, justify=justify)
    for name, work, seconds in rows:
        table.add_row(titles.get(name, name), work.what, _duration(seconds))
    console.print(table)
    console.print(basis.describe(), highlight=False)


def _duration(seconds: float) -> str:
    """``12 s``, ``4 min 29 s``."""
    if seconds < 60.0:
        return f"{seconds:.0f} s"
    minutes, rest = divmod(round(seconds), 60)
    return f"{minutes} min {rest:02d} s"
