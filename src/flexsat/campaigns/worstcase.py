"""Worst-case search: an optimizer over the dispersion box looks for what Monte Carlo misses.

A campaign with a ``[worst_case]`` table is flown by :func:`run_worst_case`: scipy's
differential evolution (seeded, so a search is reproducible) maximizes the chosen
metric over the box of its parameters. Every evaluation is an ordinary campaign
case (``de-00000`` ...) run by the same backends and stored in the same store, so
a killed search resumes without recomputing a case, and the worst case found is
replayed like any other (``flexsat campaign replay STORE de-00042``);
``worst_case.json`` names it. See docs/campaigns.md, 'Worst-case search'.
"""

from __future__ import annotations

import json
import math
import time
from collections.abc import Callable
from pathlib import Path

import numpy as np
from scipy.optimize import differential_evolution

from flexsat.campaigns.cases import HISTORY_KEY
from flexsat.campaigns.definition import (
    CampaignDefinition,
    CaseStream,
    ResolvedCase,
    WorstCaseSearch,
    dispersed_modifiers,
)
from flexsat.campaigns.kinds import CampaignKind, register_kind
from flexsat.campaigns.store import CampaignStore, _write_atomic
from flexsat.config.models import SatelliteConfig
from flexsat.errors import ConfigError

__all__ = ["WORST_CASE", "check_search", "run_worst_case"]


def run_worst_case(
    definition: CampaignDefinition,
    search: WorstCaseSearch,
    satellite: SatelliteConfig,
    out: str | Path,
    workers: int | None = 1,
    resume: bool = False,
    scheduler: str | None = None,
    dask_local: int | None = None,
    runner: str = "pool",
    *,
    backend: Callable,
) -> dict:
    """Search the dispersion box for the case that maximizes ``search.metric``.

    Parameters
    ----------
    definition : CampaignDefinition
        The base slew (``base``, ``reduced``); its own cases are not run.
    search : WorstCaseSearch
        The ``[worst_case]`` table: metric, parameters, seed.
    satellite : SatelliteConfig
        The base satellite.
    out : path
        The store (one case per evaluation).
    workers : int, optional
        Local processes (or the ensemble's threads) evaluating a generation.
    resume : bool
        Reuse the evaluations already stored (same inputs), run the rest.
    scheduler : str, optional
        Address of a running Dask scheduler that evaluates the generations.
    dask_local : int, optional
        Evaluate them on a Dask LocalCluster of this many workers.
    runner : {"pool", "ensemble"}
        Local runs only, as for :func:`~flexsat.campaigns.runner.run_campaign`.
    backend : callable
        ``backend(workers, scheduler, dask_local, runner)``: a context manager that
        yields ``execute(cases, size) -> rows``, the one the campaign runner flies its
        cases with (:func:`flexsat.campaigns.backends.backend`, which
        :func:`~flexsat.campaigns.runner.run_campaign` hands in).

    Returns
    -------
    dict
        ``case_id``, ``metric``, ``value`` and ``parameters`` of the worst case found,
        ``cases`` (evaluations), ``ran`` (computed by this call), ``resumed`` (found
        stored by this call), ``failed`` and ``failed_cases``
        (evaluations that failed, not taken as the worst), ``generations``, the
        table paths; also written to ``worst_case.json``.
    """
    stream, probe = check_search(definition, search, satellite)
    bounds = [p.bounds for p in search.parameters]
    store = CampaignStore(out)
    # the nominal case's digest covers the satellite and the base slew
    fingerprint = {"definition": _search_digest(definition, search), "satellite":
                   stream.head[0].digest, "cases": 0, "case_inputs": probe.digest}  # fmt: skip
    state = {"evaluations": 0, "ran": 0, "failed": []}
    start = time.perf_counter()
    values: dict[str, float] = {}

    with backend(workers, scheduler, dask_local, runner) as execute, store.opened(
            fingerprint, definition.name, resume):  # fmt: skip

        def evaluate(_, population) -> list[float]:
            cases = []
            for x in population:
                k = state["evaluations"]
                state["evaluations"] += 1
                cases.append(
                    stream.resolve(
                        (
                            f"de-{k:05d}",
                            (search.seed, k),
                            *dispersed_modifiers(search.parameters, x),
                        )
                    )
                )
            todo = [c for c in cases if store.stored_digest(c.case_id) != c.digest]
            for row in execute(todo, len(todo)):
                history = row.pop(HISTORY_KEY, None)
                if history is not None:
                    store.write_history(row["case_id"], history, status=row["status"])
                store.write_case(row)
            state["ran"] += len(todo)
            return [-_value(store, case, search.metric, values, state) for case in cases]

        result = differential_evolution(
            lambda x: 0.0, bounds, seed=search.seed, maxiter=search.maxiter,
            popsize=search.popsize, polish=False, updating="deferred", workers=evaluate,
            init="latinhypercube", tol=0.0,
        )  # fmt: skip
        store.write_tables()
        wall = time.perf_counter() - start
        store.record_run(state["ran"], state["evaluations"] - state["ran"], wall)
    if not values:
        raise ConfigError(
            f"worst_case.metric {search.metric!r}: no evaluation gave a finite value (a "
            "numeric slew metric such as final_pointing_error_deg or "
            "peak_tip_displacement_m; ape_deg, rpe_deg and max_rate_error_deg_s need runs "
            "that reach the end of the requirements' observation window, 120 s for the "
            "thesis's)"
        )
    worst = max(values, key=values.get)
    summary = {
        "campaign": definition.name, "worst_case": True, "case_id": worst, "metric": search.metric,
        "value": values[worst], "parameters": store.row(worst)["parameters"],
        "cases": state["evaluations"], "ran": state["ran"],
        "resumed": state["evaluations"] - state["ran"], "failed": len(state["failed"]),
        "failed_cases": state["failed"], "generations": int(result.nit), "wall_time_s": wall,
        "parquet": str(store.tables[0]), "csv": str(store.tables[1]),
    }  # fmt: skip
    _write_atomic(store.root / "worst_case.json", json.dumps(summary, indent=2))
    return summary


