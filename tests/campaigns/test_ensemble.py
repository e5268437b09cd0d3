"""The ensemble runner's accounting of each case's own time."""

from __future__ import annotations

import resource

from flexsat.campaigns.definition import resolve_cases
from flexsat.campaigns.ensemble import run_ensemble
from flexsat.config import nominal

from .test_campaigns import _short


def _cpu_s() -> float:
    usage = resource.getrusage(resource.RUSAGE_SELF)
    return usage.ru_utime + usage.ru_stime


def test_the_cases_cpu_times_add_up_to_at_most_the_processs():
    # Six cases flown one per batch: each batch waits behind the previous one's flight.
    # A case's CPU time is its preparation and post-processing (this thread's clock)
    # and its share of its own flight (the process's CPU during the flight, less this
    # thread's): disjoint parts, so their sum cannot exceed what the process spent.
    # Counting a flight's CPU from its submission instead counted the previous
    # flight's twice. Bound: the process's CPU over the run, plus 1 ms for the two
    # clocks' granularity (getrusage ticks in microseconds).
    cases = resolve_cases(_short("montecarlo-random", 1.0), nominal(), n_random=5)
    before = _cpu_s()
    rows = list(run_ensemble(cases, threads=1, batch=1))
    spent = _cpu_s() - before
    assert [r["status"] for r in rows] == ["ok"] * 6
    cpu = [r["case_cpu_time_s"] for r in rows]
    assert all(c > 0.0 for c in cpu)
    assert sum(cpu) <= spent + 1e-3
