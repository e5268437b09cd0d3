"""The campaign store: one JSON file per finished case, tables rebuilt from them.

Each finished case is written to ``cases/<id>.json`` through a temporary file and
an atomic rename, so killing the process at any moment loses at most the cases in
flight and never leaves a half-written row. ``results.parquet`` (and
``results.csv`` beside it, for people) are rebuilt from the case files.
"""

from __future__ import annotations

import json
import math
import os
import tempfile
from pathlib import Path

import pandas as pd

from flexsat.errors import ConfigError

__all__ = ["CampaignStore"]


class CampaignStore:
    """A folder holding one campaign's results."""

    def __init__(self, root: str | Path) -> None:
        self.root = Path(root)
        self.cases_dir = self.root / "cases"

    def open(self, fingerprint: str, name: str, resume: bool) -> None:
        """Create the store, or check it belongs to the same campaign when resuming."""
        marker = self.root / "campaign.json"
        if marker.exists():
            stored = json.loads(marker.read_text())
            if not resume:
                raise ConfigError(
                    f"{self.root} already holds a campaign; use --resume or another --out"
                )
            if stored["fingerprint"] != fingerprint:
                raise ConfigError(
                    f"{self.root} holds campaign {stored['name']!r} with another definition; "
                    "refusing to resume into it"
                )
        self.cases_dir.mkdir(parents=True, exist_ok=True)
        _write_atomic(marker, json.dumps({"name": name, "fingerprint": fingerprint}))

    def finished(self) -> set[str]:
        """Ids of the cases already stored."""
        if not self.cases_dir.exists():
            return set()
        return {p.stem for p in self.cases_dir.glob("*.json")}

    def write_case(self, row: dict) -> None:
        _write_atomic(self.cases_dir / f"{row['case_id']}.json", json.dumps(_clean(row)))

    def rows(self) -> list[dict]:
        return [json.loads(p.read_text()) for p in sorted(self.cases_dir.glob("*.json"))]

    def table(self) -> pd.DataFrame:
        """One row per stored case, sorted by case id; list values become columns."""
        rows = [{k: v for k, v in row.items() if k != "inputs"} for row in self.rows()]
        frame = pd.json_normalize(rows, sep=".")
        for column in list(frame.columns):
            if frame[column].map(lambda v: isinstance(v, list)).any():
                expanded = pd.DataFrame(frame[column].tolist(), index=frame.index)
                expanded.columns = [f"{column}[{k}]" for k in expanded.columns]
                frame = pd.concat([frame.drop(columns=column), expanded], axis=1)
        return frame.sort_values("case_id").reset_index(drop=True) if len(frame) else frame

    def write_tables(self) -> tuple[Path, Path]:
        """Rebuild results.parquet and results.csv from the case files (atomically)."""
        frame = self.table()
        parquet, csv = self.root / "results.parquet", self.root / "results.csv"
        for path, writer in ((parquet, frame.to_parquet), (csv, frame.to_csv)):
            fd, tmp = tempfile.mkstemp(dir=self.root, suffix=".partial")
            os.close(fd)
            writer(tmp, index=False)
            os.replace(tmp, path)
        return parquet, csv


def _clean(value):
    """JSON-safe: NaN and inf become null."""
    if isinstance(value, float) and not math.isfinite(value):
        return None
    if isinstance(value, dict):
        return {k: _clean(v) for k, v in value.items()}
    if isinstance(value, list | tuple):
        return [_clean(v) for v in value]
    return value


def _write_atomic(path: Path, text: str) -> None:
    fd, tmp = tempfile.mkstemp(dir=path.parent, suffix=".partial")
    with os.fdopen(fd, "w") as handle:
        handle.write(text)
        handle.flush()
        os.fsync(handle.fileno())
    os.replace(tmp, path)
