"""Benchmark: flexsat chains against Basilisk's three engines, per step, N = 1 ... 32.

The scenario is Basilisk's hinged flexible-panel comparison (:mod:`flexpanels`: hub
and two arrays of N hinged segments, RK4 at dt = min(10 ms, T / 200)), timed as that
comparison times it: for each engine and N, a discarded warm-up of
``TIMING_WARMUP_STEPS`` steps, then ``TIMING_TRIALS`` trials of a fixed budget of
``TIMING_STEPS`` steps, each on a freshly built model, and the median.

* flexsat: ``run_openloop`` on the chain model; the time is the integration alone
  (the dataset attribute ``wall_time_s``: the compiled RK4 loop, recording every
  ``RECORD_EVERY`` steps); building the plant and the dataset is not timed.
* Basilisk: ``ExecuteSimulation`` of ``nHingedRigidBodyStateEffector``,
  ``spinningBodyNDOFStateEffector`` and, if the wheel ships it, MuJoCo, without
  recorders; building and ``InitializeSimulation`` are not timed.

``--trials K --best``: the shortest of K trials instead, for every engine alike (on a
loaded machine interference only adds time, and the median of 5 moves by 2x).

Goal: at every N at least twice as fast as the fastest Basilisk engine (the goal of
the hinge-specialized recursion; the earlier 10x was not reached by any chain version),
and a cost linear in N (least-squares line of the per-step time against N: slope,
R^2). The load averages are printed before and after the run: read the table with them.
Run ``python bench/bench_basilisk_chain.py`` (Basilisk: ``pip install -e '.[bench]'``).
"""

from __future__ import annotations

import argparse
import sys

import numpy as np

import flexpanels as fp
import harness
from flexsat.config import validate_config
from flexsat.dynamics.plant import Plant
from flexsat.simulate import OpenLoopScenario, run_openloop

INSTALL_HINT = "Basilisk not installed: pip install -e '.[bench]'"
GOAL_RATIO = 2.0
RECORD_EVERY = 10


def time_flexsat(n: int, trials: int = fp.TIMING_TRIALS, pick=np.median) -> float:
    """Median (or ``pick``) wall time of the fixed step budget over ``trials`` [s]
    (integration only)."""
    plant = Plant.from_config(validate_config(fp.flexsat_config(n)))
    dt = fp.time_step(n)

    def scenario(steps: int) -> OpenLoopScenario:
        return OpenLoopScenario.model_validate(
            fp.flexsat_scenario(n, duration_s=steps * dt, record_every=RECORD_EVERY)
        )

    run_openloop(plant, scenario(fp.TIMING_WARMUP_STEPS), progress=False)
    budget = scenario(fp.TIMING_STEPS)
    walls = [run_openloop(plant, budget, progress=False).dataset.attrs["wall_time_s"]
             for _ in range(trials)]  # fmt: skip
    return float(pick(walls))


def time_basilisk(bsk, build, n: int, trials: int = fp.TIMING_TRIALS, pick=np.median) -> float:
    """Median (or ``pick``) ``ExecuteSimulation`` time of the fixed step budget over
    ``trials`` [s], as Basilisk's comparison measures it (fresh model per trial,
    warm-up discarded)."""
    dt = fp.time_step(n)
    warm = build(bsk, n, dt, False)
    warm.sim.ConfigureStopTime(bsk.macros.sec2nano(fp.TIMING_WARMUP_STEPS * dt))
    warm.sim.ExecuteSimulation()
    walls = []
    for _ in range(trials):
        model = build(bsk, n, dt, False)
        model.sim.ConfigureStopTime(bsk.macros.sec2nano(fp.TIMING_STEPS * dt))
        walls.append(harness.stopwatch(model.sim.ExecuteSimulation).wall_s)
    return float(pick(walls))


def linear_fit(n: np.ndarray, us: np.ndarray) -> tuple[float, float, float]:
    """Least-squares us = a + b N: slope b [us per segment], intercept a [us], R^2."""
    b, a = np.polyfit(n, us, 1)
    residual = us - (a + b * n)
    r2 = 1.0 - float(residual @ residual) / float(((us - us.mean()) ** 2).sum())
    return float(b), float(a), r2


def compare(counts: tuple[int, ...] = fp.SEGMENT_COUNTS, trials: int = fp.TIMING_TRIALS,
            pick=np.median) -> dict:  # fmt: skip
    """Per-step times [us] of flexsat and each Basilisk engine for each N."""
    bsk = fp.import_basilisk()
    engines = fp.engines(bsk)
    rows = []
    for n in counts:
        row = {"N": n, "dof": 6 + 4 * n, "dt_s": fp.time_step(n),
               "flexsat": 1e6 * time_flexsat(n, trials, pick) / fp.TIMING_STEPS}  # fmt: skip
        for name, build in engines.items():
            row[name] = 1e6 * time_basilisk(bsk, build, n, trials, pick) / fp.TIMING_STEPS
        row["fastest"] = min(engines, key=lambda e: row[e])
        row["ratio"] = row[row["fastest"]] / row["flexsat"]
        rows.append(row)
    ns = np.array(counts, dtype=float)
    fits = {e: linear_fit(ns, np.array([r[e] for r in rows])) for e in ("flexsat", *engines)}
    return {"version": bsk.version, "engines": list(engines), "rows": rows, "fits": fits}


@harness.register(
    "chains of N = 1 ... 32 hinged segments (Basilisk's flexible-panel comparison scenario) "
    "per RK4 step against Basilisk's nHingedRigidBodyStateEffector, "
    "spinningBodyNDOFStateEffector and MuJoCo; ratio against the 2x goal",
    optional=True,
)
def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--trials", type=int, default=fp.TIMING_TRIALS,
                        help="trials per engine and N (default: the comparison's)")  # fmt: skip
    parser.add_argument("--best", action="store_true",
                        help="the shortest trial instead of the median (a loaded machine "
                        "only adds time), for every engine alike")  # fmt: skip
    args = parser.parse_args(argv)
    console = harness.console(200)
    try:
        fp.import_basilisk()
    except ImportError:
        print(INSTALL_HINT)
        return 0
    console.print(f"{harness.machine()}; load average {harness.load()} (1, 5, 15 min)")
    out = compare(trials=args.trials, pick=np.min if args.best else np.median)
    engines = out["engines"]
    table = harness.table(
        f"Hinged flexible panels (Basilisk's comparison scenario), µs per RK4 step: "
        f"{'best' if args.best else 'median'} of {args.trials} x {fp.TIMING_STEPS} steps, "
        f"Basilisk {out['version']}",
        ("N", "DOF", "dt ms", "flexsat", *engines, "ratio", "goal"), left=0, no_wrap=True,
        caption=f"ratio: fastest Basilisk engine / flexsat; goal >= {GOAL_RATIO:g}x",
    )  # fmt: skip
    for r in out["rows"]:
        table.add_row(
            str(r["N"]), str(r["dof"]), f"{1e3 * r['dt_s']:.4g}", f"{r['flexsat']:.2f}",
            *(f"{r[e]:.1f}" for e in engines), f"{r['ratio']:.1f}x ({r['fastest']})",
            "met" if r["ratio"] >= GOAL_RATIO else "MISSED",
        )  # fmt: skip
    console.print(table)
    for engine, (slope, intercept, r2) in out["fits"].items():
        console.print(f"{engine}: {intercept:.2f} µs + {slope:.3f} µs per segment, R² = {r2:.4f}")
    console.print(f"load average after the run {harness.load()} (1, 5, 15 min)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
