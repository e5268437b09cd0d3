"""Benchmark: the CPU time of one campaign case, full and reduced model, part by part.

Goal (issue 18, campaigns at scale): 1000 random Monte Carlo cases of the 120 s thesis
slew in <= 30 s on 2 cores with the reduced model, so <= 0.06 CPU-s per case. Runs
cases of ``montecarlo-random`` through :func:`flexsat.campaigns.runner.run_case` in
this process (after one warm-up case), the full model (1 ms, controller every step)
and the reduced one (root translations locked, 20 ms step and control period)
interleaved case by case, and prints the median CPU time (``time.process_time``) per
case of each part: the compiled loop, the derived records (compiled), the rest of the
result dataset (xarray, attitude conversions), the metrics, the decimated history and
what remains (config validation, plant packing, the row). Timings only: CPU time does
not depend on the machine's load as much as wall time, but a loaded machine still
inflates it (shared caches); the load average is printed beside the table.

``--cases N`` (default 5 per model), ``--duration S`` (default 120). Run with
``python bench/bench_case_cost.py``.
"""

from __future__ import annotations

import argparse
import os
import statistics
import time
from collections import defaultdict

from rich.console import Console
from rich.table import Table

import flexsat.analysis.effort as effort
import flexsat.analysis.requirements as requirements
import flexsat.simulate.closedloop as closedloop
import flexsat.simulate.result as result
from flexsat.campaigns import runner
from flexsat.campaigns.definition import CaseStream, Reduced
from flexsat.config import nominal, validate_config

GOAL_S = 0.06  # CPU-s per reduced-model case: 1000 cases in 30 s on 2 cores
# (part, module, function): each part's CPU time is the function's, less the parts inside it
PARTS = (
    ("compiled loop", closedloop, "fly"),  # loaded or compiled (no chunk), then the steps
    ("derived records", result, "derive_records"),
    ("dataset", closedloop, "build_dataset"),
    ("metrics", requirements, "slew_metrics"),
    ("metrics", effort, "effort_metrics"),
    ("history", runner, "case_history"),
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


def main(argv: list[str] | None = None) -> dict:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--cases", type=int, default=5, help="cases per model")
    parser.add_argument("--duration", type=float, default=120.0, help="slew length [s]")
    args = parser.parse_args(argv)
    console = Console(width=150)
    models = ("reduced", "full")
    streams = {m: list(CaseStream(_definition(args.duration, m == "reduced"), nominal(),
                                  args.cases)) for m in models}  # fmt: skip
    for m in models:
        runner.run_case(streams[m][0])  # warm-up: compiled code loaded
    spent: dict[str, float] = defaultdict(float)
    _instrument(spent)
    samples: dict[str, dict[str, list[float]]] = {m: defaultdict(list) for m in models}
    for k in range(1, args.cases + 1):
        for m in models:  # interleaved: both models see the same load
            spent.clear()
            start = time.process_time()
            row = runner.run_case(streams[m][k])
            total = time.process_time() - start
            assert row["status"] == "ok", row["error"]
            parts = dict(spent)
            parts["dataset"] -= parts["derived records"]  # derive_records runs inside it
            parts["other"] = total - sum(parts.values())
            for part, value in parts.items():
                samples[m][part].append(value)
            samples[m]["total"].append(total)
    load = ", ".join(f"{x:.2f}" for x in os.getloadavg())
    table = Table(title=f"CPU-s per case, median of {args.cases} ({args.duration:g} s slews, "
                        f"load {load})")  # fmt: skip
    names = ["compiled loop", "derived records", "dataset", "metrics", "history", "other",
             "total"]  # fmt: skip
    table.add_column("model")
    for name in names:
        table.add_column(name, justify="right")
    table.add_column(f"<= {GOAL_S} s", justify="right")
    results = {}
    for m in models:
        median = {name: statistics.median(samples[m][name]) for name in names}
        goal = ("met" if median["total"] <= GOAL_S else "not met") if m == "reduced" else "-"
        table.add_row(m, *(f"{median[name]:.4f}" for name in names), goal)
        results[m] = median
    console.print(table)
    return {"cases": args.cases, "duration_s": args.duration, "load": load, "results": results}


if __name__ == "__main__":
    main()
