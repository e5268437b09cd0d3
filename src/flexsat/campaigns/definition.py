"""Campaign definitions: a base slew, and the cases that vary it (TOML, validated).

Cases come from any combination of:

- ``[[cases]]``: explicit cases, each with an ``id`` and its modifiers;
- ``[grid]``: the cartesian product of ``[[grid.axes]]``, each axis a list of
  levels (a label and modifiers); ``grid.common`` applies to every grid case;
- ``[random]``: ``n`` cases whose modifiers draw from distributions, one stream
  per case spawned from ``root_seed`` (``numpy.random.SeedSequence(root).spawn``);
- ``[sobol]``: Saltelli's sample of a box of parameters (:mod:`flexsat.campaigns.sobol`);

or from a search that runs alone (``[worst_case]``, :mod:`flexsat.campaigns.worstcase`).
Each is a campaign kind (:mod:`flexsat.campaigns.kinds`): the cases come from the
registered kinds whose table the campaign has, looked up, never named here but where
the built-ins register. The shipped presets are the TOML files of the ``presets``
folder (:func:`campaign_presets`).

``plant`` modifiers act on the satellite config, ``scenario`` modifiers on the slew
scenario. Cases are resolved in the parent process, one at a time as the runner
consumes them (:class:`CaseStream`): every backend and worker count runs the very
same resolved cases, and a 1e6-case campaign starts at once with flat memory.
"""

from __future__ import annotations

import collections
import hashlib
import itertools
import json
import math
import re
import warnings
from collections.abc import Iterator
from dataclasses import dataclass
from importlib import resources
from pathlib import Path
from typing import Annotated, Any, Literal

import numpy as np
from pydantic import Field, field_validator, model_validator

from flexsat.analysis.requirements import NotJudgedWarning, Requirements, unjudged_reason
from flexsat.campaigns.kinds import KINDS, CampaignKind, CaseSource, register_kind
from flexsat.campaigns.modifiers import Modifier, ModifierError, apply_modifiers
from flexsat.config.load import read_toml, validate_config
from flexsat.config.models import SatelliteConfig, _Frozen
from flexsat.errors import ConfigError
from flexsat.simulate.closedloop import design_inertia
from flexsat.simulate.scenario import SlewScenario, check_multiples_of_dt

__all__ = [
    "CAMPAIGN_PRESETS",
    "HEAD_CASES",
    "SEARCH_METRICS",
    "CampaignDefinition",
    "CaseDigest",
    "CaseStream",
    "Dispersed",
    "Reduced",
    "ResolvedCase",
    "SobolCases",
    "WorstCaseSearch",
    "campaign_fingerprint",
    "campaign_presets",
    "describe_counts",
    "dispersed_modifiers",
    "load_campaign",
    "resolve_cases",
    "sobol_problem",
    "sobol_samples",
]

PRESETS_DIR = Path(str(resources.files("flexsat.campaigns") / "presets"))
"""The folder of the shipped campaign presets: each ``<name>.toml`` is the preset ``name``."""


def campaign_presets() -> tuple[str, ...]:
    """Names of the shipped campaign presets: the TOML files of :data:`PRESETS_DIR`.

    Returns
    -------
    tuple of str
        The file names without ``.toml``, sorted.
    """
    return tuple(sorted(path.stem for path in PRESETS_DIR.glob("*.toml")))


CAMPAIGN_PRESETS = campaign_presets()
"""The presets shipped with flexsat, as :func:`campaign_presets` found them on import."""


class CaseSpec(_Frozen):
    id: Annotated[str, Field(min_length=1, max_length=80, pattern=r"^[A-Za-z0-9_.+\-]+$")]
    plant: list[Modifier] = Field(default_factory=list)
    scenario: list[Modifier] = Field(default_factory=list)


class Level(_Frozen):
    label: Annotated[str, Field(min_length=1, max_length=40, pattern=r"^[A-Za-z0-9_.+\-]+$")]
    plant: list[Modifier] = Field(default_factory=list)
    scenario: list[Modifier] = Field(default_factory=list)


class Axis(_Frozen):
    name: str
    levels: Annotated[list[Level], Field(min_length=1)]


