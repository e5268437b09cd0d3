"""The campaign store: one JSON file per finished case, tables rebuilt from them.

Each finished case is written to ``cases/<id>.json`` through a temporary file and
an atomic rename, so killing the process at any moment loses at most the cases in
flight and never leaves a half-written row. ``results.parquet`` (and
``results.csv`` beside it, for people) are rebuilt from the case files. The
decimated time history of each case is kept apart, in ``histories/<id>.nc``
(NetCDF, also written through a temporary name and an atomic rename).
"""

from __future__ import annotations

import json
import os
import tempfile
from pathlib import Path

import numpy as np
import pandas as pd
import xarray as xr

from flexsat.errors import ConfigError
from flexsat.jsonable import jsonable

__all__ = ["HISTORY_UNITS", "CampaignStore"]

HISTORY_UNITS = {
    "time": "s",
    "pointing_error_deg": "deg",
    "rate_error_deg_s": "deg/s",
    "tau_cmd": "N m",
    "tip_displacement_max": "m",
    "total_energy": "J",
    "lambda_act": "rad/s",
    "jk": "N m",
}
"""Variables of a stored case history and their units."""

_HISTORY_DESCRIPTIONS = {
    "pointing_error_deg": "2 asin |q_v,e|: absolute pointing error",
    "rate_error_deg_s": "|omega - omega_d|: residual rate (jitter)",
    "tau_cmd": "commanded body torque, frame B",
    "tip_displacement_max": "largest panel tip displacement magnitude over the appendages",
    "total_energy": "T + U",
    "lambda_act": "Lambda_act",
    "jk": "robust torque gain JK per axis",
}


class CampaignStore:
    """A folder holding one campaign's results."""

    def __init__(self, root: str | Path) -> None:
        self.root = Path(root)
        self.cases_dir = self.root / "cases"
        self.histories_dir = self.root / "histories"

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
        _write_atomic(self.cases_dir / f"{row['case_id']}.json", json.dumps(jsonable(row)))

    def write_history(self, case_id: str, data: dict, status: str = "ok") -> Path:
        """Store a case's time history (plain lists keyed as :data:`HISTORY_UNITS`).

        Written to ``histories/<case_id>.nc`` through a temporary file and an atomic
        rename. ``tau_cmd`` and ``jk`` are (time, axis); the rest are (time,).
        """
        self.histories_dir.mkdir(parents=True, exist_ok=True)
        ds = xr.Dataset(
            coords={"time": ("time", np.asarray(data.get("time", []), dtype=float),
                             {"units": HISTORY_UNITS["time"]}),
                    "axis": ("axis", ["x", "y", "z"])},
            attrs={"case_id": case_id, "status": status,
                   "title": f"flexsat campaign case {case_id!r} (decimated history)"},
        )  # fmt: skip
        for name, unit in HISTORY_UNITS.items():
            if name == "time" or name not in data:
                continue
            values = np.asarray(data[name], dtype=float)
            dims = ("time", "axis") if name in ("tau_cmd", "jk") else ("time",)
            values = values.reshape(-1, 3) if len(dims) == 2 else values
            attrs = {"units": unit, "description": _HISTORY_DESCRIPTIONS[name]}
            ds[name] = (dims, values, attrs)
        path = self.histories_dir / f"{case_id}.nc"
        fd, tmp = tempfile.mkstemp(dir=self.histories_dir, suffix=".partial")
        os.close(fd)
        try:
            ds.to_netcdf(tmp)
            os.replace(tmp, path)
        finally:
            if os.path.exists(tmp):
                os.remove(tmp)
        return path

    def histories(self) -> dict[str, xr.Dataset]:
        """Stored case histories by case id (loaded into memory)."""
        if not self.histories_dir.exists():
            return {}
        loaded = {}
        for path in sorted(self.histories_dir.glob("*.nc")):
            with xr.open_dataset(path) as ds:
                loaded[path.stem] = ds.load()
        return loaded

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


def _write_atomic(path: Path, text: str) -> None:
    fd, tmp = tempfile.mkstemp(dir=path.parent, suffix=".partial")
    with os.fdopen(fd, "w") as handle:
        handle.write(text)
        handle.flush()
        os.fsync(handle.fileno())
    os.replace(tmp, path)
