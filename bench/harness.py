"""The benchmarks' shared pieces: timing, the machine, tables and the registry.

Every ``bench_*.py`` script registers its ``main`` here with :func:`register`: its
name (the script's), what it measures, its targets (a limit with units, and how the
measured value is read from what ``main`` returns) and whether it belongs in the full
run (``bench/run_all.py``, what ``make bench`` runs). A script still runs alone
(``python bench/bench_x.py``); :func:`discover` imports every script of this folder
and returns the registry, and :func:`target_rows` turns the results of a run into
one row per target: measured, met / not met, or not measured.

Timing: :func:`stopwatch` (wall and CPU time of one call), :func:`best_of` (the
shortest of N calls: interference from the rest of the machine only adds time),
:func:`interleave` (rounds of several calls in turn, so that a load change on a
shared machine hits every call alike; keep the best or the median of each) and
:func:`per_call_us` (calls looped until a batch is long enough to time).
"""

from __future__ import annotations

import importlib
import inspect
import os
import platform
import statistics
import sys
import time
from collections.abc import Callable, Iterable, Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from rich.console import Console
from rich.markup import escape
from rich.table import Table

HERE = Path(__file__).resolve().parent
WIDE = 160  # characters: a table written to a file or a pipe is not wrapped


# -- the machine ---------------------------------------------------------------------


def cpu_model() -> str:
    """The CPU's model name (Linux ``/proc/cpuinfo``), else the platform's."""
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor() or platform.machine()


def load() -> str:
    """The 1, 5 and 15 min load averages, as text ("n/a" where the OS has none)."""
    try:
        return ", ".join(f"{x:.2f}" for x in os.getloadavg())
    except OSError:
        return "n/a"


def machine() -> str:
    """CPU, logical CPUs, Python and NumPy versions, as one line of text."""
    import numpy as np

    return (
        f"{cpu_model()}, {os.cpu_count()} logical CPUs; Python {platform.python_version()}, "
        f"NumPy {np.__version__}"
    )


# -- timing --------------------------------------------------------------------------


@dataclass(frozen=True)
class Timed:
    """One timed call: wall and CPU time of this process (threads included) [s]."""

    wall_s: float
    cpu_s: float
    value: Any  # what the call returned


def stopwatch(fn: Callable[[], Any]) -> Timed:
    """Call ``fn`` once; its wall time (``perf_counter``) and CPU time (``process_time``)."""
    wall, cpu = time.perf_counter(), time.process_time()
    value = fn()
    return Timed(time.perf_counter() - wall, time.process_time() - cpu, value)


def children_cpu_s() -> float:
    """User + system CPU seconds of this process's finished (reaped) children (Unix)."""
    import resource

    usage = resource.getrusage(resource.RUSAGE_CHILDREN)
    return usage.ru_utime + usage.ru_stime


def best_of(
    fn: Callable[..., Any],
    repeats: int,
    *,
    warm_up: bool = False,
    setup: Callable[[], Any] | None = None,
) -> tuple[float, Any]:
    """Shortest wall time of ``repeats`` calls [s], and the last call's value.

    ``warm_up`` makes one untimed call first (compiling, loading caches); ``setup``,
    if given, is called untimed before each call and its value passed to ``fn``
    (fresh inputs for every repeat).
    """
    if warm_up:
        if setup:
            fn(setup())
        else:
            fn()
    best, value = float("inf"), None
    for _ in range(repeats):
        args = (setup(),) if setup else ()
        timed = stopwatch(lambda args=args: fn(*args))
        best, value = min(best, timed.wall_s), timed.value
    return best, value


def interleave(
    calls: Mapping[str, Callable[[], Any]], rounds: int, *, warm_up: bool = False
) -> dict[str, list[Any]]:
    """Call each of ``calls`` once per round, in turn; every call's value, per name.

    A call returns its own sample: wrap it in :func:`wall` to time it, or return a
    time it measured itself. ``warm_up`` calls each once first, untimed.
    """
    if warm_up:
        for fn in calls.values():
            fn()
    samples: dict[str, list[Any]] = {name: [] for name in calls}
    for _ in range(rounds):
        for name, fn in calls.items():
            samples[name].append(fn())
    return samples


def wall(fn: Callable[[], Any]) -> Callable[[], float]:
    """``fn`` made to return its own wall time [s] (for :func:`interleave`)."""
    return lambda: stopwatch(fn).wall_s


def best(samples: Mapping[str, Sequence[float]]) -> dict[str, float]:
    """The smallest sample of each name."""
    return {name: min(values) for name, values in samples.items()}


def median(samples: Mapping[str, Sequence[float]]) -> dict[str, float]:
    """The median sample of each name."""
    return {name: statistics.median(values) for name, values in samples.items()}


def per_call_us(fn: Callable[[], Any], repeats: int = 5, target_s: float = 0.2) -> float:
    """Best-of-``repeats`` mean wall time of one call [us].

    After one warm-up call, the loop length doubles until a batch lasts more than
    ``target_s / repeats``; that batch is the first of the ``repeats``.
    """
    fn()
    loops = 1

    def batch() -> None:
        for _ in range(loops):
            fn()

    while True:
        elapsed = stopwatch(batch).wall_s
        if elapsed > target_s / repeats:
            break
        loops *= 2
    rest, _ = best_of(batch, repeats - 1) if repeats > 1 else (float("inf"), None)
    return 1e6 * min(elapsed, rest) / loops


