"""Benchmark and tables of the chain appendage model.

Run with ``python bench/bench_chain.py`` (``--quick`` for fewer steps). Prints:

1. the cost of one RK4 step against the number of segments N = 1 ... 32 of each of two
   chains (hinge about the chord axis, as the Basilisk comparison scenario), the
   least-squares line through it (slope per segment) and the largest deviation from
   that line, which checks that the cost is linear in N;
2. the clamped-root bending frequencies of a uniform cantilever as a chain of N = 2 ...
   64 segments against Euler-Bernoulli, with the observed convergence order;
3. the centrifugal stiffening of a spinning cantilever: frequency against spin rate up
   to Omega/omega_0 = 2 for the chain (N = 16) and the single rigid plate, written to
   ``docs/figures/chain_spin_stiffening.png`` (the figure of docs/model.md).

``--instructions`` prints table 1 in executed instructions instead (valgrind's
callgrind, event Ir), which the machine's load does not move: the script re-runs
itself under ``valgrind --tool=callgrind`` with instrumentation off until the shim of
``bench_avionics_instructions.py`` starts a count around one call of the compiled RK4
loop; instructions per step = (Ir(long) - Ir(short)) / (long - short steps), which
removes the call's fixed cost. numba compiles for the CPU that script names (Haswell
on an AVX-512 host, which valgrind 3.19 cannot execute), natively first (filling the
cache) and then under valgrind, which loads that machine code. Needs valgrind and gcc;
about a minute.
"""

from __future__ import annotations

import argparse
import gc
import json
import os
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np
from rich.console import Console

import harness
from flexsat.config import validate_config
from flexsat.dynamics.attitude import identity_frame
from flexsat.dynamics.integrators import rk4_hold
from flexsat.dynamics.plant import Plant
from flexsat.linear import linearize

ROOT = Path(__file__).resolve().parents[1]
SIZES = (1, 2, 4, 8, 16, 32)  # segments per chain in the cost tables


def _cantilever():
    """The tests' cantilever: (beam_frequency_hz, cantilever_chain, clamped_frequencies_hz).

    Imported when a table needs it, so that the script registers without the tests.
    """
    sys.path.insert(0, str(ROOT))
    from tests.dynamics.appendages.test_chain_beam import clamped_frequencies_hz
    from tests.dynamics.chain_satellites import beam_frequency_hz, cantilever_chain

    return beam_frequency_hz, cantilever_chain, clamped_frequencies_hz


def _two_arrays(n: int) -> Plant:
    """Hub 600 kg, diag(400, 380, 360) kg m^2; two 60 kg, 3 m arrays of n segments on
    hinges about Y at +-0.8 m on X, k = 600 N m/rad, c = 5 N m s/rad per hinge."""

    def array(name, x, span):
        return {"name": name, "model": "chain", "mount_point_m": [x, 0.0, 0.0],
                "span_direction": span, "segments": n, "length_m": 3.0, "width_m": 1.0,
                "thickness_m": 0.01, "mass_kg": 60.0,
                "joint": {"dofs": ["ry"], "stiffness": {"ry": 600.0},
                          "damping": {"ry": 5.0}, "initial": {"ry": 8.0}}}  # fmt: skip

    return Plant.from_config(validate_config({
        "name": f"arrays-{n}",
        "hub": {"mass_kg": 600.0, "inertia_kg_m2": [[400.0, 0, 0], [0, 380.0, 0], [0, 0, 360.0]]},
        "appendages": [array("array_1", 0.8, "+x"), array("array_2", -0.8, "-x")],
    }))  # fmt: skip


def step_cost_table(console: Console, steps: int) -> None:
    sizes = list(SIZES)
    costs = []
    for n in sizes:
        plant = _two_arrays(n)
        x = np.zeros(2 * plant.n_dof + 2)
        x[plant.n_dof + 3 : plant.n_dof + 6] = (0.01, -0.02, 0.015)
        # The cost of a step does not depend on dt; 1 us keeps every N far from the RK4
        # stability limit of its stiffest hinge mode, so every step is a full one.
        rk4_hold(
            x.copy(), 1e-6, 10, (0.0, 0.0, 0.0), plant.packed, identity_frame()
        )  # compile, warm

        def run(trial, plant=plant, n=n):
            status, done = rk4_hold(
                trial, 1e-6, steps, (0.0, 0.0, 0.0), plant.packed, identity_frame()
            )
            if status != 0 or done != steps:
                raise RuntimeError(f"N = {n}: the run stopped at step {done} (status {status})")

        best, _ = harness.best_of(run, 5, setup=x.copy)
        costs.append(1e6 * best / steps)
    slope, intercept = np.polyfit(sizes, costs, 1)
    table = harness.table(
        "RK4 step cost, two chains of N hinged segments (best of 5)",
        ("N", "us per step", "linear fit", "deviation"),
        left=0,
    )
    for n, c in zip(sizes, costs, strict=True):
        fit = slope * n + intercept
        table.add_row(str(n), f"{c:.2f}", f"{fit:.2f}", f"{(c - fit) / fit:+.1%}")
    console.print(table)
    console.print(f"slope {slope:.3f} us per segment (two chains), intercept {intercept:.2f} us; "
                  f"cost(32) / cost(16) = {costs[-1] / costs[-2]:.2f} (linear: ~2)")  # fmt: skip


