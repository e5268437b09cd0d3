"""Benchmark: the avionics chain's cost per step in executed instructions (callgrind).

The per-step cost of ``bench_avionics.py``'s four cases (its ``CASES`` and ``TARGET``:
the thesis slew, dt = 1 ms, with the ideal loop, the wheels, gyro + star tracker +
MEKF, and the full chain, against full chain <= 1.3x the ideal loop per step),
counted in executed instructions (valgrind's callgrind, event Ir) instead of timed.
On the shared 2-core virtual machine the wall-time ratio of ``bench_avionics.py``
moves between 1.2 and 1.5 from run to run (the machine's speed drifts by up to 3x),
so it cannot decide the goal; an instruction count does not depend on the load.

How: a three-function C shim over ``<valgrind/callgrind.h>`` (start instrumentation,
zero, collect / stop collecting, dump under a name, stop), compiled with gcc into a
temporary directory and loaded with ctypes. The script re-runs itself under
``valgrind --tool=callgrind --instr-atstart=no --collect-atstart=no``: nothing is
counted, and Python, numpy and numba run about 10x slower instead of 100x, until the
shim starts a count. Valgrind's virtual CPU is not this machine's, so numba would miss
its cache and compile for that CPU: the run names this machine's CPU and features
(``NUMBA_CPU_NAME``, ``NUMBA_CPU_FEATURES``, as numba's cache keys them) and loads
the machine code a native run executes, after one short native flight of each case
has filled the cache. On a host with AVX-512, which valgrind 3.19 cannot execute, the
script compiles for Haswell (AVX2, FMA) natively and under valgrind alike: counts are
then comparable between runs on such hosts, not with a native AVX-512 run. Under
valgrind, each case is prepared
(``closedloop.prepare_slew``) and flown once for 0.1 s (nothing loads or compiles
later; checked), then flown for ``--short``, ``--check`` and ``--long`` seconds
(default 1, 3 and the thesis's 120), each flight one call of the compiled loop
(``batch.fly``, as ``run_slew`` makes it) alone between start and dump: no Python
set-up or post-processing is counted. Instructions per step = (Ir(long) - Ir(short))
/ (steps(long) - steps(short)): the difference removes the call's fixed cost (typing
and unboxing the arguments, 1.8-2.2 million instructions, shown as "call alone").

Repeatability: two runs gave the same instructions per step to 0.1 (1-120 s) and to
1.1 (1-3 s) instructions; whole flights differed by at most 8043 instructions of 28
million to 3.9 billion, from the Python side of the call. The check column, 1 to
3 s, agrees with 1 to 120 s within 0.6 % for the ideal loop and the sensing chain.
The wheels' count per step is not constant through the slew (30 092 from 1 to 3 s,
31 115 from 1 to 120 s): a step's count follows the state through the branches
it takes, so the figure is the mean over the slew flown, and the default flies the
whole 120 s slew, as ``bench_avionics.py`` does.

Instructions are a proxy for time that gives every instruction the same cost. They
do not see cache misses (this numba code is compute-bound with a tiny working set),
instruction fetch from a larger code footprint, branch mispredictions, or the
latency of divisions, square roots and exponentials, and they do not move with the
machine's speed or the code's placement. The full chain's wall-time ratio on the
same machine is higher than its instruction ratio (1.38 by the best of nine in a run
of ``bench_avionics.py`` beside these counts, against 1.22 here).

Needs valgrind (with its header ``valgrind/callgrind.h``) and gcc; without them the
script prints what to install and exits with status 2. About 2 minutes (each 120 s
flight about 20 s under callgrind). Not in ``run_all.py``.
"""

from __future__ import annotations

import argparse
import ctypes
import gc
import json
import os
import re
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

