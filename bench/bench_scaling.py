"""Benchmark: cost of a 120 s run against the number of appendages (1, 2, 4, 8).

For each satellite it times, on one core, best of ``REPEATS`` after a warm-up run:

* plant only: ``run_openloop(plant)``, the thesis's open-loop scenario;
* closed loop, ASMC and PD: ``run_slew(plant, scenario)`` with the compiled law in
  the RK4 loop (as ``bench_slew.py``), the thesis's 45/45/45 deg slew;
* the dynamics evaluation alone: the ``accelerations`` kernel called from a compiled
  loop (its own cost) and from Python (plus the call overhead).

Columns "us/step" are the integration alone (the dataset's ``wall_time_s`` over the
RK4 steps: four dynamics evaluations, the control law, recording); "s/120 s" is the
whole call, which also builds the recorded dataset. A least-squares line cost =
a + b n over n = 1, 2, 4, 8 and its R^2 show how the cost grows; the per-appendage
increment is the slope between neighbouring sizes.

Satellites: the nominal hub (inertia, mass: unchanged) with mirrored pairs of the
nominal panel. n = 1 keeps panel_1 alone, n = 2 is the nominal preset itself, and
n = 4, 8 add pairs turned by 180 / (n / 2) deg about the hub Z axis, each pair
mounted at its own height on the hub so that no two panels cross. Every config goes
through the normal validation and joint tuning. Run with ``python bench/bench_scaling.py``.
"""

from __future__ import annotations

import copy
import tomllib

import numpy as np
from numba import njit

import harness
from flexsat.config import SatelliteConfig, preset_path, validate_config
from flexsat.dynamics import kernels
from flexsat.dynamics.plant import Plant
from flexsat.simulate import OpenLoopScenario, SlewScenario, run_openloop, run_slew

SIZES = (1, 2, 4, 8)
REPEATS = 3
MOUNT_RADIUS_M = 0.8  # the nominal mount points' distance from the hub axis
PAIR_SPACING_M = 0.3  # height between neighbouring pairs on the hub (H_hub = 1.5 m)
MODES = ("plant only", "ASMC", "PD")
LINEAR_R2 = 0.99  # the target: a straight line explains at least this share of the variance


def scaled_config(n_appendages: int) -> SatelliteConfig:
    """The nominal satellite with ``n_appendages`` copies of its panel (1 or an even number)."""
    data = tomllib.loads(preset_path("nominal").read_text())
    if n_appendages == 2:
        return validate_config(data)
    plus, minus = data["appendages"]  # panel_1 along +Y_B, panel_2 mirrored along -Y_B
    if n_appendages == 1:
        data["appendages"] = [plus]
        data["name"] = "nominal-1-panel"
        return validate_config(data)
    if n_appendages % 2:
        raise ValueError("n_appendages must be 1 or even (mirrored pairs)")
    pairs = n_appendages // 2
    apps = []
    for k in range(pairs):
        yaw = 180.0 * k / pairs
        height = PAIR_SPACING_M * (k - 0.5 * (pairs - 1))
        s, c = np.sin(np.radians(yaw)), np.cos(np.radians(yaw))
        for side, base in ((1.0, plus), (-1.0, minus)):
            app = copy.deepcopy(base)
            app.update(
                name=f"panel_{len(apps) + 1}",
                mount_yaw_deg=yaw,
                mount_point_m=[-side * MOUNT_RADIUS_M * s, side * MOUNT_RADIUS_M * c, height],
            )
            apps.append(app)
    data["appendages"] = apps
    data["name"] = f"nominal-{n_appendages}-panels"
    return validate_config(data)


@njit(cache=False)
def _evaluate(q, qd, Q, args, qdd, n_calls):
    status = 0
    for _ in range(n_calls):
        status |= kernels.accelerations(q, qd, Q, args, qdd)
    return status


def evaluation_us(plant: Plant) -> tuple[float, float]:
    """One ``accelerations`` call (us): from a compiled loop, and from Python."""
    rng = np.random.default_rng(0)
    q = rng.normal(scale=0.1, size=plant.n_dof)
    qd = rng.normal(scale=0.1, size=plant.n_dof)
    Q = rng.normal(size=plant.n_dof)
    qdd = np.empty(plant.n_dof)
    args = plant.packed
    n_calls = 100_000
    _evaluate(q, qd, Q, args, qdd, 10)  # compile (numba specializes on types, not sizes)
    compiled = harness.best_of(lambda: _evaluate(q, qd, Q, args, qdd, n_calls), 5)[0] / n_calls
    n_py = 20_000

    def from_python():
        for _ in range(n_py):
            kernels.accelerations(q, qd, Q, args, qdd)

    python = harness.best_of(from_python, 5)[0] / n_py
    return 1e6 * compiled, 1e6 * python


def _timed(run) -> tuple[float, float, object]:
    """One run: whole call [s], integration per RK4 step (us), the result."""
    timed = harness.stopwatch(run)
    attrs = timed.value.dataset.attrs
    return timed.wall_s, 1e6 * float(attrs["wall_time_s"]) / int(attrs["steps"]), timed.value


