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

* whole commands, warm, in fresh processes (:data:`COMMANDS`: ``flexsat --help``,
  ``openloop --json``, ``slew --json``, ``modal --json``): wall time and the process's
  CPU time (user + system, which a loaded machine inflates less), best of
  ``REPEATS`` after one untimed run that fills the cache; with ``--before COMMIT``
  also the code of that commit (``git archive`` into a temporary folder, its own
  caches), the two trees alternated round by round so that both see the same load;
* with ``--breakdown``, where a warm ``flexsat openloop --json`` spends its time, in
  one process: the imports (``import flexsat.cli.main``, then the command's own), the
  plant, the run, the metrics, and the compiled functions loaded from numba's disk
  cache (how many, and the seconds each took).

The first CLI run uses empty ``NUMBA_CACHE_DIR`` and ``FLEXSAT_CACHE_DIR``
(temporary folders): it compiles every kernel it needs. The later runs reuse those
folders: the cached start-up a user sees from the second run on. Python's own
bytecode cache is left at its default (on). Cached rows: best of ``REPEATS``.
With ``--after COMMIT`` the "after" code is that commit's instead of this checkout's
(a comparison of two commits, untouched by uncommitted edits).
Run with ``python bench/bench_startup.py [--repeats N] [--before COMMIT] [--after COMMIT]
[--breakdown] [--commands-only] [--write-docs]``; the load average is printed with the tables.
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import harness

REPEATS = 3
STARTUP_MAX_S = 2.0  # the target: cached start-up to simulating
OPENLOOP_MAX_S = 1.5  # the target: flexsat openloop --json, whole process, warm
ROOT = Path(__file__).resolve().parents[1]
COMMANDS = {
    "flexsat --help": ["--help"],
    "flexsat openloop --json": ["openloop", "--json"],
    "flexsat slew --json": ["slew", "--json"],
    "flexsat modal --json": ["modal", "--json"],
}
"""The whole commands timed warm (nominal config, default scenarios), by label."""
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


# Runs ``flexsat openloop --json`` in this fresh process and reports, on its last stderr
# line, when each phase ended (time.time()) and every function numba loaded from its
# disk cache (name, seconds, whether the cache had it).
_BREAKDOWN = """
import json, sys, time
stamps = {}
import numba.core.caching as caching
loads = []
load_overload = caching.Cache.load_overload

def timed_load(self, sig, target_context):
    start = time.perf_counter()
    found = load_overload(self, sig, target_context)
    loads.append([self._name.split(" at ")[0].removeprefix("<function "),
                  time.perf_counter() - start, found is not None])
    return found

caching.Cache.load_overload = timed_load
stamps["import numba"] = time.time()
import flexsat.cli.main
stamps["import flexsat.cli.main"] = time.time()
import flexsat.analysis.openloop as metrics_module
import flexsat.dynamics.plant as plant_module
import flexsat.simulate as simulate
import flexsat.simulate.openloop
import flexsat.study.outputs
stamps["the command's imports"] = time.time()
Plant = plant_module.Plant
from_config = Plant.from_config.__func__
Plant.from_config = classmethod(
    lambda cls, cfg: (stamps.setdefault("config, scenario", time.time()),
                      from_config(cls, cfg), stamps.setdefault("plant built", time.time()))[1])
run_openloop = flexsat.simulate.openloop.run_openloop
timed_run = lambda *a, **k: (run_openloop(*a, **k),
                             stamps.setdefault("run_openloop", time.time()))[0]
# the command imports it from its module; the package's name is the same function
flexsat.simulate.openloop.run_openloop = simulate.run_openloop = timed_run
openloop_metrics = metrics_module.openloop_metrics
metrics_module.openloop_metrics = lambda ds: (openloop_metrics(ds),
                                              stamps.setdefault("metrics", time.time()))[0]
sys.argv = ["flexsat", "openloop", "--json"]
try:
    sys.modules["flexsat.cli.main"].main()
except SystemExit as exc:
    if exc.code:
        raise
stamps["JSON printed, end"] = time.time()
print("STAMPS " + json.dumps({**stamps, "loads": loads}), file=sys.stderr)
"""
BREAKDOWN_PHASES = ("import numba", "import flexsat.cli.main", "the command's imports",
                    "config, scenario", "plant built", "run_openloop", "metrics",
                    "JSON printed, end")  # fmt: skip
"""The phases of :data:`_BREAKDOWN`, in order (an absent one was not reached)."""
DOCS = ROOT / "docs" / "performance.md"
BEGIN = "<!-- start-up: written by bench/bench_startup.py --write-docs; do not edit by hand -->"
END = "<!-- end of start-up -->"


def _env(cache: str) -> dict:
    env = dict(os.environ)
    env.pop("PYTHONDONTWRITEBYTECODE", None)
    env["NUMBA_CACHE_DIR"] = os.path.join(cache, "numba")
    env["FLEXSAT_CACHE_DIR"] = os.path.join(cache, "flexsat")
    return env


def _run(command: list[str], env: dict) -> dict:
    """Seconds from just before the process starts to each stamp, and to its exit;
    ``cpu``: the process's user + system CPU seconds; ``loads``: as the driver said."""
    cpu = harness.children_cpu_s()
    start = time.time()
    proc = subprocess.run(command, env=env, capture_output=True, text=True)
    end = time.time()
    if proc.returncode:
        raise RuntimeError(f"{' '.join(command)} failed:\n{proc.stderr[-2000:]}")
    out = {"process": end - start, "cpu": harness.children_cpu_s() - cpu}
    for line in proc.stderr.splitlines():
        if line.startswith("STAMPS "):
            stamps = json.loads(line[7:])
            if "loads" in stamps:
                out["loads"] = stamps.pop("loads")
            out.update({k: v - start for k, v in stamps.items()})
    return out


def _best(command: list[str], env: dict, repeats: int = REPEATS) -> dict:
    runs = [_run(command, env) for _ in range(repeats)]
    return {key: min(run[key] for run in runs) for key in runs[0] if key != "loads"}


def _export(commit: str, folder: Path) -> Path:
    """The ``src`` folder of ``commit``, exported into ``folder``."""
    archive = subprocess.run(["git", "-C", str(ROOT), "archive", commit, "src"],
                             check=True, capture_output=True).stdout  # fmt: skip
    subprocess.run(["tar", "-x", "-C", str(folder)], input=archive, check=True)
    return folder / "src"


def _trees(work: Path, before: str | None, after: str | None) -> dict[str, Path]:
    """The ``src`` folders to time: "after" (this checkout's, or ``after``'s exported)
    and, with a commit, "before"."""
    trees = {"after": ROOT / "src"}
    if after is not None:
        (work / "after").mkdir()
        trees["after"] = _export(after, work / "after")
    if before is not None:
        (work / "before").mkdir()
        trees["before"] = _export(before, work / "before")
    return trees


def measure_commands(
    repeats: int = REPEATS, before: str | None = None, after: str | None = None
) -> dict:
    """Whole commands of :data:`COMMANDS`, warm, fresh processes: best wall and CPU [s].

    Returns ``{label: {"after": {"process", "cpu"}, "before": ...}}`` ("before" only
    with a commit), and the load average before and after as ``"load"``.
    """
    python = sys.executable
    out: dict = {"load_start": harness.load()}
    with tempfile.TemporaryDirectory(prefix="flexsat-bench-") as work:
        trees = _trees(Path(work), before, after)
        envs = {}
        for name, src in trees.items():
            env = _env(os.path.join(work, f"cache-{name}"))
            env["PYTHONPATH"] = str(src)
            envs[name] = env
        for label, args in COMMANDS.items():
            command = [python, "-m", "flexsat", *args]
            for env in envs.values():
                _run(command, env)  # fills this tree's cache (compiles on the first)
            runs: dict = {name: [] for name in trees}
            for _ in range(repeats):  # rounds alternate the trees: both see the same load
                for name, env in envs.items():
                    runs[name].append(_run(command, env))
            out[label] = {name: {key: min(run[key] for run in done)
                                 for key in ("process", "cpu")}
                          for name, done in runs.items()}  # fmt: skip
    out["load_end"] = harness.load()
    return out


def measure_breakdown(
    repeats: int = REPEATS, before: str | None = None, after: str | None = None
) -> dict:
    """Phases of a warm ``flexsat openloop --json`` in one fresh process (the run with
    the shortest whole process of ``repeats``), seconds from its start; ``loads``: the
    functions numba loaded from its disk cache (name, seconds, found).

    Returns ``{"after": run}``, and ``"before"`` (the same of ``before``'s code) with a
    commit.
    """
    out = {}
    with tempfile.TemporaryDirectory(prefix="flexsat-bench-") as work:
        for name, src in _trees(Path(work), before, after).items():
            env = _env(os.path.join(work, f"cache-{name}"))
            env["PYTHONPATH"] = str(src)
            command = [sys.executable, "-c", _BREAKDOWN]
            _run(command, env)  # fills the cache
            runs = [_run(command, env) for _ in range(repeats)]
            out[name] = min(runs, key=lambda run: run["process"])
    return out


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


def _openloop_note(out: dict, _results: dict) -> str:
    commands = out.get("commands") or {}
    row = commands.get("flexsat openloop --json", {})
    before = row.get("before")
    was = f"before {before['process']:.2f} s; " if before else ""
    return (
        f"fresh process, best of {out.get('repeats', REPEATS)}; {was}"
        f"load {commands.get('load_start', '?')} -> {commands.get('load_end', '?')}"
    )


def _openloop_s(out: dict) -> float | None:
    row = (out.get("commands") or {}).get("flexsat openloop --json")
    return row["after"]["process"] if row else None


@harness.register(
    "fresh-process start-up: import flexsat, flexsat slew with empty caches (compiling) and "
    "cached, the API path phase by phase; whole commands warm (--help, openloop, slew, "
    "modal), optionally against a commit; the openloop breakdown",
    targets=[harness.Target(f"cached start-up to simulating <= {STARTUP_MAX_S:g} s",
                            STARTUP_MAX_S, "s", lambda r: r.get("cached_to_simulating_s"),
                            "{:.2f} s", note=_note),
             harness.Target(f"openloop --json, whole process, warm <= {OPENLOOP_MAX_S:g} s",
                            OPENLOOP_MAX_S, "s", _openloop_s, "{:.2f} s",
                            note=_openloop_note)],
)  # fmt: skip
def main(argv: list[str] | None = None) -> dict:
    """Print the start-up tables; return the numbers (seconds)."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=REPEATS, help="warm runs, best kept")
    parser.add_argument("--before", help="also time the commands on this commit's code")
    parser.add_argument("--after", help="time this commit's code instead of this checkout's")
    parser.add_argument(
        "--breakdown",
        action="store_true",
        help="also the phases of a warm openloop --json, in one process",
    )
    parser.add_argument(
        "--write-docs",
        action="store_true",
        help="write the commands and breakdown tables into docs/performance.md, 'Start-up'",
    )
    parser.add_argument(
        "--commands-only",
        action="store_true",
        help="only the whole commands (no compiling slew, no API path)",
    )
    args = parser.parse_args(argv or [])
    console = harness.console()
    out: dict = {"repeats": args.repeats}
    if not args.commands_only:
        out.update(measure())
        _print_slew(console, out)
    out["commands"] = measure_commands(args.repeats, args.before, args.after)
    _print_commands(console, out["commands"], args.repeats)
    if args.breakdown:
        out["breakdown"] = measure_breakdown(args.repeats, args.before, args.after)
        for name, run in out["breakdown"].items():
            _print_breakdown(console, run, name)
    if args.write_docs:
        write_docs(out, args.before, args.after)
        console.print(f"The start-up tables are written to {DOCS.name}, 'Start-up'.")
    return out


def _phases(run: dict) -> list[tuple[str, float]]:
    """(phase, seconds) of a breakdown run, the process's exit last."""
    rows, previous = [], 0.0
    for phase in BREAKDOWN_PHASES:
        if phase in run:
            rows.append((phase, run[phase] - previous))
            previous = run[phase]
    rows.append(("process exit", run["process"] - previous))
    return rows


def write_docs(out: dict, before: str | None, after: str | None = None) -> None:
    """Replace the tables between the markers of docs/performance.md, 'Start-up'."""
    commands = out["commands"]
    trees = [name for name in ("before", "after") if name in commands["flexsat --help"]]
    named = {"before": f"before ({before})", "after": f"after ({after})" if after else "after"}
    lines = [
        BEGIN,
        f"Measured {time.strftime('%Y-%m-%d')} by `python bench/bench_startup.py "
        f"--commands-only --breakdown{f' --before {before}' if before else ''}"
        f"{f' --after {after}' if after else ''} "
        f"--repeats {out['repeats']} --write-docs`. {harness.machine()}. Load average "
        f"{commands['load_start']} at the start, {commands['load_end']} at the end: the "
        "machine was shared, read the CPU columns (user + system of the process) and "
        "the ratios rather than the wall times.",
        "",
        f"Whole commands, warm cache, fresh processes, best of {out['repeats']}:",
        "",
        "| command | " + " | ".join(f"{named[t]}: wall [s] | {named[t]}: CPU [s]"
                                    for t in trees) + " |",
        "| --- |" + " ---: | ---: |" * len(trees),
    ]  # fmt: skip
    for label in COMMANDS:
        cells = [f"{commands[label][t]['process']:.2f} | {commands[label][t]['cpu']:.2f}"
                 for t in trees]  # fmt: skip
        lines.append(f"| `{label}` | " + " | ".join(cells) + " |")
    breakdown = out.get("breakdown") or {}
    if breakdown:
        runs = [t for t in ("before", "after") if t in breakdown]
        lines += [
            "",
            "Where a warm `flexsat openloop --json` spends its time, one fresh process "
            "(the fastest of the repeats), seconds per phase:",
            "",
            "| phase | " + " | ".join(named[t] for t in runs) + " |",
            "| --- |" + " ---: |" * len(runs),
        ]
        phases = {t: dict(_phases(breakdown[t])) for t in runs}
        for phase in (*BREAKDOWN_PHASES, "process exit"):
            cells = [f"{phases[t][phase]:.3f}" if phase in phases[t] else "-" for t in runs]
            lines.append(f"| {phase} | " + " | ".join(cells) + " |")
        lines.append("| whole process | " + " | ".join(
            f"{breakdown[t]['process']:.3f}" for t in runs) + " |")  # fmt: skip
        for t in runs:
            loads = breakdown[t].get("loads", [])
            first = loads[0] if loads else ("-", 0.0, True)
            lines += [
                "",
                f"Compiled functions loaded from numba's disk cache, {named[t]}: "
                f"{len(loads)}, {sum(x[1] for x in loads):.3f} s in all, of which "
                f"{first[1]:.3f} s for the first (`{first[0]}`: it also initializes "
                "numba's compiler); the others: "
                + ", ".join(f"`{name}` {dt:.3f}" for name, dt, _ in loads[1:])
                + ".",
            ]
    lines.append(END)
    text = DOCS.read_text(encoding="utf-8")
    head, rest = text.split(BEGIN, 1)
    tail = rest.split(END, 1)[1]
    DOCS.write_text(head + "\n".join(lines) + tail, encoding="utf-8")


def _print_slew(console, out: dict) -> None:
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


def _print_commands(console, commands: dict, repeats: int) -> None:
    trees = [name for name in ("before", "after") if name in commands["flexsat --help"]]
    columns = ["command"]
    for name in trees:
        columns += [f"{name}: wall [s]", f"{name}: CPU [s]"]
    table = harness.table(
        "Whole commands, warm cache, fresh processes (nominal config, default scenarios)",
        columns,
        caption=f"best of {repeats}; load average {commands['load_start']} before, "
        f"{commands['load_end']} after",
    )
    for label in COMMANDS:
        row = [label]
        for name in trees:
            row += [f"{commands[label][name]['process']:.2f}",
                    f"{commands[label][name]['cpu']:.2f}"]  # fmt: skip
        table.add_row(*row)
    console.print(table)
    openloop = commands["flexsat openloop --json"]["after"]["process"]
    verdict = "met" if openloop <= OPENLOOP_MAX_S else "not met"
    console.print(f"openloop --json, whole process, warm: {openloop:.2f} s against the "
                  f"{OPENLOOP_MAX_S:g} s goal ({verdict}; load average "
                  f"{commands['load_end']}).")  # fmt: skip


def _print_breakdown(console, run: dict, tree: str) -> None:
    table = harness.table(
        f"Where a warm flexsat openloop --json spends its time ({tree}; one fresh process)",
        ("phase", "seconds", "from start [s]"),
        caption=f"load average {harness.load()}",
    )
    previous = 0.0
    for phase in BREAKDOWN_PHASES:
        if phase in run:
            table.add_row(phase, f"{run[phase] - previous:.3f}", f"{run[phase]:.3f}")
            previous = run[phase]
    table.add_row("process exit", f"{run['process'] - previous:.3f}", f"{run['process']:.3f}")
    console.print(table)
    loads = run.get("loads", [])
    table = harness.table(
        f"Compiled functions loaded from numba's disk cache: {len(loads)}, "
        f"{sum(dt for _, dt, _ in loads):.3f} s",
        ("function", "seconds", "in the cache"),
        caption="the first load also initializes numba's compiler (target, type registries)",
    )
    for name, seconds, found in loads:
        table.add_row(name, f"{seconds:.3f}", "yes" if found else "no (compiled)")
    console.print(table)


if __name__ == "__main__":
    main(sys.argv[1:])