def _counted_flights(out: Path | None, shim: Path | None, short: int, long: int) -> None:
    """Fly every N for ``short`` and ``long`` steps, each call alone counted under
    callgrind (``out``: where the flights are listed); natively (``shim`` None) only
    compile or load the loop for every N."""
    import ctypes

    from flexsat.dynamics.integrators import rk4_hold as loop

    cg = None
    if shim is not None:
        cg = ctypes.CDLL(str(shim))
        cg.cg_stop.argtypes = [ctypes.c_char_p]
    flights = []
    for n in SIZES:
        plant = _two_arrays(n)
        x = np.zeros(2 * plant.n_dof + 2)
        x[plant.n_dof + 3 : plant.n_dof + 6] = (0.01, -0.02, 0.015)
        loop(x.copy(), 1e-6, 10, (0.0, 0.0, 0.0), plant.packed, identity_frame())
        if cg is None:
            continue
        overloads = len(loop.overloads)
        for steps in (short, long):
            trial, label = x.copy(), f"N{n}-{steps}"
            gc.disable()
            cg.cg_start()
            status, done = loop(trial, 1e-6, steps, (0.0, 0.0, 0.0), plant.packed,
                                identity_frame())  # fmt: skip
            cg.cg_stop(label.encode())
            gc.enable()
            if status != 0 or done != steps or len(loop.overloads) != overloads:
                sys.exit(f"N = {n}: status {status} after {done} of {steps} steps")
            flights.append({"N": n, "steps": steps, "dump": label})
    if out is not None:
        out.write_text(json.dumps(flights))


def instruction_table(console: Console, short: int = 200, long: int = 1200) -> dict[int, float]:
    """Table 1 in instructions (callgrind Ir) per RK4 step; returns them per N."""
    from numba.core.registry import cpu_target

    from bench_avionics_instructions import HASWELL_FEATURES, INSTALL, build_shim, read_dumps

    work = Path(tempfile.mkdtemp(prefix="flexsat-callgrind-"))
    try:
        shim = build_shim(work)
        if isinstance(shim, str):
            raise SystemExit(f"{shim}: install valgrind and gcc ({INSTALL})")
        _, cpu_name, features = cpu_target.target_context.codegen().magic_tuple()
        if "+avx512f" in features:
            cpu_name, features = "haswell", HASWELL_FEATURES
        env = os.environ | {"NUMBA_CPU_NAME": cpu_name, "NUMBA_CPU_FEATURES": features}
        script = [sys.executable, str(Path(__file__).resolve()), "--inner-steps",
                  f"{short},{long}"]  # fmt: skip
        subprocess.run(script, env=env, check=True)  # fills the cache natively
        flights_file = work / "flights.json"
        command = ["valgrind", "--tool=callgrind", "--instr-atstart=no", "--collect-atstart=no",
                   f"--callgrind-out-file={work / 'out.%p'}", f"--log-file={work / 'log'}",
                   *script, "--inner", str(flights_file), "--shim", str(shim)]  # fmt: skip
        done = subprocess.run(command, env=env, check=False)
        if done.returncode != 0 or not flights_file.exists():
            raise SystemExit(f"the run under callgrind failed (exit status {done.returncode})")
        flights = json.loads(flights_file.read_text())
        counts = read_dumps(work)
    finally:
        shutil.rmtree(work, ignore_errors=True)
    ir = {(f["N"], f["steps"]): counts[f["dump"]] for f in flights}
    per_step = {n: (ir[n, long] - ir[n, short]) / (long - short) for n in SIZES}
    slope, intercept = np.polyfit(SIZES, [per_step[n] for n in SIZES], 1)
    table = harness.table(
        f"RK4 step cost, two chains of N hinged segments, instructions (callgrind Ir, "
        f"{cpu_name}) per step, steps {short} to {long}",
        ("N", "instructions per step", "per segment (both chains)"),
        left=0,
    )
    for n in SIZES:
        table.add_row(str(n), f"{per_step[n]:,.0f}", f"{per_step[n] / (2 * n):,.0f}")
    console.print(table)
    console.print(f"line: {intercept:,.0f} + {slope:,.0f} instructions per segment (two chains)")
    return per_step


