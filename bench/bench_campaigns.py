"""Benchmark: the three thesis campaigns (68 slews of 120 s) on the local pool and Dask.

Each campaign runs into a fresh temporary store with 1 and 2 workers on each backend:
the local process pool (1 worker runs the cases in this process) and a Dask
LocalCluster (single-threaded worker processes). Wall times are those of
``run_campaign``: they include starting the pool or the cluster and writing the
store. This process first runs one short slew, as any earlier work would have, so
that its compiled code is loaded; the workers of both backends are spawned and load
it themselves from the on-disk cache (within the timed wall time).

Prints wall time and cases per second per campaign and backend, the 1 -> 2 worker
scaling (speed-up and its efficiency, speed-up / 2) of each backend over the 68
cases, and each campaign's summary (pass rates, worst case). ``--quick``: the local
pool only. Run with ``make bench`` or ``python bench/bench_campaigns.py``.
"""

from __future__ import annotations

import argparse
import tempfile
from pathlib import Path

import harness
from flexsat.campaigns import load_campaign, run_campaign, summarize
from flexsat.config import nominal

CAMPAIGNS = ("sensitivity", "montecarlo-critical", "deployment-shock")
CAMPAIGNS_MAX_S = 30.0  # the target: the three campaigns, local pool, 2 workers


def _warm_up() -> None:
    from flexsat import Plant
    from flexsat.simulate import SlewScenario, run_slew

    run_slew(Plant.from_config(nominal()), SlewScenario(duration_s=0.1), progress=False)


def _note(out: dict, _results: dict) -> str:
    local = out["scaling"]["local"]
    note = (f"{out['cases']} cases, {local['cases_per_s_2']:.2f} cases/s; "
            f"1 -> 2 workers efficiency {local['efficiency']:.0%}")  # fmt: skip
    if "dask" in out["scaling"]:
        note += f" (Dask {out['scaling']['dask']['efficiency']:.0%})"
    return note


@harness.register(
    "the three thesis campaigns on the local pool and Dask, 1 and 2 workers: wall time, "
    "cases/s, scaling efficiency",
    targets=[harness.Target(
        f"3 campaigns (68 runs), 2 workers, local pool <= {CAMPAIGNS_MAX_S:g} s", CAMPAIGNS_MAX_S,
        "s", lambda r: r["totals"]["local x2"], "{:.1f} s", note=_note)],
)  # fmt: skip
def main(argv: list[str] | None = None) -> dict:
    """Print the tables; return wall times, cases/s and the scaling of each backend."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="local pool only (no Dask)")
    args = parser.parse_args(argv)
    backends = [("local", 1), ("local", 2)]
    if not args.quick:
        backends += [("dask", 1), ("dask", 2)]
    console = harness.console()
    _warm_up()
    walls = {(b, w): {} for b, w in backends}
    cases, summaries = {}, {}
    for name in CAMPAIGNS:
        for backend, workers in backends:
            options = {"workers": workers} if backend == "local" else {"dask_local": workers}
            with tempfile.TemporaryDirectory(prefix="flexsat-bench-") as store:
                run = run_campaign(load_campaign(name), nominal(), Path(store), progress=False,
                                   **options)  # fmt: skip
                summaries[name] = summarize(store)
            walls[backend, workers][name] = run["wall_time_s"]
            cases[name] = run["cases"]
    n_cases = sum(cases.values())
    totals = {key: sum(per.values()) for key, per in walls.items()}

    timing = harness.table(
        "Thesis campaigns: wall time (s) and cases per second",
        ("campaign", "cases", *(f"{b} x{w}" for b, w in backends)),
    )
    for name in CAMPAIGNS:
        timing.add_row(name, str(cases[name]), *(
            f"{walls[key][name]:.1f} ({cases[name] / walls[key][name]:.2f}/s)" for key in walls
        ))  # fmt: skip
    timing.add_row("all three", str(n_cases),
                   *(f"{t:.1f} ({n_cases / t:.2f}/s)" for t in totals.values()))  # fmt: skip
    console.print(timing)

    scaling = {}
    table = harness.table(f"Worker scaling over the {n_cases} cases, 1 -> 2 workers",
                          ("backend", "1 worker (s)", "2 workers (s)", "cases/s x1",
                           "cases/s x2", "speed-up", "efficiency (speed-up / 2)"))  # fmt: skip
    for backend in dict.fromkeys(b for b, _ in backends):
        one, two = totals[backend, 1], totals[backend, 2]
        scaling[backend] = {
            "wall_1_s": one, "wall_2_s": two, "cases_per_s_1": n_cases / one,
            "cases_per_s_2": n_cases / two, "speedup": one / two, "efficiency": one / two / 2,
        }  # fmt: skip
        s = scaling[backend]
        table.add_row(backend, f"{one:.1f}", f"{two:.1f}", f"{s['cases_per_s_1']:.2f}",
                      f"{s['cases_per_s_2']:.2f}", f"{s['speedup']:.2f}x",
                      f"{s['efficiency']:.0%}")  # fmt: skip
    console.print(table)

    summary = harness.table("Campaign summaries (120 s slews, disturbances at maximum)",
                            ("campaign", "cases", "failed", "R1", "R2", "R3",
                             "worst error (deg)", "worst case"), right=())  # fmt: skip
    for name, s in summaries.items():
        worst = s["worst_cases"][0]["case_id"] if s["worst_cases"] else "-"
        summary.add_row(name, str(s["cases"]), str(s["failed"]), f"{s['r1_pass_rate']:.0%}",
                        f"{s['r2_pass_rate']:.0%}", f"{s['r3_pass_rate']:.0%}",
                        f"{s['worst_final_pointing_error_deg']:.3e}", worst)  # fmt: skip
    console.print(summary)
    return {
        "cases": n_cases,
        "walls": {f"{b} x{w}": per for (b, w), per in walls.items()},
        "totals": {f"{b} x{w}": t for (b, w), t in totals.items()},
        "scaling": scaling,
        "summaries": summaries,
    }


if __name__ == "__main__":
    main()
