"""Benchmark: the thesis's open-loop run with flexsat against a plain NumPy + SciPy baseline.

Scenario: at rest, body torque (0, 0, 1) N m for 0 <= t < 10 s, then free, to 120 s.
Run with ``python bench/bench_openloop.py`` (about 4 minutes: the baseline is slow)
or ``--quick`` (well under a minute: shorter runs, extrapolated to 120 s).

Rows, all timed in this one process:

* flexsat RK4 (compiled, dt = 1 ms): ``run_openloop(plant)``, run once first so that
  compilation is not timed. Its integration alone (the dataset's ``wall_time_s``)
  is the reference of the speed-up column; the whole call, which also builds the
  recorded dataset (energies, loads, momentum at every 10 ms), is shown too.
* flexsat DOP853 (rtol 1e-10, atol 1e-12): ``run_openloop`` with that solver.
* baseline RK4: :func:`baseline_numpy.run_baseline_rk4`, RK4 at 1 ms in a plain
  Python loop. A 1 s pilot run estimates the full run; if that exceeds 3 minutes a
  10 s run is timed instead and extrapolated linearly (the cost per fixed step is
  constant, so the extrapolation is sound), and the row says so.
* baseline solve_ivp: :func:`baseline_numpy.run_baseline_solve_ivp`, DOP853 at
  rtol 1e-8, atol 1e-10, split at the torque switch.

Wall times are integration only unless the row says otherwise; "per 120 s" scales
a shorter run linearly (for the adaptive solvers under ``--quick`` that over-states
the cost a little: the torque phase takes the most steps per simulated second). The
yaw rate of a shorter run is given at its end, next to flexsat RK4's at that time.
"""

from __future__ import annotations

import argparse

import numpy as np

import harness
from baseline_numpy import (
    TORQUE_END_S,
    run_baseline_rk4,
    run_baseline_solve_ivp,
    time_per_call_us,
)
from flexsat import Plant
from flexsat.config import nominal
from flexsat.simulate import run_openloop
from flexsat.simulate.scenario import OpenLoopScenario

FULL_S = 120.0
RK4_BUDGET_S = 180.0  # time the full baseline RK4 run only if it is estimated below this
RK4_SHORT_S = 10.0  # otherwise time this long a run and extrapolate


def _final(result):
    ds = result.dataset
    rate = np.degrees(ds["omega"].values[-1, 2])
    return float(rate), float(ds["angular_momentum"].values[-1, 2])


def _flexsat_rk4(plant):
    whole, result = harness.best_of(lambda: run_openloop(plant), 1, warm_up=True)
    result.raise_for_status()
    rate, h_z = _final(result)
    attrs = result.dataset.attrs
    return result, {
        "simulated_s": FULL_S,
        "wall_time_s": float(attrs["wall_time_s"]),
        "whole_call_s": whole,
        "final_rate_deg_s": rate,
        "angular_momentum_z": h_z,
        "evaluations": 4 * int(attrs["steps"]),
    }


def _flexsat_dop853(plant, duration_s):
    scenario = OpenLoopScenario(solver="dop853", rtol=1e-10, atol=1e-12, duration_s=duration_s)
    timed = harness.stopwatch(lambda: run_openloop(plant, scenario))
    whole, result = timed.wall_s, timed.value
    result.raise_for_status()
    rate, h_z = _final(result)
    return {
        "simulated_s": duration_s,
        "wall_time_s": float(result.dataset.attrs["wall_time_s"]),
        "whole_call_s": whole,
        "final_rate_deg_s": rate,
        "angular_momentum_z": h_z,
        "evaluations": int(result.dataset.attrs["steps"]),  # right-hand sides for DOP853
    }


def _baseline_rk4(console, quick):
    pilot = run_baseline_rk4(1.0)
    estimate = pilot["wall_time_s"] * FULL_S
    if quick:
        return pilot, "quick: 1 s timed"
    if estimate <= RK4_BUDGET_S:
        console.log(f"baseline RK4: full run, estimated {estimate:.0f} s")
        return run_baseline_rk4(FULL_S), ""
    console.log(
        f"baseline RK4: full run estimated {estimate:.0f} s > {RK4_BUDGET_S:.0f} s, "
        f"timing {RK4_SHORT_S:.0f} s"
    )
    return run_baseline_rk4(RK4_SHORT_S), f"{RK4_SHORT_S:.0f} s timed: full run est. > 3 min"


def _rate_cell(out, reference):
    """Final yaw rate; for a shorter run, at its end next to flexsat RK4's at that time."""
    rate = f"{out['final_rate_deg_s']:.7f}"
    if out["simulated_s"] >= FULL_S:
        return rate
    ds = reference.dataset
    ref = np.degrees(ds["omega"].sel(time=out["simulated_s"], method="nearest").values[2])
    return f"{rate} at t = {out['simulated_s']:g} s (flexsat RK4: {ref:.7f})"