# Valgrind 3.19 cannot execute AVX-512 (EVEX) instructions: on a host that has them,
# numba compiles this run for Haswell (AVX2, FMA), natively and under valgrind alike,
# before anything imports numba, when run as a script (imported by the harness, it
# leaves the environment alone). Both sides of a comparison must be run this way.
HASWELL_FEATURES = ("+64bit,+avx,+avx2,+bmi,+bmi2,+cmov,+cx16,+cx8,+f16c,+fma,+fsgsbase,"
                    "+fxsr,+lzcnt,+mmx,+movbe,+pclmul,+popcnt,+rdrnd,+sahf,+sse,+sse2,+sse3,"
                    "+sse4.1,+sse4.2,+ssse3,+xsave,+xsaveopt")  # fmt: skip
try:
    _AVX512 = " avx512f" in Path("/proc/cpuinfo").read_text()
except OSError:
    _AVX512 = False
if __name__ == "__main__" and _AVX512 and "NUMBA_CPU_NAME" not in os.environ:
    os.environ |= {"NUMBA_CPU_NAME": "haswell", "NUMBA_CPU_FEATURES": HASWELL_FEATURES}

import harness  # noqa: E402
from bench_avionics import CASES, TARGET  # noqa: E402  (bench/ on sys.path)

SHIM = r"""
#include <valgrind/callgrind.h>
void cg_start(void) {
    CALLGRIND_START_INSTRUMENTATION; CALLGRIND_ZERO_STATS; CALLGRIND_TOGGLE_COLLECT;
}
void cg_stop(const char *name) {
    CALLGRIND_TOGGLE_COLLECT; CALLGRIND_DUMP_STATS_AT(name); CALLGRIND_STOP_INSTRUMENTATION;
}
int cg_running(void) { return RUNNING_ON_VALGRIND; }
"""
INSTALL = "Debian: apt-get install valgrind gcc"
IDEAL, FULL = "ideal (thesis)", "full chain"
WARM_UP_S = 0.1  # the slew flown first in each case, outside the measured region


def build_shim(directory: Path) -> Path | str:
    """Compile the client-request shim into ``directory``; its path, or why not."""
    missing = [tool for tool in ("valgrind", "gcc") if shutil.which(tool) is None]
    if missing:
        return f"{' and '.join(missing)} not found"
    source, library = directory / "cg_shim.c", directory / "cg_shim.so"
    source.write_text(SHIM)
    built = subprocess.run(["gcc", "-O1", "-shared", "-fPIC", "-o", str(library), str(source)],
                           capture_output=True, text=True, check=False)  # fmt: skip
    if built.returncode != 0:
        error = re.search(r"error: (.+)", built.stderr)
        return f"gcc cannot build the callgrind shim ({error.group(1) if error else 'failed'})"
    return library


def dump_name(case: int, duration: float) -> str:
    return f"case{case}-{duration:g}s"


def inner(out: Path, shim: Path, durations: list[float]) -> None:
    """Under callgrind: fly every case at each duration, each flight alone instrumented."""
    from flexsat import Plant, nominal
    from flexsat.simulate import SlewScenario
    from flexsat.simulate.batch import fly
    from flexsat.simulate.closedloop import _fly_arguments, prepare_slew

    cg = ctypes.CDLL(str(shim))
    cg.cg_stop.argtypes = [ctypes.c_char_p]
    if not cg.cg_running():
        sys.exit("--inner runs under valgrind only")
    plant = Plant.from_config(nominal())
    flights = []
    for index, (name, fields) in enumerate(CASES.items()):
        start = time.perf_counter()
        warm = SlewScenario.model_validate({"duration_s": WARM_UP_S, **fields})
        run = prepare_slew(plant, warm)
        fly(*_fly_arguments(run, 0, 0, warm.n_steps + 1))  # loads (or compiles) the loop
        overloads = len(fly.overloads)
        for duration in durations:
            scenario = SlewScenario.model_validate({"duration_s": duration, **fields})
            run = prepare_slew(plant, scenario)
            arguments = _fly_arguments(run, 0, 0, scenario.n_steps + 1)
            label = dump_name(index, duration)
            gc.disable()
            cg.cg_start()
            status, done, _ = fly(*arguments)
            cg.cg_stop(label.encode())
            gc.enable()
            flights.append({"case": name, "duration_s": duration, "steps": scenario.n_steps,
                            "status": int(status), "done": int(done), "dump": label})  # fmt: skip
        if len(fly.overloads) != overloads:
            sys.exit(f"{name}: fly compiled inside the measured region")
        print(f"  {name}: {time.perf_counter() - start:.0f} s under valgrind", flush=True)
    out.write_text(json.dumps(flights))