class Grid(_Frozen):
    common: Level = Field(default_factory=lambda: Level(label="common"))
    axes: Annotated[list[Axis], Field(min_length=1)]
    seed: Annotated[int, Field(ge=0)] = 0


class RandomCases(_Frozen):
    n: Annotated[int, Field(ge=1, le=1_000_000)] = 100
    root_seed: Annotated[int, Field(ge=0)] = 0
    plant: list[Modifier] = Field(default_factory=list)
    scenario: list[Modifier] = Field(default_factory=list)


class Dispersed(_Frozen):
    """One parameter of a Sobol or worst-case campaign: a path and its range.

    Parameters
    ----------
    path : str
        Config path of the value (``hub.mass_kg``, ``appendages[*].thickness_m``...).
    op : {"set", "scale"}
        Set the value, or scale it by a factor.
    bounds : tuple of 2 float
        [low, high] of the value [its unit] or of the factor [-].
    """

    path: Annotated[str, Field(min_length=1)]
    op: Literal["set", "scale"] = "set"
    bounds: tuple[float, float] = Field(description="[low, high] of the value or factor")

    @model_validator(mode="after")
    def _ordered(self) -> Dispersed:
        low, high = self.bounds
        if not (math.isfinite(low) and math.isfinite(high) and math.isfinite(high - low)):
            raise ValueError(f"{self.path}: bounds take finite numbers with high - low <= "
                             f"{np.finfo(float).max:.4g}, got {list(self.bounds)}")  # fmt: skip
        if not low < high:
            raise ValueError(f"{self.path}: bounds must satisfy low < high")
        return self

    def modifier(self, value: float) -> Modifier:
        return Modifier(path=self.path, op=self.op, value=float(value))


def dispersed_modifiers(parameters: list[Dispersed], values) -> tuple[list, list]:
    """(plant, scenario) modifiers setting each parameter to its value: paths under
    ``hub`` and ``appendages`` are the plant's, the others the scenario's.

    Parameters
    ----------
    parameters : list of Dispersed
        The campaign's parameters.
    values : sequence of float
        One value (or factor) per parameter [the parameter's unit, or - for a factor].

    Returns
    -------
    plant, scenario : list of Modifier
        The modifiers of each config.
    """
    plant, scenario = [], []
    for parameter, value in zip(parameters, values, strict=True):
        root = parameter.path.split(".")[0].split("[")[0]
        (plant if root in ("hub", "appendages") else scenario).append(parameter.modifier(value))
    return plant, scenario


class SobolCases(_Frozen):
    """Saltelli's sampling of the parameters for first and total Sobol indices (SALib):
    ``n`` (D + 2) cases for D parameters.

    Parameters
    ----------
    n : int
        Base sample size N, a power of 2.
    seed : int
        Seed of the scrambled Sobol' sequence.
    parameters : list of Dispersed
        The dispersed parameters (1 to 64).
    """

    n: Annotated[int, Field(ge=2, le=65536)] = Field(
        64, description="base sample size N, a power of 2"
    )
    seed: Annotated[int, Field(ge=0)] = 0
    parameters: Annotated[list[Dispersed], Field(min_length=1, max_length=64)]

    @model_validator(mode="after")
    def _power_of_two(self) -> SobolCases:
        if self.n & (self.n - 1):
            raise ValueError(f"n must be a power of 2 (Sobol' sequence), got {self.n}")
        return self


SEARCH_METRICS = (
    "final_pointing_error_deg", "final_rate_error_deg_s", "ape_deg", "rpe_deg",
    "max_rate_error_deg_s", "settling_time_s", "r2_settling_time_s", "lambda_switch_time_s",
    "peak_tip_displacement_m", "finite_until_s", "control_energy_j", "residual_elastic_energy_j",
)  # fmt: skip
"""The numeric slew metrics a worst-case search can maximize (a case row's scalar
``metrics``: :func:`~flexsat.analysis.requirements.slew_metrics` and
:func:`~flexsat.analysis.effort.effort_metrics`)."""


