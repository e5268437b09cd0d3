"""Sobol sensitivity indices of a campaign's metrics (SALib).

A campaign with a ``[sobol]`` table runs Saltelli's sample of its parameters
(:func:`~flexsat.campaigns.definition.sobol_samples`, cases ``sobol-00000`` ...);
:func:`sobol_indices` reads the stored metrics back in sample order and gives, per
metric and parameter, the first-order index S1 and the total index ST with SALib's
bootstrap confidence half-widths (docs/campaigns.md, 'Sobol sensitivity').
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd

from flexsat.campaigns.definition import (
    SobolCases,
    dispersed_modifiers,
    sobol_problem,
    sobol_samples,
)
from flexsat.campaigns.kinds import CampaignKind, CaseSource, register_kind
from flexsat.campaigns.statistics import metric_columns
from flexsat.campaigns.store import CampaignStore

__all__ = ["SOBOL", "analyze_sobol", "sobol_indices"]


def analyze_sobol(sobol: SobolCases, outputs: np.ndarray, seed: int = 0) -> pd.DataFrame:
    """First and total Sobol indices of one output over Saltelli's sample.

    Parameters
    ----------
    sobol : SobolCases
        The sample's definition (parameters and their bounds).
    outputs : ndarray, shape (n (D + 2),)
        The output at each row of :func:`sobol_samples`, in order [its unit].
    seed : int
        Seed of SALib's bootstrap (confidence intervals).

    Returns
    -------
    DataFrame
        Index: parameter paths; columns ``S1``, ``S1_conf``, ``ST``, ``ST_conf``
        (half-widths of SALib's 95 % bootstrap intervals).
    """
    from SALib.analyze import sobol as analyzer

    result = analyzer.analyze(sobol_problem(sobol), np.asarray(outputs, dtype=float),
                              calc_second_order=False, seed=seed)  # fmt: skip
    names = [p.path for p in sobol.parameters]
    return pd.DataFrame({k: result[k] for k in ("S1", "S1_conf", "ST", "ST_conf")}, index=names)


def sobol_indices(store: str | Path, sobol: SobolCases) -> pd.DataFrame:
    """Sobol indices of every numeric metric of a stored Sobol campaign.

    Parameters
    ----------
    store : path
        The campaign's store folder.
    sobol : SobolCases
        The campaign's ``[sobol]`` table (the sample's order).

    Returns
    -------
    DataFrame
        Columns ``metric``, ``parameter``, ``S1``, ``S1_conf``, ``ST``, ``ST_conf``;
        a metric missing in a case (failed, NaN) is left out, named in ``skipped``
        of the frame's ``attrs``.
    """
    table = CampaignStore(store).table()
    sobol_rows = table[table["case_id"].str.startswith("sobol-")].sort_values("stream_index")
    frames, skipped = [], []
    for column in metric_columns(table):
        values = pd.to_numeric(sobol_rows[column], errors="coerce").to_numpy(dtype=float)
        if not np.all(np.isfinite(values)) or np.ptp(values) == 0.0:
            skipped.append(column.removeprefix("metrics."))
            continue
        frame = analyze_sobol(sobol, values).rename_axis("parameter").reset_index()
        frame.insert(0, "metric", column.removeprefix("metrics."))
        frames.append(frame)
    out = pd.concat(frames, ignore_index=True) if frames else pd.DataFrame()
    out.attrs["skipped"] = skipped
    return out


def _sobol_cases(sobol: SobolCases, n_cases: int | None) -> CaseSource:
    """``[sobol]``: the k-th row of Saltelli's sample, each parameter a modifier of the
    plant (paths under ``hub`` and ``appendages``) or of the scenario (the others)."""
    samples = sobol_samples(sobol)
    return CaseSource(
        len(samples),
        lambda k: (
            f"sobol-{k:05d}",
            (sobol.seed, k),
            *dispersed_modifiers(sobol.parameters, samples[k]),
        ),
    )


def _sobol_summary(store: Path, sobol: SobolCases) -> dict:
    """The Sobol indices of every metric (:func:`sobol_indices`)."""
    indices = sobol_indices(store, sobol)
    return {"indices": indices.to_dict("records"), "skipped": indices.attrs["skipped"]}


SOBOL = register_kind(
    CampaignKind(
        "sobol",
        SobolCases,
        "Saltelli's sample for Sobol indices",
        _sobol_cases,
        streamed=True,
        id_prefix="sobol",
        words="from Saltelli's sample",
        summarize=_sobol_summary,
    )
)
"""The ``[sobol]`` campaign kind (:mod:`flexsat.campaigns.kinds`)."""
