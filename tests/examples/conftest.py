"""Run a gallery example as a script, on a short horizon, and hand back its variables."""

from __future__ import annotations

import runpy
from pathlib import Path

import pytest

EXAMPLES = Path(__file__).resolve().parents[2] / "examples"


@pytest.fixture
def run_example(monkeypatch, tmp_path):
    """``run_example(name, duration_s)``: the example's globals after it ran.

    The example reads its run length from ``FLEXSAT_EXAMPLE_DURATION_S`` (the
    documentation build runs the full length); its figures are drawn, and
    dropped with its variables. Temporary folders go to ``tmp_path``.
    """
    monkeypatch.setenv("TMPDIR", str(tmp_path))
    monkeypatch.setattr("tempfile.tempdir", None)

    def run(name: str, duration_s: float | None = None) -> dict:
        if duration_s is not None:
            monkeypatch.setenv("FLEXSAT_EXAMPLE_DURATION_S", str(duration_s))
        path = EXAMPLES / f"{name}.py"
        return runpy.run_path(str(path), run_name="__main__")

    return run
