"""Run every flexsat benchmark in order and finish with the performance targets.

``python bench/run_all.py`` (what ``make bench`` runs) prints, in this order, the tables
of bench_dynamics, bench_openloop, bench_slew, bench_laws, bench_scaling, bench_startup,
bench_campaigns, bench_scale, bench_contention, bench_ensemble, bench_case_cost, bench_avionics,
bench_avionics_parts, bench_reduction, bench_campaign_start, bench_modal, bench_figures,
bench_demo, bench_basilisk and bench_basilisk_chain (the last two skipped with a line when Basilisk
or the script is missing), then one table of the performance targets: each target, the
measured value, and met / not met. A benchmark that fails is reported and the others
still run; the exit status is then 1.

Options: ``--quick`` passes ``--quick`` to bench_openloop (its plain NumPy baseline
then runs shorter and is extrapolated: about 15 s instead of about 4 minutes); names
of benchmarks (e.g. ``bench_slew bench_scaling``) run those only.

Timings are wall-clock times on one core unless a table says otherwise; run on a
quiet machine (the load average is printed before and after).
"""

from __future__ import annotations

import argparse
import importlib
import inspect
import os
import platform
import sys
import time
import traceback
from pathlib import Path

from rich.console import Console
from rich.rule import Rule
from rich.table import Table

BENCHMARKS = (
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
    "bench_demo",
    "bench_basilisk",
    "bench_basilisk_chain",
)
# skipped, not failed, when it or its dependency is missing
OPTIONAL = {"bench_basilisk", "bench_basilisk_chain"}
LINEAR_R2 = 0.99  # a straight line explains at least this share of the variance

# (target, limit) of the performance issue; values in seconds unless noted.
OPENLOOP_MAX_S = 0.6
SLEW_MAX_S = 0.7
STARTUP_MAX_S = 2.0
CAMPAIGNS_MAX_S = 30.0
SCALE_MAX_S = 30.0  # 1000 random Monte Carlo cases, reduced model, 2 cores
SCALE_EFFICIENCY = 0.9


def cpu_model() -> str:
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor() or platform.machine()


def _load() -> str:
    try:
        return ", ".join(f"{x:.2f}" for x in os.getloadavg())
    except OSError:
        return "n/a"


def run_benchmark(name: str, argv: list[str], console: Console):
    """Import bench/<name>.py and call its main (with argv if it takes arguments).

    Returns what main returns (the numbers), or None when an optional benchmark is
    skipped.
    """
    console.print(Rule(f"[bold]{name}"))
    start = time.perf_counter()
    try:
        module = importlib.import_module(name)
    except ImportError as exc:
        if name in OPTIONAL:
            console.print(f"{name}: skipped ({exc})")
            return None
        raise
    takes_argv = bool(inspect.signature(module.main).parameters)
    try:
        out = module.main(argv) if takes_argv else module.main()
    except ImportError as exc:
        if name in OPTIONAL:
            console.print(f"{name}: skipped ({exc})")
            return None
        raise
    console.print(f"[dim]{name}: {time.perf_counter() - start:.0f} s[/dim]")
    return out


def _verdict(ok: bool | None) -> str:
    if ok is None:
        return "not measured"
    return "[green]met[/green]" if ok else "[red]NOT MET[/red]"


