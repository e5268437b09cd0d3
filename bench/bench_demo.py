"""Benchmark: ``flexsat study --quick`` (what ``make demo`` runs), before and after.

"Before" is the code of :data:`BEFORE` (the commit the fast demo started from),
exported with ``git archive`` into a temporary folder; "after" is this checkout's
``src``. Each runs in a fresh process (``python -m flexsat study --quick``) with its
own empty ``NUMBA_CACHE_DIR`` and ``FLEXSAT_CACHE_DIR``: the first run compiles every
kernel (the first run after an install), the later ones load them from that cache
(warm; best of ``--repeats``). Times are wall-clock, from the process's start to
its end; the study's own wall times (in its manifest) exclude compilation after
the change, which this benchmark does not.

Targets: warm <= 20 s, first run <= 60 s, on 2 cores. Run with
``python bench/bench_demo.py [--repeats N] [--before COMMIT]``; on a loaded machine
the times grow with the load average, printed before and after.
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
import tempfile
from pathlib import Path

import harness

BEFORE = "4357442"
"""The commit the fast demo was last measured against (the branch point of its second
round; the first round started from e9c18b0)."""
WARM_MAX_S = 20.0
FIRST_MAX_S = 60.0
ROOT = Path(__file__).resolve().parents[1]


def _study(src: Path, caches: Path, out: Path) -> float:
    env = {
        **os.environ,
        "PYTHONPATH": str(src),
        "NUMBA_CACHE_DIR": str(caches / "numba"),
        "FLEXSAT_CACHE_DIR": str(caches / "flexsat"),
    }
    return harness.stopwatch(lambda: subprocess.run(
        [sys.executable, "-m", "flexsat", "study", "--quick", "--out", str(out)],
        env=env, check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
    )).wall_s  # fmt: skip


def _measure(src: Path, work: Path, repeats: int) -> tuple[float, float]:
    caches = work / "caches"
    first = _study(src, caches, work / "out-first")
    warm = min(_study(src, caches, work / f"out-{k}") for k in range(repeats))
    return first, warm


def _export(commit: str, folder: Path) -> Path:
    archive = subprocess.run(["git", "-C", str(ROOT), "archive", commit, "src"],
                             check=True, capture_output=True).stdout  # fmt: skip
    subprocess.run(["tar", "-x", "-C", str(folder)], input=archive, check=True)
    return folder / "src"


def _demo_target(key: str, limit: float, what: str) -> harness.Target:
    before = 1 if key == "warm_s" else 0  # (first, warm) of the 'before' code
    return harness.Target(f"flexsat study --quick, {what} <= {limit:g} s", limit, "s",
                          lambda r: r[key], "{:.1f} s",
                          note=lambda r, _: f"before: {r['before'][before]:.1f} s")  # fmt: skip


@harness.register(
    "flexsat study --quick (what make demo runs) before and after, compiling and warm, "
    "fresh processes",
    targets=[_demo_target("warm_s", WARM_MAX_S, "warm"),
             _demo_target("first_s", FIRST_MAX_S, "first run")],
)  # fmt: skip
def main(argv: list[str] | None = None) -> dict:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=2, help="warm runs, best kept")
    parser.add_argument("--before", default=BEFORE, help="commit of the 'before' code")
    args = parser.parse_args(argv)
    console = harness.console()
    console.print(f"load average before: {harness.load()}")
    results = {}
    with tempfile.TemporaryDirectory(prefix="flexsat-bench-demo-") as tmp:
        tmp = Path(tmp)
        (tmp / "before").mkdir()
        sources = {f"before ({args.before})": _export(args.before, tmp / "before"),
                   "after (this checkout)": ROOT / "src"}  # fmt: skip
        for k, (label, src) in enumerate(sources.items()):
            results[label] = _measure(src, tmp / f"run-{k}", args.repeats)
    table = harness.table(
        "flexsat study --quick, whole process [s] (2 cores: targets below)",
        ("code", "first run (compiles)", f"warm (best of {args.repeats})"),
    )
    for label, (first, warm) in results.items():
        table.add_row(label, f"{first:.1f}", f"{warm:.1f}")
    after_first, after_warm = results["after (this checkout)"]
    table.add_row("target", f"<= {FIRST_MAX_S:.0f}", f"<= {WARM_MAX_S:.0f}")
    table.add_row("after: met?", str(after_first <= FIRST_MAX_S), str(after_warm <= WARM_MAX_S))
    console.print(table)
    console.print(f"load average after: {harness.load()}")
    return {"first_s": after_first, "warm_s": after_warm,
            "before": results[f"before ({args.before})"]}  # fmt: skip


if __name__ == "__main__":
    main(sys.argv[1:])
