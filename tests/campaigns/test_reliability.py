"""Campaign reliability with real processes, signals and files: resume rules, Ctrl-C,
SIGTERM, dead workers and parents, damaged stores, the lock, paths."""

from __future__ import annotations

import fcntl
import json
import os
import resource
import signal
import socket
import subprocess
import sys
import threading
import time

import psutil
import pytest

from flexsat.campaigns import CampaignStore, load_campaign, replay_case, run_campaign, summarize
from flexsat.campaigns.definition import CampaignDefinition, campaign_fingerprint, resolve_cases
from flexsat.config import nominal, validate_config
from flexsat.errors import ConfigError
from tests.conftest import nominal_dict

FLEXSAT = [sys.executable, "-m", "flexsat"]


def _short(name: str, duration: float) -> CampaignDefinition:
    data = load_campaign(name).model_dump(mode="json")
    data["base"] = {**data["base"], "duration_s": duration}
    return validate_config(data, model=CampaignDefinition)


def _heavy():
    data = nominal_dict()
    data["hub"]["mass_kg"] = 300.0
    return validate_config(data)


@pytest.fixture(scope="module")
def small_store(tmp_path_factory):
    """A finished 3-case random campaign (1 s slews), the store the resume tests start from."""
    store = tmp_path_factory.mktemp("small")
    definition = _short("montecarlo-random", 1.0)
    run_campaign(definition, nominal(), store, workers=1, n_random=2, progress=False)
    return store, definition


def test_resume_refuses_another_satellite_naming_it(small_store):
    store, definition = small_store
    with pytest.raises(ConfigError, match="the satellite config"):
        run_campaign(definition, _heavy(), store, resume=True, n_random=2, progress=False)


def test_resume_refuses_another_case_count_naming_both(small_store):
    store, definition = small_store
    with pytest.raises(ConfigError, match=r"the number of cases \(stored 3, given 5\)"):
        run_campaign(definition, nominal(), store, resume=True, n_random=4, progress=False)


def test_the_study_resumes_only_an_identical_campaign(tmp_path):
    """The study resumes its campaigns (``fly_campaign(..., resume=True)``): another
    satellite in the same folder is refused, naming it; the same one runs nothing."""
    from flexsat.study.outputs import fly_campaign

    definition = _short("montecarlo-random", 1.0)
    options = {"workers": 1, "resume": True, "n_random": 1, "progress": False}
    assert fly_campaign(definition, nominal(), tmp_path, **options)["computed_this_run"] == 2
    with pytest.raises(ConfigError, match="the satellite config"):
        fly_campaign(definition, _heavy(), tmp_path, **options)
    assert fly_campaign(definition, nominal(), tmp_path, **options)["computed_this_run"] == 0


def test_damaged_cases_are_named_then_recomputed_alone(tmp_path, small_store):
    source, definition = small_store
    store = tmp_path / "store"
    subprocess.run(["cp", "-r", str(source), str(store)], check=True)
    cases = store / "cases"
    truncated, emptied = cases / "random-00000.json", cases / "random-00001.json"
    truncated.write_text(truncated.read_text()[:40])
    emptied.write_text("{}")
    (store / "histories" / "tmpabc.partial").write_text("left by a kill")
    with pytest.raises(ConfigError, match=r"damaged case file .*random-00000\.json"):
        summarize(store)
    untouched = (cases / "nominal.json").stat().st_mtime_ns
    run = run_campaign(
        definition, nominal(), store, workers=1, resume=True, n_random=2, progress=False
    )
    assert run["ran"] == 2  # only the two damaged cases
    assert (cases / "nominal.json").stat().st_mtime_ns == untouched
    assert summarize(store)["cases"] == 3
    assert not list(store.rglob("*.partial"))


def test_a_live_store_is_locked_and_the_holder_named(tmp_path):
    definition = _short("montecarlo-random", 1.0)
    cases = resolve_cases(definition, nominal(), n_random=1)
    store = CampaignStore(tmp_path)
    with store.opened(campaign_fingerprint(definition, nominal(), cases), "x", False):
        with pytest.raises(ConfigError, match=f"in use by process {os.getpid()} on "):
            run_campaign(definition, nominal(), tmp_path, resume=True, n_random=1, progress=False)


