"""Run every flexsat benchmark of the full run in order and finish with the performance targets.

``python bench/run_all.py`` (what ``make bench`` runs) prints the tables of every
benchmark registered for the full run (``bench/harness.py``; the order is
:data:`ORDER`), then one table of the performance targets of every registered
benchmark: each target, the measured value, met / not met / not measured, and a note.
A benchmark that fails is reported and the others still run; the exit status is then
1. An optional benchmark (Basilisk) is skipped with a line when its dependency is
missing.

Options: ``--quick`` passes each benchmark its quick arguments (bench_openloop: its
plain NumPy baseline then runs shorter and is extrapolated: about 15 s instead of
about 4 minutes); names of benchmarks (e.g. ``bench_slew bench_scaling``) run those
only, whether or not they belong to the full run.

Timings are wall-clock times on one core unless a table says otherwise; run on a
quiet machine (the load average is printed before and after).
"""

from __future__ import annotations

import argparse
import os
import sys
import time
import traceback
from pathlib import Path

from rich.console import Console
from rich.rule import Rule

import harness

# The order of a full run: the kernels and single runs first, the campaigns later, the
# slow fresh-process demo and the optional comparisons last.
ORDER = (
    "bench_dynamics",
    "bench_openloop",
    "bench_slew",
    "bench_laws",
    "bench_scaling",
    "bench_startup",
    "bench_campaigns",
    "bench_scale",
    "bench_contention",
    "bench_ensemble",
    "bench_case_cost",
    "bench_avionics",
    "bench_avionics_parts",
    "bench_reduction",
    "bench_campaign_start",
    "bench_figures",
    "bench_modal",
    "bench_modal_large_motion",
    "bench_environment",
    "bench_realtime",
    "bench_demo",
    "bench_basilisk",
    "bench_basilisk_chain",
)


def full_run(registry: dict[str, harness.Benchmark]) -> list[str]:
    """The benchmarks of a full run: those of :data:`ORDER`, then any other registered
    for it (by name)."""
    full = [name for name, bench in registry.items() if bench.full]
    return [name for name in ORDER if name in full] + sorted(set(full) - set(ORDER))


def run_benchmark(bench: harness.Benchmark, argv: list[str], console: Console):
    """Call the benchmark's main (with argv if it takes arguments).

    Returns what main returns (the numbers), or None when an optional benchmark is
    skipped.
    """
    console.print(Rule(f"[bold]{bench.name}"))
    start = time.perf_counter()
    try:
        out = bench.run(argv)
    except ImportError as exc:
        if bench.optional:
            console.print(f"{bench.name}: skipped ({exc})")
            return None
        raise
    console.print(f"[dim]{bench.name}: {time.perf_counter() - start:.0f} s[/dim]")
    return out


DOCS = Path(__file__).resolve().parents[1] / "docs" / "performance.md"
BEGIN = "<!-- targets: written by bench/run_all.py; do not edit by hand -->"
END = "<!-- end of targets -->"


def _cell(text: str) -> str:
    """A table cell of Markdown: rich's colour markup dropped, pipes escaped."""
    for markup in ("[green]", "[/green]", "[red]", "[/red]"):
        text = text.replace(markup, "")
    return text.replace("|", "\\|")


def write_targets(rows: list[tuple[str, str, bool | None, str]], machine: str) -> None:
    """Replace the table between the markers of docs/performance.md, 'Targets'."""
    lines = [
        BEGIN,
        f"Last full run: {time.strftime('%Y-%m-%d')}. {machine}.",
        "",
        "| target | measured | verdict | note |",
        "| --- | --- | --- | --- |",
        *(
            f"| {_cell(t)} | {_cell(v)} | {_cell(harness.verdict(ok))} | {_cell(note)} |"
            for t, v, ok, note in rows
        ),
        END,
    ]
    text = DOCS.read_text(encoding="utf-8")
    head, rest = text.split(BEGIN, 1)
    tail = rest.split(END, 1)[1]
    DOCS.write_text(head + "\n".join(lines) + tail, encoding="utf-8")


def main(argv: list[str] | None = None) -> int:
    registry = harness.discover()
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument(
        "--quick", action="store_true", help="quick arguments (bench_openloop: shorter baseline)"
    )
    parser.add_argument("names", nargs="*", metavar="BENCHMARK",
                        help=f"run only these, of: {', '.join(registry)}")  # fmt: skip
    args = parser.parse_args(argv)
    unknown = sorted(set(args.names) - set(registry))
    if unknown:
        parser.error(f"unknown benchmark(s) {', '.join(unknown)}; choose from {list(registry)}")
    if not sys.stdout.isatty():  # to a file or a pipe: wide enough for every table
        os.environ.setdefault("COLUMNS", str(harness.WIDE))
    console = Console()
    machine = f"{harness.machine()}; load average at start {harness.load()}"
    console.print(f"flexsat benchmarks: {machine}")
    start = time.perf_counter()
    names = args.names or full_run(registry)
    results, failed = {}, []
    for name in names:
        bench = registry[name]
        try:
            results[name] = run_benchmark(bench, list(bench.quick_argv) * args.quick, console)
        except Exception:
            failed.append(name)
            console.print(f"[red]{name} failed:[/red]\n{traceback.format_exc()}")

    console.print(Rule("[bold]targets"))
    in_order = full_run(registry) + sorted(set(registry) - set(full_run(registry)))
    rows = harness.target_rows([registry[name] for name in in_order], results)
    table = harness.table(
        "Performance targets (nominal satellite, RK4 dt = 1 ms, one core)",
        ("target", "measured", "verdict", "note"), right=("measured",),
    )  # fmt: skip
    for target, value, ok, note in rows:
        table.add_row(target, value, harness.verdict(ok), note)
    console.print(table)
    console.print(
        f"Machine: {harness.machine()}; load average at the end {harness.load()}; "
        f"all benchmarks {time.perf_counter() - start:.0f} s."
    )
    if not args.names and not failed:
        write_targets(rows, f"{machine}; at the end {harness.load()}")
        console.print(f"The targets table is written to {DOCS.name}, 'Targets'.")
    else:
        console.print(f"A partial run: {DOCS.name} is left as it is.")
    if failed:
        console.print(f"[red]failed: {', '.join(failed)}[/red]")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
