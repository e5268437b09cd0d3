"""The quick study of the nominal case, run once for every study test."""

from __future__ import annotations

import fcntl
import json

import pytest

from flexsat.config import nominal
from flexsat.study import run_study


@pytest.fixture(scope="session")
def quick_study(tmp_path_factory, worker_id):
    """``run_study(nominal(), quick=True)`` into a temporary folder: (folder, manifest).

    One run for the whole suite: under pytest-xdist each worker process is a session
    of its own, and the study's test files land on both, so the workers share the
    run through their common temporary folder. The first to ask runs it under a file
    lock and leaves its manifest beside it; the others wait for the lock and read it
    (about 35 s of a worker saved). Every worker gets the manifest as read back from
    that file, so each sees the same objects.
    """
    root = tmp_path_factory.getbasetemp()
    if worker_id != "master":  # each worker's folder sits in the run's common one
        root = root.parent
    out, saved = root / "quick_study", root / "quick_study_manifest.json"
    with open(root / "quick_study.lock", "w") as lock:
        fcntl.flock(lock, fcntl.LOCK_EX)  # released when the file closes
        if not saved.exists():
            manifest = run_study(nominal(), out, quick=True, progress=False)
            saved.write_text(json.dumps(manifest))
    return out, json.loads(saved.read_text())
