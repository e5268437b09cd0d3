"""Benchmark: the thesis's 120 s closed-loop slew (dt = 1 ms, controller every step).

Prints wall time and microseconds per RK4 step for each built-in law (compiled into
the loop) and for the ASMC called through the plain-Python controller path, beside
the plant-only open-loop run. Run with ``make bench``.
"""

from __future__ import annotations

import time

from rich.console import Console
from rich.table import Table

from flexsat import Plant, nominal
from flexsat.control.laws import CompiledLaw
from flexsat.control.quaternion import target_quaternion
from flexsat.simulate import OpenLoopScenario, SlewScenario, design_inertia, run_openloop, run_slew

PYTHON_PATH_DURATION_S = 10.0  # the Python-callback path is timed on 10 s, scaled to 120 s


def _best(fn, repeats: int = 3) -> float:
    fn()  # compile / warm up
    best = float("inf")
    for _ in range(repeats):
        start = time.perf_counter()
        fn()
        best = min(best, time.perf_counter() - start)
    return best


def main(argv: list[str] | None = None) -> dict:
    """Print the table; return each row's wall time per 120 s [s] and us per step."""
    del argv  # no options
    plant = Plant.from_config(nominal())
    rows = []
    wall = _best(lambda: run_openloop(plant, OpenLoopScenario()))
    rows.append(("plant only (open loop)", 120.0, wall))
    for kind in ("asmc", "smc", "pd"):
        scenario = SlewScenario.model_validate({"controller": {"kind": kind}})
        wall = _best(lambda scenario=scenario: run_slew(plant, scenario))
        rows.append((f"{kind.upper()}, compiled", 120.0, wall))
    short = SlewScenario(duration_s=PYTHON_PATH_DURATION_S)

    def python_path():
        q_d = target_quaternion(short.target_euler_deg)
        law = CompiledLaw(
            short.controller, short.actuator, design_inertia(), q_d, short.control_dt_s
        )
        run_slew(plant, short, controller=law)

    rows.append(("ASMC, Python callback", PYTHON_PATH_DURATION_S, _best(python_path, 1)))
    table = Table(title="Closed-loop slew, nominal case, RK4 dt = 1 ms, whole run incl. recording")
    for column in ("run", "simulated s", "wall s", "wall per 120 s", "us per step"):
        table.add_column(column, justify="right" if column != "run" else "left")
    numbers = {}
    for name, simulated, wall in rows:
        per_120 = wall * 120.0 / simulated
        per_step = 1e6 * wall / (simulated / 1e-3)
        numbers[name] = {"wall_per_120_s": per_120, "us_per_step": per_step}
        table.add_row(name, f"{simulated:.0f}", f"{wall:.3f}", f"{per_120:.3f}",
                      f"{per_step:.2f}")  # fmt: skip
    Console().print(table)
    return numbers


if __name__ == "__main__":
    main()
