"""The campaign-kind contract: how a kind of campaign generates its cases and is summarized.

A kind is one module that builds a :class:`CampaignKind` and one
:func:`register_kind` line (the built-ins: ``cases``, ``grid`` and ``random`` in
:mod:`flexsat.campaigns.definition`, ``sobol`` in :mod:`flexsat.campaigns.sobol`,
``worst_case`` in :mod:`flexsat.campaigns.worstcase`, imported by
:mod:`flexsat.campaigns`, whose import line is a built-in's registration; a user's
kind in their own file, or an installed package's through the entry-point group
``flexsat.campaign_kinds``). A campaign TOML names a kind by its table,
``[<name>]``; the definition (:class:`~flexsat.campaigns.definition.CaseStream`), the
runner (:func:`~flexsat.campaigns.runner.run_campaign`) and the summary
(:func:`~flexsat.campaigns.summary.summarize`) look the kind up here; none of them
names one.

A kind either *generates* cases (``cases``), which every backend flies and the store
keeps, or *searches* (``search``), choosing its cases as it goes; a searching kind
runs alone. A case is given as its spec ``(case_id, (root_seed, stream_index),
plant_modifiers, scenario_modifiers)``: the random stream of the case is
``numpy.random.SeedSequence(root_seed, spawn_key=(stream_index,))`` and its modifiers
(:class:`~flexsat.campaigns.modifiers.Modifier`) act on the satellite config and the
slew scenario.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

from pydantic import BaseModel

from flexsat.control.registry import Registry

__all__ = ["KINDS", "CampaignKind", "CaseSource", "get_kind", "kind_names", "register_kind"]


@dataclass(frozen=True)
class CaseSource:
    """The cases a kind generates: how many, and the spec of the k-th.

    Parameters
    ----------
    count : int
        Number of cases.
    spec : callable
        ``spec(k) -> (case_id, (root_seed, stream_index), plant_modifiers,
        scenario_modifiers)`` for ``0 <= k < count``; ids unique within the campaign.
    """

    count: int
    spec: Callable[[int], tuple[str, tuple[int, int], list, list]]


@dataclass(frozen=True)
class CampaignKind:
    """A kind of campaign as the definition, the runner and the summary see it.

    Parameters
    ----------
    name : str
        The campaign TOML's table that selects it (``[grid]``), and its key in
        :meth:`CampaignDefinition.tables`.
    config : type of pydantic model
        The model of its table. The built-ins' tables are declared fields of
        :class:`~flexsat.campaigns.definition.CampaignDefinition`; any other kind's
        table is validated by this model.
    description : str
        One line for the docs.
    cases : callable, optional
        ``cases(table, n_cases) -> CaseSource``: the cases it generates (``n_cases``
        is ``--cases``, None when not given; a kind that has no use for it ignores it).
    streamed : bool
        True: the cases are drawn (resolved one at a time as the runner consumes them,
        ids ``<id_prefix>-NNNNN``, the first ones checked up front); False: every case
        is resolved and checked before any runs.
    id_prefix : str
        The prefix of a streamed kind's case ids (an explicit case may not take one of
        them).
    counted_as : str
        Its key in :meth:`CaseStream.counts` (default: ``name``).
    words : str
        How :func:`describe_counts` says where its cases come from (``"drawn"``).
    search : callable, optional
        ``search(definition, table, satellite, out, *, workers, resume, scheduler,
        dask_local, runner, backend) -> dict``: a kind that chooses its cases as it
        goes; it runs alone and flies them with ``backend`` (the runner's,
        :func:`flexsat.campaigns.backends.backend`).
    summarize : callable, optional
        ``summarize(store, table) -> dict``: what it adds to a campaign's summary,
        under its name (:func:`~flexsat.campaigns.summary.summarize` given the
        definition).
    """

    name: str
    config: type[BaseModel]
    description: str = ""
    cases: Callable[[Any, int | None], CaseSource] | None = None
    streamed: bool = False
    id_prefix: str = ""
    counted_as: str = ""
    words: str = ""
    search: Callable[..., dict] | None = None
    summarize: Callable[[Any, Any], dict] | None = None

    @property
    def count_key(self) -> str:
        """Its key in :meth:`CaseStream.counts`."""
        return self.counted_as or self.name


KINDS: Registry[CampaignKind] = Registry("campaign kind", "flexsat.campaign_kinds")
"""Every registered campaign kind, built-ins first; installed packages add theirs
through ``flexsat.campaign_kinds``."""


def register_kind(kind: CampaignKind) -> CampaignKind:
    """Register a campaign kind under ``kind.name`` (replacing one of that name).

    Parameters
    ----------
    kind : CampaignKind
        The kind.

    Returns
    -------
    CampaignKind
        ``kind``, so a module can keep it: ``X = register_kind(CampaignKind(...))``.

    Raises
    ------
    ValueError
        If it neither generates nor searches cases, or does both, or is streamed
        without an id prefix.
    """
    if (kind.cases is None) == (kind.search is None):
        raise ValueError(f"campaign kind {kind.name!r}: give exactly one of cases and search")
    if kind.streamed and not kind.id_prefix:
        raise ValueError(f"campaign kind {kind.name!r}: a streamed kind needs an id_prefix")
    return KINDS.register(kind.name, kind)


def get_kind(name: str) -> CampaignKind:
    """The registered campaign kind ``name``.

    Parameters
    ----------
    name : str
        The kind's name, the TOML table that selects it (``"random"``, ``"sobol"``...).

    Returns
    -------
    CampaignKind
        Its registered declaration.

    Raises
    ------
    ValueError
        If no kind of that name is registered (the message lists the kinds).
    """
    return KINDS.get(name)


def kind_names() -> tuple[str, ...]:
    """Names of every registered campaign kind, built-ins first."""
    return KINDS.names()
