"""Benchmark: memory of a 2000-case campaign stays flat while it runs.

Runs ``montecarlo-random`` with 1999 random cases plus the nominal (short slews, so
the run takes minutes, not hours) on the local pool with 2 workers, into a fresh
temporary store, and samples the resident memory (RSS) of this process (the parent:
it resolves the cases, receives every row and writes the store) and of the worker
processes every 0.2 s. Prints RSS against the number of stored cases, and the growth
of the parent from the first to the last quarter of the run: flat means the parent
keeps nothing per case beyond its resolved inputs.

``--cases N`` and ``--duration S`` change the size; run with
``python bench/bench_campaign_memory.py`` (or ``make bench``).
"""

from __future__ import annotations

import argparse
import tempfile
import threading
import time
from pathlib import Path

import psutil

import harness
from flexsat.campaigns import load_campaign, run_campaign
from flexsat.campaigns.definition import CampaignDefinition
from flexsat.config import nominal, validate_config

MB = 2**20


def _definition(duration_s: float) -> CampaignDefinition:
    data = load_campaign("montecarlo-random").model_dump(mode="json")
    data["base"] = {**data["base"], "duration_s": duration_s}
    return validate_config(data, model=CampaignDefinition)


def _sample(store: Path, stop: threading.Event, samples: list) -> None:
    me = psutil.Process()
    cases = store / "cases"
    while not stop.is_set():
        workers = 0.0
        for child in me.children(recursive=True):
            try:
                workers += child.memory_info().rss
            except psutil.Error:
                pass
        stored = sum(1 for _ in cases.glob("*.json")) if cases.exists() else 0
        samples.append((time.perf_counter(), stored, me.memory_info().rss, workers))
        stop.wait(0.2)


@harness.register(
    "a 2000-case campaign on two workers: resident memory of the parent and the workers "
    "against the cases stored",
    full=False,
)
def main(argv: list[str] | None = None) -> dict:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--cases", type=int, default=1999, help="random cases (+ the nominal)")
    parser.add_argument("--duration", type=float, default=0.5, help="slew length [s]")
    args = parser.parse_args(argv)
    console = harness.console()
    samples: list = []
    with tempfile.TemporaryDirectory() as tmp:
        store = Path(tmp) / "store"
        stop = threading.Event()
        sampler = threading.Thread(target=_sample, args=(store, stop, samples), daemon=True)
        start = time.perf_counter()
        sampler.start()
        try:
            run = run_campaign(_definition(args.duration), nominal(), store, workers=2,
                               n_random=args.cases, progress=False)  # fmt: skip
        finally:
            stop.set()
            sampler.join()
        wall = time.perf_counter() - start
    total = run["cases"]
    table = harness.table(
        f"Memory of a {total}-case campaign (2 local workers, {wall:.0f} s)",
        ("stored cases", "parent RSS [MB]", "workers RSS [MB]"),
        left=0,
    )
    marks = [round(total * k / 8) for k in range(9)]
    shown = []
    for mark in marks:
        row = next((s for s in samples if s[1] >= mark), samples[-1])
        shown.append(row)
        table.add_row(str(row[1]), f"{row[2] / MB:.0f}", f"{row[3] / MB:.0f}")
    console.print(table)
    running = [s for s in samples if 0 < s[1] < total]
    quarter = max(len(running) // 4, 1)
    first = max(s[2] for s in running[:quarter]) / MB if running else float("nan")
    last = max(s[2] for s in running[-quarter:]) / MB if running else float("nan")
    console.print(f"parent RSS, peak of the first quarter {first:.0f} MB, of the last "
                  f"{last:.0f} MB: growth {last - first:+.0f} MB over {total} cases")  # fmt: skip
    return {"cases": total, "wall_s": wall, "parent_first_mb": first, "parent_last_mb": last}


if __name__ == "__main__":
    main()
