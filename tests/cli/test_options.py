"""Command-line options: help texts keep their units, bad overrides give one message."""

from __future__ import annotations

import re

import pytest
import typer.main
from typer.testing import CliRunner

from flexsat.cli.main import app
from tests.cli.test_cli import run

UNIT = re.compile(r"\[[^\]\s]+\]")  # "[s]", "[deg]": a bracketed unit in a help text


def _commands(command, path: tuple[str, ...] = ()):
    """Every command of the app with its argument path, groups included."""
    yield path, command
    for name, sub in getattr(command, "commands", {}).items():
        yield from _commands(sub, (*path, name))


def _help_units(command) -> set[str]:
    texts = [command.help or ""] + [getattr(p, "help", None) or "" for p in command.params]
    return {unit for text in texts for unit in UNIT.findall(text)}


COMMANDS = list(_commands(typer.main.get_command(app)))


def test_the_commands_document_units_in_brackets():
    # The check below is not vacuous: openloop, slew and campaign state units.
    with_units = {" ".join(path) for path, command in COMMANDS if _help_units(command)}
    assert {"openloop", "slew", "campaign"} <= with_units


@pytest.mark.parametrize(
    ("path", "command"), COMMANDS, ids=[" ".join(path) or "flexsat" for path, _ in COMMANDS]
)
def test_help_shows_every_bracketed_unit(path, command):
    # Rich markup would read "[s]" as a style tag and drop it ("the duration .").
    result = CliRunner().invoke(app, [*path, "--help"], env={"COLUMNS": "200"})
    assert result.exit_code == 0, result.output
    for unit in _help_units(command):
        assert unit in result.output, f"{' '.join(path)} --help lost {unit}"


@pytest.mark.parametrize(
    ("args", "fragment"),
    [
        (("openloop", "--dt", "0"), "--dt: dt_s: Input should be greater than 0"),
        (("openloop", "--dt", "-0.001"), "--dt: dt_s: Input should be greater than 0"),
        (("openloop", "--dt", "nan"), "--dt: dt_s: Input should be a finite number"),
        (("openloop", "--dt", "0.5"), "--dt: dt_s: Input should be less than or equal to 0.1"),
        (("openloop", "--duration", "0.001"), "duration_s must be at least record_dt_s"),
        (("slew", "--duration", "0"), "--duration: duration_s: Input should be greater than 0"),
        (("slew", "--duration", "inf"), "--duration: duration_s: Input should be a finite"),
    ],
)
def test_bad_overrides_exit_2_with_one_message(args, fragment):
    result = run(*args)
    assert result.returncode == 2
    assert fragment in result.stderr
    assert "Traceback" not in result.stderr
    assert len(result.stderr.strip().splitlines()) == 1
