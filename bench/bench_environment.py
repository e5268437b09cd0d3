"""Benchmark of the environment's loads and of magnetic momentum dumping.

Run with ``python bench/bench_environment.py`` (``--quick`` for shorter runs). Prints:

1. the closed loop's cost per RK4 step with every environment model (gravity
   gradient, radiation pressure, drag, magnetic field on a residual dipole) against
   the same loop without ``[environment]``: the ``orbit-nadir`` template (nominal
   satellite, 2 ms step, control every 10 ms, loads every 0.1 s), target <= 1.3x;
   the thesis's cadence (control at every 1 ms step); and the loads evaluated at
   every 1 ms step (``period_s = 1e-3``, the worst case). Each variant runs at two
   lengths, interleaved with the others, the shortest of several rounds kept, and the
   lengths are differenced, so the set-up (the orbit's propagation, the load geometry)
   drops out;
2. the wheels' momentum over five orbits with and without magnetorquers (the
   dumping run of ``tests/environment/test_magnetorquers.py`` over a longer span and
   on the propagated J2 orbit instead of the tests' circular table), the peak of
   each orbit, written to ``docs/figures/momentum_dumping.png`` (the figure of
   docs/environment.md).
"""

from __future__ import annotations

import argparse
import tomllib
from pathlib import Path

import numpy as np

import harness
from flexsat.config import preset_path, validate_config
from flexsat.dynamics.plant import Plant
from flexsat.environment.gravity_gradient import MU_EARTH
from flexsat.simulate import SlewScenario, run_slew

ROOT = Path(__file__).resolve().parents[1]
TEMPLATE_ROW = "orbit-nadir: dt 2 ms, control 10 ms, loads every 0.1 s"
COST_TARGET = 1.3  # the loop with every environment model per step / without
MODELS = {"gravity_gradient": {}, "srp": {}, "drag": {},
          "magnetic": {"residual_dipole_a_m2": [0.1, 0.1, 0.1]}}  # fmt: skip
ALTITUDE_M = 500e3
PERIOD_S = 2.0 * np.pi * np.sqrt((6_378_137.0 + ALTITUDE_M) ** 3 / MU_EARTH)


def _template(**changes) -> SlewScenario:
    """The orbit-nadir template without its [environment] table, with ``changes``."""
    data = tomllib.loads(preset_path("orbit-nadir").read_text())
    data.pop("environment", None)
    data.update(record_dt_s=1.0, **changes)
    return SlewScenario.model_validate(data)


def cost_table(console, short_s: float, long_s: float, rounds: int) -> dict:
    """us per RK4 step with and without the environment at three cadences: each variant
    run at two lengths, interleaved (a load change on a shared machine hits all alike),
    the shortest of ``rounds`` kept, the lengths differenced (the set-up drops out)."""
    plant = Plant.from_config(validate_config(tomllib.loads(preset_path("nominal").read_text())))
    every_instant = {"models": MODELS, "period_s": 1e-3}
    cadences = (
        (TEMPLATE_ROW, {}, {"models": MODELS}),
        ("control every 1 ms step, loads every 0.1 s", {"dt_s": 1e-3, "control_dt_s": 1e-3},
         {"models": MODELS}),
        ("control and loads every 1 ms step", {"dt_s": 1e-3, "control_dt_s": 1e-3},
         every_instant),
    )  # fmt: skip
    out = harness.table("Closed loop per RK4 step, nominal satellite, 500 km orbit",
                        ["cadence", "without [us]", "every model [us]", "ratio"])  # fmt: skip
    rows = {}
    for label, cadence, environment in cadences:
        calls = {}
        for name, env in (("without", None), ("with", environment)):
            for duration in (short_s, long_s):
                extra = {"environment": env} if env else {}
                run = _template(**cadence, **extra, duration_s=duration)
                calls[name, duration] = harness.wall(
                    lambda run=run: run_slew(plant, run, progress=False))  # fmt: skip
        best = harness.best(harness.interleave(calls, rounds, warm_up=True))
        steps = (long_s - short_s) / _template(**cadence).dt_s
        us = {n: 1e6 * (best[n, long_s] - best[n, short_s]) / steps for n in ("without", "with")}
        rows[label] = {"without_us": us["without"], "with_us": us["with"],
                       "ratio": us["with"] / us["without"]}  # fmt: skip
        out.add_row(label, f"{us['without']:.2f}", f"{us['with']:.2f}",
                    f"{us['with'] / us['without']:.3f}")  # fmt: skip
    console.print(out)
    return rows


