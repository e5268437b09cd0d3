"""Run the real ``flexsat`` entry point in this process, and write configs as TOML.

In-process runs cost milliseconds instead of a second of interpreter start-up, so
hundreds of bad inputs fit in a test; the entry point is the one the installed
command calls (:func:`flexsat.cli.main.main`).
"""

from __future__ import annotations

import math
import signal
import sys
from dataclasses import dataclass

from flexsat.cli.main import main


@dataclass(frozen=True)
class Outcome:
    code: int
    stdout: str
    stderr: str


class Hang(Exception):
    """A command ran past its time limit."""


def flexsat(argv: list[str], capsys, timeout_s: int = 60) -> Outcome:
    """Run ``flexsat *argv``; any exception but SystemExit escapes (a traceback)."""
    saved = sys.argv
    sys.argv = ["flexsat", *argv]

    def hang(signum, frame):
        raise Hang(f"flexsat {' '.join(argv)[:200]} ran more than {timeout_s} s")

    previous = signal.signal(signal.SIGALRM, hang)
    signal.alarm(timeout_s)
    try:
        main()
        code = 0
    except SystemExit as exc:
        code = exc.code if isinstance(exc.code, int) else (0 if exc.code is None else 1)
    finally:
        signal.alarm(0)
        signal.signal(signal.SIGALRM, previous)
        sys.argv = saved
    out, err = capsys.readouterr()
    return Outcome(code, out, err)


def to_toml(data: dict) -> str:
    """TOML text of a plain dict (top-level keys, inline tables below)."""
    return "".join(f"{_key(key)} = {_value(value)}\n" for key, value in data.items())


def _key(key) -> str:
    text = str(key)
    if text and all(c.isalnum() or c in "_-" for c in text):
        return text
    return _string(text)


def _string(text: str) -> str:
    escaped = text.replace("\\", "\\\\").replace('"', '\\"')
    escaped = "".join(c if c.isprintable() else f"\\u{ord(c):04x}" for c in escaped)
    return f'"{escaped}"'


def _value(value) -> str:
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, int):
        return str(value)
    if isinstance(value, float):
        if math.isnan(value):
            return "nan"
        if math.isinf(value):
            return "inf" if value > 0 else "-inf"
        return repr(value)
    if isinstance(value, str):
        return _string(value)
    if isinstance(value, dict):
        return "{" + ", ".join(f"{_key(k)} = {_value(v)}" for k, v in value.items()) + "}"
    if isinstance(value, list | tuple):
        return "[" + ", ".join(_value(v) for v in value) + "]"
    raise TypeError(f"no TOML form for {value!r}")


def modal_table() -> dict:
    """A small valid table of the modal data format: a 6.75 kg panel, two modes, a tip.

    Its rigid mass matrix about the interface is positive definite and the two modes'
    effective masses stay below it (docs/modal_format.md, "Checks at load").
    """
    return {
        "format_version": 1, "mass_kg": 6.75, "center_of_mass_m": [0.0, 0.75, 0.0],
        "inertia_interface_kg_m2": [[5.0, 0.0, 0.0], [0.0, 1.3, 0.0], [0.0, 0.0, 6.0]],
        "frequencies_hz": [0.8, 2.5], "damping_ratios": [0.005, 0.005],
        "participation": [[0.0, 0.0, 1.5, 1.4, 0.0, 0.0], [0.0, 0.0, 0.5, 0.1, 0.0, 0.0]],
        "output_points": [{"name": "tip", "position_m": [0.0, 1.5, 0.0],
                           "mode_shapes": [[0.0, 0.0, 0.5], [0.0, 0.0, 0.3]]}],
    }  # fmt: skip


def npz_bytes(arrays: dict) -> bytes:
    """An NPZ archive of ``arrays`` (name -> array), as bytes."""
    import io

    import numpy as np

    buffer = io.BytesIO()
    np.savez(buffer, **arrays)
    return buffer.getvalue()
