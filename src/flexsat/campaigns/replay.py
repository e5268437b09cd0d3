"""Replaying one stored campaign case alone, from the inputs its row keeps."""

from __future__ import annotations

import re
from pathlib import Path

from flexsat.campaigns.store import CampaignStore
from flexsat.errors import ConfigError, shorten

__all__ = ["replay_case"]

_CASE_ID = re.compile(r"^[A-Za-z0-9_+\-][A-Za-z0-9_.+\-]*$")


def replay_case(store: str | Path, case_id: str):
    """Re-run one stored case alone from its stored inputs.

    Parameters
    ----------
    store : str or Path
        The campaign's store folder.
    case_id : str
        The id of the case (a row of ``results.parquet``).

    Returns
    -------
    Result
        The case's slew, as :func:`flexsat.simulate.run_slew` returns it.

    Raises
    ------
    ConfigError
        ``store`` holds no campaign, ``case_id`` is not a case id (no path
        separators) or not in the store, or its stored inputs are refused.
    """
    from flexsat.config.load import validate_config
    from flexsat.dynamics.plant import Plant
    from flexsat.simulate import SlewScenario, run_slew

    store = CampaignStore(store)
    if not (store.root / "campaign.json").is_file():
        raise ConfigError(f"{store.root} is not a campaign store (no campaign.json)")
    if not _CASE_ID.match(case_id):
        raise ConfigError(
            f"{shorten(repr(case_id))} is not a case id (letters, digits and _ . + -)"
        )
    path = store.cases_dir / f"{case_id}.json"
    if not path.exists():
        raise ConfigError(f"no case {case_id!r} in {store.root}")
    row = store.row(case_id)
    inputs = row.get("inputs") or {}
    source = f"case {case_id!r}"
    plant = Plant.from_config(validate_config(inputs.get("plant"), source=f"{source} (plant)"))
    scenario = validate_config(
        inputs.get("scenario"), source=f"{source} (scenario)", model=SlewScenario
    )
    return run_slew(plant, scenario)
