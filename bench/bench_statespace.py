"""Benchmark: the statespace law with an order-20 controller against the ASMC.

Flies the thesis's 45/45/45 deg slew (RK4 dt = 1 ms, controller every step, compiled
loop) with the ASMC and with a dense order-20 discrete controller read from a file
(the statespace law: a PD through a roll-off in parallel with a random stable
17-state part, seed printed), and prints microseconds per RK4 step and the ratio
(target: within 1.2x). Runs interleaved, best of three. ``--duration`` shortens the
runs.
"""

from __future__ import annotations

import argparse
import tempfile
from pathlib import Path

import numpy as np

import control
import harness  # the benchmarks run with bench/ on sys.path
from flexsat import Plant, nominal
from flexsat.control.laws.statespace import DiscreteController, StateSpaceConfig, save_controller
from flexsat.simulate import SlewScenario, design_inertia, run_slew

TARGET = 1.2  # per RK4 step, against the ASMC
SEED = 20261207
ORDER = 20
DT = 1e-3


def order_20_controller(seed: int = SEED) -> DiscreteController:
    """A dense order-20 controller at 1 ms: PD with roll-off + a random stable part."""
    rng = np.random.default_rng(seed)
    J, I3, wn, zeta, wf = design_inertia(), np.eye(3), 0.3, 0.9, 5.0
    pd = control.ss(-wf * I3, wf * np.hstack([wn**2 * I3, 2 * zeta * wn * I3]), -J,
                    np.zeros((3, 6)))  # fmt: skip
    pd = control.c2d(pd, DT, method="tustin")
    n = ORDER - 3
    Q, _ = np.linalg.qr(rng.standard_normal((n, n)))
    extra = control.ss(Q @ np.diag(rng.uniform(0.5, 0.99, n)) @ Q.T, rng.standard_normal((n, 6)),
                       1e-3 * rng.standard_normal((3, n)), 1e-3 * rng.standard_normal((3, 6)),
                       DT)  # fmt: skip
    both = control.parallel(pd, extra)
    return DiscreteController(both.A, both.B, both.C, both.D, DT)


@harness.register(
    "the thesis's 120 s slew with an order-20 statespace controller against the ASMC: us "
    "per RK4 step (target within 1.2x), interleaved, best of three",
    targets=[harness.Target(
        f"order-20 statespace law per step <= {TARGET}x the ASMC", TARGET, "x",
        lambda r: r["ratio_per_step"], "{:.3f}x")],
)  # fmt: skip
def main(argv: list[str] | None = None) -> dict:
    """Print the table; return the per-step costs and their ratio."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--duration", type=float, default=120.0, help="simulated s per run")
    args = parser.parse_args(argv)
    print(f"seed {SEED}")
    plant = Plant.from_config(nominal())
    with tempfile.TemporaryDirectory() as folder:
        path = save_controller(order_20_controller(), Path(folder) / "k20.npz")
        ss = StateSpaceConfig(file=str(path))
        scenarios = {
            "ASMC": SlewScenario(duration_s=args.duration),
            f"statespace, order {ORDER}": SlewScenario(duration_s=args.duration, controller=ss),
        }
        walls = harness.best(harness.interleave(
            {name: harness.wall(lambda s=s: run_slew(plant, s, progress=False))
             for name, s in scenarios.items()}, 3, warm_up=True))  # fmt: skip
    steps = args.duration / DT
    per_step = {name: 1e6 * wall / steps for name, wall in walls.items()}
    ratio = per_step[f"statespace, order {ORDER}"] / per_step["ASMC"]
    table = harness.table(f"Per-step cost in the compiled loop ({args.duration:g} s slews, "
                          "RK4 1 ms, controller every step)",
                          ("law", "us per RK4 step", "/ ASMC"))  # fmt: skip
    for name, us in per_step.items():
        table.add_row(name, f"{us:.2f}", f"{us / per_step['ASMC']:.3f}")
    harness.console().print(table)
    return {"us_per_step": per_step, "ratio_per_step": ratio}


if __name__ == "__main__":
    main()
