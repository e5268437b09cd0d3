"""Benchmark: start-up, compiling against loading the compiled code from the disk cache.

Every measurement runs in a fresh Python process, timed from just before the process
is started:

* ``python -c "pass"`` (the interpreter alone) and ``python -c "import flexsat"``;
* ``flexsat slew --scenario short.toml --json`` (a 0.1 s slew whose observation window
  opens at 0.05 s: a run must hold its window), run in-process by a small driver that notes
  when the first compiled chunk of the closed loop has returned, i.e. when the
  simulation is running (the 100 steps of that chunk take about half a millisecond):
  "to simulating" is that moment, "whole command" the process's end (metrics, JSON);
* the same through the Python API: import ``flexsat.simulate``, build the nominal
  plant, ``run_slew`` (with the time spent in each phase).

The first CLI run uses empty ``NUMBA_CACHE_DIR`` and ``FLEXSAT_CACHE_DIR``
(temporary folders): it compiles every kernel it needs. The later runs reuse those
folders: the cached start-up a user sees from the second run on. Python's own
bytecode cache is left at its default (on). Cached rows: best of ``REPEATS``.
Run with ``python bench/bench_startup.py``.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import tempfile
import time

import harness

REPEATS = 3
STARTUP_MAX_S = 2.0  # the target: cached start-up to simulating
SHORT_SLEW = "duration_s = 0.1\n[requirements]\nsettling_deadline_s = 0.05\n"
"""The slew the CLI rows fly, as a scenario file (``short.toml``)."""
SLEW_ARGS = ["slew", "--scenario", "short.toml", "--json"]

# Runs the CLI or the API in this fresh process and reports, on its last stderr line,
# the wall-clock times (time.time()) at which each phase ended.
_DRIVER = """
import json, sys, time
stamps = {}
mode = sys.argv[1]
if mode == "import":
    import flexsat
    stamps["import flexsat"] = time.time()
else:
    if mode == "api":
        import flexsat
        stamps["import flexsat"] = time.time()
    import flexsat.simulate.closedloop as closedloop
    if mode == "api":
        stamps["import flexsat.simulate"] = time.time()
    compiled_loop = closedloop._compiled_loop  # called once the loop is compiled or loaded

    def first_chunk(*args):
        stamps.setdefault("simulating", time.time())
        return compiled_loop(*args)

    closedloop._compiled_loop = first_chunk
    if mode == "cli":
        from flexsat.cli.main import main
        sys.argv = ["flexsat", *sys.argv[2:]]
        try:
            main()
        except SystemExit as exc:
            if exc.code:
                raise
    else:
        from flexsat import Plant, nominal
        from flexsat.simulate import SlewScenario, run_slew
        plant = Plant.from_config(nominal())
        stamps["plant built"] = time.time()
        run_slew(plant, SlewScenario(duration_s=0.1), progress=False)
        stamps["run_slew returned"] = time.time()
stamps["end"] = time.time()
print("STAMPS " + json.dumps(stamps), file=sys.stderr)
"""


def _env(cache: str) -> dict:
    env = dict(os.environ)
    env.pop("PYTHONDONTWRITEBYTECODE", None)
    env["NUMBA_CACHE_DIR"] = os.path.join(cache, "numba")
    env["FLEXSAT_CACHE_DIR"] = os.path.join(cache, "flexsat")
    return env


def _run(command: list[str], env: dict) -> dict:
    """Seconds from just before the process starts to each stamp, and to its exit."""
    start = time.time()
    proc = subprocess.run(command, env=env, capture_output=True, text=True)
    end = time.time()
    if proc.returncode:
        raise RuntimeError(f"{' '.join(command)} failed:\n{proc.stderr[-2000:]}")
    out = {"process": end - start}
    for line in proc.stderr.splitlines():
        if line.startswith("STAMPS "):
            out.update({k: v - start for k, v in json.loads(line[7:]).items()})
    return out


def _best(command: list[str], env: dict, repeats: int = REPEATS) -> dict:
    runs = [_run(command, env) for _ in range(repeats)]
    return {key: min(run[key] for run in runs) for key in runs[0]}


def measure() -> dict:
    python = sys.executable
    driver = [python, "-c", _DRIVER]
    with tempfile.TemporaryDirectory(prefix="flexsat-bench-") as cache:
        env = _env(cache)
        short = os.path.join(cache, "short.toml")
        with open(short, "w") as file:
            file.write(SHORT_SLEW)
        slew = [short if arg == "short.toml" else arg for arg in SLEW_ARGS]
        bare = _best([python, "-c", "pass"], env)
        imported = _best([*driver, "import"], env)
        cold = _run([*driver, "cli", *slew], env)
        cached = _best([*driver, "cli", *slew], env)
        api = _best([*driver, "api"], env)
    return {
        "python_s": bare["process"],
        "import_process_s": imported["process"],
        "import_s": imported["import flexsat"],
        "cold_to_simulating_s": cold["simulating"],
        "cold_process_s": cold["process"],
        "cached_to_simulating_s": cached["simulating"],
        "cached_process_s": cached["process"],
        "compile_s": cold["simulating"] - cached["simulating"],
        "api": api,
    }


def _note(out: dict, _results: dict) -> str:
    return (
        f"flexsat slew, fresh process; API path {out['api']['simulating']:.2f} s; "
        f"import flexsat {out['import_process_s']:.2f} s; "
        f"cold (compiling) {out['cold_to_simulating_s']:.1f} s"
    )


@harness.register(
    "fresh-process start-up: import flexsat, flexsat slew with empty caches (compiling) and "
    "cached, the API path phase by phase",
    targets=[harness.Target(f"cached start-up to simulating <= {STARTUP_MAX_S:g} s",
                            STARTUP_MAX_S, "s", lambda r: r["cached_to_simulating_s"],
                            "{:.2f} s", note=_note)],
)  # fmt: skip
def main(argv: list[str] | None = None) -> dict:
    """Print the start-up table; return the numbers (seconds)."""
    del argv  # no options
    console = harness.console()
    out = measure()
    table = harness.table(
        "Start-up in a fresh process: seconds from process start",
        ("what", "to simulating", "whole process"),
        caption=f"cached rows: best of {REPEATS}; compile = cold - cached, to simulating",
    )
    command = "flexsat " + " ".join(SLEW_ARGS)
    table.add_row("python -c pass (interpreter alone)", "", f"{out['python_s']:.3f}")
    table.add_row('python -c "import flexsat"', "", f"{out['import_process_s']:.3f}")
    table.add_row(f"{command}, empty caches (compiles)", f"{out['cold_to_simulating_s']:.2f}",
                  f"{out['cold_process_s']:.2f}")  # fmt: skip
    table.add_row(f"{command}, cached", f"{out['cached_to_simulating_s']:.2f}",
                  f"{out['cached_process_s']:.2f}")  # fmt: skip
    api = out["api"]
    table.add_row("API: import, nominal plant, run_slew 0.1 s, cached", f"{api['simulating']:.2f}",
                  f"{api['process']:.2f}")  # fmt: skip
    console.print(table)
    phases = ("import flexsat", "import flexsat.simulate", "plant built", "simulating")
    # "simulating": setting up the run and loading the closed loop's cached machine code
    previous = 0.0
    parts = []
    for phase in phases:
        parts.append(f"{phase} {api[phase] - previous:.2f}")
        previous = api[phase]
    console.print(f"API path, cached, time per phase (s): {', '.join(parts)}.")
    console.print(f"Compile time (cold - cached, to simulating): {out['compile_s']:.1f} s.")
    return out


if __name__ == "__main__":
    main()