@harness.register(
    "the thesis's 120 s open-loop run: flexsat RK4 and DOP853 against a NumPy + SciPy "
    "baseline (RK4 Python loop, solve_ivp)",
    quick_argv=["--quick"],
)
def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument(
        "--quick", action="store_true", help="time shorter runs and extrapolate them to 120 s"
    )
    args = parser.parse_args(argv)
    console = harness.console(240)  # the table's width to a file or a pipe
    plant = Plant.from_config(nominal())

    dop_s = 20.0 if args.quick else FULL_S
    ivp_s = 10.0 if args.quick else FULL_S

    console.log("flexsat RK4 (compile, then timed run)")
    reference, flex_rk4 = _flexsat_rk4(plant)
    console.log(f"flexsat DOP853, {dop_s:g} s")
    flex_dop = _flexsat_dop853(plant, dop_s)
    console.log("baseline RK4 Python loop (1 s pilot run first)")
    base_rk4, rk4_note = _baseline_rk4(console, args.quick)
    console.log(f"baseline solve_ivp DOP853, {ivp_s:g} s")
    base_ivp = run_baseline_solve_ivp(ivp_s)
    console.log("cost of one q_ddot evaluation")
    per_call = {route: time_per_call_us(route) for route in ("sympy", "jacobian")}

    ref_per_120 = flex_rk4["wall_time_s"] * FULL_S / flex_rk4["simulated_s"]
    rows = [
        ("flexsat RK4, compiled, dt 1 ms", flex_rk4, "wall_time_s", "integration only"),
        ("flexsat RK4, whole run_openloop call", flex_rk4, "whole_call_s",
         "incl. building the recorded dataset"),
        ("flexsat DOP853, rtol 1e-10 atol 1e-12", flex_dop, "wall_time_s",
         "quick: shorter run" if args.quick else ""),
        ("baseline RK4, Python loop, dt 1 ms", base_rk4, "wall_time_s", rk4_note),
        ("baseline solve_ivp DOP853, rtol 1e-8 atol 1e-10", base_ivp, "wall_time_s",
         "quick: shorter run" if args.quick else ""),
    ]  # fmt: skip

    columns = (
        "implementation",
        "simulated s",
        "wall s",
        "wall per simulated 120 s",
        "speed-up vs flexsat RK4",
        "final yaw rate deg/s",
        "H_z N m s",
        "note",
    )
    table = harness.table(
        "Open loop, thesis scenario: 1 N m yaw torque for "
        f"{TORQUE_END_S:g} s, free to {FULL_S:g} s (nominal satellite, 18 DOF)",
        columns, right=columns[1:-1], no_wrap=True,
        caption="speed-up: how many times faster flexsat RK4 (integration) is, per simulated "
        "120 s; '~' marks a shorter run extrapolated linearly to 120 s",
    )  # fmt: skip
    for name, out, key, note in rows:
        wall = out[key]
        per_120 = wall * FULL_S / out["simulated_s"]
        extrapolated = out["simulated_s"] < FULL_S
        mark = "~" if extrapolated else ""
        if extrapolated:
            note = ", ".join(filter(None, [note, "per 120 s EXTRAPOLATED"]))
        table.add_row(
            name,
            f"{out['simulated_s']:g}",
            f"{wall:.3f}",
            f"{mark}{per_120:.3f}",
            f"{mark}{per_120 / ref_per_120:.3g}x",
            _rate_cell(out, reference),
            f"{out['angular_momentum_z']:.9f}",
            note,
        )
    console.print(table)

    flex_us = 1e6 * flex_rk4["wall_time_s"] / flex_rk4["evaluations"]
    console.print(
        f"One q_ddot evaluation: flexsat compiled RK4 loop {flex_us:.2f} us (whole step / 4); "
        f"baseline, SymPy-generated M and h (used above) {per_call['sympy']:.0f} us, "
        f"hand-written Jacobian route {per_call['jacobian']:.0f} us."
    )
    console.print(
        f"Evaluations: flexsat RK4 {flex_rk4['evaluations']}, flexsat DOP853 "
        f"{flex_dop['evaluations']}, baseline RK4 {base_rk4['evaluations']}, baseline "
        f"solve_ivp {base_ivp['evaluations']} ({base_ivp['steps']} accepted steps)."
    )
    console.print(f"Machine: {harness.machine()}.")
    return {
        "quick": args.quick,
        "flexsat_rk4": flex_rk4,
        "flexsat_dop853": flex_dop,
        "baseline_rk4": base_rk4,
        "baseline_solve_ivp": base_ivp,
        "eval_us": {"flexsat_rk4_loop": flex_us, **per_call},
    }


if __name__ == "__main__":
    main()