def measure() -> dict:
    """Every timing of every size. Each run is warmed up once, then the repeats of all
    runs are interleaved, so that a passing load on the machine does not hit one alone."""
    asmc = SlewScenario()
    pd = SlewScenario.model_validate({"controller": {"kind": "pd"}})
    sizes, runs = {}, {}
    for n in SIZES:
        plant = Plant.from_config(scaled_config(n))
        compiled_us, python_us = evaluation_us(plant)
        sizes[n] = {"n_dof": plant.n_dof, "eval_compiled_us": compiled_us,
                    "eval_python_us": python_us}  # fmt: skip
        runs[n, "plant only"] = lambda p=plant: run_openloop(p, OpenLoopScenario(), progress=False)
        runs[n, "ASMC"] = lambda p=plant: run_slew(p, asmc, progress=False)
        runs[n, "PD"] = lambda p=plant: run_slew(p, pd, progress=False)
    samples = harness.interleave({key: lambda run=run: _timed(run) for key, run in runs.items()},
                                 REPEATS, warm_up=True)  # fmt: skip
    for (n, mode), timed in samples.items():
        result = timed[-1][2]
        sizes[n][mode] = {"whole_s": min(t[0] for t in timed),
                          "us_per_step": min(t[1] for t in timed), "ok": result.ok,
                          "simulated_s": float(result.dataset["time"].values[-1])}  # fmt: skip
    return sizes


def linear_fit(n: np.ndarray, cost: np.ndarray) -> tuple[float, float, float]:
    """Least-squares cost = a + b n; returns a, b and R^2."""
    b, a = np.polyfit(n, cost, 1)
    residual = cost - (a + b * n)
    r2 = 1.0 - float(residual @ residual) / float(((cost - cost.mean()) ** 2).sum())
    return float(a), float(b), r2


def _linearity(result: dict) -> float:
    """The worst R^2 of the per-step cost lines (us/step) of the three modes."""
    return min(fit["r2"] for k, fit in result["fits"].items() if k.endswith("(us/step)"))


def _slopes(result: dict, _results: dict) -> str:
    fits = {k: v for k, v in result["fits"].items() if k.endswith("(us/step)")}
    slopes = ", ".join(f"{k.split(' (')[0]} {v['a']:.2f} + {v['b']:.2f} n us"
                       for k, v in fits.items())  # fmt: skip
    return f"R^2 >= {LINEAR_R2} required; per step: {slopes}"


@harness.register(
    "us per RK4 step and s per 120 s run for 1, 2, 4 and 8 appendages (plant only, ASMC, "
    "PD), q_ddot alone, and a least-squares line cost = a + b n",
    targets=[harness.Target("cost linear in the number of appendages (1, 2, 4, 8)", LINEAR_R2,
                            "R^2", _linearity, "min R^2 = {:.4f}", at_most=False,
                            note=_slopes)],
)  # fmt: skip
def main(argv: list[str] | None = None) -> dict:
    """Print the tables; return the numbers (``sizes``: per n, ``fits``: per mode)."""
    del argv  # no options
    console = harness.console()
    sizes = measure()

    table = harness.table(
        f"Cost against the number of appendages: 120 s runs, RK4 dt = 1 ms, one core, "
        f"best of {REPEATS}",
        ("appendages", "DOF", "q_ddot compiled (us)", "q_ddot from Python (us)",
         *(f"{mode} {unit}" for mode in MODES for unit in ("us/step", "s/120 s"))),
        left=0,
        caption="us/step: integration only (4 evaluations + law + recording); "
        "s/120 s: whole call incl. the recorded dataset",
    )  # fmt: skip
    for n, out in sizes.items():
        cells = [str(n), str(out["n_dof"]), f"{out['eval_compiled_us']:.2f}",
                 f"{out['eval_python_us']:.2f}"]  # fmt: skip
        for mode in MODES:
            run = out[mode]
            flag = "" if run["ok"] else f" (FAILED at {run['simulated_s']:.1f} s)"
            cells += [f"{run['us_per_step']:.2f}", f"{run['whole_s']:.3f}{flag}"]
        table.add_row(*cells)
    console.print(table)

    n = np.array(SIZES, dtype=float)
    fits = {}
    growth = harness.table(
        "Growth per appendage: least-squares line cost = a + b n over n = 1, 2, 4, 8",
        ("cost", "a", "b per appendage", "R^2", "b / cost(n=2)", "increment 1->2", "2->4",
         "4->8"),
    )  # fmt: skip
    series = {"q_ddot compiled (us)": [sizes[k]["eval_compiled_us"] for k in SIZES]}
    for mode in MODES:
        series[f"{mode} (us/step)"] = [sizes[k][mode]["us_per_step"] for k in SIZES]
    for mode in MODES:
        series[f"{mode} (s/120 s, whole call)"] = [sizes[k][mode]["whole_s"] for k in SIZES]
    for name, values in series.items():
        cost = np.array(values)
        a, b, r2 = linear_fit(n, cost)
        steps = np.diff(cost) / np.diff(n)
        fits[name] = {"a": a, "b": b, "r2": r2, "increments": steps.tolist()}
        digits = 3 if "s/120 s" in name else 2
        growth.add_row(name, f"{a:.{digits}f}", f"{b:.{digits + 1}f}", f"{r2:.4f}",
                       f"{b / cost[1]:.1%}", *(f"{s:.{digits + 1}f}" for s in steps))  # fmt: skip
    console.print(growth)
    return {"sizes": sizes, "fits": fits}


if __name__ == "__main__":
    main()
