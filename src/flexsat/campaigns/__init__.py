"""Robustness campaigns: definitions (TOML presets), runners (local or Dask), the store.

The campaign kinds (:mod:`flexsat.campaigns.kinds`) built in: explicit cases, grid
and random Monte Carlo (:mod:`~flexsat.campaigns.definition`), Saltelli's sample for
Sobol indices (:mod:`~flexsat.campaigns.sobol`) and the worst-case search
(:mod:`~flexsat.campaigns.worstcase`); importing this package registers them.
"""

from flexsat.campaigns.definition import (
    CAMPAIGN_PRESETS,
    CampaignDefinition,
    ResolvedCase,
    campaign_presets,
    load_campaign,
    resolve_cases,
)
from flexsat.campaigns.kinds import CampaignKind, CaseSource, kind_names, register_kind
from flexsat.campaigns.runner import replay_case, run_campaign, run_case, summarize
from flexsat.campaigns.sobol import SOBOL
from flexsat.campaigns.store import CampaignStore
from flexsat.campaigns.worstcase import WORST_CASE

__all__ = [
    "CAMPAIGN_PRESETS",
    "SOBOL",
    "WORST_CASE",
    "CampaignDefinition",
    "CampaignKind",
    "CampaignStore",
    "CaseSource",
    "ResolvedCase",
    "campaign_presets",
    "kind_names",
    "load_campaign",
    "register_kind",
    "replay_case",
    "resolve_cases",
    "run_campaign",
    "run_case",
    "summarize",
]