class WorstCaseSearch(_Frozen):
    """Differential evolution over the parameters' box, maximizing ``metric``.

    Parameters
    ----------
    metric : str
        A numeric slew metric (``final_pointing_error_deg``...).
    parameters : list of Dispersed
        The parameters searched (1 to 32).
    seed : int
        Seed of the search.
    """

    metric: str = Field("final_pointing_error_deg", description="a numeric slew metric")
    parameters: Annotated[list[Dispersed], Field(min_length=1, max_length=32)]
    seed: Annotated[int, Field(ge=0)] = 0
    maxiter: Annotated[int, Field(ge=1, le=1000)] = Field(10, description="generations")
    popsize: Annotated[int, Field(ge=2, le=100)] = Field(
        5, description="population = popsize x number of parameters"
    )

    @field_validator("metric")
    @classmethod
    def _searchable(cls, metric: str) -> str:
        if metric not in SEARCH_METRICS:
            raise ValueError(f"{metric!r} is not a numeric slew metric; one of "
                             f"{', '.join(SEARCH_METRICS)}")  # fmt: skip
        return metric


class Reduced(_Frozen):
    """A reduced model for every case: joint DOFs locked, a longer step.

    The controller's rate is its own setting (``control_dt_s``, a whole multiple of
    ``dt_s``), and so is the record period (``record_dt_s``, a whole multiple of
    ``dt_s``, default two steps; a longer base period is kept). The defaults, a 20 ms
    step and control period and 40 ms records, keep every verdict of the 69 thesis cases; see
    docs/campaigns.md, 'Reduced models', for what they change and when the reduction
    is safe.
    """

    locked_dofs: list[str] = Field(
        default_factory=lambda: ["eta_x", "eta_y", "eta_z"],
        description="coordinates locked on every appendage whose model has them",
    )
    dt_s: Annotated[float, Field(gt=0.0, le=0.1, allow_inf_nan=False)] = Field(
        0.02, description="RK4 step of the reduced model [s]"
    )
    control_dt_s: Annotated[float, Field(gt=0.0, le=10.0, allow_inf_nan=False)] = Field(
        0.02, description="control period [s] (a whole multiple of dt_s)"
    )
    record_dt_s: Annotated[float, Field(gt=0.0, le=10.0, allow_inf_nan=False)] | None = Field(
        None,
        description="record period [s] (a whole multiple of dt_s; default two "
        "steps; a longer base record period is kept)",
    )

    @model_validator(mode="after")
    def _periods(self) -> Reduced:
        check_multiples_of_dt(self, ("control_dt_s", "record_dt_s") if self.record_dt_s
                              else ("control_dt_s",))  # fmt: skip
        return self

    @property
    def record_period_s(self) -> float:
        """The record period: ``record_dt_s``, or two steps [s]."""
        return self.record_dt_s or 2.0 * self.dt_s


