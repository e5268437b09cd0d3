"""Campaigns at scale, with real processes: a Dask cluster losing a worker, and seeded
kill-and-resume of the parent and of the workers; both against a serial run."""

from __future__ import annotations

import json
import os
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pandas as pd
import psutil
import pytest

from flexsat.campaigns import run_campaign

from .test_campaigns import TIMING, _short, _table
from .test_reliability import pool_workers

DASK = [str(Path(sys.executable).with_name("dask"))]
FLEXSAT = [sys.executable, "-m", "flexsat"]
DURATION = "10"  # s of slew per case: long enough to kill a worker mid-case


def _env() -> dict:
    """Subprocesses import this checkout's flexsat, whatever the installed one."""
    src = str(Path(__file__).resolve().parents[2] / "src")
    return {**os.environ, "PYTHONPATH": os.pathsep.join([src, os.environ.get("PYTHONPATH", "")])}


def _wait_for(predicate, timeout: float = 300.0) -> None:
    deadline = time.monotonic() + timeout
    while not predicate():
        if time.monotonic() > deadline:
            raise AssertionError("timed out")
        time.sleep(0.05)


def _stored(store: Path) -> int:
    return len(list((store / "cases").glob("*.json")))


@pytest.fixture(scope="module")
def serial(tmp_path_factory):
    """The reference: the 12 sensitivity cases (10 s) in this process."""
    store = tmp_path_factory.mktemp("serial")
    run_campaign(_short("sensitivity", float(DURATION)), _cli_satellite(), store, workers=1,
                 progress=False)  # fmt: skip
    return _table(store)


def _cli_satellite():
    from flexsat.config import nominal

    return nominal()


def _kill_tree(process: subprocess.Popen) -> None:
    """SIGKILL a process we started and its children."""
    try:
        parent = psutil.Process(process.pid)
        family = [*parent.children(recursive=True), parent]
    except psutil.NoSuchProcess:
        return
    for member in family:
        try:
            member.kill()
        except psutil.NoSuchProcess:
            pass
    process.wait(timeout=30)


def test_a_real_dask_cluster_loses_a_worker_and_the_campaign_completes(tmp_path, serial):
    # A scheduler and two workers as separate processes on loopback; one worker is
    # SIGKILLed (with its nanny) once the first case is stored. The scheduler
    # reruns its tasks on the other: every case stored once, rows identical to the
    # serial run's bit for bit.
    env = _env()
    scheduler_file = tmp_path / "scheduler.json"
    started = [subprocess.Popen(
        [*DASK, "scheduler", "--host", "127.0.0.1", "--port", "0", "--no-dashboard",
         "--scheduler-file", str(scheduler_file)], env=env,
        stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)]  # fmt: skip
    try:
        _wait_for(lambda: scheduler_file.exists() and scheduler_file.stat().st_size > 0, 120)
        address = json.loads(scheduler_file.read_text())["address"]
        for name in ("w1", "w2"):
            started.append(subprocess.Popen(
                [*DASK, "worker", "--scheduler-file", str(scheduler_file), "--nthreads", "1",
                 "--nworkers", "1", "--name", name, "--no-dashboard", "--host", "127.0.0.1"],
                env=env, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL))  # fmt: skip
        store = tmp_path / "store"
        campaign = subprocess.Popen(
            [*FLEXSAT, "campaign", "sensitivity", "--duration", DURATION, "--scheduler",
             address, "--out", str(store), "--json"],
            env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)  # fmt: skip
        _wait_for(lambda: (store / "cases").exists() and _stored(store) >= 1)
        _kill_tree(started[1])  # worker w1, mid-run
        out, err = campaign.communicate(timeout=600)
        assert campaign.returncode == 0, err
        summary = json.loads(out)
        assert summary["cases"] == summary["computed_this_run"] == 12
        assert summary["failed"] == 0
        table = _table(store)
        assert table["case_id"].is_unique and len(table) == 12
        pd.testing.assert_frame_equal(table, serial)
    finally:
        for process in reversed(started):
            _kill_tree(process)


def test_seeded_kills_of_parent_and_workers_lose_and_recompute_nothing(tmp_path, serial):
    # Three kills at seeded moments (0.1-1 s after a new case is stored): the
    # parent, then a worker (the pool replaces it), then the parent again; each
    # restart resumes. A stored case is never rewritten (its file's mtime stays),
    # and the final rows equal the serial run's bit for bit.
    rng = np.random.default_rng(18)
    store, env = tmp_path / "store", _env()
    command = [*FLEXSAT, "campaign", "sensitivity", "--duration", DURATION, "--workers", "2",
               "--out", str(store), "--json"]  # fmt: skip
    seen: dict[str, int] = {}
    for kill in ("parent", "worker", "parent"):
        before = _stored(store) if store.exists() else 0
        resume = ["--resume"] if store.exists() else []
        process = subprocess.Popen([*command, *resume], env=env, stdout=subprocess.DEVNULL,
                                   stderr=subprocess.DEVNULL)  # fmt: skip
        _wait_for(lambda b=before: (store / "cases").exists() and _stored(store) > b)
        time.sleep(rng.uniform(0.1, 1.0))
        workers = pool_workers(process.pid)
        if kill == "parent" or not workers:  # (no worker left: the run is ending)
            _kill_tree(process)
        else:
            workers[int(rng.integers(len(workers)))].kill()
            process.wait(timeout=600)
        for path in (store / "cases").glob("*.json"):
            mtime = path.stat().st_mtime_ns
            assert seen.setdefault(path.name, mtime) == mtime, f"{path.name} was recomputed"
        if _stored(store) == 12:
            break
    result = subprocess.run([*command, "--resume"], env=env, capture_output=True, text=True,
                            timeout=600)  # fmt: skip
    assert result.returncode == 0, result.stderr
    ran = json.loads(result.stdout)["computed_this_run"]
    assert ran == 12 - len(seen)
    for path in (store / "cases").glob("*.json"):
        if path.name in seen:
            assert path.stat().st_mtime_ns == seen[path.name]
    pd.testing.assert_frame_equal(_table(store), serial)


assert TIMING  # the columns _table drops: wall times, which differ between runs


def test_a_local_dask_cluster_runs_without_the_dashboard_feeds():
    # The settings reach the worker processes of the LocalCluster (their profiler
    # sampling every thread every 10 ms would be most of an idle cluster's CPU).
    import dask

    from flexsat.campaigns.backends import QUIET_DASK, _dask_client

    def settings() -> dict:
        return {key: dask.config.get(key) for key in QUIET_DASK}

    with _dask_client(None, 1) as client:
        (worker,) = client.run(settings).values()
        assert worker == QUIET_DASK
        assert settings() == QUIET_DASK  # the client's (and scheduler's) process too
    assert dask.config.get("distributed.worker.profile.enabled") is True  # restored
