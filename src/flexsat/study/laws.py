"""The law comparison over the thesis's campaigns: every law, and the ASMC with hybrid
active damping, flown through the same cases.

For each campaign of :data:`~flexsat.study.thesis.CAMPAIGNS` and each variant
(the study's laws with their default gains, then :data:`DAMPED` = the ASMC with the
root actuators of :data:`HYBRID_DAMPING`), the cases' stored metrics are reduced to
one column of figures (:func:`law_statistics`): R1/R2/R3 pass rates, the
settling-time distributions, peak tau_flex, peak tip displacement, the control
energy and the residual elastic energy (``docs/control.md``, "Comparing the laws
over the campaigns"). The full study flies every case into a store per campaign
and variant (``campaigns/<campaign>-<variant>``; the default law's is the
campaigns part's own, resumed), the cases only (no summary or figures: the report
shows the comparison's table); the quick study flies the first
:data:`QUICK_CASES` case(s) of each campaign, each distinct case once, in forked
processes side by side.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

__all__ = [
    "DAMPED",
    "FULL_MODEL_LAWS",
    "HYBRID_DAMPING",
    "QUICK_CASES",
    "REDUCED_CAMPAIGNS",
    "law_comparison",
    "law_statistics",
]

HYBRID_DAMPING = {
    "kind": "rate_feedback",
    "coordinates": ["eta_rx", "eta_ry", "eta_rz"],
    "gain": 10.0,
    "limit": 0.1,
    "bandwidth_hz": 20.0,
}
"""The root actuators of the deployment-shock solution (``docs/control.md``, "Hybrid
active damping"): 0.1 N m on each panel root rotation, 20 Hz, 10 N m s/rad."""

DAMPED = "asmc+damping"
"""The name of the ASMC-with-hybrid-damping variant in the comparison."""

QUICK_CASES = 1
"""Cases per campaign and variant in the quick study."""

REDUCED_CAMPAIGNS = ("sensitivity", "montecarlo-critical")
"""The campaigns whose law comparison the full study flies on the reduced model (root
translations locked, 20 ms step): slews from rest, on which the reduced model keeps
every R1-R3 verdict and the peak tau_flex within 5.1 % (docs/campaigns.md, 'Reduced
models'). The deployment shock flies the full model: on the reduced one its 32 cases
lose the STSMC's R2 in every case (the 20 ms control period) and one of the SMC's,
and the table's peak tau_flex rises by up to 17 % (the panels' 50 Hz root modes ride
on it); docs/control.md, 'Comparing the laws over the campaigns'."""

FULL_MODEL_LAWS = ("stsmc",)
"""Variants flown on the full model in :data:`REDUCED_CAMPAIGNS` too: the super-twisting
law at the reduced model's 20 ms control period misses R2 (1e-3 deg/s) in every case
where at 1 ms it meets it (measured on the sensitivity campaign, R2 in 12 of 12 cases
on the full model and 0 of 12 on the reduced one; on the deployment shock 32 of 32
and 0 of 32). The SMC, the PD law and the damped ASMC kept theirs on the sensitivity
campaign (docs/results.md, 'Which model the law comparison flies')."""

_QUANTILES = {"min": 0.0, "median": 0.5, "p90": 0.9, "max": 1.0}


def _variants(laws: tuple[str, ...], default_law: str) -> dict[str, dict]:
    """Base-scenario overrides of each variant: the laws (none for the default law: the
    campaign as it stands), then the damped ASMC."""
    out = {law: {} if law == default_law else {"controller": {"kind": law}} for law in laws}
    out[DAMPED] = {"controller": {"kind": "asmc"}, "joint_actuator": HYBRID_DAMPING}
    return out


def _distribution(values: list[float]) -> dict:
    """Quantiles of the finite values, and how many never settled (NaN/None)."""
    finite = np.array([v for v in values if v is not None and np.isfinite(v)], dtype=float)
    out: dict = {"never": len(values) - finite.size}
    for name, q in _QUANTILES.items():
        out[name] = float(np.quantile(finite, q)) if finite.size else None
    return out


def law_statistics(rows: list[dict]) -> dict:
    """One variant's figures over a campaign's case rows (``run_case`` rows).

    Parameters
    ----------
    rows : list of dict
        The case rows.

    Returns
    -------
    dict
        ``cases``, ``failed``, ``r1_pass_rate``, ``r2_pass_rate``, ``r3_pass_rate``
        (over the judged cases, a case that failed to run counting as failing; None
        when no case is judged: docs/campaigns.md, 'Cases not judged'),
        ``settling_time_s`` and ``r2_settling_time_s`` (min, median, p90, max over
        the cases that settle, ``never`` the count of those that do not),
        ``peak_flex_torque_nm`` and ``peak_tip_displacement_m`` (largest over the
        cases), ``control_energy_j`` and ``residual_elastic_energy_j`` (median and
        max over the cases).
    """
    ok = [r["metrics"] for r in rows if r.get("status") == "ok"]
    n = len(rows)

    def rate(key: str) -> float | None:  # over the judged cases, a failed case failing
        judged = n - sum(m.get(key) is None for m in ok)
        return sum(m.get(key) is True for m in ok) / judged if judged else None

    def largest(key: str) -> float | None:
        values = [np.max(m[key]) for m in ok if m.get(key) is not None]
        return float(np.max(values)) if values else None

    def spread(key: str) -> dict:
        values = [m[key] for m in ok if m.get(key) is not None]
        return {"median": float(np.median(values)) if values else None,
                "max": float(np.max(values)) if values else None}  # fmt: skip

    return {
        "cases": n,
        "failed": n - len(ok),
        "r1_pass_rate": rate("r1_pass"),
        "r2_pass_rate": rate("r2_pass"),
        "r3_pass_rate": rate("r3_pass"),
        "settling_time_s": _distribution([m.get("settling_time_s") for m in ok]),
        "r2_settling_time_s": _distribution([m.get("r2_settling_time_s") for m in ok]),
        "peak_flex_torque_nm": largest("peak_flex_torque_nm"),
        "peak_tip_displacement_m": largest("peak_tip_displacement_m"),
        "control_energy_j": spread("control_energy_j"),
        "residual_elastic_energy_j": spread("residual_elastic_energy_j"),
    }


def _with_base(definition, overrides: dict, reduced: bool = False):
    from flexsat.campaigns.definition import CampaignDefinition, Reduced
    from flexsat.config import validate_config

    if not overrides and not reduced:
        return definition
    data = definition.model_dump(mode="json")
    data["base"] = {**data["base"], **overrides}
    if reduced:
        data["reduced"] = Reduced().model_dump(mode="json")
    return validate_config(data, source="law comparison", model=CampaignDefinition)


def _quick_rows(definitions: dict, config) -> dict:
    """The first QUICK_CASES case rows of each definition, flown in forked processes
    side by side; a case several definitions share (same digest of its plant and
    scenario: the nominal opens both the sensitivity and the critical-case sets)
    flies once."""
    from flexsat.campaigns import resolve_cases
    from flexsat.campaigns.runner import run_case
    from flexsat.parallel import forked_map

    cases = {key: resolve_cases(d, config)[:QUICK_CASES] for key, d in definitions.items()}
    unique = {case.digest: case for chosen in cases.values() for case in chosen}
    flown = dict(zip(unique, forked_map(run_case, unique.values()), strict=True))
    return {key: [flown[case.digest] for case in chosen] for key, chosen in cases.items()}


def _stored_rows(definition, config, store: Path, workers: int | None, progress: bool):
    """Every case of ``definition`` into ``store`` (resumed), and their rows.

    The cases only: no summary and no figures (the report shows the comparison's table,
    not the variants' campaign figures; the default law's full-model store is the
    campaigns part's, whose figures that part draws)."""
    from flexsat.campaigns import run_campaign
    from flexsat.campaigns.store import CampaignStore

    run_campaign(definition, config, store, workers=workers, resume=True, progress=progress)
    return CampaignStore(store).rows()


def law_comparison(
    config, out: Path, laws: tuple[str, ...], *, quick: bool, workers: int | None = None,
    progress: bool = True, campaigns: tuple[str, ...] | None = None, default_law: str = "asmc",
    reduced_campaigns: tuple[str, ...] | None = None,
) -> dict:  # fmt: skip
    """Fly each campaign with each variant and write ``out/laws/laws.json``.

    Parameters
    ----------
    config : SatelliteConfig
        The base satellite the campaigns vary.
    out : Path
        The study folder.
    laws : tuple of str
        Registered laws compared (with their default gains).
    quick : bool
        Only the first :data:`QUICK_CASES` case(s) of each campaign, in-process.
    workers : int, optional
        Campaign worker processes (full study).
    progress : bool
        Progress bars (full study).
    campaigns : tuple of str, optional
        Campaign presets; default the thesis's three.
    default_law : str
        The law of the campaigns part, whose stores are reused.
    reduced_campaigns : tuple of str, optional
        The campaigns flown on the reduced model in the full study; default
        :data:`REDUCED_CAMPAIGNS` (``bench/bench_reduction.py --laws`` flies the
        deployment shock on both models with it).

    Returns
    -------
    dict
        ``quick``, ``variants`` (names, in order), ``models``: per campaign, "full" or
        "reduced" (``reduced_campaigns``, full study only), ``full_model_variants``:
        per reduced campaign, its variants flown on the full model all the same
        (:data:`FULL_MODEL_LAWS`), ``campaigns``: per campaign, per variant,
        :func:`law_statistics`; also written to ``out/laws/laws.json``.
    """
    from flexsat.campaigns import load_campaign
    from flexsat.study.outputs import write_json
    from flexsat.study.thesis import CAMPAIGNS

    variants = _variants(laws, default_law)
    names = campaigns or CAMPAIGNS
    on_reduced = REDUCED_CAMPAIGNS if reduced_campaigns is None else reduced_campaigns
    reduced = {name: not quick and name in on_reduced for name in names}
    full_too = [variant for variant in variants if variant in FULL_MODEL_LAWS]
    payload: dict = {"quick": quick, "variants": list(variants),
                     "models": {n: "reduced" if reduced[n] else "full" for n in names},
                     "full_model_variants": {n: full_too for n in names if reduced[n]},
                     "campaigns": {}}  # fmt: skip
    definitions, on_model = {}, {}
    for name in names:
        base = load_campaign(name)
        for variant, overrides in variants.items():
            on_model[name, variant] = reduced[name] and variant not in FULL_MODEL_LAWS
            definitions[name, variant] = _with_base(base, overrides, on_model[name, variant])
    if quick:
        rows = _quick_rows(definitions, config)
    else:  # a full-model default law's folder is the campaigns part's own store
        rows = {}
        for (name, variant), definition in definitions.items():
            if on_model[name, variant]:
                folder = f"{name}-{variant}-reduced"
            else:
                folder = f"{name}-{variant}" if variants[variant] else name
            rows[name, variant] = _stored_rows(definition, config, out / "campaigns" / folder,
                                               workers, progress)  # fmt: skip
    for (name, variant), chosen in rows.items():
        payload["campaigns"].setdefault(name, {})[variant] = law_statistics(chosen)
    write_json(out / "laws" / "laws.json", payload)
    return payload