def read_dumps(directory: Path) -> dict[str, int]:
    """Instructions (Ir) of each named dump in ``directory``."""
    counts = {}
    for path in directory.glob("out.*"):
        text = path.read_text(errors="replace")
        trigger = re.search(r"^desc: Trigger: Client Request: (.+)$", text, re.M)
        totals = re.search(r"^(?:totals|summary): (\d+)", text, re.M)
        if trigger and totals:
            counts[trigger.group(1).strip()] = int(totals.group(1))
    return counts


def native_warm_up() -> tuple[str, str]:
    """Fly each case briefly here (fills numba's cache); this machine's (CPU name, features)."""
    from numba.core.registry import cpu_target

    from flexsat import Plant, nominal
    from flexsat.simulate import SlewScenario, run_slew

    plant = Plant.from_config(nominal())
    for fields in CASES.values():
        run_slew(plant, SlewScenario.model_validate({"duration_s": WARM_UP_S, **fields}),
                 progress=False)  # fmt: skip
    _, cpu_name, features = cpu_target.target_context.codegen().magic_tuple()
    return cpu_name, features


@harness.register(
    "the four cases of bench_avionics in executed instructions (valgrind's callgrind) instead "
    "of wall time: instructions per step of the compiled loop, against the 1.3x goal; "
    "repeatable under any load; needs valgrind and gcc",
    full=False,
)
def main(argv: list[str] | None = None) -> dict:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--short", type=float, default=1.0, help="shorter slew [s]")
    parser.add_argument("--long", type=float, default=120.0,
                        help="longer slew [s]; default the thesis's 120 s")  # fmt: skip
    parser.add_argument("--check", type=float, default=3.0,
                        help="third slew [s]: Ir per step from --short to it too")  # fmt: skip
    parser.add_argument("--inner", type=Path, help=argparse.SUPPRESS)
    parser.add_argument("--shim", type=Path, help=argparse.SUPPRESS)
    args = parser.parse_args(argv)
    first, check, last = args.short, args.check, args.long
    if not (0 < first < check and first < last and check != last):
        parser.error("needs 0 < --short < --check and --short < --long, --check != --long")
    durations = sorted({first, check, last})
    if args.inner is not None:
        inner(args.inner, args.shim, durations)
        return {}
    start = time.perf_counter()
    work = Path(tempfile.mkdtemp(prefix="flexsat-callgrind-"))
    try:
        shim = build_shim(work)
        if isinstance(shim, str):
            print(f"{shim}: install valgrind and gcc ({INSTALL})", file=sys.stderr)
            raise SystemExit(2)
        version = subprocess.run(["valgrind", "--version"], capture_output=True, text=True,
                                 check=False).stdout.strip()  # fmt: skip
        cpu_name, features = native_warm_up()
        if "+avx512f" in features:
            print("numba compiled for AVX-512, which valgrind cannot run: run this script "
                  "on its own (python bench/bench_avionics_instructions.py), or set "
                  "NUMBA_CPU_NAME=haswell and NUMBA_CPU_FEATURES as HASWELL_FEATURES",
                  file=sys.stderr)  # fmt: skip
            raise SystemExit(2)
        # Valgrind's CPU is not this machine's: numba would miss its cache and compile
        # for that CPU. Naming this machine's CPU loads the code a native run executes.
        env = os.environ | {"NUMBA_CPU_NAME": cpu_name, "NUMBA_CPU_FEATURES": features}
        flights_file = work / "flights.json"
        command = ["valgrind", "--tool=callgrind", "--instr-atstart=no", "--collect-atstart=no",
                   f"--callgrind-out-file={work / 'out.%p'}", f"--log-file={work / 'log'}",
                   sys.executable, str(Path(__file__).resolve()), "--inner", str(flights_file),
                   "--shim", str(shim), "--short", str(first), "--check", str(check),
                   "--long", str(last)]  # fmt: skip
        print(f"{version}: {len(CASES)} cases, slews of {', '.join(f'{d:g}' for d in durations)}"
              " s under callgrind (a few minutes)", flush=True)  # fmt: skip
        done = subprocess.run(command, env=env, check=False)
        if done.returncode != 0 or not flights_file.exists():
            log = (work / "log").read_text(errors="replace") if (work / "log").exists() else ""
            print(log[-3000:], file=sys.stderr)
            raise SystemExit(f"the run under callgrind failed (exit status {done.returncode})")
        flights = json.loads(flights_file.read_text())
        counts = read_dumps(work)
    finally:
        shutil.rmtree(work, ignore_errors=True)
    wall = time.perf_counter() - start
    for flight in flights:
        if flight["status"] != 0 or flight["done"] != flight["steps"]:
            raise SystemExit(f"{flight['case']}, {flight['duration_s']:g} s: status "
                             f"{flight['status']} after {flight['done']} steps")  # fmt: skip
    ir = {(f["case"], f["duration_s"]): counts[f["dump"]] for f in flights}
    steps = {(f["case"], f["duration_s"]): f["steps"] for f in flights}

    def per_step(case: str, short: float, long: float) -> float:
        return (ir[case, long] - ir[case, short]) / (steps[case, long] - steps[case, short])

    rows = {}
    for case in CASES:
        rows[case] = {"ir_per_step": per_step(case, first, last),
                      "check_ir_per_step": per_step(case, first, check),
                      "ir": {d: ir[case, d] for d in durations}}  # fmt: skip
        # the call's own cost (typing and unboxing the arguments), from the short pair
        call = ir[case, first] - rows[case]["check_ir_per_step"] * steps[case, first]
        rows[case]["call_ir"] = call
    ideal, ideal_check = rows[IDEAL]["ir_per_step"], rows[IDEAL]["check_ir_per_step"]
    span = f"{first:g}-{check:g} s"
    table = harness.table(f"closed loop with avionics, instructions (callgrind Ir) per step, "
                          f"dt = 1 ms, from the {first:g} s to the {last:g} s slew "
                          f"({span}: the {first:g} s to the {check:g} s one); {version}",
                          ("case", "Ir / step", "x ideal", "target", "verdict",
                           f"Ir / step {span}", f"x ideal {span}"))  # fmt: skip
    for case, row in rows.items():
        row["ratio"] = row["ir_per_step"] / ideal
        row["check_ratio"] = row["check_ir_per_step"] / ideal_check
        target, verdict = "", ""
        if case == FULL:
            row["met"] = row["ratio"] <= TARGET
            target = f"<= {TARGET}"
            verdict = "[green]met[/green]" if row["met"] else "[red]NOT MET[/red]"
        table.add_row(case, f"{row['ir_per_step']:,.1f}", f"{row['ratio']:.4f}", target,
                      verdict, f"{row['check_ir_per_step']:,.1f}",
                      f"{row['check_ratio']:.4f}")  # fmt: skip
    flown = harness.table(
        "instructions per flight (one call of the compiled loop)",
        ("case", *(f"{d:g} s" for d in durations), "call alone"),
    )
    for case, row in rows.items():
        flown.add_row(case, *(f"{row['ir'][d]:,}" for d in durations), f"{row['call_ir']:,.0f}")
    console = harness.console()
    console.print(table)
    console.print(flown)
    console.print(f"[dim]{wall:.0f} s in all[/dim]")
    return {"version": version, "durations_s": durations, "wall_s": wall, "rows": rows}


if __name__ == "__main__":
    main()