class CampaignDefinition(_Frozen):
    """A campaign: the satellite, the base slew, and how the cases vary them."""

    name: Annotated[
        str, Field(min_length=1, max_length=80, pattern=r"^[A-Za-z0-9_][A-Za-z0-9_.+\-]*$")
    ] = Field(description="campaign name, also its store folder's (no path separators)")
    description: str = Field("", description="one line for listings")
    include_nominal: bool = Field(True, description="add the unmodified case 'nominal'")
    base: dict = Field(default_factory=dict, description="SlewScenario fields for every case")
    cases: list[CaseSpec] = Field(default_factory=list, description="cases listed one by one")
    grid: Grid | None = Field(None, description="cases crossed from levels of several axes")
    random: RandomCases | None = Field(None, description="cases drawn from distributions")
    sobol: SobolCases | None = Field(
        None, description="Saltelli's sample for Sobol indices (SALib)"
    )
    worst_case: WorstCaseSearch | None = Field(
        None, description="search the parameters' box for the worst case (runs alone)"
    )
    reduced: Reduced | None = Field(None, description="fly every case on a reduced model")
    other_kinds: dict[str, Any] = Field(
        default_factory=dict, exclude=True,
        description="the tables of registered kinds that are not built in, by kind name",
    )  # fmt: skip

    @model_validator(mode="before")
    @classmethod
    def _other_kinds(cls, data: Any) -> Any:
        """Move the table of a registered kind that is not a declared field into
        ``other_kinds``, validated by the kind's model."""
        if not isinstance(data, dict):
            return data
        names = [n for n in KINDS.names() if n not in cls.model_fields and n in data]
        if not names:
            return data
        data = dict(data)
        other = dict(data.get("other_kinds") or {})
        for name in names:
            try:  # its problems named in its table, then given as the definition's
                other[name] = validate_config(data.pop(name), source=f"[{name}]",
                                              model=KINDS.get(name).config)  # fmt: skip
            except ConfigError as exc:
                raise ValueError(str(exc)) from None
        data["other_kinds"] = other
        return data

    @model_validator(mode="after")
    def _has_cases(self) -> CampaignDefinition:
        tables = self.tables()
        searches = [KINDS.get(n) for n in tables if KINDS.get(n).search is not None]
        if searches and len(tables) > 1:
            others = [n for n in KINDS.names() if n != searches[0].name]
            listed = ", ".join(others[:-1]) + f" or {others[-1]}" if len(others) > 1 else others[0]
            raise ValueError(f"a {searches[0].name} search runs alone: no {listed}")
        if not (tables or self.include_nominal):
            raise ValueError("a campaign needs cases, a grid, random or Sobol cases or the nominal")
        validate_config(self.base, source="base", model=SlewScenario)
        return self

    def tables(self) -> dict[str, Any]:
        """The campaign's kinds: each registered kind's table it has, in registration order.

        Returns
        -------
        dict
            Kind name (:mod:`flexsat.campaigns.kinds`) to its validated table (for
            ``cases``, the non-empty list of explicit cases).
        """
        out = {}
        for name in KINDS.names():
            table = getattr(self, name) if name in type(self).model_fields else (
                self.other_kinds.get(name))  # fmt: skip
            if table is not None and not (isinstance(table, list) and not table):
                out[name] = table
        return out

    def fingerprint(self) -> str:
        """Hash of the definition, to refuse resuming a store made by another one."""
        data = self.model_dump(mode="json")
        if self.other_kinds:  # absent otherwise: a built-in campaign's hash is unchanged
            data["other_kinds"] = {k: v.model_dump(mode="json")
                                   for k, v in self.other_kinds.items()}  # fmt: skip
        text = json.dumps(data, sort_keys=True)
        return hashlib.sha256(text.encode()).hexdigest()[:16]


@dataclass(frozen=True)
class ResolvedCase:
    """A case ready to run anywhere: validated plant config and scenario as plain dicts.

    ``error`` is empty, or why the case's inputs were refused (a random draw out of
    range met while streaming): such a case is stored as failed without running.

    Attributes
    ----------
    case_id : str
        The case's id, also its file name in the store.
    root_seed : int
        The campaign's root seed.
    stream_index : int
        Index of the case's random stream, ``SeedSequence(root_seed, spawn_key=(index,))``.
    plant : dict
        The case's satellite config, validated, as plain data (SI).
    scenario : dict
        The case's slew scenario, validated, as plain data.
    parameters : dict
        The realised value of each modifier, by config path (SI or the path's unit).
    error : str
        Empty, or why the case's inputs were refused.
    """

    case_id: str
    root_seed: int
    stream_index: int
    plant: dict
    scenario: dict
    parameters: dict
    error: str = ""

    @property
    def digest(self) -> str:
        """Hash of everything that defines this case's result (plant and scenario)."""
        return _digest({"plant": self.plant, "scenario": self.scenario})


def describe_counts(counts: dict[str, int]) -> str:
    """A campaign's cases in words: ``"101 cases: 100 drawn + the nominal"``.

    Parameters
    ----------
    counts : dict
        Cases per source, as :meth:`CaseStream.counts` gives them.

    Returns
    -------
    str
        The total and its parts.
    """
    words = {kind.count_key: kind.words or f"from {kind.name}" for kind in KINDS}
    parts = [f"{counts[key]} {word}" for key, word in words.items() if counts.get(key)]
    if counts.get("nominal"):
        parts.append("the nominal")
    total = sum(counts.values())
    return f"{total} case{'' if total == 1 else 's'}: {' + '.join(parts)}"


def _digest(data) -> str:
    return hashlib.sha256(json.dumps(data, sort_keys=True).encode()).hexdigest()[:16]