def targets(results: dict) -> list[tuple[str, str, bool | None, str]]:
    """(target, measured, met, note) for each target of the performance issue."""
    rows = []
    slew = results.get("bench_slew")
    scaling = results.get("bench_scaling")
    nominal = scaling["sizes"][2] if scaling else None

    def from_slew(row: str, limit: float, target: str, mode: str) -> None:
        if slew is None:
            rows.append((target, "-", None, "bench_slew not run"))
            return
        value = slew[row]["wall_per_120_s"]
        note = f"whole call, best of 3; {slew[row]['us_per_step']:.2f} us/step"
        if nominal is not None:
            note += f"; integration alone {nominal[mode]['us_per_step']:.2f} us/step"
        rows.append((target, f"{value:.3f} s", value <= limit, note))

    from_slew(
        "plant only (open loop)",
        OPENLOOP_MAX_S,
        f"plant-only open loop, 120 s, nominal <= {OPENLOOP_MAX_S} s",
        "plant only",
    )
    from_slew("ASMC, compiled", SLEW_MAX_S, f"ASMC slew, 120 s, nominal <= {SLEW_MAX_S} s", "ASMC")
    target = "a user's compiled law per step <= 1.2x the built-in PD"
    if slew is None:
        rows.append((target, "-", None, "bench_slew not run"))
    else:
        ratio = slew["user_law_ratio"]
        rows.append((target, f"{ratio:.3f}x", ratio <= 1.2, "examples/compiled_law.py, 120 s"))

    target = "cost linear in the number of appendages (1, 2, 4, 8)"
    if scaling is None:
        rows.append((target, "-", None, "bench_scaling not run"))
    else:
        fits = {k: v for k, v in scaling["fits"].items() if k.endswith("(us/step)")}
        worst = min(fit["r2"] for fit in fits.values())
        slopes = ", ".join(
            f"{k.split(' (')[0]} {v['a']:.2f} + {v['b']:.2f} n us" for k, v in fits.items()
        )
        rows.append(
            (target, f"min R^2 = {worst:.4f}", worst >= LINEAR_R2,
             f"R^2 >= {LINEAR_R2} required; per step: {slopes}")
        )  # fmt: skip

    startup = results.get("bench_startup")
    target = f"cached start-up to simulating <= {STARTUP_MAX_S} s"
    if startup is None:
        rows.append((target, "-", None, "bench_startup not run"))
    else:
        value = startup["cached_to_simulating_s"]
        note = (
            f"flexsat slew, fresh process; API path {startup['api']['simulating']:.2f} s; "
            f"import flexsat {startup['import_process_s']:.2f} s; "
            f"cold (compiling) {startup['cold_to_simulating_s']:.1f} s"
        )
        rows.append((target, f"{value:.2f} s", value <= STARTUP_MAX_S, note))

    campaigns = results.get("bench_campaigns")
    target = f"3 campaigns (68 runs), 2 workers, local pool <= {CAMPAIGNS_MAX_S:g} s"
    if campaigns is None:
        rows.append((target, "-", None, "bench_campaigns not run"))
    else:
        value = campaigns["totals"]["local x2"]
        local = campaigns["scaling"]["local"]
        note = (
            f"{campaigns['cases']} cases, {local['cases_per_s_2']:.2f} cases/s; "
            f"1 -> 2 workers efficiency {local['efficiency']:.0%}"
        )
        if "dask" in campaigns["scaling"]:
            note += f" (Dask {campaigns['scaling']['dask']['efficiency']:.0%})"
        rows.append((target, f"{value:.1f} s", value <= CAMPAIGNS_MAX_S, note))

    scale = results.get("bench_scale")
    target = f"1000 random MC cases, reduced model, 2 workers <= {SCALE_MAX_S:g} s"
    reduced = (scale or {}).get("results", {}).get("reduced local")
    if reduced is None:
        rows.append((target, "-", None, "bench_scale not run"))
    else:
        full = scale["results"].get("full local")
        note = f"{reduced['cases_per_s_2']:.2f} cases/s"
        if full is not None:
            note += f"; full model {full['per_1000_cases_2_s']:.0f} s"
        value = reduced["per_1000_cases_2_s"]
        rows.append((target, f"{value:.0f} s", value <= SCALE_MAX_S, note))
    ceiling = (results.get("bench_contention") or {}).get("efficiency_ceiling")
    for key, run in (scale or {}).get("results", {}).items():
        target = f"{key}: 1 -> 2 workers efficiency >= {SCALE_EFFICIENCY:.0%}"
        note = f"{scale['cases']} cases of {scale['duration_s']:g} s"
        if ceiling is not None:  # what two busy cores allow (bench_contention)
            note += f"; the machine's ceiling {ceiling:.0%}"
        rows.append((target, f"{run['efficiency']:.0%}", run["efficiency"] >= SCALE_EFFICIENCY,
                     note))  # fmt: skip
    demo = results.get("bench_demo")
    for key, limit, what in (("warm_s", 20.0, "warm"), ("first_s", 60.0, "first run")):
        target = f"flexsat study --quick, {what} <= {limit:g} s"
        if demo is None:
            rows.append((target, "-", None, "bench_demo not run"))
        else:
            note = f"before: {demo['before'][1 if key == 'warm_s' else 0]:.1f} s"
            rows.append((target, f"{demo[key]:.1f} s", demo[key] <= limit, note))
    return rows


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
            f"| {_cell(t)} | {_cell(v)} | {_cell(_verdict(ok))} | {_cell(note)} |"
            for t, v, ok, note in rows
        ),
        END,
    ]
    text = DOCS.read_text(encoding="utf-8")
    head, rest = text.split(BEGIN, 1)
    tail = rest.split(END, 1)[1]
    DOCS.write_text(head + "\n".join(lines) + tail, encoding="utf-8")


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument(
        "--quick", action="store_true", help="bench_openloop --quick (shorter NumPy baseline)"
    )
    parser.add_argument("names", nargs="*", metavar="BENCHMARK",
                        help=f"run only these, of: {', '.join(BENCHMARKS)}")  # fmt: skip
    args = parser.parse_args(argv)
    unknown = sorted(set(args.names) - set(BENCHMARKS))
    if unknown:
        parser.error(f"unknown benchmark(s) {', '.join(unknown)}; choose from {BENCHMARKS}")
    if not sys.stdout.isatty():  # to a file or a pipe: wide enough for every table
        os.environ.setdefault("COLUMNS", "160")
    console = Console()
    machine = (
        f"{cpu_model()}, {os.cpu_count()} logical CPUs; Python {platform.python_version()}; "
        f"load average at start {_load()}"
    )
    console.print(f"flexsat benchmarks: {machine}")
    start = time.perf_counter()
    results, failed = {}, []
    for name in args.names or BENCHMARKS:
        argv_of = ["--quick"] if (args.quick and name == "bench_openloop") else []
        try:
            results[name] = run_benchmark(name, argv_of, console)
        except Exception:
            failed.append(name)
            console.print(f"[red]{name} failed:[/red]\n{traceback.format_exc()}")

    console.print(Rule("[bold]targets"))
    table = Table(title="Performance targets (nominal satellite, RK4 dt = 1 ms, one core)")
    for column in ("target", "measured", "verdict", "note"):
        table.add_column(column, justify="right" if column == "measured" else "left")
    rows = targets(results)
    for target, value, ok, note in rows:
        table.add_row(target, value, _verdict(ok), note)
    console.print(table)
    console.print(
        f"Machine: {cpu_model()}, {os.cpu_count()} logical CPUs; load average at the end "
        f"{_load()}; all benchmarks {time.perf_counter() - start:.0f} s."
    )
    if not args.names and not failed:
        write_targets(rows, f"{machine}; at the end {_load()}")
        console.print(f"The targets table is written to {DOCS.name}, 'Targets'.")
    else:
        console.print(f"A partial run: {DOCS.name} is left as it is.")
    if failed:
        console.print(f"[red]failed: {', '.join(failed)}[/red]")
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
