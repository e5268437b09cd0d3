"""A stored campaign's summary: pass rates, the worst cases, the statistics and the cost.

:func:`summarize` reads the store alone; given the campaign's definition it adds what
each of its kinds reports (:attr:`flexsat.campaigns.kinds.CampaignKind.summarize`).
"""

from __future__ import annotations

import math
from pathlib import Path

from flexsat.campaigns.definition import CampaignDefinition
from flexsat.campaigns.kinds import KINDS
from flexsat.campaigns.store import CampaignStore

__all__ = ["SUMMARY_ROWS", "WORST_BY", "WORST_CASES", "summarize"]


WORST_CASES = 5
"""Worst cases listed per requirement and for the pointing error."""

WORST_BY = (
    ("R1", "r1_pass", "ape_deg", "deg"),
    ("R2", "r2_pass", "max_rate_error_deg_s", "deg/s"),
    ("R3", "r3_pass", "max_commanded_torque_nm", "N m"),
    ("pointing", None, "final_pointing_error_deg", "deg"),
)
"""What the worst cases are ranked by: (name, verdict key or None, metric, unit). R1 by
the absolute pointing error over the window, R2 by the largest residual rate over it,
R3 by the peak commanded torque (the largest axis), the pointing error at the end."""


SUMMARY_ROWS = (
    ("cases", "cases stored"),
    ("computed_this_run", "computed by this run"),
    ("resumed_this_run", "resumed from the store by this run"),
    ("failed", "failed cases (stopped or refused)"),
    ("r1_pass_rate", "R1 pass rate (absolute pointing, over the judged cases)"),
    ("r2_pass_rate", "R2 pass rate (residual rate, over the judged cases)"),
    ("r3_pass_rate", "R3 pass rate (torque limit)"),
    ("r1_not_judged", "R1 not judged (the run ends before the observation window)"),
    ("r2_not_judged", "R2 not judged (the run ends before the observation window)"),
    ("worst_final_pointing_error_deg", "worst final pointing error [deg]"),
    ("cpu_time_s", "CPU time of the stored cases [s]"),
    ("case_wall_time_s", "wall time of the stored cases, summed [s]"),
    ("campaign_wall_time_s", "wall time of every run into the store [s]"),
    ("runs", "runs recorded in the store"),
    ("run_wall_time_s", "wall time of this run [s]"),
)
"""The rows of a campaign's summary table (CLI and report): key in the summary, and
the label that says what it counts."""