HEAD_CASES = 100
"""Cases resolved before a campaign starts: their digest is the store's ``case_inputs``."""


class CaseStream:
    """The cases of a campaign, resolved one at a time as they are consumed.

    Preparing a case (applying its modifiers, validating its plant and scenario)
    takes a few milliseconds; a 1e6-case campaign is never held in memory nor
    prepared up front. What can be checked without resolving every case is checked
    on construction, before any case runs: the case count, unique ids, every
    explicit and grid case and the first :data:`HEAD_CASES` cases (resolved,
    validated and their run sizes estimated, strictly). When those cases' runs end
    before their observation window, a :class:`~flexsat.analysis.requirements.NotJudgedWarning`
    says so then: their R1 and R2 will read "not judged".

    Iterating resolves the cases in order; a later case whose draws are refused is
    yielded with its ``error`` set (stored as a failed row), not raised, unless
    ``strict``.

    Parameters
    ----------
    definition : CampaignDefinition
        The campaign.
    satellite : SatelliteConfig
        Its base satellite.
    n_random : int, optional
        Random cases to draw (``--cases``, handed to every kind); default the
        definition's ``[random] n``.
    strict : bool
        Raise on a refused case instead of yielding it with its ``error``.

    Raises
    ------
    ConfigError
        On construction: a bad count, duplicate ids, a bad modifier or value in
        the checked cases.
    """

    def __init__(
        self,
        definition: CampaignDefinition,
        satellite: SatelliteConfig,
        n_random: int | None = None,
        strict: bool = False,
    ) -> None:
        from flexsat.dynamics.plant import Plant

        self.definition, self.strict = definition, strict
        self._plant_base = satellite.model_dump(mode="json")
        scenario_base = SlewScenario.model_validate(definition.base).model_dump(
            mode="json", by_alias=True
        )
        if definition.reduced is not None:
            _reduce(self._plant_base, scenario_base, definition.reduced)
        if scenario_base["design_inertia_kg_m2"] is None:  # the base configuration's design
            scenario_base["design_inertia_kg_m2"] = design_inertia(satellite).tolist()
        self._scenario_base = scenario_base
        self._n_dof = Plant.from_config(satellite).n_dof  # modifiers change values only
        self._sized: set[tuple] = set()
        # each kind of the campaign that generates cases, its source, in registration order
        self._kinds: list[tuple[CampaignKind, CaseSource]] = [
            (kind, kind.cases(table, n_random))
            for kind, table in ((KINDS.get(n), t) for n, t in definition.tables().items())
            if kind.cases is not None
        ]  # fmt: skip
        self._fixed = self._fixed_specs()
        # the streamed sources: (case count, spec of its k-th case)
        self._sources = [(src.count, src.spec) for kind, src in self._kinds if kind.streamed]
        streamed = {kind.id_prefix: src.count for kind, src in self._kinds if kind.streamed}
        ids = [spec[0] for spec in self._fixed]
        drawn_id = re.compile(rf"({'|'.join(map(re.escape, streamed)) or '(?!)'})-(\d{{5,}})")
        clash = [i for i in ids if (m := drawn_id.fullmatch(i)) and int(m[2]) < streamed[m[1]]]
        counted = collections.Counter(ids)
        repeated = sorted({i for i, n in counted.items() if n > 1} | set(clash))
        if repeated:
            shown = ", ".join(map(repr, repeated[:5])) + (" ..." if len(repeated) > 5 else "")
            own = " and ".join(f"{kind.id_prefix}-NNNNN" for kind in KINDS if kind.streamed)
            raise ConfigError(f"campaign {definition.name}: duplicate case ids: {shown} (each "
                              f"case id once; {own} are the drawn cases' own)")  # fmt: skip
        self.head = [self.resolve(spec) for spec in self._fixed]
        n_head = min(self._n_streamed, max(1, HEAD_CASES - len(self.head)))
        self.head += [self.resolve(self._streamed_spec(i)) for i in range(n_head)]
        _announce_unjudged(definition.name, self.head)

    def counts(self) -> dict[str, int]:
        """How many cases come from each source (see :func:`describe_counts`).

        Returns
        -------
        dict
            ``nominal`` (0 or 1), then each registered kind that generates cases by its
            :attr:`~flexsat.campaigns.kinds.CampaignKind.count_key`: ``listed``
            (``[[cases]]``), ``grid``, ``random`` (drawn, ``--cases``), ``sobol``
            (Saltelli's sample)..., 0 for a kind the campaign does not have.
        """
        sources = {kind.name: src.count for kind, src in self._kinds}
        counts = {"nominal": int(self.definition.include_nominal)}
        counts |= {kind.count_key: sources.get(kind.name, 0) for kind in KINDS if kind.cases}
        return counts

    @property
    def _n_streamed(self) -> int:
        return sum(n for n, _ in self._sources)

    def __len__(self) -> int:
        return len(self._fixed) + self._n_streamed

    def __iter__(self) -> Iterator[ResolvedCase]:
        yield from self.head
        for i in range(len(self.head) - len(self._fixed), self._n_streamed):
            spec = self._streamed_spec(i)
            try:
                yield self.resolve(spec)
            except ConfigError as exc:
                if self.strict:
                    raise
                yield ResolvedCase(spec[0], *spec[1], plant={}, scenario={}, parameters={},
                                   error=str(exc))  # fmt: skip

    def _streamed_spec(self, i: int) -> tuple[str, tuple[int, int], list, list]:
        for n, spec in self._sources:
            if i < n:
                return spec(i)
            i -= n
        raise IndexError(i)

    def _fixed_specs(self) -> list[tuple[str, tuple[int, int], list, list]]:
        """(id, (root seed, index) of its random stream, plant and scenario modifiers)
        of the nominal and of every case of the kinds that are not streamed."""
        specs: list[tuple[str, tuple[int, int], list[Modifier], list[Modifier]]] = []
        if self.definition.include_nominal:
            specs.append(("nominal", (0, 0), [], []))
        for kind, source in self._kinds:
            if not kind.streamed:
                specs += [source.spec(k) for k in range(source.count)]
        return specs

    def resolve(self, spec) -> ResolvedCase:
        """Resolve one case from ``(id, (root seed, index), plant mods, scenario mods)``."""
        from flexsat.simulate.run_setup import check_run_size

        case_id, (root, index), plant_mods, scenario_mods = spec
        # The stream SeedSequence(root).spawn(n)[index] would give, built directly.
        rng = np.random.default_rng(np.random.SeedSequence(root, spawn_key=(index,)))
        realised: dict = {}
        try:
            plant = apply_modifiers(self._plant_base, plant_mods, rng, realised)
            scenario = apply_modifiers(self._scenario_base, scenario_mods, rng, realised)
        except (KeyError, ModifierError) as exc:
            raise ConfigError(f"campaign case {case_id!r}: {exc.args[0]}") from None
        satellite = validate_config(plant, source=f"campaign case {case_id!r} (plant)")
        source = f"campaign case {case_id!r} (scenario)"
        model = validate_config(scenario, source=source, model=SlewScenario)
        if model.initial.appendages:  # each entry fits its appendage (model, locked DOFs)
            _check_initial_state(satellite, model, source)
        timing = (model.duration_s, model.dt_s, model.record_dt_s)
        if timing not in self._sized:  # the records must fit in a worker
            try:
                check_run_size(self._n_dof, model)
            except ConfigError as exc:
                name = self.definition.name
                raise ConfigError(f"campaign {name}, case {case_id!r}: {exc}") from None
            self._sized.add(timing)
        return ResolvedCase(case_id, root, index, plant, scenario, realised)


