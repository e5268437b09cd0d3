"""Benchmark: the thesis's 120 s closed-loop slew (dt = 1 ms, controller every step).

Prints wall time and microseconds per RK4 step for each registered law (compiled
into the loop), for a user's own compiled law (the quaternion PID of
``examples/compiled_law.py``, registered from that file) against the built-in PD
(target: within 1.2x per step), every registered law against the ASMC (the same
target), and for the ASMC called through the plain-Python
controller path, beside the plant-only open-loop run. Run with ``make bench``.
"""

from __future__ import annotations

import importlib.util
import sys
import time
from pathlib import Path

from rich.console import Console
from rich.table import Table

from flexsat import Plant, nominal
from flexsat.control.laws import CompiledLaw, get_law, law_names
from flexsat.control.quaternion import target_quaternion
from flexsat.simulate import OpenLoopScenario, SlewScenario, design_inertia, run_openloop, run_slew

PYTHON_PATH_DURATION_S = 10.0  # the Python-callback path is timed on 10 s, scaled to 120 s
USER_LAW = Path(__file__).resolve().parents[1] / "examples" / "compiled_law.py"
USER_LAW_TARGET = 1.2  # a user's compiled law per step / the built-in PD's
LAW_TARGET = 1.2  # each registered law per step / the ASMC's


def _register_user_law() -> str:
    """Import the example file as a user's script would run it: it registers its law."""
    spec = importlib.util.spec_from_file_location("compiled_law", USER_LAW)
    module = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = module  # pydantic resolves the model's annotations there
    spec.loader.exec_module(module)
    return module.QPID.name


def _best(fn, repeats: int = 3) -> float:
    return interleaved_best([fn], repeats)[0]


def interleaved_best(fns, repeats: int = 3) -> list[float]:
    """Best wall time of each function, the repeats taken in turn (a load change on a
    shared machine then affects every function alike, not the last one timed)."""
    for fn in fns:
        fn()  # compile / warm up
    best = [float("inf")] * len(fns)
    for _ in range(repeats):
        for k, fn in enumerate(fns):
            start = time.perf_counter()
            fn()
            best[k] = min(best[k], time.perf_counter() - start)
    return best


def main(argv: list[str] | None = None) -> dict:
    """Print the table; return each row's wall time per 120 s [s] and us per step."""
    del argv  # no options
    plant = Plant.from_config(nominal())
    rows = []
    wall = _best(lambda: run_openloop(plant, OpenLoopScenario()))
    rows.append(("plant only (open loop)", 120.0, wall))
    builtin = law_names()
    user = _register_user_law()
    kinds = (*builtin, user)
    scenarios = [SlewScenario.model_validate({"controller": {"kind": k}}) for k in kinds]
    walls = interleaved_best([lambda s=s: run_slew(plant, s) for s in scenarios])
    for kind, wall in zip(kinds, walls, strict=True):
        origin = "user's own law" if kind == user else "compiled"
        rows.append((f"{get_law(kind).label}, {origin}", 120.0, wall))
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
    console = Console()
    console.print(table)
    ratio = numbers[f"{get_law(user).label}, user's own law"]["us_per_step"] / numbers[
        "PD, compiled"]["us_per_step"]  # fmt: skip
    verdict = "met" if ratio <= USER_LAW_TARGET else "MISSED"
    console.print(f"user's compiled PID / built-in PD per step: {ratio:.3f} "
                  f"(target <= {USER_LAW_TARGET}: {verdict})")  # fmt: skip
    numbers["user_law_ratio"] = ratio
    asmc = numbers[f"{get_law('asmc').label}, compiled"]["us_per_step"]
    for kind in (k for k in builtin if k != "asmc"):
        law_ratio = numbers[f"{get_law(kind).label}, compiled"]["us_per_step"] / asmc
        verdict = "met" if law_ratio <= LAW_TARGET else "MISSED"
        console.print(f"{get_law(kind).label} / ASMC per step: {law_ratio:.3f} "
                      f"(target <= {LAW_TARGET}: {verdict})")  # fmt: skip
        numbers[f"{kind}_to_asmc_ratio"] = law_ratio
    return numbers


if __name__ == "__main__":
    main()
