"""Benchmark: 1000 random Monte Carlo cases of the thesis slew, full and reduced model,
local pool and Dask, 1 and 2 workers, against the goal.

Goal (campaigns at scale, issue 46; issue 18 asked 30 s): 1000 random Monte Carlo cases
of the 120 s thesis slew in <= 15 s on 2 cores with the reduced model (root translations
locked, 20 ms step and control period), the full model (1 ms) beside it; >= 90 % parallel
efficiency from 1 to 2 workers, local and Dask. Each configuration runs the same cases into a fresh
temporary store; the wall time includes starting the workers. A one-worker run is
confined to one core, with every process and thread it starts (``sched_setaffinity``):
one worker on two cores would have a spare core for the campaign's own process (the
store, Dask's client and scheduler) and the ensemble's second thread, and its run
would not be one worker's. Backends: ``local``
(the process pool; 1 worker runs in this process), ``ensemble`` (batches in one
compiled call, 1 or 2 numba threads, in this process) and ``dask`` (LocalCluster,
each task an ensemble). The CPU time per case is that of this process (threads
included): given for the runs that stay in it. For the local pool on two workers it
is split into this process's (storing results, resolving cases) and the workers'
(``RUSAGE_CHILDREN``: the cases, their start-up and the transfers), which is what
two cores must carry: 1000 cases in 15 s allow 0.030 CPU s per case in all. Each run's
line gives the load average before and after it; the reduced rows end with their
verdict against 15 s and the CPU s per case against 0.030 (the CPU time, which the
load moves less than the wall time, says whether two quiet cores would meet the goal).

``--repeat N`` runs every configuration N times, the configurations in turn each
time, and the table gives the best run of each (the runs are printed as they end):
the speed of a shared or throttled machine drifts by 15-30 % over minutes, and with
one run each, the one-worker and two-worker runs of a backend, minutes apart, may
fall in different phases; the best run is the one that lost least to the machine.
The efficiency is given both ways: from the best runs (the verdict), and as the
median over the repeats of each one-worker run against the two-worker run right
after it (a pair minutes apart, in one phase of the machine more often than not).
bench_contention measures what a second busy core costs the first on this machine.

``--cases N`` (default 999 random + the nominal), ``--duration S`` (default 120),
``--only full|reduced``, ``--backends local,ensemble,dask``, ``--repeat N`` (default
1). Run with
``python bench/bench_scale.py`` (or ``make bench``); on a shared machine the numbers
are pessimistic.
"""

from __future__ import annotations

import argparse
import contextlib
import itertools
import math
import os
import shutil
import statistics
import tempfile
import time
from pathlib import Path

import harness
from flexsat.campaigns import load_campaign, run_campaign
from flexsat.campaigns.definition import CampaignDefinition, Reduced
from flexsat.config import nominal, validate_config

GOAL_S = 15.0  # 1000 reduced-model cases on 2 cores (issue 46; issue 18 asked 30 s)
GOAL_EFFICIENCY = 0.9


def definition(duration_s: float, reduced: bool) -> CampaignDefinition:
    data = load_campaign("montecarlo-random").model_dump(mode="json")
    data["base"] = {**data["base"], "duration_s": duration_s}
    if reduced:
        data["reduced"] = Reduced().model_dump(mode="json")
    return validate_config(data, model=CampaignDefinition)


def _reduced_note(out: dict, _results: dict) -> str:
    note = f"{out['results']['reduced local']['cases_per_s_2']:.2f} cases/s"
    full = out["results"].get("full local")
    if full is not None:
        note += f"; full model {full['per_1000_cases_2_s']:.0f} s"
    return note


def _efficiency_note(out: dict, results: dict) -> str:
    note = f"{out['cases']} cases of {out['duration_s']:g} s"
    ceiling = (results.get("bench_contention") or {}).get("efficiency_ceiling")
    if ceiling is not None:  # what two busy cores allow (bench_contention)
        note += f"; the machine's ceiling {ceiling:.0%}"
    return note


def _efficiency(key: str) -> harness.Target:
    return harness.Target(
        f"{key}: 1 -> 2 workers efficiency >= {GOAL_EFFICIENCY:.0%}", GOAL_EFFICIENCY, "",
        lambda r: r["results"][key]["efficiency"] if key in r["results"] else None, "{:.0%}",
        at_most=False, note=_efficiency_note)  # fmt: skip


