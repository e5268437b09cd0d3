"""The smallest ASMC robustness gain JK_min for which every case of a campaign meets R1-R3.

Bisection on the ASMC's ``jk_min_nm`` (eq. 4.21): each step runs the whole campaign
with that gain in its base scenario's controller (:func:`run_campaign`, one store per
step) and counts a step as passing when every case ran and met R1, R2 and R3
(:mod:`flexsat.analysis.requirements`). The analytical estimate it is compared with is
:func:`flexsat.simulate.robustness_gain.jk_min_estimate` (docs/control.md, "The minimum
robustness gain JK_min").

Bisection assumes that the campaign passes above some gain and fails below it; the
docs say where that was checked. It needs judged runs: a campaign whose runs end
before their observation window (R1 and R2 "not judged",
:func:`flexsat.analysis.requirements.unjudged_reason`) is refused.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

from flexsat.analysis.requirements import unjudged_reason
from flexsat.campaigns.definition import CampaignDefinition
from flexsat.campaigns.runner import run_campaign
from flexsat.campaigns.store import CampaignStore
from flexsat.config.models import SatelliteConfig
from flexsat.errors import ConfigError

__all__ = ["JKBisection", "JKStep", "bisect_jk_min", "with_jk_min"]

_REQUIREMENTS = ("r1_pass", "r2_pass", "r3_pass")


@dataclass(frozen=True)
class JKStep:
    """One campaign of the bisection.

    Attributes
    ----------
    jk_min_nm : float
        The ASMC's JK_min flown [N m].
    cases : int
        Cases the campaign ran.
    failing : tuple of str
        Ids of the cases that failed to run or missed R1, R2 or R3.
    wall_time_s : float
        The campaign's wall time [s].
    """

    jk_min_nm: float
    cases: int
    failing: tuple[str, ...]
    wall_time_s: float

    @property
    def passed(self) -> bool:
        """Every case met R1, R2 and R3."""
        return not self.failing


@dataclass(frozen=True)
class JKBisection:
    """What the bisection found.

    Attributes
    ----------
    low_nm, high_nm : float
        The final bracket [N m]: ``high_nm`` passed (when ``found``), ``low_nm``
        failed (unless the lower end of the range passed, then both are that end).
    found : bool
        False when even the upper end of the range failed.
    steps : list of JKStep
        Every campaign run, in order (the two ends first).
    """

    low_nm: float
    high_nm: float
    found: bool
    steps: list[JKStep] = field(default_factory=list)

    @property
    def jk_min_nm(self) -> float:
        """The smallest gain seen to pass: the bracket's upper end [N m]."""
        return self.high_nm

    def to_dict(self) -> dict:
        """JSON-ready: the bracket, the verdict and each step."""
        return {
            "low_nm": self.low_nm, "high_nm": self.high_nm, "found": self.found,
            "jk_min_nm": self.jk_min_nm,
            "steps": [{"jk_min_nm": s.jk_min_nm, "cases": s.cases, "passed": s.passed,
                       "failing": list(s.failing), "wall_time_s": s.wall_time_s}
                      for s in self.steps],
        }  # fmt: skip


def with_jk_min(definition: CampaignDefinition, jk_min_nm: float) -> CampaignDefinition:
    """The campaign with its base scenario's ASMC flying ``jk_min_nm``.

    Parameters
    ----------
    definition : CampaignDefinition
        A campaign whose base controller is the ASMC (the default law).
    jk_min_nm : float
        JK_min [N m], > 0.

    Returns
    -------
    CampaignDefinition
        A copy; its other controller fields are kept.

    Raises
    ------
    ConfigError
        The base controller is another law, or ``jk_min_nm`` is not positive.
    """
    if not jk_min_nm > 0.0:
        raise ConfigError(f"jk_min_nm: must be > 0 N m, got {jk_min_nm!r}")
    controller = dict(definition.base.get("controller") or {"kind": "asmc"})
    if controller.get("kind", "asmc") != "asmc":
        kind = controller["kind"]
        raise ConfigError(f"base.controller.kind: the bisection flies the ASMC, got {kind!r}")
    controller.update(kind="asmc", jk_min_nm=float(jk_min_nm))
    # A copy, not a re-validation of a dump: the tables of kinds registered outside
    # flexsat (``other_kinds``) are not in the dump. The base is validated as every
    # campaign's is, when its cases are resolved.
    return definition.model_copy(update={"base": {**definition.base, "controller": controller}})