def _announce_unjudged(name: str, head: list[ResolvedCase]) -> None:
    """Say before any case runs when the checked cases' runs end before their observation
    window: their R1 and R2 will read "not judged" (a :class:`NotJudgedWarning`, which
    ``flexsat`` prints as one line), neither passed nor failed."""
    reasons: dict[str, list[str]] = {}
    for case in head:
        if case.scenario:
            requirements = Requirements.model_validate(case.scenario.get("requirements") or {})
            reason = unjudged_reason(requirements, case.scenario["duration_s"])
            if reason:
                reasons.setdefault(reason, []).append(case.case_id)
    for reason, ids in reasons.items():
        where = "" if len(ids) == len(head) else f" in {len(ids)} of the first {len(head)} cases"
        warnings.warn(f"campaign {name}: R1 and R2 are not judged{where}: {reason}; their "
                      "verdicts read 'not judged', neither pass nor fail",
                      NotJudgedWarning, stacklevel=3)  # fmt: skip


def _check_initial_state(satellite: SatelliteConfig, scenario: SlewScenario, source: str) -> None:
    """Refuse, before any case runs, a scenario's initial appendage state the satellite
    cannot take (an appendage it lacks, a model with no initial state to set, a rate on
    a locked coordinate): otherwise every such case would fail as it starts to fly."""
    from flexsat.dynamics.plant import Plant
    from flexsat.simulate.openloop import initial_state

    try:
        initial_state(Plant.from_config(satellite), scenario)
    except ConfigError as exc:
        raise ConfigError(f"{source}: {exc}") from None


