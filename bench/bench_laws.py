"""Benchmark: per-step cost of each law and of the reference and joint-actuator slots.

Flies the thesis's 45/45/45 deg slew (RK4 dt = 1 ms, controller every step,
compiled loop) with each registered law, the ASMC with the smooth Lambda
adaptation, the ASMC tracking the eigenaxis trapezoid, the same with the
five-mode ZVD shaper (243 impulses summed per control instant), the ASMC
with the root actuators of the deployment-shock solution, and a dense order-20
discrete controller through the statespace law (a PD with roll-off in parallel with
a random stable 17-state part, seeded), and prints
microseconds per RK4 step against the thesis's ASMC (step reference, no joint
actuator). Target: within 1.2x. Runs interleaved, best of three, so a load change
on a shared machine affects every row alike. ``--duration`` shortens the runs.
"""

from __future__ import annotations

import argparse
import tempfile
from pathlib import Path

import numpy as np

import control
import harness  # the benchmarks run with bench/ on sys.path
from flexsat import Plant, nominal
from flexsat.control.laws import get_law, law_names
from flexsat.control.laws.statespace import DiscreteController, save_controller
from flexsat.simulate import SlewScenario, design_inertia, run_slew
from flexsat.study.laws import HYBRID_DAMPING

TARGET = 1.2  # per step, against the ASMC with the step reference
TRAPEZOID = {"kind": "eigenaxis", "rate_limit_deg_s": 2.0, "acceleration_limit_deg_s2": 0.2}
SEED = 20261207  # the order-20 controller's random part


def order_20_controller(seed: int = SEED, dt: float = 1e-3) -> DiscreteController:
    """A dense order-20 controller at ``dt``: PD with roll-off + a random stable part."""
    rng = np.random.default_rng(seed)
    J, I3, wn, zeta, wf = design_inertia(), np.eye(3), 0.3, 0.9, 5.0
    pd = control.ss(-wf * I3, wf * np.hstack([wn**2 * I3, 2 * zeta * wn * I3]), -J,
                    np.zeros((3, 6)))  # fmt: skip
    pd = control.c2d(pd, dt, method="tustin")
    Q, _ = np.linalg.qr(rng.standard_normal((17, 17)))
    extra = control.ss(Q @ np.diag(rng.uniform(0.5, 0.99, 17)) @ Q.T,
                       rng.standard_normal((17, 6)), 1e-3 * rng.standard_normal((3, 17)),
                       1e-3 * rng.standard_normal((3, 6)), dt)  # fmt: skip
    both = control.parallel(pd, extra)
    return DiscreteController(both.A, both.B, both.C, both.D, dt)


def _variants(folder: Path) -> dict[str, dict]:
    rows = {get_law(kind).label: {"controller": {"kind": kind}} for kind in law_names()}
    rows["ASMC, smooth Lambda"] = {"controller": {"lambda_adaptation": "smooth"}}
    rows["ASMC, eigenaxis reference"] = {"reference": TRAPEZOID}
    rows["ASMC, ZVD-shaped reference (5 modes)"] = {
        "reference": {**TRAPEZOID, "shaper": {"kind": "zvd"}}
    }
    rows["ASMC + root actuators"] = {"joint_actuator": HYBRID_DAMPING}
    k20 = save_controller(order_20_controller(), folder / "k20.npz")
    rows["statespace, order 20"] = {"controller": {"kind": "statespace", "file": str(k20)}}
    return rows


@harness.register(
    "the thesis's 120 s slew with each registered law, the smooth Lambda adaptation, the "
    "eigenaxis reference, the ZVD shaper and the root actuators: us per RK4 step against "
    "the thesis's ASMC (target within 1.2x), interleaved, best of three",
    targets=[harness.Target(
        f"every law and slot variant per step <= {TARGET}x the ASMC", TARGET, "x",
        lambda r: max(row["ratio_to_asmc"] for row in r.values()), "max {:.3f}x",
        note=lambda r, _: "slowest: " + max(r, key=lambda k: r[k]["ratio_to_asmc"]))],
)  # fmt: skip
def main(argv: list[str] | None = None) -> dict:
    """Print the table; return microseconds per step and the ratio to the ASMC per row."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--duration", type=float, default=120.0, help="simulated s per run")
    args = parser.parse_args(argv)
    plant = Plant.from_config(nominal())
    print(f"seed {SEED}")
    folder = tempfile.TemporaryDirectory()
    variants = _variants(Path(folder.name))
    scenarios = {name: SlewScenario.model_validate({"duration_s": args.duration, **fields})
                 for name, fields in variants.items()}  # fmt: skip
    walls = harness.best(harness.interleave(
        {name: harness.wall(lambda s=s: run_slew(plant, s, progress=False))
         for name, s in scenarios.items()}, 3, warm_up=True))  # fmt: skip
    steps = args.duration / 1e-3
    per_step = {name: 1e6 * wall / steps for name, wall in walls.items()}
    reference = per_step[get_law("asmc").label]
    table = harness.table(f"Per-step cost in the compiled loop ({args.duration:g} s slews, "
                          "RK4 1 ms, controller every step)",
                          ("run", "us per step", "/ ASMC", f"target <= {TARGET}"))  # fmt: skip
    numbers = {}
    for name, us in per_step.items():
        ratio = us / reference
        numbers[name] = {"us_per_step": us, "ratio_to_asmc": ratio}
        table.add_row(name, f"{us:.2f}", f"{ratio:.3f}", "met" if ratio <= TARGET else "MISSED")
    harness.console().print(table)
    folder.cleanup()
    return numbers


if __name__ == "__main__":
    main()
