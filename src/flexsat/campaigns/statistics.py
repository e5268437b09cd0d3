"""Campaign statistics a review board signs off on.

- pass rates with exact (Clopper–Pearson) confidence intervals, and the number of
  cases a campaign needs to claim a requirement at a confidence;
- percentiles (5/50/95 %) of every metric beside its minimum and maximum, and
  percentile envelopes of the stored time histories;
- the failing cases listed per requirement;
- parameter columns with their physical values and units beside the scale factors
  (``appendages[0].target_frequencies_hz.flapping`` = 1.176 is a factor, not a
  frequency);
- rank correlations of every metric with every dispersed parameter (the tornado
  chart's bars).

Definitions are in docs/campaigns.md, 'Statistics'.
"""

from __future__ import annotations

import math

import numpy as np
import pandas as pd
from scipy import stats

from flexsat.campaigns.modifiers import _targets, derived_path

__all__ = [
    "PERCENTILES",
    "REQUIREMENTS",
    "cases_needed",
    "metric_columns",
    "metric_statistics",
    "parameter_table",
    "pass_rate_interval",
    "percentile_envelope",
    "rank_correlations",
    "requirement_statistics",
]

REQUIREMENTS = {
    "r1_pass": "R1 absolute pointing",
    "r2_pass": "R2 residual rate (jitter)",
    "r3_pass": "R3 torque within the actuator limit",
}
"""The verdict columns of a campaign (``metrics.<key>``) and what each requirement is."""

PERCENTILES = (5.0, 50.0, 95.0)
"""The percentiles reported beside the minimum and maximum [%]."""

# Units of a config path, from the suffix of its last name (SI, degrees at the boundary).
_UNITS = (("_hz", "Hz"), ("_kg_m2", "kg m^2"), ("_kg", "kg"), ("_deg_s", "deg/s"),
          ("_deg", "deg"), ("_nm", "N m"), ("_m_s", "m/s"), ("_m", "m"), ("_s", "s"),
          ("ratio", "-"), ("gain", "-"))  # fmt: skip


def pass_rate_interval(passes: int, cases: int, confidence: float = 0.95) -> tuple[float, float]:
    """Exact (Clopper–Pearson) two-sided interval of a pass probability.

    Parameters
    ----------
    passes, cases : int
        Cases that met the requirement, out of ``cases`` (>= 1).
    confidence : float
        Two-sided confidence level, in (0, 1) [-].

    Returns
    -------
    (low, high) : tuple of float
        The bounds, in [0, 1]: the beta quantiles (1 - c)/2 of Beta(k, n - k + 1)
        and (1 + c)/2 of Beta(k + 1, n - k), 0 and 1 at k = 0 and k = n.
    """
    if cases < 1 or not 0 <= passes <= cases:
        raise ValueError(f"need 0 <= passes <= cases and cases >= 1, got {passes}/{cases}")
    alpha = 1.0 - confidence
    low = 0.0 if passes == 0 else float(stats.beta.ppf(alpha / 2, passes, cases - passes + 1))
    high = 1.0 if passes == cases else float(stats.beta.ppf(1 - alpha / 2, passes + 1,
                                                            cases - passes))  # fmt: skip
    return low, high


def cases_needed(probability: float, confidence: float = 0.95, failures: int = 0) -> int:
    """Cases a campaign needs to claim ``P(pass) >= probability`` at ``confidence``.

    The smallest n whose one-sided Clopper–Pearson lower bound with ``failures``
    failing cases reaches ``probability``: with no failure, the smallest n with
    probability^n <= 1 - confidence (n = 1109 for 99.73 % at 95 %).

    Parameters
    ----------
    probability : float
        The pass probability to demonstrate, in (0, 1) [-].
    confidence : float
        One-sided confidence level, in (0, 1) [-].
    failures : int
        Failing cases allowed.

    Returns
    -------
    int
        The number of cases.
    """
    if not (0.0 < probability < 1.0 and 0.0 < confidence < 1.0) or failures < 0:
        raise ValueError("need 0 < probability < 1, 0 < confidence < 1, failures >= 0")
    n = max(failures + 1, math.ceil(math.log(1.0 - confidence) / math.log(probability)))
    while stats.beta.ppf(1.0 - confidence, n - failures, failures + 1) < probability:
        n += 1
    return n


def requirement_statistics(table: pd.DataFrame, confidence: float = 0.95) -> pd.DataFrame:
    """Pass rate, its exact interval and the failing cases of each requirement.

    A case that failed to run counts as failing every requirement. A case whose
    verdict is "not judged" (null, with a ``metrics.not_judged_reason``: its run was
    planned to end before the observation window, docs/control.md, 'How R1 and R2 are
    judged') is left out of the pass rate and counted apart.

    Parameters
    ----------
    table : DataFrame
        A store's table (:meth:`~flexsat.campaigns.store.CampaignStore.table`).
    confidence : float
        Two-sided confidence level of the intervals [-].

    Returns
    -------
    DataFrame
        One row per requirement present: ``requirement``, ``passes``, ``cases``
        (the judged ones), ``not_judged``, ``pass_rate`` (over the judged cases; NaN
        when none is), ``ci_low``, ``ci_high`` (at ``confidence``), ``failing`` (the
        failing case ids, sorted).
    """
    reason = table.get("metrics.not_judged_reason", pd.Series("", index=table.index))
    explained = reason.map(lambda text: isinstance(text, str) and bool(text))
    rows = []
    for key, what in REQUIREMENTS.items():
        column = f"metrics.{key}"
        if column not in table:
            continue
        verdict = table[column]
        unjudged = verdict.isna() & explained
        passed = verdict.fillna(False).astype(bool) & (table["status"] == "ok")
        judged = ~unjudged
        n, k = int(judged.sum()), int(passed.sum())
        low, high = pass_rate_interval(k, n, confidence) if n else (np.nan, np.nan)
        rows.append({"requirement": key, "description": what, "passes": k, "cases": n,
                     "not_judged": int(unjudged.sum()), "pass_rate": k / n if n else np.nan,
                     "ci_low": low, "ci_high": high,
                     "failing": sorted(table.loc[judged & ~passed, "case_id"])})  # fmt: skip
    return pd.DataFrame(rows)


