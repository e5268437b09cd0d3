"""Robustness campaigns: definitions (TOML presets), runners (local or Dask), the store."""

from flexsat.campaigns.definition import (
    CAMPAIGN_PRESETS,
    CampaignDefinition,
    ResolvedCase,
    load_campaign,
    resolve_cases,
)
from flexsat.campaigns.runner import replay_case, run_campaign, run_case, summarize
from flexsat.campaigns.store import CampaignStore

__all__ = [
    "CAMPAIGN_PRESETS",
    "CampaignDefinition",
    "CampaignStore",
    "ResolvedCase",
    "load_campaign",
    "replay_case",
    "resolve_cases",
    "run_campaign",
    "run_case",
    "summarize",
]