TARGETS = (
    harness.Target(
        f"1000 random MC cases, reduced model, 2 workers <= {GOAL_S:g} s", GOAL_S, "s",
        lambda r: (r["results"].get("reduced local") or {}).get("per_1000_cases_2_s"),
        "{:.0f} s", note=_reduced_note),
    *(_efficiency(f"{model} {backend}") for model in ("reduced", "full")
      for backend in ("local", "ensemble", "dask")),
)  # fmt: skip


@harness.register(
    "1000 random Monte Carlo cases of the 120 s slew, reduced and full model, local pool, "
    "ensemble runner and Dask, 1 worker (on one core) and 2: wall time, cases/s, efficiency, "
    "against 15 s and 90 %",
    targets=TARGETS,
)
def main(argv: list[str] | None = None) -> dict:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--cases", type=int, default=999, help="random cases (+ the nominal)")
    parser.add_argument("--duration", type=float, default=120.0, help="slew length [s]")
    parser.add_argument("--only", choices=("full", "reduced"), default=None)
    parser.add_argument("--backends", default="local,ensemble,dask")
    parser.add_argument("--repeat", type=int, default=1, help="runs of each configuration")
    args = parser.parse_args(argv)
    console = harness.console(150)
    models = [args.only] if args.only else ["reduced", "full"]
    backends = args.backends.split(",")
    n = args.cases + 1
    console.print(f"{n} cases of {args.duration:g} s, {os.cpu_count()} cores, load "
                  f"{harness.load()}")  # fmt: skip
    walls: dict[tuple[str, str, int], float] = {}  # the best run's
    runs_s: dict[tuple[str, str, int], list[float]] = {}  # every run's, in order
    cpus: dict[tuple[str, str, int], float] = {}  # CPU s per case, runs in this process
    split: dict[str, tuple[float, float]] = {}  # model: (parent, workers) CPU s per case, x2
    with tempfile.TemporaryDirectory(prefix="flexsat-bench-scale-") as tmp:
        for model in models:
            campaign = definition(args.duration, model == "reduced")
            for runner in ("pool", "ensemble"):  # warm up: compiled code loaded in this process
                run_campaign(definition(1.0, model == "reduced"), nominal(),
                             Path(tmp) / f"warm-{model}-{runner}", workers=1, n_random=1,
                             progress=False, runner=runner)  # fmt: skip
            runs = itertools.product(range(args.repeat), backends, (1, 2))
            for attempt, backend, workers in runs:
                store = Path(tmp) / f"{model}-{backend}-{workers}-{attempt}"
                options = {"local": {"workers": workers},
                           "ensemble": {"workers": workers, "runner": "ensemble"},
                           "dask": {"dask_local": workers}}[backend]  # fmt: skip
                cpu, children = time.process_time(), harness.children_cpu_s()
                before = harness.load()
                with _cores(workers):
                    run = run_campaign(campaign, nominal(), store, n_random=args.cases,
                                       progress=False, **options)  # fmt: skip
                key, wall = (model, backend, workers), run["wall_time_s"]
                runs_s.setdefault(key, []).append(wall)
                best = wall < walls.get(key, float("inf"))
                walls[key] = min(wall, walls.get(key, float("inf")))
                here = backend == "ensemble" or (backend == "local" and workers == 1)
                if here and best:
                    cpus[key] = (time.process_time() - cpu) / n
                if backend == "local" and workers == 2 and best:  # the workers are reaped
                    split[model] = ((time.process_time() - cpu) / n,
                                    (harness.children_cpu_s() - children) / n)  # fmt: skip
                console.print(f"  {model:7s} {backend:8s} x{workers} (run {attempt + 1}): "
                              f"{wall:.1f} s ({n / wall:.2f} cases/s)"
                              + (f", {(time.process_time() - cpu) / n:.4f} CPU s per case"
                                 if here else "")
                              + f"; load before {before}, after {harness.load()}")  # fmt: skip
                shutil.rmtree(store)  # about 0.24 GB per 1000 cases: not kept N times over
    table = harness.table(
        f"{n} random Monte Carlo cases ({args.duration:g} s slews), best of "
        f"{args.repeat} run{'s' * (args.repeat > 1)}",
        ("model", "backend", "x1 (s)", "x2 (s)", "cases/s x2", "efficiency", "efficiency, pairs",
         "1000 cases x2 (s)", "CPU s/case x1", "CPU s/case x2", f"<= {GOAL_S:g} s", ">= 90 %"),
        left=2,
    )  # fmt: skip
    results = {}
    for model in models:
        for backend in backends:
            one, two = walls[model, backend, 1], walls[model, backend, 2]
            per_1000 = two * 1000 / n
            efficiency = one / two / 2
            # each run's x1 against the x2 run right after it, the pair in one phase
            paired = zip(runs_s[model, backend, 1], runs_s[model, backend, 2], strict=True)
            pairs = statistics.median(a / b / 2 for a, b in paired)
            speed = ("met" if per_1000 <= GOAL_S else "not met") if model == "reduced" else "-"
            scaling = "met" if efficiency >= GOAL_EFFICIENCY else "not met"
            cpu = cpus.get((model, backend, 1), float("nan"))
            cpu_2 = cpus.get((model, backend, 2), float("nan"))
            if backend == "local" and model in split:  # this process's and the workers'
                cpu_2 = sum(split[model])
            table.add_row(model, backend, f"{one:.1f}", f"{two:.1f}", f"{n / two:.2f}",
                          f"{efficiency:.0%}", f"{pairs:.0%}", f"{per_1000:.1f}",
                          *("-" if math.isnan(c) else f"{c:.4f}" for c in (cpu, cpu_2)),
                          speed, scaling)  # NaN: run elsewhere (Dask's workers)  # fmt: skip
            results[f"{model} {backend}"] = {"wall_1_s": one, "wall_2_s": two,
                                             "cases_per_s_2": n / two, "efficiency": efficiency,
                                             "efficiency_pairs": pairs,
                                             "per_1000_cases_2_s": per_1000,
                                             "cpu_per_case_1_s": cpu,
                                             "cpu_per_case_2_s_all": cpu_2}  # fmt: skip
    console.print(table)
    for model, (parent, workers) in split.items():
        console.print(f"{model} local x2, CPU s per case: {parent:.4f} parent + {workers:.4f} "
                      f"workers = {parent + workers:.4f} (two cores at {GOAL_S:g} s per 1000 "
                      f"cases: "
                      f"<= {2 * GOAL_S / 1000:.3f})")  # fmt: skip
        results[f"{model} local"]["cpu_per_case_2_s"] = {"parent": parent, "workers": workers}
    for model_backend, row in results.items():  # the goal, wall time and CPU time
        if model_backend.startswith("reduced"):
            per_1000, cpu_2 = row["per_1000_cases_2_s"], row["cpu_per_case_2_s_all"]
            verdict = "met" if per_1000 <= GOAL_S else "not met"
            budget = 2 * GOAL_S / 1000  # two cores' CPU s per case at the goal
            console.print(f"{model_backend} x2: {per_1000:.1f} s per 1000 cases against "
                          f"{GOAL_S:g} s: {verdict}; "
                          + ("CPU s per case not measured here" if math.isnan(cpu_2) else
                             f"{cpu_2:.4f} CPU s per case against {budget:.3f}: "
                             f"{'met' if cpu_2 <= budget else 'not met'}"))  # fmt: skip
    console.print(f"load {harness.load()}")
    return {"cases": n, "duration_s": args.duration, "results": results}


@contextlib.contextmanager
def _cores(count: int):
    """Confine this process's threads, and so the processes and threads they start,
    to ``count`` cores for the block.

    One worker gets one core: otherwise its run has a spare core for the campaign's
    own process (storing, resolving, Dask's client and scheduler) or for the
    ensemble's second thread, and "one worker" would be measured on two cores.
    """
    if not hasattr(os, "sched_setaffinity"):  # Linux only: elsewhere, every core
        yield
        return
    everything = os.sched_getaffinity(0)
    chosen = set(sorted(everything)[:count])
    tasks = Path("/proc/self/task")

    def pin(cores: set[int]) -> None:
        for thread in tasks.iterdir():  # every thread: numba's, Dask's event loop...
            with contextlib.suppress(ProcessLookupError):
                os.sched_setaffinity(int(thread.name), cores)

    pin(chosen)
    try:
        yield
    finally:
        pin(everything)


if __name__ == "__main__":
    main()