def sobol_problem(sobol: SobolCases) -> dict:
    """SALib's problem dictionary of a Sobol campaign (names are the paths).

    Parameters
    ----------
    sobol : SobolCases
        The campaign's ``[sobol]`` table.

    Returns
    -------
    dict
        ``num_vars``, ``names`` and ``bounds``.
    """
    return {
        "num_vars": len(sobol.parameters),
        "names": [p.path for p in sobol.parameters],
        "bounds": [list(p.bounds) for p in sobol.parameters],
    }


def sobol_samples(sobol: SobolCases) -> np.ndarray:
    """Saltelli's sample (SALib, scrambled Sobol' sequence, seeded): first and total
    indices, no second order.

    Parameters
    ----------
    sobol : SobolCases
        The campaign's ``[sobol]`` table.

    Returns
    -------
    ndarray, shape (n (D + 2), D)
        One row of parameter values per case [each parameter's unit].
    """
    try:
        from SALib.sample import sobol as sampler
    except ImportError:
        raise ConfigError(
            "a Sobol campaign needs SALib: pip install 'flexsat[sensitivity]'"
        ) from None
    return sampler.sample(sobol_problem(sobol), sobol.n, calc_second_order=False,
                          seed=sobol.seed)  # fmt: skip


def _reduce(plant: dict, scenario: dict, reduced: Reduced) -> None:
    """Apply a :class:`Reduced` model to the base plant and scenario (plain dicts).

    The record period is raised to the reduced one when shorter.
    """
    from flexsat.config.models import appendage_config_class, table_model

    for appendage in plant["appendages"]:
        fields = appendage_config_class(table_model(appendage)).model_fields
        if "locked_dofs" in fields:  # a model that can lock coordinates
            appendage["locked_dofs"] = list(reduced.locked_dofs)
    scenario["dt_s"], scenario["control_dt_s"] = reduced.dt_s, reduced.control_dt_s
    scenario["record_dt_s"] = max(scenario.get("record_dt_s", 0.01), reduced.record_period_s)


class CaseDigest:
    """The digest over every case's id and inputs, built as the cases stream by."""

    def __init__(self) -> None:
        self._hash = hashlib.sha256()
        self.count = 0

    def add(self, case: ResolvedCase) -> None:
        self._hash.update(f"{case.case_id}:{case.digest};".encode())
        self.count += 1

    def hexdigest(self) -> str:
        return self._hash.hexdigest()[:16]


def campaign_fingerprint(
    definition: CampaignDefinition,
    satellite: SatelliteConfig,
    cases: CaseStream | list[ResolvedCase],
) -> dict:
    """What a store's results depend on, part by part, to refuse a mixed resume.

    Parameters
    ----------
    definition : CampaignDefinition
        The campaign.
    satellite : SatelliteConfig
        Its base satellite.
    cases : CaseStream or list of ResolvedCase
        Its cases (a stream's checked head).

    Returns
    -------
    dict
        ``definition`` and ``satellite`` (digests), ``cases`` (count) and
        ``case_inputs`` (a digest over the ids and inputs of the first
        :data:`HEAD_CASES` cases). Every later case's inputs are checked against
        its stored digest as the cases stream by, and the digest over all of them
        (:class:`CaseDigest`) is recorded when the stream ends.
    """
    head = cases.head if isinstance(cases, CaseStream) else cases
    return {
        "definition": definition.fingerprint(),
        "satellite": _digest(satellite.model_dump(mode="json")),
        "cases": len(cases),
        "case_inputs": _digest([[c.case_id, c.digest] for c in head[:HEAD_CASES]]),
    }


