"""Benchmark: the reduced model against the full one on the 69 thesis cases, full length.

Flies sensitivity, montecarlo-critical and deployment-shock (120 s slews) on the full
model (1 ms, controller every step) and on the reduced one (root translations locked,
20 ms step and control period), and prints, metric by metric, the verdicts changed
and the largest differences (:func:`flexsat.campaigns.reduction.reduction_table`),
for the slews from rest and for the deployment shock apart, with the wall times.

``--duration S`` shortens the slews; ``--workers N`` (default 2). Run with
``python bench/bench_reduction.py`` (or ``make bench``).

``--laws`` flies instead the law comparison's deployment shock
(:func:`flexsat.study.laws.law_comparison`: every registered law and the ASMC with
the root actuators, 32 cases each) on both models, and prints per variant the R1-R3
verdicts changed and the figures of the study's law table, full against reduced:
whether that campaign may fly the reduced model (it may not: docs/control.md,
'Comparing the laws over the campaigns').
"""

from __future__ import annotations

import argparse
import tempfile
from pathlib import Path

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
    parser.add_argument("--laws", action="store_true",
                        help="the law comparison's deployment shock, every variant")  # fmt: skip
    args = parser.parse_args(argv)
    console = harness.console(150)
    if args.laws:
        return _laws(console, args.workers)
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


SHOCK = "deployment-shock"
LAW_FIGURES = {  # the law table's figures compared (flexsat.study.laws.law_statistics)
    "R1 / R2 / R3 pass": lambda s: "/".join(f"{s[f'r{k}_pass_rate']:.3g}" for k in (1, 2, 3)),
    "R2 settling median [s]": lambda s: _fmt(s["r2_settling_time_s"]["median"]),
    "never in R2": lambda s: str(s["r2_settling_time_s"]["never"]),
    "peak tau_flex [N m]": lambda s: _fmt(s["peak_flex_torque_nm"]),
    "peak tip [m]": lambda s: _fmt(s["peak_tip_displacement_m"]),
    "control energy median [J]": lambda s: _fmt(s["control_energy_j"]["median"]),
    "residual elastic energy max [J]": lambda s: _fmt(s["residual_elastic_energy_j"]["max"]),
}  # fmt: skip


def _laws(console, workers: int) -> dict:
    """The deployment shock of the law comparison, every variant, on both models."""
    import time

    from flexsat.campaigns.reduction import reduction_table
    from flexsat.campaigns.store import CampaignStore
    from flexsat.control.laws import LAWS
    from flexsat.study.laws import law_comparison

    laws = LAWS.names()
    results: dict = {}
    with tempfile.TemporaryDirectory(prefix="flexsat-bench-reduction-laws-") as tmp:
        stats, wall = {}, {}
        for model, reduced in (("full", ()), ("reduced", (SHOCK,))):
            start = time.perf_counter()
            payload = law_comparison(
                nominal(), Path(tmp) / model, laws, quick=False, workers=workers,
                progress=False, campaigns=(SHOCK,), default_law=LAWS.default,
                reduced_campaigns=reduced,
            )  # fmt: skip
            wall[model] = time.perf_counter() - start
            stats[model] = payload["campaigns"][SHOCK]
        table = harness.table(f"Law comparison over the {SHOCK} campaign, full / reduced model; "
                              f"wall: full {wall['full']:.0f} s, reduced {wall['reduced']:.0f} s",
                              ("variant", "verdicts changed (R1, R2, R3)",
                               *LAW_FIGURES), right=())  # fmt: skip
        for variant in stats["full"]:
            full = Path(tmp) / "full" / "campaigns"
            folder = SHOCK if variant == LAWS.default else f"{SHOCK}-{variant}"
            store = Path(tmp) / "reduced" / "campaigns" / f"{SHOCK}-{variant}-reduced"
            diff = reduction_table(CampaignStore(full / folder).table(),
                                   CampaignStore(store).table())  # fmt: skip
            changed = diff.set_index("metric")["verdicts_changed"]
            verdicts = ", ".join(str(int(changed[f"r{k}_pass"])) for k in (1, 2, 3))
            f, r = stats["full"][variant], stats["reduced"][variant]
            table.add_row(variant, verdicts,
                          *(f"{show(f)} / {show(r)}" for show in LAW_FIGURES.values()))  # fmt: skip
            results[variant] = {"verdicts_changed": verdicts, "full": f, "reduced": r}
        console.print(table)
    return {"laws": results, "wall_s": wall}


def _fmt(value) -> str:
    return "-" if value is None or value != value else f"{value:.3g}"


if __name__ == "__main__":
    main()