def summarize(store: str | Path, definition: CampaignDefinition | None = None) -> dict:
    """Pass rates, the worst cases and the cost of a stored campaign.

    Parameters
    ----------
    store : str or Path
        The campaign's store folder.
    definition : CampaignDefinition, optional
        The campaign: each of its kinds that reports a summary
        (:attr:`~flexsat.campaigns.kinds.CampaignKind.summarize`) adds it under the
        kind's name (``sobol``: the indices; ``worst_case``: what the search found).

    Returns
    -------
    dict
        ``cases`` (stored), ``failed``, the pass rate of each requirement
        (``r1_pass_rate``..., fractions in [0, 1] of the judged cases; None when no
        case is judged, NaN when none is stored), ``r1_not_judged`` and
        ``r2_not_judged`` (the cases whose run was planned to end before the
        observation window: R1 and R2 "not judged", neither passed nor failed;
        ``not_judged_reason`` says why, "" when every case is judged),
        ``worst_by_requirement`` (for R1, R2, R3 and the final pointing
        error, :data:`WORST_BY`: the metric, its unit, the failing count and the
        :data:`WORST_CASES` worst cases, failing ones first, then by the metric,
        largest first: ``case_id``, ``value``, ``passes``, None when not judged) and
        ``worst_cases``, those by final pointing error alone [deg]. ``cpu_time_s``: the
        stored cases' own CPU time, summed [s] (a case stored without it counts its
        wall time); ``case_wall_time_s``: their own wall times, summed [s] (what a
        run stopped before recording itself spent is in both);
        ``campaign_wall_time_s``: the wall times of the runs recorded in the store,
        summed [s] (``runs`` of them). Also ``requirements`` (per
        requirement: passes, the exact 95 % interval of the pass rate and the failing
        case ids), ``metrics`` (per metric: min, 5/50/95 %, max) and
        ``cases_for_3sigma_at_95`` (the cases needed, with no failure, to claim
        99.73 % at 95 % confidence); see :mod:`flexsat.campaigns.statistics`. With
        ``definition``, one more entry per kind that reports a summary.
    """
    from flexsat.campaigns.statistics import (
        cases_needed,
        metric_statistics,
        requirement_statistics,
    )

    opened = CampaignStore(store)
    table = opened.table()
    rows = opened.rows()
    n = len(rows)

    def rate(key: str) -> float | None:
        if not n:
            return float("nan")
        judged = [r for r in rows if not _not_judged(r, key)]
        passed = sum(bool(r["metrics"].get(key)) for r in judged)
        return passed / len(judged) if judged else None  # not judged, as the verdicts

    reasons = sorted({r["metrics"]["not_judged_reason"] for r in rows
                      if _not_judged(r, "r1_pass") or _not_judged(r, "r2_pass")})  # fmt: skip

    def seconds(row: dict, key: str) -> float:
        value = row.get(key, row.get("case_wall_time_s"))
        return value if isinstance(value, int | float) and math.isfinite(value) else 0.0

    worst_by = [_worst(rows, *spec) for spec in WORST_BY]
    pointing = [c for c in worst_by[-1]["cases"] if c["value"] is not None]
    worst_cases = [
        {"case_id": c["case_id"], "final_pointing_error_deg": c["value"]} for c in pointing
    ]
    runs = opened.runs()
    summary = {
        "cases": n,
        "failed": sum(r["status"] != "ok" for r in rows),
        "r1_pass_rate": rate("r1_pass"),
        "r2_pass_rate": rate("r2_pass"),
        "r3_pass_rate": rate("r3_pass"),
        "r1_not_judged": sum(_not_judged(r, "r1_pass") for r in rows),
        "r2_not_judged": sum(_not_judged(r, "r2_pass") for r in rows),
        "not_judged_reason": "; ".join(reasons),
        "worst_final_pointing_error_deg": pointing[0]["value"] if pointing else float("nan"),
        "worst_cases": worst_cases,
        "worst_by_requirement": worst_by,
        "cpu_time_s": sum(seconds(r, "case_cpu_time_s") for r in rows),
        "case_wall_time_s": sum(seconds(r, "case_wall_time_s") for r in rows),
        "campaign_wall_time_s": sum(float(r.get("wall_time_s", 0.0)) for r in runs),
        "runs": len(runs),
        "requirements": requirement_statistics(table).to_dict("records") if n else [],
        "metrics": metric_statistics(table).to_dict("records") if n else [],
        "cases_for_3sigma_at_95": cases_needed(0.9973, 0.95),
    }
    for name, table in ({} if definition is None else definition.tables()).items():
        kind = KINDS.get(name)
        if kind.summarize is not None:
            summary[name] = kind.summarize(opened.root, table)
    return summary


def _not_judged(row: dict, verdict: str) -> bool:
    """Whether a case's verdict is "not judged": None, with the reason its metrics give
    (its run was planned to end before the observation window). A case that failed
    before it had metrics is not that: it fails every requirement."""
    metrics = row["metrics"]
    return (
        verdict in metrics and metrics[verdict] is None and bool(metrics.get("not_judged_reason"))
    )


def _worst(rows: list[dict], name: str, verdict: str | None, metric: str, unit: str) -> dict:
    """The worst cases by one requirement (see :data:`WORST_BY`)."""
    ranked = []
    for row in rows:
        ok = row["status"] == "ok"
        value = row["metrics"].get(metric) if ok else None
        if isinstance(value, list):  # per axis: the largest
            value = max(value) if value else None
        if not isinstance(value, int | float) or not math.isfinite(value):
            value = None
        if verdict is None or _not_judged(row, verdict):
            passes = None  # no verdict to rank by (not judged: neither pass nor fail)
        else:
            passes = bool(ok and row["metrics"].get(verdict))
        if passes is None and value is None:
            continue  # nothing to rank by
        # failing first, then the largest value; a case without a value after those with
        # one; a case not judged after every judged one
        ranked.append(((passes is not False, passes is None, value is None, -(value or 0.0),
                        row["case_id"]),
                       {"case_id": row["case_id"], "value": value, "passes": passes}))  # fmt: skip
    ranked.sort(key=lambda item: item[0])
    return {
        "requirement": name, "verdict": verdict, "metric": metric, "unit": unit,
        "failing": sum(entry["passes"] is False for _, entry in ranked),
        "cases": [entry for _, entry in ranked[:WORST_CASES]],
    }  # fmt: skip
