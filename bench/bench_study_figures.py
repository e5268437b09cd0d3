"""Benchmark: CPU time of the quick study's figure sets, before and after, interleaved.

Each trial runs one fresh process per code (the commit :data:`BEFORE`, exported with
``git archive``, and this checkout's ``src``), in turn, that draws every figure set
from the runs of a finished study folder (``flexsat study --quick --out DIR``) into a
scratch folder: the slew's, the open loop's, the comparison, the frequency part
(:func:`flexsat.study.linear.write_margins`, its linear models included) and the
modal part (:func:`flexsat.study.outputs.write_modal`, its GIFs included). Times are
CPU seconds (user + sys of the process and its forked drawing processes), median of
the trials; the load average is printed before and after.

Run with ``python bench/bench_study_figures.py STUDY_DIR [--trials N] [--before COMMIT]``.
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import harness

BEFORE = "7108d3f"
"""The commit the fixed figure layout started from."""
ROOT = Path(__file__).resolve().parents[1]


def _cpu_s() -> float:
    """CPU seconds of this process and its finished children."""
    return time.process_time() + harness.children_cpu_s()


def _draw_sets(study: Path, scratch: Path) -> dict:
    """CPU seconds of each figure set (run inside the measured process)."""
    from flexsat.config import load_config
    from flexsat.dynamics.plant import Plant
    from flexsat.plots.comparison import write_comparison_figure
    from flexsat.plots.openloop import write_openloop_figures
    from flexsat.plots.slew import write_slew_figures
    from flexsat.simulate import SlewScenario
    from flexsat.simulate.result import Result
    from flexsat.study.linear import write_margins
    from flexsat.study.outputs import write_modal

    plant = Plant.from_config(load_config(None))
    slews = {p.parent.name: Result.from_netcdf(p).dataset
             for p in sorted((study / "slew").glob("*/result.nc"))}  # fmt: skip
    nominal = slews["asmc"] if "asmc" in slews else next(iter(slews.values()))
    openloop = Result.from_netcdf(study / "openloop" / "result.nc").dataset
    sets = {
        "slew": lambda: write_slew_figures(nominal, scratch / "slew"),
        "openloop": lambda: write_openloop_figures(openloop, None, scratch / "openloop"),
        "comparison": lambda: write_comparison_figure(slews, scratch / "comparison.png"),
        "frequency": lambda: write_margins(plant, SlewScenario(), scratch / "frequency"),
        "modal": lambda: write_modal(plant, scratch / "modal"),
    }
    times = {}
    for name, draw in sets.items():
        start = _cpu_s()
        draw()
        times[name] = _cpu_s() - start
    return times


def _trial(src: Path, study: Path) -> dict:
    env = {**os.environ, "PYTHONPATH": f"{src}{os.pathsep}{ROOT / 'bench'}"}
    with tempfile.TemporaryDirectory(prefix="flexsat-bench-figures-") as scratch:
        code = (
            "import json, sys; from pathlib import Path; import bench_study_figures as b; "
            "print(json.dumps(b._draw_sets(Path(sys.argv[1]), Path(sys.argv[2]))))"
        )
        out = subprocess.run([sys.executable, "-c", code, str(study), scratch], env=env,
                             check=True, capture_output=True, text=True).stdout  # fmt: skip
    return json.loads(out.strip().splitlines()[-1])


@harness.register(
    "CPU time of the quick study's figure sets (slew, open loop, comparison, frequency, "
    "modal) drawn from a finished study folder, before (a commit) and after, interleaved, "
    "median of trials; takes the folder as argument",
    full=False,
)
def main(argv: list[str] | None = None) -> dict:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("study", type=Path, help="folder of a finished quick study")
    parser.add_argument("--trials", type=int, default=3)
    parser.add_argument("--before", default=BEFORE)
    args = parser.parse_args(argv)
    print("load average before:", harness.load())
    with tempfile.TemporaryDirectory(prefix="flexsat-bench-figures-src-") as tmp:
        archive = subprocess.run(["git", "-C", str(ROOT), "archive", args.before, "src"],
                                 check=True, capture_output=True).stdout  # fmt: skip
        subprocess.run(["tar", "-x", "-C", tmp], input=archive, check=True)
        codes = {"before": Path(tmp) / "src", "after": ROOT / "src"}
        trials = harness.interleave({label: lambda src=src: _trial(src, args.study.resolve())
                                     for label, src in codes.items()}, args.trials)  # fmt: skip
    print("load average after:", harness.load())
    medians = {label: {name: statistics.median(t[name] for t in runs) for name in runs[0]}
               for label, runs in trials.items()}  # fmt: skip
    print(f"{'figure set':<12} {'before [CPU s]':>15} {'after [CPU s]':>14} {'after/before':>13}")
    for name in medians["before"]:
        b, a = medians["before"][name], medians["after"][name]
        print(f"{name:<12} {b:>15.2f} {a:>14.2f} {a / b:>13.2f}")
    b, a = sum(medians["before"].values()), sum(medians["after"].values())
    print(f"{'total':<12} {b:>15.2f} {a:>14.2f} {a / b:>13.2f}")
    return medians


if __name__ == "__main__":
    main()
