"""Benchmark: the ensemble runner against cases run one by one, in one process.

The same resolved Monte Carlo cases (``montecarlo-random``, the thesis slew) run
three ways, the trials interleaved and the median kept: one by one
(``run_case``, what a pool worker does), as an ensemble on 1 numba thread and on 2
(``run_ensemble``). Printed: wall time and CPU time per case (``time.process_time``,
threads included), the ratio to one by one, the 1 → 2 thread efficiency, and the
1000 cases on 2 cores the CPU time per case gives at perfect scaling, against the
goal (<= 30 s, reduced model). CPU time does not depend on the machine's load; the
wall times do. ``--cases N`` (default 16), ``--trials T`` (default 3),
``--duration S`` (default 120), ``--only full|reduced``.
"""

from __future__ import annotations

import argparse
import statistics

import harness
from bench_scale import GOAL_EFFICIENCY, GOAL_S, definition
from flexsat.campaigns.definition import CaseStream
from flexsat.campaigns.ensemble import run_ensemble
from flexsat.campaigns.runner import run_case
from flexsat.config import nominal


@harness.register(
    "the ensemble runner against the same cases run one by one, in one process, on 1 and 2 "
    "numba threads: CPU and wall time per case, medians of interleaved trials"
)
def main(argv: list[str] | None = None) -> dict:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--cases", type=int, default=16)
    parser.add_argument("--trials", type=int, default=3)
    parser.add_argument("--duration", type=float, default=120.0, help="slew length [s]")
    parser.add_argument("--only", choices=("full", "reduced"), default=None)
    args = parser.parse_args(argv)
    console = harness.console(150)
    console.print(f"{args.cases} cases of {args.duration:g} s, {args.trials} trials, "
                  f"load {harness.load()}")  # fmt: skip
    ways = {
        "one by one": lambda cases: [run_case(c) for c in cases],
        "ensemble x1": lambda cases: list(run_ensemble(cases, threads=1)),
        "ensemble x2": lambda cases: list(run_ensemble(cases, threads=2)),
    }
    table = harness.table("Ensemble runner against one case at a time (median of trials)",
                          ("model", "runner", "wall/case (s)", "CPU/case (s)",
                           "CPU vs one by one", "1000 cases, 2 cores (s)", "<= 30 s"),
                          left=2)  # fmt: skip
    results = {}
    for model in [args.only] if args.only else ["reduced", "full"]:
        campaign = definition(args.duration, model == "reduced")
        cases = list(CaseStream(campaign, nominal(), args.cases - 1))
        for way in ways.values():
            way(cases[:2])  # warm up: compiled code loaded, modules imported
        samples = harness.interleave(
            {name: lambda way=way, cases=cases: harness.stopwatch(lambda: way(cases))
             for name, way in ways.items()}, args.trials)  # fmt: skip
        n = len(cases)
        medians = {name: (statistics.median(t.wall_s for t in s) / n,
                          statistics.median(t.cpu_s for t in s) / n)
                   for name, s in samples.items()}  # fmt: skip
        base_cpu = medians["one by one"][1]
        for name, (wall, cpu) in medians.items():
            per_1000 = 1000 * cpu / 2
            goal = ("met" if per_1000 <= GOAL_S else "not met") if model == "reduced" else "-"
            table.add_row(model, name, f"{wall:.3f}", f"{cpu:.3f}", f"{cpu / base_cpu:.2f}",
                          f"{per_1000:.0f}", goal)  # fmt: skip
            results[f"{model} {name}"] = {"wall_per_case_s": wall, "cpu_per_case_s": cpu}
        efficiency = medians["ensemble x1"][0] / medians["ensemble x2"][0] / 2
        results[f"{model} efficiency"] = efficiency
        console.print(
            f"{model}: ensemble 1 -> 2 threads, wall efficiency {efficiency:.0%} "
            f"(goal >= {GOAL_EFFICIENCY:.0%}; meaningful on a quiet machine only)"
        )
    console.print(table)
    console.print(f"load {harness.load()}")
    return results


if __name__ == "__main__":
    main()