def check_search(definition: CampaignDefinition, search: WorstCaseSearch,
                 satellite: SatelliteConfig) -> tuple[CaseStream, ResolvedCase]:  # fmt: skip
    """Check a search before any evaluation runs: the base slew, and the cases at both
    corners of the parameters' box (every parameter at its low, then its high bound).

    Parameters
    ----------
    definition : CampaignDefinition
        The campaign (its base slew).
    search : WorstCaseSearch
        Its ``[worst_case]`` table.
    satellite : SatelliteConfig
        The base satellite.

    Returns
    -------
    stream : CaseStream
        The base slew's cases (the nominal), which resolves each evaluation.
    probe : ResolvedCase
        The low corner's case (its digest is part of the store's fingerprint).

    Raises
    ------
    ConfigError
        Naming the case and the value its modifier gives that is refused.
    """
    base = definition.model_copy(update={"cases": [], "grid": None, "random": None,
                                         "sobol": None, "include_nominal": True})  # fmt: skip
    stream = CaseStream(base, satellite)  # validates the base slew
    corners = [[p.bounds[k] for p in search.parameters] for k in (0, 1)]
    probe, _ = (stream.resolve((f"de-check-{name}", (search.seed, 0),
                                *dispersed_modifiers(search.parameters, corner)))
                for name, corner in zip(("low", "high"), corners, strict=True))  # fmt: skip
    return stream, probe


def _value(store: CampaignStore, case: ResolvedCase, metric: str, values: dict, state: dict
           ) -> float:  # fmt: skip
    row = store.row(case.case_id)
    value = row["metrics"].get(metric) if row["status"] == "ok" else None
    if not isinstance(value, int | float) or not math.isfinite(value):
        state["failed"].append(case.case_id)
        return -np.inf  # a failed evaluation is not taken as the worst: reported apart
    values[case.case_id] = float(value)
    return float(value)


def _search_digest(definition: CampaignDefinition, search: WorstCaseSearch) -> str:
    import hashlib

    text = json.dumps([definition.model_dump(mode="json"), search.model_dump(mode="json")],
                      sort_keys=True)  # fmt: skip
    return hashlib.sha256(text.encode()).hexdigest()[:16]


def _worst_case_summary(store: Path, search: WorstCaseSearch) -> dict:
    """What the search found, as ``worst_case.json`` records it (empty before it ends)."""
    path = CampaignStore(store).root / "worst_case.json"
    return json.loads(path.read_text()) if path.is_file() else {}


WORST_CASE = register_kind(CampaignKind(
    "worst_case", WorstCaseSearch, "differential evolution over a box, for the worst case",
    search=run_worst_case, summarize=_worst_case_summary,
))  # fmt: skip
"""The ``[worst_case]`` campaign kind (:mod:`flexsat.campaigns.kinds`): a search."""