def _dumping_scenario(duration_s: float, torquers: dict | None) -> SlewScenario:
    """Inertial hold by four wheels against a constant disturbance on a 500 km
    sun-synchronous orbit (J2), dipole field; with ``torquers`` the magnetorquers."""
    environment = {"models": {"magnetic": {}}}
    if torquers:
        environment["magnetorquers"] = torquers
    return SlewScenario.model_validate({
        "duration_s": duration_s, "dt_s": 0.05, "control_dt_s": 0.5, "record_dt_s": 10.0,
        "target_euler_deg": [0.0, 0.0, 0.0], "controller": {"kind": "pd"},
        "actuator": {"kind": "wheels", "motor_time_constant_s": 0.1, "t_max_nm": 0.1},
        "disturbances": {"environment_nm": [2e-4, -1e-4, 1.5e-4], "sloshing_ratio": 0.0},
        "orbit": {"epoch": "2026-01-01T00:00:00Z", "altitude_m": ALTITUDE_M,
                  "inclination_deg": 97.4},
        "environment": environment,
    })  # fmt: skip


def dumping_figure(console, orbits: int) -> dict:
    """Peak wheel momentum per orbit with and without dumping; the figure."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    data = tomllib.loads(preset_path("nominal").read_text())
    for app in data["appendages"]:  # the 50 Hz root translations would need a 5 ms step
        app["locked_dofs"] = ["eta_x", "eta_y", "eta_z"]
    plant = Plant.from_config(validate_config(data))
    duration = round(orbits * PERIOD_S / 10.0) * 10.0
    runs = {}
    for label, torquers in (("wheels only", None),
                            ("magnetorquers 20 A m^2, k = 2e-3 1/s",
                             {"dipole_max_a_m2": 20.0, "gain_1_s": 2e-3})):  # fmt: skip
        result = run_slew(plant, _dumping_scenario(duration, torquers), progress=False)
        assert result.dataset.attrs["status"] == "ok", result.dataset.attrs["status"]
        runs[label] = result.dataset
    out = harness.table(f"Peak wheel momentum per orbit [N m s], {orbits} orbits",
                        ["run", *[f"orbit {k + 1}" for k in range(orbits)]])  # fmt: skip
    peaks = {}
    fig, ax = plt.subplots(figsize=(7.0, 3.6))
    for label, ds in runs.items():
        t = ds["time"].values
        h = np.linalg.norm(ds["wheel_momentum_B"].values, axis=1)
        peaks[label] = [float(h[(t >= k * PERIOD_S) & (t < (k + 1) * PERIOD_S)].max())
                        for k in range(orbits)]  # fmt: skip
        out.add_row(label, *[f"{p:.3f}" for p in peaks[label]])
        ax.plot(t / PERIOD_S, h, label=label)
    console.print(out)
    ax.set_xlabel("time [orbits of 5677 s]")
    ax.set_ylabel("|h_wheels| [N m s]")
    ax.set_title("Wheel momentum against a 2.8e-4 N m disturbance, 500 km SSO")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    path = ROOT / "docs" / "figures" / "momentum_dumping.png"
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=120, bbox_inches="tight")
    console.print(f"wrote {path.relative_to(ROOT)}")
    return peaks


TARGETS = (
    harness.Target(
        f"every environment model per step, orbit-nadir <= {COST_TARGET}x without",
        COST_TARGET, "x",
        lambda r: r["cost"][TEMPLATE_ROW]["ratio"], "{:.3f}x",
        note=lambda r, _: "gravity gradient, SRP, drag, magnetic; 32 mass elements, 74 surfaces",
    ),
)  # fmt: skip


@harness.register(
    "environment loads: closed-loop cost per step with every model against none; "
    "momentum dumping over five orbits and its figure",
    targets=TARGETS,
    quick_argv=("--quick",),
)
def main(argv: list[str] | None = None) -> dict:
    """Print the tables; return the costs and the peaks per orbit."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="shorter runs, three orbits")
    args = parser.parse_args(argv)
    console = harness.console()
    cost = cost_table(console, *((2.0, 6.0, 2) if args.quick else (10.0, 40.0, 5)))
    peaks = dumping_figure(console, 3 if args.quick else 5)
    return {"cost": cost, "peaks": peaks}


if __name__ == "__main__":
    main()
