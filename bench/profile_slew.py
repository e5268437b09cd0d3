"""Profile the compiled closed loop with Linux ``perf``, compiled functions named.

``perf`` cannot name numba's machine code: it lives in anonymous memory. This script
compiles the loop, writes ``/tmp/perf-<pid>.map`` (the map ``perf report`` reads for
just-in-time code) with the address of every compiled function's entry point, then
records itself with ``perf record`` over ``--runs`` slews and prints the report's top
symbols. Functions numba inlined are counted in their caller; an unnamed address in
``[JIT]`` memory outside the map is numba's runtime (its reference counting,
``docs/performance.md``, 'Reference counting').

Needs ``perf`` (``linux-perf``) and permission to profile the own process
(``kernel.perf_event_paranoid`` <= 2). Usage::

    python bench/profile_slew.py --case full --duration 120 --runs 4
    python bench/profile_slew.py --case ideal --reduced --runs 30
"""

from __future__ import annotations

import argparse
import gc
import os
import shutil
import signal
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from numba.core.registry import CPUDispatcher

from flexsat import Plant, nominal
from flexsat.campaigns.definition import Reduced
from flexsat.simulate import SlewScenario, run_slew

SENSORS = [{"kind": "gyro"}, {"kind": "star_tracker"}, {"kind": "mekf"}]
CASES = {
    "ideal": {},
    "sensors": {"sensor_stages": SENSORS},
    "wheels": {"actuator": {"kind": "wheels"}},
    "full": {"sensor_stages": SENSORS, "actuator": {"kind": "wheels"}},
}


def write_symbol_map(path: Path) -> int:
    """Write perf's map of every compiled function in this process; return its size."""
    entries: dict[int, str] = {}
    for obj in gc.get_objects():
        if not isinstance(obj, CPUDispatcher):
            continue
        for result in obj.overloads.values():
            described = result.fndesc
            for symbol, label in ((described.mangled_name, described.qualname),
                                  (described.llvm_cfunc_wrapper_name,
                                   f"{described.qualname} (C wrapper)")):  # fmt: skip
                try:
                    address = result.library.get_pointer_to_function(symbol)
                except Exception:  # not emitted for this overload
                    continue
                if address:
                    entries[address] = label
    addresses = sorted(entries)
    with path.open("w") as handle:  # a function ends where the next begins
        for start, end in zip(addresses, [*addresses[1:], addresses[-1] + 4096], strict=True):
            handle.write(f"{start:x} {min(end - start, 1 << 20):x} {entries[start]}\n")
    return len(addresses)


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--case", choices=sorted(CASES), default="full")
    parser.add_argument("--duration", type=float, default=120.0, help="slew length [s]")
    parser.add_argument("--runs", type=int, default=4, help="slews recorded")
    parser.add_argument("--top", type=int, default=25, help="symbols printed")
    parser.add_argument("--reduced", action="store_true",
                        help="the campaigns' reduced model: root translations locked, "
                             "20 ms step and control period, 40 ms records")  # fmt: skip
    args = parser.parse_args(argv)
    if shutil.which("perf") is None:
        sys.exit("perf is not installed (Debian: linux-perf)")
    config, fields = nominal(), {"duration_s": args.duration, **CASES[args.case]}
    if args.reduced:
        reduced = Reduced()
        config = config.model_copy(update={"appendages": [
            app.model_copy(update={"locked_dofs": reduced.locked_dofs})
            for app in config.appendages]})  # fmt: skip
        fields |= {
            "dt_s": reduced.dt_s,
            "control_dt_s": reduced.control_dt_s,
            "record_dt_s": reduced.record_period_s,
        }
    plant = Plant.from_config(config)
    scenario = SlewScenario.model_validate(fields)
    run_slew(plant, scenario.model_copy(update={"duration_s": 0.1}))  # compile
    count = write_symbol_map(Path(f"/tmp/perf-{os.getpid()}.map"))
    data = Path(tempfile.mkdtemp()) / "perf.data"
    recorder = subprocess.Popen(
        ["perf", "record", "-F", "4999", "-p", str(os.getpid()), "-o", str(data)],
        stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
    )  # fmt: skip
    time.sleep(1.0)  # perf attaches
    for _ in range(args.runs):
        run_slew(plant, scenario, progress=False)
    recorder.send_signal(signal.SIGINT)
    recorder.wait()
    report = subprocess.run(
        ["perf", "report", "-i", str(data), "--no-children", "--sort", "symbol", "--stdio"],
        capture_output=True, text=True, check=False,
    )  # fmt: skip
    rows = [line for line in report.stdout.splitlines() if "%" in line and "[" in line]
    model = " (reduced)" if args.reduced else ""
    print(f"{args.case}{model}: {args.runs} slews of {args.duration:g} s, {count} compiled "
          f"functions mapped; share of samples:")  # fmt: skip
    for line in rows[: args.top]:
        print(line[:120])


if __name__ == "__main__":
    main()
