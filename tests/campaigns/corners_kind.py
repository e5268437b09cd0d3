"""A campaign kind written outside flexsat, as a user would: every corner of a box.

One module and one :func:`register_kind` line; no flexsat module names it. Cases
``corner-00000`` ... set each parameter to its low or high bound: corner k takes
parameter j at its high bound when bit j of k is set (2**D corners for D parameters).
"""

from __future__ import annotations

from typing import Annotated

from pydantic import Field

from flexsat.campaigns.definition import Dispersed, dispersed_modifiers
from flexsat.campaigns.kinds import CampaignKind, CaseSource, register_kind
from flexsat.config.models import _Frozen


class Corners(_Frozen):
    """The ``[corners]`` table: the parameters whose box's corners are flown."""

    parameters: Annotated[list[Dispersed], Field(min_length=1, max_length=8)]


def corner_values(corners: Corners, k: int) -> list[float]:
    """Parameter values of corner ``k`` (bit j of k set: parameter j at its high bound)."""
    return [p.bounds[(k >> j) & 1] for j, p in enumerate(corners.parameters)]


def corner_cases(corners: Corners, n_cases: int | None) -> CaseSource:
    return CaseSource(2 ** len(corners.parameters), lambda k: (
        f"corner-{k:05d}", (0, k), *dispersed_modifiers(corners.parameters,
                                                        corner_values(corners, k))))  # fmt: skip


def corner_summary(store, corners: Corners) -> dict:
    return {"corners": 2 ** len(corners.parameters)}


CORNERS = register_kind(CampaignKind("corners", Corners, "every corner of a box", corner_cases,
                                     words="corners", summarize=corner_summary))  # fmt: skip