def test_a_lock_named_for_a_process_that_is_gone_is_waited_for(tmp_path):
    """A killed run's ``flock`` is freed a little after the run and its workers exit
    (measured up to 0.05 s): a run started at once waits for it (up to 2 s) when the
    process the lock names is gone. Here the lock is released 0.3 s in."""
    definition = _short("montecarlo-random", 1.0)
    cases = resolve_cases(definition, nominal(), n_random=1)
    fingerprint = campaign_fingerprint(definition, nominal(), cases)
    gone = subprocess.Popen(["true"])
    gone.wait()  # reaped: its number names no process
    held = open(tmp_path / "campaign.lock", "a+")  # closed by the timer
    fcntl.flock(held.fileno(), fcntl.LOCK_EX)
    held.write(f"process {gone.pid} on {socket.gethostname()} (since 2026-01-01 00:00:00 UTC)")
    held.flush()
    threading.Timer(0.3, held.close).start()
    started = time.monotonic()
    with CampaignStore(tmp_path).opened(fingerprint, "x", False):
        waited = time.monotonic() - started
    assert 0.25 < waited < 2.0  # it waited for the release and returned on it


def test_store_files_share_one_mode(small_store):
    store, _ = small_store
    umask = os.umask(0)
    os.umask(umask)
    expected = 0o666 & ~umask
    for path in [*store.glob("cases/*.json"), *store.glob("histories/*.nc"),
                 store / "campaign.json", store / "results.parquet"]:  # fmt: skip
        assert path.stat().st_mode & 0o777 == expected, path


@pytest.mark.parametrize("name", ["../../outside", "/tmp/absolute", ".hidden", "a/b"])
def test_campaign_names_cannot_leave_the_output_folder(tmp_path, name):
    path = tmp_path / "c.toml"
    path.write_text(f'name = "{name}"\n')
    with pytest.raises(ConfigError, match="name: contains characters that are not allowed"):
        load_campaign(path)


@pytest.mark.parametrize("case_id", ["../../outside", "/etc/passwd", "..", "a/b"])
def test_replay_validates_the_case_id(small_store, case_id):
    store, _ = small_store
    with pytest.raises(ConfigError, match="is not a case id"):
        replay_case(store, case_id)


def test_replay_needs_a_campaign_store(tmp_path):
    with pytest.raises(ConfigError, match="not a campaign store"):
        replay_case(tmp_path, "nominal")


# -- signals and processes ---------------------------------------------------------


def _start(store, *extra: str, duration: str = "5") -> subprocess.Popen:
    """The 12 sensitivity cases on 2 workers (``extra`` options may change the campaign)."""
    command = [*FLEXSAT, "campaign", *(extra or ("sensitivity",)), "--duration", duration,
               "--workers", "2", "--out", str(store), "--json"]  # fmt: skip
    return subprocess.Popen(command, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)


def _wait_for(predicate, timeout: float = 240.0) -> None:
    deadline = time.monotonic() + timeout
    while not predicate():
        if time.monotonic() > deadline:
            raise AssertionError("timed out waiting for the campaign")
        time.sleep(0.05)


def _workers_of(process: subprocess.Popen) -> list[psutil.Process]:
    _wait_for(lambda: len(pool_workers(process.pid)) >= 2)
    return pool_workers(process.pid)


def pool_workers(pid: int) -> list[psutil.Process]:
    """The live pool workers of a campaign process: its children but multiprocessing's
    resource tracker (a spawned worker's command line names ``spawn_main``, a forked
    one's is its parent's); one gone, or a zombie, while listed is left out."""
    try:
        children = psutil.Process(pid).children()
    except psutil.NoSuchProcess:
        return []
    return [c for c in children if _cmdline(c) and "resource_tracker" not in " ".join(_cmdline(c))]


def _cmdline(child: psutil.Process) -> list[str]:
    try:
        return child.cmdline()
    except psutil.Error:
        return []


def _stored(store) -> int:
    return len(list((store / "cases").glob("*.json")))


def _gone_within(workers: list[psutil.Process], seconds: float) -> bool:
    """Every worker exited (an orphan may stay a zombie until its new parent reaps it)."""
    deadline = time.monotonic() + seconds
    while any(_running(w) for w in workers):
        if time.monotonic() > deadline:
            return False
        time.sleep(0.02)
    return True


def _running(process: psutil.Process) -> bool:
    try:
        return process.status() != psutil.STATUS_ZOMBIE
    except psutil.NoSuchProcess:
        return False


@pytest.mark.parametrize(("signum", "code"), [(signal.SIGINT, 130), (signal.SIGTERM, 143)])
def test_interrupt_cancels_pending_cases_and_stops_the_workers(tmp_path, signum, code):
    store = tmp_path / "store"
    process = _start(store)
    workers = _workers_of(process)
    _wait_for(lambda: _stored(store) >= 1)
    process.send_signal(signum)
    _, stderr = process.communicate(timeout=30)
    assert _gone_within(workers, 2.0)  # the brief: workers exit within 2 s
    assert process.returncode == code
    stored = _stored(store)
    assert stored < 12  # pending cases were cancelled, not run to the end
    assert f"{stored} of 12 cases are stored" in stderr
    assert "--resume" in stderr
    assert "Traceback" not in stderr


