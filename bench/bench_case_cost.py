"""Benchmark: the CPU time of one campaign case, full and reduced model, part by part.

Goal (issue 46, campaigns at scale): 1000 random Monte Carlo cases of the 120 s thesis
slew in <= 15 s on 2 cores with the reduced model, so <= 0.03 CPU-s per case in all
(issue 18's 30 s allowed 0.06). Runs cases of ``montecarlo-random`` through
:func:`flexsat.campaigns.cases.run_case` in this process (after one warm-up case), the
full model (1 ms, controller every step) and the reduced one (root translations locked,
20 ms step and control period) interleaved case by case, and prints the median CPU
time (``time.process_time``) per case of each part: the config validated and the plant
built (``case_inputs``), the loop's arrays prepared (``prepare_slew``), the compiled
loop (``fly_whole``), the derived records (compiled), the rest of the records (numpy:
attitude conversions, quaternions, root motion, errors; no xarray dataset is built),
the metrics, the decimated history and what remains (the row, the run's attributes).
Timings only: CPU time does not depend on the machine's load as much as wall time, but
a loaded machine still inflates it (shared caches); the load average is printed beside
the table.

``--cases N`` (default 5 per model), ``--duration S`` (default 120). Run with
``python bench/bench_case_cost.py``.
"""

from __future__ import annotations

import argparse
import time
from collections import defaultdict

import flexsat.analysis.effort as effort
import flexsat.analysis.requirements as requirements
import flexsat.simulate.batch as batch
import flexsat.simulate.closedloop as closedloop
import flexsat.simulate.result as result
import harness  # the benchmarks run with bench/ on sys.path
from flexsat.campaigns import cases
from flexsat.campaigns.definition import CaseStream, Reduced
from flexsat.config import nominal, validate_config

GOAL_S = 0.03  # CPU-s per reduced-model case: 1000 cases in 15 s on 2 cores (issue 46)
# (part, module, function): each part's CPU time is the function's, less the parts inside it
PARTS = (
    ("config + plant", cases, "case_inputs"),
    ("prepare", closedloop, "prepare_slew"),
    ("compiled loop", batch, "fly_whole"),  # the entry point found, the steps
    ("derived records", result, "derive_records"),
    ("records", closedloop, "build_records"),  # the rest of the records (numpy)
    ("metrics", requirements, "slew_metrics"),
    ("metrics", effort, "effort_metrics"),
    ("history", cases, "case_history"),
)


def _definition(duration_s: float, reduced: bool):
    from flexsat.campaigns import load_campaign
    from flexsat.campaigns.definition import CampaignDefinition

    data = load_campaign("montecarlo-random").model_dump(mode="json")
    data["base"] = {**data["base"], "duration_s": duration_s}
    if reduced:
        data["reduced"] = Reduced().model_dump(mode="json")
    return validate_config(data, model=CampaignDefinition)


def _instrument(spent: dict[str, float]) -> None:
    """Wrap each part's function to add its CPU time to ``spent``."""
    for part, module, name in PARTS:
        inner = getattr(module, name)

        def timed(*args, _inner=inner, _part=part, **kwargs):
            start = time.process_time()
            try:
                return _inner(*args, **kwargs)
            finally:
                spent[_part] += time.process_time() - start

        setattr(module, name, timed)


@harness.register(
    "CPU time of one campaign case (120 s thesis slew), full and reduced model, part by part "
    "(config + plant, prepare, compiled loop, derived records, records, metrics, history, rest) "
    "against 0.03 CPU-s per reduced case",
    targets=[harness.Target(
        f"one reduced campaign case <= {GOAL_S} CPU-s", GOAL_S, "CPU-s",
        lambda r: r["results"]["reduced"]["total"], "{:.4f} CPU-s",
        note=lambda r, _: f"median of {r['cases']}; full {r['results']['full']['total']:.4f}")],
)  # fmt: skip
def main(argv: list[str] | None = None) -> dict:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--cases", type=int, default=5, help="cases per model")
    parser.add_argument("--duration", type=float, default=120.0, help="slew length [s]")
    args = parser.parse_args(argv)
    console = harness.console(150)
    models = ("reduced", "full")
    streams = {m: list(CaseStream(_definition(args.duration, m == "reduced"), nominal(),
                                  args.cases)) for m in models}  # fmt: skip
    for m in models:
        cases.run_case(streams[m][0])  # warm-up: compiled code loaded
    spent: dict[str, float] = defaultdict(float)
    _instrument(spent)
    remaining = {m: iter(streams[m][1:]) for m in models}

    def case(m: str) -> dict[str, float]:
        """The next case of model ``m``: CPU s of each part and in all."""
        spent.clear()
        timed = harness.stopwatch(lambda: cases.run_case(next(remaining[m])))
        assert timed.value["status"] == "ok", timed.value["error"]
        parts = dict(spent)
        parts["records"] -= parts["derived records"]  # derive_records runs inside it
        parts["other"] = timed.cpu_s - sum(parts.values())
        return {**parts, "total": timed.cpu_s}

    # interleaved: both models see the same load
    rounds = harness.interleave({m: lambda m=m: case(m) for m in models}, args.cases)
    load = harness.load()
    names = ["config + plant", "prepare", "compiled loop", "derived records", "records",
             "metrics", "history", "other", "total"]  # fmt: skip
    table = harness.table(f"CPU-s per case, median of {args.cases} ({args.duration:g} s slews, "
                          f"load {load})", ("model", *names, f"<= {GOAL_S} s"))  # fmt: skip
    results = {}
    for m in models:
        median = harness.median({name: [r[name] for r in rounds[m]] for name in names})
        goal = ("met" if median["total"] <= GOAL_S else "not met") if m == "reduced" else "-"
        table.add_row(m, *(f"{median[name]:.4f}" for name in names), goal)
        results[m] = median
    console.print(table)
    return {"cases": args.cases, "duration_s": args.duration, "load": load, "results": results}


if __name__ == "__main__":
    main()
