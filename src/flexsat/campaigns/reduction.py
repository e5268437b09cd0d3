"""How much a reduced model changes a campaign's metrics: full against reduced, case by case.

:func:`compare_reduction` flies the same campaign definitions twice, on the full model
(as defined) and on a reduced one (:class:`~flexsat.campaigns.definition.Reduced`:
locked joint DOFs, a longer step), and :func:`reduction_table` says, metric by
metric, how far apart the two are over every case: verdicts (R1, R2, R3) as the
number of cases whose verdict changed, numbers as the largest absolute and relative
difference. docs/campaigns.md, 'Reduced models', gives the table for the thesis
campaigns and when the reduction is safe.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd

from flexsat.campaigns.definition import CampaignDefinition, Reduced
from flexsat.campaigns.store import CampaignStore
from flexsat.config.models import SatelliteConfig

__all__ = ["REDUCTION_METRICS", "compare_reduction", "reduction_table"]

VERDICTS = ("r1_pass", "r2_pass", "r3_pass")
REDUCTION_METRICS = {
    "r1_pass": "-",
    "r2_pass": "-",
    "r3_pass": "-",
    "settling_time_s": "s",
    "r2_settling_time_s": "s",
    "final_pointing_error_deg": "deg",
    "final_rate_error_deg_s": "deg/s",
    "ape_deg": "deg",
    "rpe_deg": "deg",
    "peak_flex_torque_nm[0]": "N m",
    "peak_flex_torque_nm[1]": "N m",
    "peak_flex_torque_nm[2]": "N m",
    "peak_tip_displacement_m": "m",
}
"""The metrics compared (columns ``metrics.<name>`` of a store's table) and their units."""


def reduction_table(full: pd.DataFrame, reduced: pd.DataFrame) -> pd.DataFrame:
    """Metric-by-metric differences between two metric tables of the same cases.

    Parameters
    ----------
    full, reduced : DataFrame
        Store tables (:meth:`CampaignStore.table`), one row per case, joined on
        ``case_id``; only cases that succeeded in both are compared.

    Returns
    -------
    DataFrame
        One row per metric of :data:`REDUCTION_METRICS` present: ``units``,
        ``cases``, ``verdicts_changed`` (verdicts only: pass, fail and "not judged"
        are three verdicts, so a case judged on one model and not on the other
        counts), ``not_judged`` (verdicts only: the cases not judged on the full
        model), ``max_abs_diff`` and
        ``max_rel_diff`` (numbers only; relative to the full model's value), and the
        case where the largest relative difference occurs.
    """
    ok = lambda t: t[t["status"] == "ok"].set_index("case_id")  # noqa: E731
    a, b = ok(full), ok(reduced)
    common = a.index.intersection(b.index)
    rows = []
    for name, units in REDUCTION_METRICS.items():
        column = f"metrics.{name}"
        if column not in a or column not in b:
            continue
        x, y = a.loc[common, column], b.loc[common, column]
        row = {"metric": name, "units": units, "cases": len(common)}
        if name in VERDICTS:  # three states: pass, fail, not judged (null)
            x, y = _verdicts(x), _verdicts(y)
            row["verdicts_changed"] = int((x != y).sum())
            row["not_judged"] = int((x == "not judged").sum())
        else:
            x, y = x.astype(float), y.astype(float)
            diff = (y - x).abs()
            rel = diff / x.abs().where(x.abs() > 0)
            row["max_abs_diff"] = float(diff.max()) if len(diff) else np.nan
            row["max_rel_diff"] = float(rel.max()) if rel.notna().any() else np.nan
            row["worst_case"] = str(rel.idxmax()) if rel.notna().any() else ""
        rows.append(row)
    return pd.DataFrame(rows)


def _verdicts(column: pd.Series) -> pd.Series:
    """A verdict column as text: "pass", "fail" or "not judged" (null)."""
    return column.map(lambda v: "not judged" if pd.isna(v) else ("pass" if v else "fail"))


def compare_reduction(
    definitions: list[CampaignDefinition],
    satellite: SatelliteConfig,
    out: str | Path,
    reduced: Reduced | None = None,
    workers: int | None = 1,
) -> tuple[pd.DataFrame, dict]:
    """Fly the campaigns on the full and the reduced model and compare their metrics.

    Parameters
    ----------
    definitions : list of CampaignDefinition
        Flown as given (the full model) and with ``reduced`` set.
    satellite : SatelliteConfig
        The base satellite of every campaign.
    out : path
        Stores go to ``out/full/<name>`` and ``out/reduced/<name>`` (resumed if there).
    reduced : Reduced, optional
        Default: the root translations locked, 20 ms step and control period.
    workers : int or None
        Worker processes of each campaign (None: one per core).

    Returns
    -------
    table : DataFrame
        :func:`reduction_table` over the cases of every campaign.
    wall : dict
        Wall time of each model's runs [s], keys ``full`` and ``reduced``.
    """
    from flexsat.campaigns.runner import run_campaign

    reduced = reduced or Reduced()
    tables: dict[str, list[pd.DataFrame]] = {"full": [], "reduced": []}
    wall = {"full": 0.0, "reduced": 0.0}
    for definition in definitions:
        variants = {
            "full": definition,
            "reduced": definition.model_copy(update={"reduced": reduced}),
        }
        for kind, variant in variants.items():
            store = Path(out) / kind / definition.name
            run = run_campaign(variant, satellite, store, workers=workers, resume=True,
                               progress=False)  # fmt: skip
            wall[kind] += run["wall_time_s"]
            table = CampaignStore(store).table()
            table["case_id"] = definition.name + "/" + table["case_id"]
            tables[kind].append(table)
    return reduction_table(pd.concat(tables["full"]), pd.concat(tables["reduced"])), wall
