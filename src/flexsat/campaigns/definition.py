"""Campaign definitions: a base slew, and the cases that vary it (TOML, validated).

Cases come from any combination of:

- ``[[cases]]``: explicit cases, each with an ``id`` and its modifiers;
- ``[grid]``: the cartesian product of ``[[grid.axes]]``, each axis a list of
  levels (a label and modifiers); ``grid.common`` applies to every grid case;
- ``[random]``: ``n`` cases whose modifiers draw from distributions, one stream
  per case spawned from ``root_seed`` (``numpy.random.SeedSequence(root).spawn``).

``plant`` modifiers act on the satellite config, ``scenario`` modifiers on the slew
scenario. Expansion happens once, in the parent process: every backend and worker
count runs the very same resolved cases.
"""

from __future__ import annotations

import hashlib
import itertools
import json
from dataclasses import dataclass
from importlib import resources
from pathlib import Path
from typing import Annotated

import numpy as np
from pydantic import Field, model_validator

from flexsat.campaigns.modifiers import Modifier, apply_modifiers
from flexsat.config.load import read_toml, validate_config
from flexsat.config.models import SatelliteConfig, _Frozen
from flexsat.errors import ConfigError
from flexsat.simulate.closedloop import design_inertia
from flexsat.simulate.scenario import SlewScenario

__all__ = [
    "CAMPAIGN_PRESETS",
    "CampaignDefinition",
    "ResolvedCase",
    "campaign_fingerprint",
    "load_campaign",
    "resolve_cases",
]

CAMPAIGN_PRESETS = ("sensitivity", "montecarlo-critical", "deployment-shock", "montecarlo-random")


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

    @model_validator(mode="after")
    def _has_cases(self) -> CampaignDefinition:
        if not (self.cases or self.grid or self.random or self.include_nominal):
            raise ValueError("a campaign needs cases, a grid, random cases or the nominal")
        validate_config(self.base, source="base", model=SlewScenario)
        return self

    def fingerprint(self) -> str:
        """Hash of the definition, to refuse resuming a store made by another one."""
        text = json.dumps(self.model_dump(mode="json"), sort_keys=True)
        return hashlib.sha256(text.encode()).hexdigest()[:16]


@dataclass(frozen=True)
class ResolvedCase:
    """A case ready to run anywhere: validated plant config and scenario as plain dicts.

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
    """

    case_id: str
    root_seed: int
    stream_index: int
    plant: dict
    scenario: dict
    parameters: dict

    @property
    def digest(self) -> str:
        """Hash of everything that defines this case's result (plant and scenario)."""
        return _digest({"plant": self.plant, "scenario": self.scenario})


def _digest(data) -> str:
    return hashlib.sha256(json.dumps(data, sort_keys=True).encode()).hexdigest()[:16]


def campaign_fingerprint(
    definition: CampaignDefinition, satellite: SatelliteConfig, cases: list[ResolvedCase]
) -> dict:
    """What a store's results depend on, part by part, to refuse a mixed resume.

    Returns
    -------
    dict
        ``definition`` and ``satellite`` (digests), ``cases`` (count) and
        ``case_inputs`` (a digest over every case's id and inputs).
    """
    return {
        "definition": definition.fingerprint(),
        "satellite": _digest(satellite.model_dump(mode="json")),
        "cases": len(cases),
        "case_inputs": _digest([[case.case_id, case.digest] for case in cases]),
    }


def load_campaign(name_or_path: str | Path) -> CampaignDefinition:
    """A shipped preset by name, or a campaign TOML file.

    Parameters
    ----------
    name_or_path : str or Path
        A preset name (``sensitivity``, ``montecarlo-critical``, ``deployment-shock``,
        ``montecarlo-random``) or the path of a campaign TOML file.

    Returns
    -------
    CampaignDefinition

    Raises
    ------
    ConfigError
        If no preset has that name and no such file exists, or the file is invalid.
    """
    if str(name_or_path) in CAMPAIGN_PRESETS:
        path = Path(str(resources.files("flexsat.campaigns") / "presets" / f"{name_or_path}.toml"))
    else:
        path = Path(name_or_path)
        if not path.exists():
            raise ConfigError(
                f"campaign {str(name_or_path)!r} is neither a preset "
                f"({', '.join(CAMPAIGN_PRESETS)}) nor a file"
            )
    return validate_config(read_toml(path, "campaign"), source=str(path), model=CampaignDefinition)


def resolve_cases(
    definition: CampaignDefinition, satellite: SatelliteConfig, n_random: int | None = None
) -> list[ResolvedCase]:
    """Expand and validate every case; any bad modifier is refused before a case runs.

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
    plant_base = satellite.model_dump(mode="json")
    scenario_base = SlewScenario.model_validate(definition.base).model_dump(
        mode="json", by_alias=True
    )
    if scenario_base["design_inertia_kg_m2"] is None:  # the base configuration's design model
        scenario_base["design_inertia_kg_m2"] = design_inertia(satellite).tolist()
    # (id, (root seed, case index) of its random stream, plant and scenario modifiers)
    specs: list[tuple[str, tuple[int, int], list[Modifier], list[Modifier]]] = []
    if definition.include_nominal:
        specs.append(("nominal", (0, 0), [], []))
    specs += [(c.id, (0, k), c.plant, c.scenario) for k, c in enumerate(definition.cases)]
    if definition.grid is not None:
        grid = definition.grid
        for k, levels in enumerate(itertools.product(*(axis.levels for axis in grid.axes))):
            case_id = "+".join(level.label for level in levels)
            plant = [*grid.common.plant, *(m for lv in levels for m in lv.plant)]
            scenario = [*grid.common.scenario, *(m for lv in levels for m in lv.scenario)]
            specs.append((case_id, (grid.seed, k), plant, scenario))
    if definition.random is not None:
        rnd = definition.random
        n = rnd.n if n_random is None else n_random
        if n < 1:
            raise ConfigError(f"--cases must be >= 1, got {n}")
        for i in range(n):
            specs.append((f"random-{i:05d}", (rnd.root_seed, i), rnd.plant, rnd.scenario))
    ids = [spec[0] for spec in specs]
    if len(set(ids)) != len(ids):
        raise ConfigError(f"campaign {definition.name}: duplicate case ids")
    resolved = []
    for case_id, (root, index), plant_mods, scenario_mods in specs:
        # The stream SeedSequence(root).spawn(n)[index] would give, built directly.
        rng = np.random.default_rng(np.random.SeedSequence(root, spawn_key=(index,)))
        realised: dict = {}
        try:
            plant = apply_modifiers(plant_base, plant_mods, rng, realised)
            scenario = apply_modifiers(scenario_base, scenario_mods, rng, realised)
        except KeyError as exc:
            raise ConfigError(f"campaign case {case_id!r}: {exc.args[0]}") from None
        validate_config(plant, source=f"campaign case {case_id!r} (plant)")
        source = f"campaign case {case_id!r} (scenario)"
        validate_config(scenario, source=source, model=SlewScenario)
        resolved.append(ResolvedCase(case_id, root, index, plant, scenario, realised))
    return resolved