def test_ctrl_c_while_drawing_the_figures_says_the_cases_are_stored(tmp_path):
    # The figures' folder is made just before the first figure is drawn (each takes
    # tenths of a second): SIGINT then lands while they are drawn. The command says
    # what is stored, and --resume runs no case and draws the figures.
    store = tmp_path / "store"
    process = _start(store)
    _wait_for(lambda: (store / "figures").exists(), timeout=300)
    process.send_signal(signal.SIGINT)
    _, stderr = process.communicate(timeout=30)
    assert process.returncode == 130
    assert "interrupted (SIGINT) while drawing its figures: its 12 cases are stored" in stderr
    assert "--resume" in stderr and "Traceback" not in stderr
    resumed = subprocess.run([*process.args, "--resume"], capture_output=True, text=True,
                             check=True)  # fmt: skip
    summary = json.loads(resumed.stdout)
    assert summary["computed_this_run"] == 0 and len(summary["figures"]) > 0


def test_killing_the_parent_leaves_no_worker_behind(tmp_path):
    store = tmp_path / "store"
    process = _start(store)
    workers = _workers_of(process)
    if sys.platform.startswith("linux"):  # the command runs one thread: its workers fork
        assert all(_cmdline(w) == psutil.Process(process.pid).cmdline() for w in workers)
    _wait_for(lambda: _stored(store) >= 1)  # the workers are past their start-up
    process.send_signal(signal.SIGKILL)  # as the out-of-memory killer does
    process.wait()
    assert _gone_within(workers, 2.0)
    # A forked worker held a copy of the store's lock; gone with it, the store is free
    # (the kernel frees it a little after the exits: up to 0.05 s measured, 2 s given).
    with open(store / "campaign.lock") as lock:
        _wait_for(lambda: _locked_now(lock), timeout=2.0)


def _locked_now(lock) -> bool:
    try:
        fcntl.flock(lock.fileno(), fcntl.LOCK_EX | fcntl.LOCK_NB)
    except BlockingIOError:
        return False
    return True


def test_a_killed_worker_is_replaced_and_the_campaign_completes(tmp_path):
    store = tmp_path / "store"
    process = _start(store, "montecarlo-random", "--cases", "4", duration="2")
    workers = _workers_of(process)
    workers[0].kill()
    stdout, stderr = process.communicate(timeout=300)
    assert process.returncode == 0, stderr
    summary = json.loads(stdout)
    assert (summary["cases"], summary["failed"]) == (5, 0)


def test_a_write_error_stops_the_run_at_once_with_one_message(tmp_path):
    """Files above 8 kB cannot be written (as on a full disk): the first history (a
    10 s slew's, about 20 kB) fails."""

    def small_files() -> None:
        resource.setrlimit(resource.RLIMIT_FSIZE, (8192, 8192))

    store = tmp_path / "store"
    command = [*FLEXSAT, "campaign", "sensitivity", "--duration", "10", "--workers", "1",
               "--out", str(store), "--json"]  # fmt: skip
    result = subprocess.run(command, capture_output=True, text=True, timeout=300,
                            preexec_fn=small_files)  # fmt: skip
    assert result.returncode == 2
    assert "cannot write to the campaign store" in result.stderr
    assert "0 of 12 cases are stored" in result.stderr and "--resume" in result.stderr
    assert "Traceback" not in result.stderr


def test_a_signal_while_the_cases_are_prepared_stops_the_campaign(tmp_path, monkeypatch):
    # A process that starts with SIGINT ignored (a background job, a test runner's
    # worker) and is signalled while its cases are prepared, which on a first run is
    # the minute the kernels compile: the signal stops it, nothing runs, no store.
    from flexsat.campaigns import runner

    class Signalled(runner.CaseStream):
        def __init__(self, *args, **kwargs):
            os.kill(os.getpid(), signal.SIGINT)  # delivered before the next bytecode
            super().__init__(*args, **kwargs)

    monkeypatch.setattr(runner, "CaseStream", Signalled)
    previous = signal.signal(signal.SIGINT, signal.SIG_IGN)
    try:
        with pytest.raises(runner.CampaignInterrupted, match="while preparing its cases") as caught:
            run_campaign(_short("sensitivity", 0.2), nominal(), tmp_path / "s", workers=1,
                         progress=False)  # fmt: skip
        assert signal.getsignal(signal.SIGINT) == signal.SIG_IGN  # given back as it was
    finally:
        signal.signal(signal.SIGINT, previous)
    assert caught.value.exit_code == 130
    assert not (tmp_path / "s" / "cases").exists()
