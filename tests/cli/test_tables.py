"""Every table of the command line at 80 and 60 columns: no cell is cut, every number
reads back as the value it shows, to its printed significant digits."""

from __future__ import annotations

import importlib
import json
import math
import re

import pytest
from rich.console import Console

import flexsat.study.outputs as outputs
from flexsat.cli.tables import cell, format_number, print_table
from tests.cli.harness import flexsat

cli = importlib.import_module("flexsat.cli.main")  # the module; flexsat.cli.main is the function

WIDTHS = (80, 60)
NUMBER = re.compile(r"[-+]?(\d+\.?\d*|\.\d+)([eE][-+]?\d+)?")
SEPARATORS = re.compile(r"[\s│┃┆|,;:=\[\](){}]+")  # table borders and list punctuation

CAMPAIGN = """name = "two-cases"
include_nominal = true
[base]
duration_s = 1.0
[[cases]]
id = "heavier"
plant = [{ path = "hub.mass_kg", value = 180.0 }]
"""

SLEW = """duration_s = 3.0
[requirements]
settling_deadline_s = 1.0
"""


def _numbers(data) -> list[float]:
    """Every finite number of a JSON document (bools are not numbers)."""
    if isinstance(data, dict):
        return [v for value in data.values() for v in _numbers(value)]
    if isinstance(data, list):
        return [v for value in data for v in _numbers(value)]
    if isinstance(data, int | float) and not isinstance(data, bool) and math.isfinite(data):
        return [float(data)]
    return []


def _half_unit(token: str) -> float:
    """Half a unit in the last printed digit of a number token: '5.065e-07' -> 5e-11."""
    mantissa, _, exponent = token.lower().lstrip("+-").partition("e")
    decimals = len(mantissa.partition(".")[2])
    return 0.5 * 10.0 ** (int(exponent or 0) - decimals)


def assert_whole(stdout: str, reference) -> int:
    """No cell ends cut, and every number token is a value of ``reference`` to its digits.

    Returns the number of number tokens checked.
    """
    assert "…" not in stdout and "..." not in stdout, stdout  # rich's ellipsis of a cut cell
    values = _numbers(reference)
    checked = 0
    for token in SEPARATORS.split(stdout):
        if not NUMBER.fullmatch(token):
            continue
        x, tol = float(token), _half_unit(token)
        # A value shown to p significant digits is within half a unit of its last digit
        # (round-off of the decimal conversion: 1e-12 relative on top).
        assert any(abs(v - x) <= tol + 1e-12 * abs(v) for v in values), (token, stdout)
        checked += 1
    return checked


@pytest.fixture
def narrow(monkeypatch):
    """Set COLUMNS and give the command a console that reads it, as at start-up."""

    def set_width(width: int) -> None:
        monkeypatch.setenv("COLUMNS", str(width))
        monkeypatch.setattr(cli, "_console", Console(markup=False))
        assert cli._console.width == width

    return set_width


@pytest.fixture
def recorded(monkeypatch):
    """The metrics each run of the command returned, in the same process as its table."""
    runs: list[dict] = []
    for name in ("fly_slew", "fly_openloop"):
        original = getattr(outputs, name)

        def record(*args, _original=original, **kwargs):
            result, metrics = _original(*args, **kwargs)
            runs.append(metrics)
            return result, metrics

        monkeypatch.setattr(outputs, name, record)
    return runs


def test_format_number_keeps_four_significant_digits_and_the_exponent():
    # The numbers the comparison table used to cut: STSMC's 5.06e-07 deg, ISMC's 2.73e-05.
    assert format_number(5.0647e-07) == "5.065e-07"
    assert format_number(2.72657e-05) == "2.727e-05"
    assert format_number(0.35072474726197167) == "0.3507"
    assert format_number(666198.2970735317) == "6.662e+05"
    assert (format_number(20), format_number(20.0)) == ("20", "20")
    assert (format_number(math.nan), format_number(-math.inf)) == ("nan", "-inf")
    assert cell([[189.9, 0.0], [0.0, 44.16]]) == "[189.9, 0] [0, 44.16]"
    assert (cell(True), cell(None), cell([]), cell({})) == ("True", "-", "-", "-")


@pytest.mark.parametrize("width", WIDTHS)
def test_a_table_wider_than_the_terminal_is_split_not_cut(width, capsys):
    # Ten columns of nine-character numbers need 10 * 12 + 30 characters: more than
    # either width, so the columns go into several parts, each with the label column.
    values = [1.23456789e-7 * 10**k for k in range(10)]
    console = Console(width=width, markup=False)
    print_table(console, "wide", ("metric", *(f"law{k}" for k in range(10))),
                [["a_rather_long_metric_name_deg", *values]])  # fmt: skip
    out = capsys.readouterr().out
    assert max(len(line) for line in out.splitlines()) <= width
    assert assert_whole(out, values) == 10
    assert "wide (continued)" in out