def beam_table(console: Console) -> None:
    beam_frequency_hz, cantilever_chain, clamped_frequencies_hz = _cantilever()
    reference = np.array([beam_frequency_hz(n) for n in (1, 2, 3)])
    table = harness.table("Clamped cantilever as a chain: error against Euler-Bernoulli",
                          ("N", "mode 1", "mode 2", "mode 3", "order 1", "order 2", "order 3"),
                          left=0)  # fmt: skip
    previous = None
    for n in (2, 4, 8, 16, 32, 64):
        plant = Plant.from_config(validate_config(cantilever_chain(n)))
        found = clamped_frequencies_hz(plant, 3)
        errors = np.full(3, np.nan)
        errors[: found.size] = found / reference[: found.size] - 1.0
        orders = np.log2(previous / errors) if previous is not None else np.full(3, np.nan)
        table.add_row(str(n), *(f"{e:+.3%}" for e in errors), *(f"{o:.2f}" for o in orders))
        previous = errors
    console.print(table)


def spin_figure(console: Console) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    _, cantilever_chain, clamped_frequencies_hz = _cantilever()
    ratios = np.linspace(0.0, 2.0, 21)
    fig, ax = plt.subplots(figsize=(6.4, 4.2))
    for dof, label in (("rx", "flapwise"), ("rz", "in-plane")):
        for segments, style in ((16, "-"), (1, "--")):
            plant = Plant.from_config(validate_config(
                cantilever_chain(segments, dofs=(dof,), hub_scale=1e5)))  # fmt: skip
            omega_0 = 2.0 * np.pi * clamped_frequencies_hz(plant, 1)[0]
            curve = []
            for r in ratios:
                if r == 0.0:
                    curve.append(1.0)
                    continue
                model = linearize(plant, about=[0.0, 0.0, r * omega_0], outputs=("joint",))
                rates = np.abs(np.linalg.eigvals(model.A).imag)
                rates = rates[rates > 1.001 * r * omega_0]  # drop the spin's own lines
                curve.append(float(rates.min() / omega_0) if rates.size else np.nan)
            name = f"{label}, {'chain N = 16' if segments > 1 else 'one rigid plate'}"
            ax.plot(ratios, curve, style, label=name)
            k = (curve[5] ** 2 - 1.0) / ratios[5] ** 2
            console.print(f"{name}: Southwell K at Omega/omega_0 = 0.5: {k:.4f}")
    ax.plot(ratios, np.sqrt(1.0 + 1.193 * ratios**2), ":", color="grey",
            label="beam, K = 1.193 (flapwise)")  # fmt: skip
    ax.set_xlabel("spin rate Omega / omega_0 [-]")
    ax.set_ylabel("first mode omega / omega_0 [-]")
    ax.set_title("Centrifugal stiffening of a cantilever spinning about its root")
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8)
    out = ROOT / "docs" / "figures" / "chain_spin_stiffening.png"
    out.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(out, dpi=120, bbox_inches="tight")
    console.print(f"wrote {out.relative_to(ROOT)}")


@harness.register(
    "chain appendages: cost per RK4 step against N = 1 ... 32 segments, bending frequencies "
    "against Euler-Bernoulli with the convergence order, centrifugal stiffening",
    full=False,
)
def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="fewer steps in the cost table")
    parser.add_argument("--instructions", action="store_true",
                        help="the cost table in instructions (callgrind) alone")  # fmt: skip
    parser.add_argument("--inner-steps", help=argparse.SUPPRESS)
    parser.add_argument("--inner", type=Path, help=argparse.SUPPRESS)
    parser.add_argument("--shim", type=Path, help=argparse.SUPPRESS)
    args = parser.parse_args(argv)
    if args.inner_steps is not None:
        short, long = (int(v) for v in args.inner_steps.split(","))
        _counted_flights(args.inner, args.shim, short, long)
        return
    console = harness.console()
    if args.instructions:
        instruction_table(console)
        return
    step_cost_table(console, 2_000 if args.quick else 20_000)
    beam_table(console)
    spin_figure(console)


if __name__ == "__main__":
    main()