def bisect_jk_min(
    definition: CampaignDefinition,
    satellite: SatelliteConfig,
    out: str | Path,
    low_nm: float,
    high_nm: float,
    steps: int = 8,
    workers: int | None = 1,
    runner: str = "pool",
) -> JKBisection:
    """Bisect JK_min between ``low_nm`` and ``high_nm``: each step one campaign.

    The two ends are run first: if the upper end fails there is nothing to bisect
    (``found`` False); if the lower end passes, it is the answer. Then ``steps``
    halvings, so the bracket ends ``(high_nm - low_nm) / 2**steps`` wide.

    Parameters
    ----------
    definition : CampaignDefinition
        The cases (its base controller the ASMC).
    satellite : SatelliteConfig
        The base satellite.
    out : str or Path
        Folder of the stores, one per gain (``jk-<value>``); an existing store of
        the same inputs is resumed, not recomputed.
    low_nm, high_nm : float
        The range [N m], 0 < low_nm < high_nm.
    steps : int
        Halvings after the two ends, >= 0.
    workers : int, optional
        Local worker processes of each campaign (:func:`run_campaign`).
    runner : {"pool", "ensemble"}
        As :func:`run_campaign`.

    Returns
    -------
    JKBisection

    Raises
    ------
    ConfigError
        A range that is not 0 < low_nm < high_nm, a negative ``steps``, a campaign
        whose runs end before their observation window (R1 and R2 not judged: its
        base scenario, checked before any run, or a case, once flown), or a
        campaign the runner refuses.
    """
    if not 0.0 < low_nm < high_nm:
        raise ConfigError(f"low_nm, high_nm: need 0 < low_nm < high_nm, got {low_nm}, {high_nm}")
    if steps < 0:
        raise ConfigError(f"steps: must be >= 0, got {steps}")
    from flexsat.config.load import validate_config
    from flexsat.simulate.scenario import SlewScenario

    base = validate_config(definition.base, source="base", model=SlewScenario)
    _refuse_unjudged(unjudged_reason(base.requirements, base.duration_s), ["every case"])
    out = Path(out)
    done: list[JKStep] = []

    def fly(jk: float) -> JKStep:
        store = out / f"jk-{jk:.6f}"
        summary = run_campaign(with_jk_min(definition, jk), satellite, store, workers=workers,
                               resume=store.exists(), progress=False, runner=runner)  # fmt: skip
        rows = CampaignStore(store).rows()
        unjudged = [row for row in rows if row["metrics"].get("not_judged_reason")]
        if unjudged:  # a case whose scenario modifiers shortened its run
            _refuse_unjudged(unjudged[0]["metrics"]["not_judged_reason"],
                             [f"case {row['case_id']!r}" for row in unjudged])  # fmt: skip
        failing = tuple(sorted(
            row["case_id"] for row in rows
            if row["status"] != "ok" or not all(row["metrics"].get(k) for k in _REQUIREMENTS)
        ))  # fmt: skip
        step = JKStep(float(jk), len(rows), failing, float(summary["wall_time_s"]))
        done.append(step)
        return step

    if not fly(high_nm).passed:
        return JKBisection(low_nm, high_nm, False, done)
    if fly(low_nm).passed:
        return JKBisection(low_nm, low_nm, True, done)
    for _ in range(steps):
        middle = 0.5 * (low_nm + high_nm)
        if fly(middle).passed:
            high_nm = middle
        else:
            low_nm = middle
    return JKBisection(low_nm, high_nm, True, done)


def _refuse_unjudged(reason: str, cases: list[str]) -> None:
    """Refuse a bisection over runs whose R1 and R2 are not judged (``reason`` given)."""
    if reason:
        shown = ", ".join(cases[:5]) + (f" and {len(cases) - 5} more" if len(cases) > 5 else "")
        raise ConfigError(
            f"duration_s: R1 and R2 are not judged in {shown}: {reason}; the JK_min "
            "bisection needs judged runs: give duration_s past the end of the observation "
            "window (requirements.settling_deadline_s, window_end_s)"
        )
