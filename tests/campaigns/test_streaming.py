"""Streamed case preparation: a 1e6-case campaign starts at once, resumes by its inputs."""

from __future__ import annotations

import itertools
import signal
import subprocess
import sys
import time

import pytest

from flexsat.campaigns import CampaignStore, load_campaign, resolve_cases, run_campaign
from flexsat.campaigns.definition import HEAD_CASES, CaseStream, campaign_fingerprint
from flexsat.config import nominal
from flexsat.errors import ConfigError

from .test_campaigns import _short
from .test_scale_acceptance import _env


def test_a_million_case_stream_resolves_only_what_is_consumed():
    # Resolving all 1e6 cases would take about an hour: this returns at once because
    # only the head (HEAD_CASES) is prepared up front and the rest as consumed.
    stream = CaseStream(load_campaign("montecarlo-random"), nominal(), n_random=1_000_000)
    assert len(stream) == 1_000_001 and len(stream.head) == HEAD_CASES
    first = list(itertools.islice(stream, HEAD_CASES + 3))
    assert first[-1].case_id == "random-00101"  # after the nominal
    assert campaign_fingerprint(stream.definition, nominal(), stream)["cases"] == 1_000_001


def test_the_stream_gives_the_cases_the_list_gives():
    definition = load_campaign("montecarlo-random")
    listed = resolve_cases(definition, nominal(), n_random=150)
    streamed = list(CaseStream(definition, nominal(), n_random=150))
    assert [c.digest for c in listed] == [c.digest for c in streamed]
    assert campaign_fingerprint(definition, nominal(), listed) == campaign_fingerprint(
        definition, nominal(), CaseStream(definition, nominal(), n_random=150)
    )


def test_a_million_case_campaign_starts_at_once_and_stops_cleanly(tmp_path):
    # The CLI with --cases 1000000: cases are stored within the test's patience (no
    # up-front preparation), Ctrl-C stops it with the stored count out of 1000001.
    store = tmp_path / "big"
    command = [sys.executable, "-m", "flexsat", "campaign", "montecarlo-random", "--cases",
               "1000000", "--duration", "0.1", "--workers", "1", "--out", str(store),
               "--json"]  # fmt: skip
    process = subprocess.Popen(command, env=_env(), stdout=subprocess.PIPE,
                               stderr=subprocess.PIPE, text=True)  # fmt: skip
    deadline = time.monotonic() + 900  # a first run compiles for about a minute
    while not (started := len(list(store.glob("cases/*.json"))) >= 3) and (
        time.monotonic() < deadline and process.poll() is None
    ):
        time.sleep(0.05)
    process.send_signal(signal.SIGINT)  # stops it in any case: no process left behind
    _, err = process.communicate(timeout=120)
    assert started, f"no 3 cases stored in 900 s: {err[-2000:]}"
    assert process.returncode == 130
    assert "of 1000001 cases are stored" in err and "--resume" in err


def test_a_stored_case_made_from_other_inputs_is_refused_when_reached(tmp_path):
    definition = _short("montecarlo-random", 0.2)
    run_campaign(definition, nominal(), tmp_path, workers=1, n_random=2, progress=False)
    path = tmp_path / "cases" / "random-00001.json"
    path.write_text(path.read_text().replace('"inputs_digest": "', '"inputs_digest": "x'))
    with pytest.raises(ConfigError, match="random-00001' is stored with other inputs"):
        run_campaign(definition, nominal(), tmp_path, workers=1, n_random=2, resume=True,
                     progress=False)  # fmt: skip
    assert CampaignStore(tmp_path).finished() == 3