@pytest.mark.parametrize("width", WIDTHS)
def test_tables_of_the_deterministic_commands(width, narrow, capsys, tmp_path):
    narrow(width)
    for argv in (["modal"], ["margins"], ["linearize"], ["config", "show"]):
        table = flexsat(argv, capsys, timeout_s=600)
        assert table.code == 0, table.stderr
        reference = flexsat([*argv, "--json"], capsys, timeout_s=600)
        assert reference.code == 0, reference.stderr
        summary = json.loads(reference.stdout)
        for key in ("A", "B", "C", "D"):  # the model's matrices are not printed
            summary.pop(key, None)
        # linearize prints the sizes of the model and numbers its modes 1, 2...
        summary["counts"] = [len(summary.get(k, [])) for k in ("input_names", "output_names")]
        summary["mode_numbers"] = list(range(1, len(summary.get("modes", [])) + 1))
        assert assert_whole(table.stdout, summary) > 5, argv
        assert max(len(line) for line in table.stdout.splitlines()) <= width


@pytest.mark.parametrize("width", WIDTHS)
def test_controller_comparison_and_run_tables(width, narrow, recorded, capsys, tmp_path):
    narrow(width)
    (tmp_path / "slew.toml").write_text(SLEW)
    argv = ["slew", "--scenario", str(tmp_path / "slew.toml"), "--controller", "all"]
    out = flexsat(argv, capsys, timeout_s=900)
    assert out.code in (0, 1), out.stderr  # a failed requirement is exit 1, not a crash
    assert len(recorded) == 5  # one run per built-in law
    assert assert_whole(out.stdout, recorded) > 50
    out = flexsat(["openloop", "--duration", "2"], capsys, timeout_s=600)
    assert out.code == 0, out.stderr
    assert assert_whole(out.stdout, recorded[-1]) > 10


@pytest.mark.parametrize("width", WIDTHS)
def test_campaign_table(width, narrow, capsys, tmp_path):
    narrow(width)
    (tmp_path / "k.toml").write_text(CAMPAIGN)
    store = tmp_path / "store"
    argv = ["campaign", str(tmp_path / "k.toml"), "--out", str(store), "--workers", "1"]
    out = flexsat(argv, capsys, timeout_s=900)
    assert out.code == 0, out.stderr
    summary = json.loads((store / "summary.json").read_text())
    assert assert_whole(out.stdout, summary) >= 8
    # Its 1 s runs end before the default observation window opens (90 s): R1 and R2
    # are not judged, said once before the cases fly, and no table reads FAIL.
    notice = (
        "campaign two-cases: R1 and R2 are not judged: the run ends at 1 s, before "
        "the observation window starts at 90 s (requirements.settling_deadline_s)"
    )
    assert notice in " ".join(out.stderr.split())
    assert "FAIL" not in out.stdout
    assert (summary["r1_not_judged"], summary["r2_not_judged"]) == (2, 2)
    for label in ("R1 pass rate", "R2 pass rate"):
        row = next(line for line in out.stdout.splitlines() if label in line)
        assert "not judged" in row, row


def test_a_verdict_not_judged_reads_so_in_its_rows(capsys):
    console = Console(width=100, markup=False)
    print_table(console, "verdicts", ("metric", "asmc", "pd"),
                [["r1_pass", None, False], ["r2_pass", True, None],
                 ["R1 pass rate (absolute pointing, over the judged cases)", math.nan, 0.5],
                 ["settling_time_s", None, math.nan]])  # fmt: skip
    rows = [line.split("│")[1:4] for line in capsys.readouterr().out.splitlines()
            if line.startswith("│")]  # fmt: skip
    cells = [[c.strip() for c in row] for row in rows]
    assert cells == [["r1_pass", "not judged", "False"], ["r2_pass", "True", "not judged"],
                         ["R1 pass rate (absolute pointing, over the judged cases)",
                          "not judged", "0.5"],
                         ["settling_time_s", "-", "nan"]]  # fmt: skip


def test_config_show_prints_tables_and_keeps_json(narrow, capsys):
    narrow(100)
    out = flexsat(["config", "show"], capsys)
    assert out.code == 0, out.stderr
    assert not out.stdout.lstrip().startswith("{")
    for heading in ("Satellite nominal", "Appendages", "hub inertia", "Derived per appendage"):
        assert heading in out.stdout
    row = next(line for line in out.stdout.splitlines() if "length_m" in line)
    assert [c.strip() for c in row.split("│")[2:4]] == ["4.5", "4.5"]  # panel_1, panel_2 [m]
    assert json.loads(flexsat(["config", "show", "--json"], capsys).stdout)["config"]["name"] == (
        "nominal"
    )