def load_campaign(name_or_path: str | Path) -> CampaignDefinition:
    """A shipped preset by name, or a campaign TOML file.

    Parameters
    ----------
    name_or_path : str or Path
        A preset name (:func:`campaign_presets`) or the path of a campaign TOML file.

    Returns
    -------
    CampaignDefinition

    Raises
    ------
    ConfigError
        If no preset has that name and no such file exists, or the file is invalid.
    """
    presets = campaign_presets()
    if str(name_or_path) in presets:
        path = PRESETS_DIR / f"{name_or_path}.toml"
    else:
        path = Path(name_or_path)
        if not path.exists():
            raise ConfigError(
                f"campaign {str(name_or_path)!r} is neither a preset "
                f"({', '.join(presets)}) nor a file"
            )
    return validate_config(read_toml(path, "campaign"), source=str(path), model=CampaignDefinition)


def resolve_cases(
    definition: CampaignDefinition, satellite: SatelliteConfig, n_random: int | None = None
) -> list[ResolvedCase]:
    """Expand and validate every case; any bad modifier is refused before a case runs.

    The whole list, in memory: for small campaigns and analyses. Campaign runs
    stream them (:class:`CaseStream`).

    Parameters
    ----------
    definition : CampaignDefinition
        The campaign.
    satellite : SatelliteConfig
        The base satellite every case modifies.
    n_random : int, optional
        Number of random cases (``--cases``) of a campaign with a ``[random]`` table;
        default the definition's own.

    Returns
    -------
    list of ResolvedCase
        In run order, the nominal first when the campaign includes it.

    Raises
    ------
    ConfigError
        Naming the case and the problem (unknown path, invalid resulting value).
    """
    return list(CaseStream(definition, satellite, n_random, strict=True))


# The built-in kinds that generate cases, each its cases and one registration line
# (Sobol's and the worst-case search register in flexsat.campaigns.sobol and
# flexsat.campaigns.worstcase).


def _listed_cases(cases: list[CaseSpec], n_cases: int | None) -> CaseSource:
    """``[[cases]]``: each explicit case, stream (0, k)."""
    return CaseSource(len(cases), lambda k: (cases[k].id, (0, k), cases[k].plant,
                                             cases[k].scenario))  # fmt: skip


def _grid_cases(grid: Grid, n_cases: int | None) -> CaseSource:
    """``[grid]``: the cartesian product of the axes' levels, stream (seed, k)."""
    crossed = list(itertools.product(*(axis.levels for axis in grid.axes)))

    def spec(k: int) -> tuple[str, tuple[int, int], list, list]:
        levels = crossed[k]
        plant = [*grid.common.plant, *(m for lv in levels for m in lv.plant)]
        scenario = [*grid.common.scenario, *(m for lv in levels for m in lv.scenario)]
        return ("+".join(level.label for level in levels), (grid.seed, k), plant, scenario)

    return CaseSource(len(crossed), spec)


def _random_cases(rnd: RandomCases, n_cases: int | None) -> CaseSource:
    """``[random]``: ``n`` (or ``--cases``) draws, stream (root_seed, k)."""
    n = rnd.n if n_cases is None else n_cases
    if n < 1:
        raise ConfigError(f"--cases must be >= 1, got {n}")
    return CaseSource(n, lambda k: (f"random-{k:05d}", (rnd.root_seed, k), rnd.plant,
                                    rnd.scenario))  # fmt: skip


register_kind(CampaignKind("cases", CaseSpec, "explicit cases, one by one", _listed_cases,
                           counted_as="listed", words="listed"))  # fmt: skip
register_kind(CampaignKind("grid", Grid, "the levels of several axes, crossed", _grid_cases,
                           words="from the grid"))  # fmt: skip
register_kind(
    CampaignKind(
        "random",
        RandomCases,
        "Monte Carlo draws from distributions",
        _random_cases,
        streamed=True,
        id_prefix="random",
        words="drawn",
    )
)
