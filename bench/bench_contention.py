"""Benchmark: what a second busy core costs the first, the ceiling of any 2-worker run.

Two worker processes, each confined to its own core, hold the same resolved reduced
campaign cases (the 120 s thesis slew, as in bench_scale) and run ``run_case`` on
command. Each round runs ``--cases`` cases in one worker alone, then in both at once,
and compares the wall time per case. The rounds alternate which worker runs alone,
and alone and together follow each other within seconds, so that the machine's drift
(its speed moves by 15-30 % over minutes) hits both alike. Nothing is shared between
the two workers (no pipe traffic during a round, no store): a slowdown together is
the machine's (shared caches and memory bandwidth, the host's scheduling of two
virtual cores), not flexsat's. Its inverse bounds the parallel efficiency that a
two-worker campaign can reach against a one-worker one (bench_scale's goal: 90 %).

Prints each round and the median ratio. ``--cases K`` (default 30) per round,
``--rounds N`` (default 12). Linux only (``sched_setaffinity``); elsewhere it says so.
"""

from __future__ import annotations

import argparse
import multiprocessing
import os
import statistics
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).parent))  # the spawned workers import bench_scale

import harness


def _serve(conn, core: int, n_cases: int) -> None:
    """Worker: resolve ``n_cases`` reduced cases, run one, then run ``k`` on each command."""
    os.sched_setaffinity(0, {core})
    from bench_scale import definition
    from flexsat.campaigns.definition import CaseStream
    from flexsat.campaigns.runner import run_case
    from flexsat.config import nominal

    cases = list(CaseStream(definition(120.0, reduced=True), nominal(), n_cases))
    run_case(cases[0])  # compiled code loaded
    conn.send("ready")
    while (k := conn.recv()) is not None:
        conn.send(harness.stopwatch(lambda k=k: [run_case(c) for c in cases[:k]]).wall_s / k)


@harness.register(
    "the same reduced cases in two processes, one per core, alone and together, rounds "
    "alternated: what a second busy core costs the first, the ceiling of a two-worker run's "
    "efficiency"
)
def main(argv: list[str] | None = None) -> dict:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--cases", type=int, default=30, help="cases per round")
    parser.add_argument("--rounds", type=int, default=12, help="alternated rounds")
    args = parser.parse_args(argv)
    console = harness.console()
    if not hasattr(os, "sched_setaffinity") or len(os.sched_getaffinity(0)) < 2:
        console.print("bench_contention: needs Linux and two cores; skipped")
        return {}
    context = multiprocessing.get_context("spawn")  # fresh workers, nothing inherited
    cores = sorted(os.sched_getaffinity(0))[:2]
    conns, workers = [], []
    for core in cores:
        ours, theirs = context.Pipe()
        worker = context.Process(target=_serve, args=(theirs, core, args.cases), daemon=True)
        worker.start()
        conns.append(ours)
        workers.append(worker)
    for conn in conns:
        conn.recv()
    table = harness.table(f"reduced case, wall ms per case: one core busy, then both "
                          f"({args.cases} cases each, rounds alternated)",
                          ("round", "alone (ms)", "together (ms)", "together / alone"),
                          left=0)  # fmt: skip
    ratios = []
    for r in range(args.rounds):
        conns[r % 2].send(args.cases)
        alone = conns[r % 2].recv()
        for conn in conns:
            conn.send(args.cases)
        together = statistics.mean(conn.recv() for conn in conns)
        ratios.append(together / alone)
        table.add_row(str(r + 1), f"{1e3 * alone:.1f}", f"{1e3 * together:.1f}",
                      f"{ratios[-1]:.3f}")  # fmt: skip
    for conn in conns:
        conn.send(None)
    for worker in workers:
        worker.join()
    median = statistics.median(ratios)
    console.print(table)
    console.print(f"median together / alone: {median:.3f} (range {min(ratios):.3f}-"
                  f"{max(ratios):.3f}): two busy cores give at most {1 / median:.0%} "
                  f"parallel efficiency on this machine now")  # fmt: skip
    return {"ratios": ratios, "median_ratio": median, "efficiency_ceiling": 1 / median}


if __name__ == "__main__":
    main()
