"""Benchmark: the reduced model against the full one on the 69 thesis cases, full length.

Flies sensitivity, montecarlo-critical and deployment-shock (120 s slews) on the full
model (1 ms, controller every step) and on the reduced one (root translations locked,
20 ms step and control period), and prints, metric by metric, the verdicts changed
and the largest differences (:func:`flexsat.campaigns.reduction.reduction_table`),
for the slews from rest and for the deployment shock apart, with the wall times.

``--duration S`` shortens the slews; ``--workers N`` (default 2). Run with
``python bench/bench_reduction.py`` (or ``make bench``).
"""

from __future__ import annotations

import argparse
import tempfile

import harness
from flexsat.campaigns import load_campaign
from flexsat.campaigns.definition import CampaignDefinition, Reduced
from flexsat.campaigns.reduction import compare_reduction
from flexsat.config import nominal, validate_config

SETS = {"from rest": ("sensitivity", "montecarlo-critical"), "deployment shock":
        ("deployment-shock",)}  # fmt: skip


def _definition(name: str, duration_s: float | None) -> CampaignDefinition:
    data = load_campaign(name).model_dump(mode="json")
    if duration_s is not None:
        data["base"] = {**data["base"], "duration_s": duration_s}
    return validate_config(data, model=CampaignDefinition)


@harness.register(
    "the reduced model against the full one on the 69 thesis cases at full length: verdicts "
    "changed and largest differences, metric by metric"
)
def main(argv: list[str] | None = None) -> dict:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--duration", type=float, default=None, help="slew length [s]")
    parser.add_argument("--workers", type=int, default=2)
    args = parser.parse_args(argv)
    console = harness.console(150)
    results = {}
    with tempfile.TemporaryDirectory(prefix="flexsat-bench-reduction-") as tmp:
        for label, names in SETS.items():
            definitions = [_definition(name, args.duration) for name in names]
            frame, wall = compare_reduction(definitions, nominal(), tmp, Reduced(),
                                            workers=args.workers)  # fmt: skip
            table = harness.table(f"Reduced vs full model, {label} "
                                  f"({int(frame['cases'].iloc[0])} cases); wall: full "
                                  f"{wall['full']:.0f} s, reduced {wall['reduced']:.0f} s",
                                  ("metric", "units", "verdicts changed", "max |diff|",
                                   "max rel. diff", "worst case"), right=())  # fmt: skip
            for row in frame.to_dict("records"):
                changed = row.get("verdicts_changed")
                table.add_row(row["metric"], row["units"],
                              "-" if changed != changed or changed is None else str(int(changed)),
                              _fmt(row.get("max_abs_diff")), _fmt(row.get("max_rel_diff")),
                              str(row.get("worst_case") or ""))  # fmt: skip
            console.print(table)
            results[label] = {"table": frame.to_dict("records"), "wall_s": wall}
    return results


def _fmt(value) -> str:
    return "-" if value is None or value != value else f"{value:.3g}"


if __name__ == "__main__":
    main()
