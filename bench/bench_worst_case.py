"""Benchmark: does a worst-case search find worse than Monte Carlo on the thesis set?

On the reduced model (root translations locked, 20 ms), flies the 24 critical corners
(+ nominal, montecarlo-critical), ``--random`` random Monte Carlo draws
(montecarlo-random) and a seeded differential-evolution search over the same box
(target frequencies 0.8-1.2, hub and panel inertia 0.8-1.2, SADM 0-90 deg, damping
ratio 0-0.01), maximizing the final pointing error; prints the worst of each and
whether the search beat both. The worst case found is stored for replay
(``worst_case.json`` in the printed store).

``--duration S`` (default 120), ``--random N`` (default 100), ``--maxiter``,
``--popsize``, ``--workers``, ``--out DIR`` (default a temporary folder).
"""

from __future__ import annotations

import argparse
import tempfile
from pathlib import Path

import harness
from flexsat.campaigns import CampaignStore, load_campaign, run_campaign
from flexsat.campaigns.definition import CampaignDefinition, Reduced
from flexsat.config import nominal, validate_config

METRIC = "final_pointing_error_deg"
BOX = [
    {"path": "appendages[*].target_frequencies_hz.flapping", "op": "scale", "bounds": [0.8, 1.2]},
    {"path": "appendages[*].target_frequencies_hz.in_plane", "op": "scale", "bounds": [0.8, 1.2]},
    {"path": "appendages[*].target_frequencies_hz.torsion", "op": "scale", "bounds": [0.8, 1.2]},
    {"path": "hub.inertia", "bounds": [0.8, 1.2]},
    {"path": "appendages[*].inertia", "bounds": [0.8, 1.2]},
    {"path": "appendages[*].sadm_angle_deg", "bounds": [0.0, 90.0]},
    {"path": "appendages[*].damping_ratio", "bounds": [0.0, 0.01]},
]


def _definition(data: dict, duration_s: float) -> CampaignDefinition:
    data = {**data, "base": {**data.get("base", {}), "duration_s": duration_s},
            "reduced": Reduced().model_dump(mode="json")}  # fmt: skip
    return validate_config(data, model=CampaignDefinition)


def _worst(store: Path) -> tuple[str, float]:
    rows = [r for r in CampaignStore(store).rows() if r["status"] == "ok"]
    worst = max(rows, key=lambda r: r["metrics"][METRIC])
    return worst["case_id"], worst["metrics"][METRIC]


@harness.register(
    "the worst-case search against the 24 corners and random draws on the reduced model: the "
    "worst case of each, stored for replay",
    full=False,
)
def main(argv: list[str] | None = None) -> dict:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--duration", type=float, default=120.0)
    parser.add_argument("--random", type=int, default=100)
    parser.add_argument("--maxiter", type=int, default=5)
    parser.add_argument("--popsize", type=int, default=2)
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--out", type=Path, default=None)
    args = parser.parse_args(argv)
    console = harness.console(150)
    with tempfile.TemporaryDirectory(prefix="flexsat-bench-worst-") as tmp:
        out = args.out or Path(tmp)
        stores, found = {}, {}
        for name in ("montecarlo-critical", "montecarlo-random"):
            definition = _definition(load_campaign(name).model_dump(mode="json"), args.duration)
            stores[name] = out / name
            run_campaign(definition, nominal(), stores[name], workers=args.workers,
                         n_random=args.random, resume=True, progress=False)  # fmt: skip
            found[name] = _worst(stores[name])
        search = _definition({"name": "worst-case", "worst_case": {
            "metric": METRIC, "seed": 2026, "maxiter": args.maxiter, "popsize": args.popsize,
            "parameters": BOX}}, args.duration)  # fmt: skip
        stores["search"] = out / "worst-case"
        summary = run_campaign(search, nominal(), stores["search"], workers=args.workers,
                               resume=True, progress=False)  # fmt: skip
        found["search"] = (summary["case_id"], summary["value"])
        table = harness.table(
            f"Worst {METRIC} (reduced model, {args.duration:g} s slews)",
            ("set", "cases", "worst case", METRIC),
            right=(),
        )
        for key, (case_id, value) in found.items():
            table.add_row(key, str(len(CampaignStore(stores[key]).rows())), case_id,
                          f"{value:.6g}")  # fmt: skip
        console.print(table)
        beaten = found["search"][1] > max(found["montecarlo-critical"][1],
                                          found["montecarlo-random"][1])  # fmt: skip
        console.print(
            f"the search {'found' if beaten else 'did not find'} a worse case than "
            f"the corners and the random draws; parameters: {summary['parameters']}"
        )
        return {"found": found, "search_beats_monte_carlo": beaten,
                "parameters": summary["parameters"]}  # fmt: skip


if __name__ == "__main__":
    main()
