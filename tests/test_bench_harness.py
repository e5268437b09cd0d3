"""The benchmark harness (bench/harness.py): the registry and the targets table.

No timing is asserted here (timings belong in bench/): the registry must name every
benchmark script with what it measures, and the targets table must say which targets
a run did not measure instead of failing.
"""

from __future__ import annotations

import io
import sys
from pathlib import Path

import pytest

BENCH = Path(__file__).resolve().parents[1] / "bench"
sys.path.insert(0, str(BENCH))

import harness  # noqa: E402
import run_all  # noqa: E402


@pytest.fixture(scope="module")
def registry() -> dict[str, harness.Benchmark]:
    return harness.discover()


def test_every_script_is_registered_with_a_description(registry):
    scripts = sorted(p.stem for p in BENCH.glob("bench_*.py"))
    assert len(scripts) >= 20  # the folder is found, not an empty glob
    assert sorted(registry) == scripts
    for name, bench in registry.items():
        assert bench.name == name
        assert len(bench.measures.split()) >= 5, f"{name}: say what it measures"
        assert callable(bench.main)


def test_the_full_run_is_ordered_and_complete(registry):
    full = {name for name, bench in registry.items() if bench.full}
    assert set(run_all.ORDER) == full  # every benchmark of a full run has its place
    assert run_all.full_run(registry) == list(run_all.ORDER)


def test_targets_of_benchmarks_not_run_read_not_measured(registry):
    rows = harness.target_rows(registry.values(), {})
    expected = sum(len(bench.targets) for bench in registry.values())
    assert expected >= 10  # the targets of docs/performance.md, 'Targets', and more
    assert len(rows) == expected
    for _target, measured, met, note in rows:
        assert (measured, met) == ("-", None)
        assert note.endswith(" not run")
    assert {harness.verdict(met) for *_, met, _ in rows} == {"not measured"}


def test_a_target_reads_met_not_met_and_a_missing_value():
    target = harness.Target("x <= 2 s", 2.0, "s", lambda r: r.get("x"), "{:.2f} s")
    assert target.row({"x": 1.5}, {})[1:3] == ("1.50 s", True)
    assert target.row({"x": 2.5}, {})[1:3] == ("2.50 s", False)
    assert target.row({}, {})[1:3] == ("-", None)  # run, but this value not measured
    at_least = harness.Target("y >= 90 %", 0.9, "", lambda r: r["y"], "{:.0%}", at_most=False)
    assert at_least.row({"y": 0.95}, {})[1:3] == ("95%", True)


def test_a_partial_result_gives_the_others_not_measured(registry):
    # bench_scale run with --only reduced --backends local: the other rows not measured
    scale = {"cases": 10, "duration_s": 1.0, "results": {"reduced local": {
        "cases_per_s_2": 5.0, "per_1000_cases_2_s": 14.0, "efficiency": 0.95}}}  # fmt: skip
    rows = harness.target_rows([registry["bench_scale"]], {"bench_scale": scale})
    verdicts = {target: met for target, _, met, _ in rows}
    assert verdicts["1000 random MC cases, reduced model, 2 workers <= 15 s"] is True
    assert verdicts["reduced local: 1 -> 2 workers efficiency >= 90%"] is True
    assert verdicts["full dask: 1 -> 2 workers efficiency >= 90%"] is None


def test_the_markdown_table_drops_colour_and_escapes_pipes():
    assert run_all._cell(harness.verdict(True)) == "met"
    assert run_all._cell(harness.verdict(False)) == "NOT MET"
    assert run_all._cell("a | b") == "a \\| b"


def test_the_script_table_of_the_docs_matches_the_registry(registry):
    # docs/performance.md, 'Running the benchmarks': a row per script, and "not in the
    # full run" exactly where the registry says so
    text = (BENCH.parent / "docs" / "performance.md").read_text(encoding="utf-8")
    rows = {
        line.split("`")[1].removesuffix(".py"): line
        for line in text.splitlines()
        if line.startswith("| `bench_")
    }
    assert sorted(rows) == sorted(registry)
    for name, bench in registry.items():
        assert ("not in the full run" in rows[name]) == (not bench.full), name


def test_units_in_brackets_are_printed():
    from rich.console import Console

    table = harness.table("times [s]", ("what", "wall [s]", "time [ms]"))
    table.add_row("a run", "1.5", "1500")
    console = Console(record=True, width=80, file=io.StringIO())
    console.print(table)
    text = console.export_text()
    assert "times [s]" in text and "wall [s]" in text and "time [ms]" in text
