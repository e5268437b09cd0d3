"""Benchmark: the three thesis campaigns (68 slews of 120 s) on the local pool and Dask.

Prints wall time and cases per second with 1 and 2 workers for each backend, and
each campaign's summary (pass rates, worst case). Run with ``make bench``.
"""

from __future__ import annotations

import sys
import tempfile
from pathlib import Path

from rich.console import Console
from rich.table import Table

from flexsat.campaigns import load_campaign, run_campaign, summarize
from flexsat.config import nominal

CAMPAIGNS = ("sensitivity", "montecarlo-critical", "deployment-shock")


def main() -> None:
    backends = [("local", 1, {}), ("local", 2, {}), ("dask", 1, {}), ("dask", 2, {})]
    if "--quick" in sys.argv:
        backends = backends[:2]
    console = Console()
    timing = Table(title="Thesis campaigns: wall time [s] and cases per second")
    timing.add_column("campaign")
    timing.add_column("cases", justify="right")
    for backend, workers, _ in backends:
        timing.add_column(f"{backend} x{workers}", justify="right")
    summaries = {}
    totals = {f"{b} x{w}": 0.0 for b, w, _ in backends}
    for name in CAMPAIGNS:
        cells = []
        for backend, workers, _ in backends:
            with tempfile.TemporaryDirectory() as store:
                options = {"workers": workers} if backend == "local" else {"dask_local": workers}
                run = run_campaign(load_campaign(name), nominal(), Path(store), progress=False,
                                   **options)  # fmt: skip
                summaries[name] = summarize(store)
            totals[f"{backend} x{workers}"] += run["wall_time_s"]
            cells.append(f"{run['wall_time_s']:.1f} ({run['cases'] / run['wall_time_s']:.2f}/s)")
        timing.add_row(name, str(run["cases"]), *cells)
    n_cases = sum(s["cases"] for s in summaries.values())
    timing.add_row("all three", str(n_cases), *(f"{v:.1f}" for v in totals.values()))
    console.print(timing)
    table = Table(title="Campaign summaries (120 s slews, disturbances at maximum)")
    columns = ("campaign", "cases", "failed", "R1", "R2", "R3", "worst error [deg]", "worst case")
    for column in columns:
        table.add_column(column)
    for name, s in summaries.items():
        worst = s["worst_cases"][0]["case_id"] if s["worst_cases"] else "-"
        table.add_row(name, str(s["cases"]), str(s["failed"]), f"{s['r1_pass_rate']:.0%}",
                      f"{s['r2_pass_rate']:.0%}", f"{s['r3_pass_rate']:.0%}",
                      f"{s['worst_final_pointing_error_deg']:.3e}", worst)  # fmt: skip
    console.print(table)


if __name__ == "__main__":
    main()