# -- printing ------------------------------------------------------------------------


def console(width: int = WIDE) -> Console:
    """A rich console: the terminal's width, or ``width`` characters to a file or a pipe."""
    return Console() if sys.stdout.isatty() else Console(width=width)


def table(
    title: str,
    columns: Iterable[str],
    *,
    left: int = 1,
    right: Iterable[str] | None = None,
    caption: str | None = None,
    **kw: Any,
) -> Table:
    """A table whose first ``left`` columns are text (left-aligned), the rest numbers.

    The title, caption and column names are shown as written: a unit in brackets
    ("wall [s]") is not taken for rich's markup.

    ``right``, if given, names the right-aligned columns instead. Column names carry
    the units of their numbers ("wall [s]", "us / step"). Extra keywords go to every
    column (``no_wrap=True``).
    """
    out = Table(title=escape(title), caption=escape(caption) if caption else None)
    numbers = set(right) if right is not None else None
    for k, column in enumerate(columns):
        at_right = column in numbers if numbers is not None else k >= left
        out.add_column(escape(column), justify="right" if at_right else "left", **kw)
    return out


# -- the registry --------------------------------------------------------------------


@dataclass(frozen=True)
class Target:
    """A performance target: a limit on one number read from a benchmark's result.

    ``read`` takes what the benchmark's ``main`` returned and gives the measured
    value in ``unit`` (None: not measured in this run). ``shown`` formats it for the
    table (``"{:.3f} s"``); ``note``, given the benchmark's result and all results of
    the run, adds context. ``at_most``: the value must not exceed ``limit``;
    otherwise it must reach it.
    """

    name: str
    limit: float
    unit: str
    read: Callable[[Any], float | None]
    shown: str = "{:.3g}"
    at_most: bool = True
    note: Callable[[Any, Mapping[str, Any]], str] | None = None

    def row(self, result: Any, results: Mapping[str, Any]) -> tuple[str, str, bool | None, str]:
        """(target, measured, met, note) of this target for a run's result (not None)."""
        value = self.read(result)
        if value is None:
            return self.name, "-", None, "not measured in this run"
        met = value <= self.limit if self.at_most else value >= self.limit
        note = self.note(result, results) if self.note else ""
        return self.name, self.shown.format(value), met, note


@dataclass(frozen=True)
class Benchmark:
    """A registered benchmark: its script's ``main`` and what it is measured against."""

    name: str  # the script's name, bench_x
    measures: str  # one line: what it measures
    main: Callable[..., Any]
    targets: tuple[Target, ...] = ()
    full: bool = True  # part of a full run of run_all.py
    optional: bool = False  # skipped, not failed, when a dependency is missing
    quick_argv: tuple[str, ...] = ()  # its arguments under run_all.py --quick
    takes_argv: bool = field(default=True)

    def run(self, argv: Sequence[str] = ()) -> Any:
        """Call ``main`` (with ``argv`` when it takes arguments); its numbers."""
        return self.main(list(argv)) if self.takes_argv else self.main()


REGISTRY: dict[str, Benchmark] = {}


def register(
    measures: str,
    *,
    targets: Iterable[Target] = (),
    full: bool = True,
    optional: bool = False,
    quick_argv: Sequence[str] = (),
) -> Callable[[Callable[..., Any]], Callable[..., Any]]:
    """Register the decorated ``main`` under its script's name; ``main`` is returned as is."""

    def wrap(main: Callable[..., Any]) -> Callable[..., Any]:
        name = Path(main.__globals__["__file__"]).stem
        REGISTRY[name] = Benchmark(
            name, measures, main, tuple(targets), full, optional, tuple(quick_argv),
            takes_argv=bool(inspect.signature(main).parameters),
        )  # fmt: skip
        return main

    return wrap


def scripts() -> list[str]:
    """The names of the benchmark scripts of this folder (bench_*.py), sorted."""
    return sorted(p.stem for p in HERE.glob("bench_*.py"))


def discover() -> dict[str, Benchmark]:
    """Import every benchmark script (bench/ on ``sys.path``); the registry, by name."""
    if str(HERE) not in sys.path:
        sys.path.insert(0, str(HERE))
    for name in scripts():
        importlib.import_module(name)
    return {name: REGISTRY[name] for name in scripts() if name in REGISTRY}


def verdict(met: bool | None) -> str:
    """'met', 'NOT MET' (in colour markup) or 'not measured'."""
    if met is None:
        return "not measured"
    return "[green]met[/green]" if met else "[red]NOT MET[/red]"


def target_rows(
    benchmarks: Iterable[Benchmark], results: Mapping[str, Any]
) -> list[tuple[str, str, bool | None, str]]:
    """(target, measured, met, note) of every target of ``benchmarks``.

    A benchmark missing from ``results`` (not run, skipped or failed: None) gives
    each of its targets "not measured", with the reason in the note.
    """
    rows = []
    for bench in benchmarks:
        result = results.get(bench.name)
        for target in bench.targets:
            if result is None:
                rows.append((target.name, "-", None, f"{bench.name} not run"))
            else:
                rows.append(target.row(result, results))
    return rows
