"""Benchmark: the thesis's 120 s closed-loop slew (dt = 1 ms, controller every step).

Prints wall time and microseconds per RK4 step for each registered law (compiled
into the loop), for a user's own compiled law (the quaternion PID of
``examples/compiled_law.py``, registered from that file) against the built-in PD
(target: within 1.2x per step), every registered law against the ASMC (the same
target), and for the ASMC called through the plain-Python
controller path, beside the plant-only open-loop run. Run with ``make bench``.
``--duration S`` shortens the runs (default the thesis's 120 s; the Python path flies
at most 10 s); "wall per 120 s" scales a run linearly.
"""

from __future__ import annotations

import argparse
import importlib.util
import sys
from pathlib import Path

import harness
from flexsat import Plant, nominal
from flexsat.control.laws import CompiledLaw, get_law, law_names
from flexsat.control.quaternion import target_quaternion
from flexsat.simulate import OpenLoopScenario, SlewScenario, design_inertia, run_openloop, run_slew

PYTHON_PATH_DURATION_S = 10.0  # the Python-callback path is timed on 10 s, scaled to 120 s
USER_LAW = Path(__file__).resolve().parents[1] / "examples" / "compiled_law.py"
USER_LAW_TARGET = 1.2  # a user's compiled law per step / the built-in PD's
LAW_TARGET = 1.2  # each registered law per step / the ASMC's
OPENLOOP_MAX_S = 0.6  # the plant-only open loop, whole call per 120 s
SLEW_MAX_S = 0.7  # the ASMC slew, whole call per 120 s


def _register_user_law() -> str:
    """Import the example file as a user's script would run it: it registers its law."""
    spec = importlib.util.spec_from_file_location("compiled_law", USER_LAW)
    module = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = module  # pydantic resolves the model's annotations there
    spec.loader.exec_module(module)
    return module.QPID.name


def _whole_call(row: str, mode: str):
    """The note of a whole-call target: us/step, and bench_scaling's integration alone."""

    def note(result: dict, results: dict) -> str:
        text = f"whole call, best of 3; {result[row]['us_per_step']:.2f} us/step"
        scaling = results.get("bench_scaling")
        if scaling is not None:
            text += f"; integration alone {scaling['sizes'][2][mode]['us_per_step']:.2f} us/step"
        return text

    return note


TARGETS = (
    harness.Target(
        f"plant-only open loop, 120 s, nominal <= {OPENLOOP_MAX_S} s", OPENLOOP_MAX_S, "s",
        lambda r: r["plant only (open loop)"]["wall_per_120_s"], "{:.3f} s",
        note=_whole_call("plant only (open loop)", "plant only"),
    ),
    harness.Target(
        f"ASMC slew, 120 s, nominal <= {SLEW_MAX_S} s", SLEW_MAX_S, "s",
        lambda r: r["ASMC, compiled"]["wall_per_120_s"], "{:.3f} s",
        note=_whole_call("ASMC, compiled", "ASMC"),
    ),
    harness.Target(
        f"a user's compiled law per step <= {USER_LAW_TARGET}x the built-in PD", USER_LAW_TARGET,
        "x", lambda r: r["user_law_ratio"], "{:.3f}x",
        note=lambda r, _: "examples/compiled_law.py, 120 s",
    ),
)  # fmt: skip


@harness.register(
    "the thesis's 120 s slew with each compiled law, and with the ASMC as a Python callback",
    targets=TARGETS,
)
def main(argv: list[str] | None = None) -> dict:
    """Print the table; return each row's wall time per 120 s [s] and us per step."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--duration", type=float, default=120.0, help="simulated s per run")
    args = parser.parse_args(argv)
    plant = Plant.from_config(nominal())
    rows = []
    openloop = OpenLoopScenario(duration_s=args.duration)
    wall, _ = harness.best_of(lambda: run_openloop(plant, openloop), 3, warm_up=True)
    rows.append(("plant only (open loop)", args.duration, wall))
    builtin = law_names()
    user = _register_user_law()
    kinds = (*builtin, user)
    scenarios = [
        SlewScenario.model_validate({"duration_s": args.duration, "controller": {"kind": k}})
        for k in kinds
    ]
    walls = harness.best(harness.interleave(
        {k: harness.wall(lambda s=s: run_slew(plant, s)) for k, s in zip(kinds, scenarios,
                                                                          strict=True)},
        3, warm_up=True))  # fmt: skip
    for kind, wall in walls.items():
        origin = "user's own law" if kind == user else "compiled"
        rows.append((f"{get_law(kind).label}, {origin}", args.duration, wall))
    short = SlewScenario(duration_s=min(PYTHON_PATH_DURATION_S, args.duration))

    def python_path():
        q_d = target_quaternion(short.target_euler_deg)
        law = CompiledLaw(
            short.controller, short.actuator, design_inertia(), q_d, short.control_dt_s
        )
        run_slew(plant, short, controller=law)

    rows.append(("ASMC, Python callback", short.duration_s,
                 harness.best_of(python_path, 1, warm_up=True)[0]))  # fmt: skip
    table = harness.table(
        "Closed-loop slew, nominal case, RK4 dt = 1 ms, whole run incl. recording",
        ("run", "simulated s", "wall s", "wall per 120 s", "us per step"),
    )
    numbers = {}
    for name, simulated, wall in rows:
        per_120 = wall * 120.0 / simulated
        per_step = 1e6 * wall / (simulated / 1e-3)
        numbers[name] = {"wall_per_120_s": per_120, "us_per_step": per_step}
        table.add_row(name, f"{simulated:.0f}", f"{wall:.3f}", f"{per_120:.3f}",
                      f"{per_step:.2f}")  # fmt: skip
    console = harness.console()
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
