"""The quick study of the nominal case, run once for every study test."""

from __future__ import annotations

import pytest

from flexsat.config import nominal
from flexsat.study import run_study


@pytest.fixture(scope="session")
def quick_study(tmp_path_factory):
    """``run_study(nominal(), quick=True)`` into a temporary folder: (folder, manifest)."""
    out = tmp_path_factory.mktemp("study")
    manifest = run_study(nominal(), out, quick=True, progress=False)
    return out, manifest