def metric_statistics(table: pd.DataFrame) -> pd.DataFrame:
    """Minimum, 5/50/95 % percentiles, maximum, mean and std of every numeric metric.

    Over the cases that ran (status ``ok``).

    Parameters
    ----------
    table : DataFrame
        A store's table.

    Returns
    -------
    DataFrame
        One row per metric column: ``metric``, ``cases``, ``min``, ``p5``, ``p50``,
        ``p95``, ``max``, ``mean``, ``std``, in the metric's unit.
    """
    ok = table[table["status"] == "ok"]
    rows = []
    for column in metric_columns(table):
        values = pd.to_numeric(ok[column], errors="coerce").dropna().to_numpy(dtype=float)
        if not values.size:
            continue
        p5, p50, p95 = np.percentile(values, PERCENTILES)
        rows.append({"metric": column.removeprefix("metrics."), "cases": values.size,
                     "min": values.min(), "p5": p5, "p50": p50, "p95": p95,
                     "max": values.max(), "mean": values.mean(), "std": values.std(ddof=1)
                     if values.size > 1 else np.nan})  # fmt: skip
    return pd.DataFrame(rows)


def metric_columns(table: pd.DataFrame) -> list[str]:
    """The numeric (non-verdict) metric columns of a store's table.

    Parameters
    ----------
    table : DataFrame
        A store's table.

    Returns
    -------
    list of str
        Column names, ``metrics.<name>``.
    """
    skip = {f"metrics.{k}" for k in REQUIREMENTS}
    return [c for c in table.columns if c.startswith("metrics.") and c not in skip
            and pd.api.types.is_numeric_dtype(table[c]) and not pd.api.types.is_bool_dtype(
                table[c])]  # fmt: skip


def percentile_envelope(values: np.ndarray, percentiles=PERCENTILES) -> np.ndarray:
    """Percentiles across cases at each sample, NaN-aware.

    Parameters
    ----------
    values : ndarray, shape (cases, samples)
        One history per case [any unit].
    percentiles : sequence of float
        The percentiles, in [0, 100] [%].

    Returns
    -------
    ndarray, shape (len(percentiles), samples)
        The envelopes [unit of values].
    """
    return np.nanpercentile(np.asarray(values, dtype=float), percentiles, axis=0)


def _unit(path: str) -> str:
    """The unit the innermost suffixed name of a path gives (``target_frequencies_hz.x``)."""
    for name in reversed([part.split("[", 1)[0] for part in path.split(".")]):
        for suffix, unit in _UNITS:
            if name.endswith(suffix):
                return unit
    return ""


def parameter_table(rows: list[dict]) -> pd.DataFrame:
    """Each case's realised parameters, with their physical values beside scale factors.

    Parameters
    ----------
    rows : list of dict
        Stored case rows (:meth:`CampaignStore.rows`), with their inputs.

    Returns
    -------
    DataFrame
        ``case_id``, then per parameter path ``<path> [<unit>]``: the value in the
        case's inputs at that path, and ``<path> [factor]`` beside it when the
        realised value differs from it (a scale factor; also for derived paths such
        as ``hub.inertia``, which have no physical column).
    """
    records = []
    for row in rows:
        record = {"case_id": row["case_id"]}
        inputs = row.get("inputs") or {}
        for path, value in (row.get("parameters") or {}).items():
            physical = _value_at(inputs, path, value)
            if physical is None or physical != value:
                record[f"{path} [factor]"] = value
            if physical is not None:
                record[f"{path} [{_unit(path) or '-'}]"] = physical
        records.append(record)
    return pd.DataFrame(records)


def _value_at(inputs: dict, path: str, realised):
    """The physical value at ``path`` in a case's inputs, or None (a factor)."""
    for part in ("plant", "scenario"):
        data = inputs.get(part)
        if not isinstance(data, dict):
            continue
        try:
            hits = list(_targets(data, path))
        except KeyError:
            continue
        if len(hits) == 1:
            concrete, parent, key = hits[0]
            derived = derived_path(concrete, parent, key)
            if derived is not None:  # computed: the realised value is physical or a factor
                return None if derived.factor else realised
            try:
                value = parent[key]
            except (KeyError, IndexError, TypeError):
                return None  # a derived path (hub.inertia): no stored value there
            return value if isinstance(value, int | float) else None
    return None


def rank_correlations(parameters: pd.DataFrame, metrics: pd.DataFrame) -> pd.DataFrame:
    """Spearman rank correlation of each metric with each parameter (tornado bars).

    Parameters
    ----------
    parameters, metrics : DataFrame
        Indexed alike (one row per case); numeric columns.

    Returns
    -------
    DataFrame
        Index: parameters, columns: metrics; NaN where a column is constant.
    """
    out = pd.DataFrame(index=parameters.columns, columns=metrics.columns, dtype=float)
    for p in parameters.columns:
        x = pd.to_numeric(parameters[p], errors="coerce")
        for m in metrics.columns:
            y = pd.to_numeric(metrics[m], errors="coerce")
            keep = x.notna() & y.notna()
            if keep.sum() > 2 and x[keep].nunique() > 1 and y[keep].nunique() > 1:
                out.loc[p, m] = stats.spearmanr(x[keep], y[keep]).statistic
    return out
