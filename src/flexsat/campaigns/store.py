"""The campaign store: one JSON file per finished case, tables rebuilt from them.

Each finished case is written to ``cases/<id>.json`` through a temporary file and
an atomic rename, so killing the process at any moment loses at most the cases in
flight and never leaves a half-written row. ``results.parquet`` (and
``results.csv`` beside it, for people) are rebuilt from the case files. The
decimated time history of each case is kept apart, in ``histories/<id>.nc``
(NetCDF, also written through a temporary name and an atomic rename).

``campaign.json`` holds the store's fingerprint: a digest of the campaign
definition, of the satellite config, the number of cases and a digest of the first
cases' inputs, checked before any case runs; every stored case's own inputs digest,
checked as the cases stream by; and, once a run has streamed every case, the
digest over all cases' inputs (``all_case_inputs``). Resuming is refused when any
of them differs, naming which. It also lists the runs made into the store (``runs``:
the cases each computed and resumed, its wall time). While a
campaign runs into the store, ``campaign.lock`` is locked (``flock``) and names
the process holding it, so a second run into the same store is refused instead of
recomputing the same cases. A killed run's lock is freed by the kernel shortly
after the run and its workers exit; a run started at once waits up to
:data:`_DEAD_HOLDER_WAIT_S` for it when the process named in the lock is gone.
"""

from __future__ import annotations

import contextlib
import datetime as dt
import fcntl
import json
import os
import re
import socket
import time
from collections.abc import Iterator
from pathlib import Path

import numpy as np
import pandas as pd
import xarray as xr

from flexsat.errors import ConfigError
from flexsat.files import ensure_dir, open_lock, output_root, replacing, replacing_name
from flexsat.strict_json import dumps

__all__ = ["HISTORY_UNITS", "CampaignStore"]

_ROW_KEYS = ("case_id", "status", "metrics", "inputs_digest")
_FINGERPRINT_PARTS = {
    "definition": "the campaign definition",
    "satellite": "the satellite config",
    "cases": "the number of cases",
    "case_inputs": "the cases' inputs",
}

HISTORY_UNITS = {
    "time": "s",
    "pointing_error_deg": "deg",
    "rate_error_deg_s": "deg/s",
    "tau_cmd": "N m",
    "tip_displacement_max": "m",
    "total_energy": "J",
}
"""Variables every stored case history has, and their units; the law's declared
diagnostics come with their own (the history's ``channels``)."""

_HISTORY_DESCRIPTIONS = {
    "pointing_error_deg": "2 asin |q_v,e|: absolute pointing error",
    "rate_error_deg_s": "|omega - omega_d|: residual rate (jitter)",
    "tau_cmd": "commanded body torque, frame B",
    "tip_displacement_max": "largest panel tip displacement magnitude over the appendages",
    "total_energy": "T + U",
}


class CampaignStore:
    """A folder holding one campaign's results (``docs/campaigns.md``, 'Resume rules').

    Parameters
    ----------
    root : str or Path
        The store folder (``--out`` of ``flexsat campaign``); created when written.

    Attributes
    ----------
    tables : tuple of Path
        results.parquet and results.csv: every stored case, one row each.
    """

    def __init__(self, root: str | Path) -> None:
        self.root = Path(root)
        self.cases_dir = self.root / "cases"
        self.histories_dir = self.root / "histories"
        self.tables = (self.root / "results.parquet", self.root / "results.csv")

    @contextlib.contextmanager
    def opened(self, fingerprint: dict, name: str, resume: bool) -> Iterator[None]:
        """Create (or check, when resuming) and lock the store for one run.

        Parameters
        ----------
        fingerprint : dict
            What defines the cases' results (keys of ``_FINGERPRINT_PARTS``).
        name : str
            The campaign's name.
        resume : bool
            Accept a store that already holds this very campaign.

        Raises
        ------
        ConfigError
            The folder cannot be created or written, holds another campaign (or
            this one without ``resume``), or another process is running into it.
        """
        try:
            output_root(self.root)  # below it, a link in place of a folder is refused
            ensure_dir(self.cases_dir)
            if self.histories_dir.is_symlink():
                ensure_dir(self.histories_dir)  # refused before anything is removed there
            lock = open_lock(self.root / "campaign.lock")  # never through a link
        except OSError as exc:
            raise ConfigError(
                f"cannot create the campaign store {self.root}: {exc.strerror or exc}"
            ) from None
        try:
            _acquire(lock, self.root)
            self._check(fingerprint, resume)
            self._remove_partials()
            try:
                marker = self.root / "campaign.json"
                record = json.loads(marker.read_text()) if resume and marker.exists() else {}
                record.update(name=name, fingerprint=fingerprint)
                _write_atomic(marker, json.dumps(record, indent=2))
            except OSError as exc:
                raise ConfigError(
                    f"cannot write the campaign store {self.root}: {exc.strerror or exc}"
                ) from None
            yield
        finally:
            lock.close()  # releases the flock

    def _check(self, fingerprint: dict, resume: bool) -> None:
        marker = self.root / "campaign.json"
        if not marker.exists():
            return
        if not resume:
            raise ConfigError(
                f"{self.root} already holds a campaign; use --resume or another --out"
            )
        try:
            stored = json.loads(marker.read_text())
            old = stored["fingerprint"]
        except (OSError, ValueError, KeyError, TypeError):
            raise ConfigError(f"{marker} is damaged; refusing to resume into {self.root}") from None
        if not isinstance(old, dict):
            old = {"definition": old}  # a store written by an older flexsat
        differs = [
            f"{what} (stored {old.get(key)!r}, given {fingerprint[key]!r})"
            for key, what in _FINGERPRINT_PARTS.items()
            if old.get(key) != fingerprint[key]
        ]
        if differs:
            raise ConfigError(
                f"{self.root} holds campaign {stored.get('name')!r} made with other inputs; "
                f"refusing to resume into it: {'; '.join(differs)}. Use another --out"
            )

    def _remove_partials(self) -> None:
        """Temporary files left by a killed run (never a finished case)."""
        for folder in (self.root, self.cases_dir, self.histories_dir):
            for path in folder.glob("*.partial"):
                with contextlib.suppress(OSError):
                    path.unlink()

    def finished(self) -> int:
        """Number of cases stored intact (a damaged case file is not finished: it is
        run again and overwritten)."""
        return sum(_read_row(path) is not None for path in self.cases_dir.glob("*.json"))

    def stored_ids(self) -> set[str]:
        """Ids of the case files present (intact or not), without reading them."""
        if not self.cases_dir.exists():
            return set()
        return {path.stem for path in self.cases_dir.glob("*.json")}

    def stored_digest(self, case_id: str) -> str | None:
        """The inputs digest of a case stored intact, or None (absent or damaged)."""
        row = _read_row(self.cases_dir / f"{case_id}.json")
        return None if row is None else row["inputs_digest"]

    def record_case_inputs(self, digest: str) -> None:
        """Once every case has streamed by: record the digest over all cases' inputs.

        Raises
        ------
        ConfigError
            A resumed store whose recorded digest differs (its cases were made
            with other inputs).
        """
        marker = self.root / "campaign.json"
        stored = json.loads(marker.read_text())
        old = stored.get("all_case_inputs")
        if old is not None and old != digest:
            raise ConfigError(
                f"{self.root} holds cases made with other inputs (digest over every case: "
                f"stored {old!r}, given {digest!r}); use another --out"
            )
        stored["all_case_inputs"] = digest
        _write_atomic(marker, json.dumps(stored, indent=2))

    def record_run(self, computed: int, resumed: int, wall_time_s: float) -> None:
        """Append one run's counts and wall time to ``campaign.json`` (``runs``).

        Parameters
        ----------
        computed : int
            Cases the run computed.
        resumed : int
            Cases it found stored (same inputs) and did not recompute.
        wall_time_s : float
            The run's wall time, from its start to its tables written [s].
        """
        marker = self.root / "campaign.json"
        stored = json.loads(marker.read_text())
        runs = stored.get("runs") if isinstance(stored.get("runs"), list) else []
        runs.append({"computed": int(computed), "resumed": int(resumed),
                     "wall_time_s": float(wall_time_s)})  # fmt: skip
        stored["runs"] = runs
        _write_atomic(marker, json.dumps(stored, indent=2))

    def runs(self) -> list[dict]:
        """The runs recorded into this store (:meth:`record_run`), oldest first; none for
        a store written before runs were recorded, or a damaged ``campaign.json``."""
        try:
            runs = json.loads((self.root / "campaign.json").read_text()).get("runs", [])
        except (OSError, ValueError, AttributeError):
            return []
        return [r for r in runs if isinstance(r, dict)] if isinstance(runs, list) else []

    def write_case(self, row: dict) -> None:
        _write_atomic(self.cases_dir / f"{row['case_id']}.json", dumps(row))

    def write_history(self, case_id: str, data: dict, status: str = "ok") -> Path:
        """Store a case's time history (arrays or lists keyed as :data:`HISTORY_UNITS`,
        and the law's diagnostics named with their units under ``channels``).

        Written to ``histories/<case_id>.nc`` (NetCDF-3, 64-bit offset: what
        :func:`xarray.open_dataset` reads as any NetCDF file) through a temporary
        file and an atomic rename. Per-axis variables (``tau_cmd``, ``jk``...) are
        (time, axis); the rest are (time,). Each carries ``units`` and
        ``description``; the file carries ``case_id``, ``status`` and ``title``.
        """
        described = {name: {"units": unit, "description": _HISTORY_DESCRIPTIONS.get(name, "")}
                     for name, unit in HISTORY_UNITS.items()}  # fmt: skip
        described.update(data.get("channels", {}))
        path = self.histories_dir / f"{case_id}.nc"
        with replacing_name(path) as tmp:
            _write_netcdf3(tmp, data, described, {
                "case_id": case_id, "status": status,
                "title": f"flexsat campaign case {case_id!r} (decimated history)"})  # fmt: skip
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
        """Every stored case row, sorted by case id (see :meth:`row`)."""
        return [self.row(path.stem) for path in sorted(self.cases_dir.glob("*.json"))]

    def row(self, case_id: str) -> dict:
        """The stored row of one case.

        Raises
        ------
        ConfigError
            Naming the case file when it is damaged (resuming recomputes it).
        """
        path = self.cases_dir / f"{case_id}.json"
        row = _read_row(path)
        if row is None:
            raise ConfigError(
                f"damaged case file {path} (not a complete case row); run the campaign "
                "again with --resume to recompute it"
            )
        return row

    def table(self) -> pd.DataFrame:
        """One row per stored case, sorted by case id; list values become columns."""
        rows = [{k: v for k, v in row.items() if k != "inputs"} for row in self.rows()]
        frame = pd.json_normalize(rows, sep=".")
        for column in list(frame.columns):
            if frame[column].map(lambda v: isinstance(v, list)).any():
                # a case without the value (one that failed before its metrics) gets NaN
                lists = [v if isinstance(v, list) else [] for v in frame[column]]
                width = max(map(len, lists))
                padded = [v + [np.nan] * (width - len(v)) for v in lists]
                expanded = pd.DataFrame(padded, index=frame.index)
                expanded.columns = [f"{column}[{k}]" for k in expanded.columns]
                frame = pd.concat([frame.drop(columns=column), expanded], axis=1)
        for column in frame.columns:  # a verdict not judged (None) stays null, not False
            if column.startswith("metrics.") and _nullable_verdict(frame[column]):
                frame[column] = frame[column].astype("boolean")
        return frame.sort_values("case_id").reset_index(drop=True) if len(frame) else frame

    def write_tables(self) -> pd.DataFrame:
        """Rebuild results.parquet and results.csv (:attr:`tables`) from the case files
        (atomically); return the table written (:meth:`table`)."""
        frame = self.table()
        for path, writer in zip(self.tables, (frame.to_parquet, frame.to_csv), strict=True):
            with replacing_name(path) as tmp:
                writer(tmp, index=False)
        return frame


_VERDICTS = ("metrics.r1_pass", "metrics.r2_pass", "metrics.r3_pass")
"""The requirement verdicts: True, False or None ("not judged", the run ended before
its observation window; ``docs/control.md``, 'How R1 and R2 are judged')."""


def _nullable_verdict(column: pd.Series) -> bool:
    """Whether a table column holds verdicts with nulls among them (object dtype).

    Such a column is cast to pandas' nullable ``boolean``: Parquet stores it as a
    boolean column with nulls (even when every case is null), never as False.
    """
    if column.dtype != object:
        return False
    values = column.dropna()
    return column.name in _VERDICTS or (
        len(values) > 0 and all(isinstance(v, bool) for v in values)
    )


def _read_row(path: Path) -> dict | None:
    """A stored case row, or None when the file is damaged (not JSON, not a row)."""
    try:
        row = json.loads(path.read_text())
    except (OSError, ValueError):
        return None
    if not isinstance(row, dict) or any(key not in row for key in _ROW_KEYS):
        return None
    if row["case_id"] != path.stem or not isinstance(row["metrics"], dict):
        return None
    return row


_DEAD_HOLDER_WAIT_S = 2.0
"""Time a run waits for the lock of a process that is gone [s]. The kernel frees a
killed process's ``flock`` after the process and the workers that share its open
files have exited, not at once: measured up to 0.05 s after they were reaped."""


def _acquire(lock, root: Path) -> None:
    """Lock the store for this process, or say which process holds it."""
    deadline = time.monotonic() + _DEAD_HOLDER_WAIT_S
    while True:
        try:
            fcntl.flock(lock.fileno(), fcntl.LOCK_EX | fcntl.LOCK_NB)
            break
        except OSError:
            lock.seek(0)
            holder = lock.read().strip() or "another process"
            if _gone(holder) and time.monotonic() < deadline:
                time.sleep(0.01)
                continue
            lock.close()
            raise ConfigError(
                f"{root} is in use by {holder}; wait for it to finish (or stop it) "
                "before running into this store"
            ) from None
    lock.seek(0)
    lock.truncate()
    started = dt.datetime.now(dt.UTC).strftime("%Y-%m-%d %H:%M:%S UTC")
    lock.write(f"process {os.getpid()} on {socket.gethostname()} (since {started})")
    lock.flush()


def _gone(holder: str) -> bool:
    """Whether the lock's holder, as :func:`_acquire` names it, is a process of this
    machine that no longer exists."""
    named = re.match(r"process (\d+) on (\S+) ", holder)
    if named is None or named[2] != socket.gethostname():
        return False
    try:
        os.kill(int(named[1]), 0)
    except ProcessLookupError:
        return True
    except OSError:  # it exists, as another user's
        return False
    return False


def _write_netcdf3(path: str, data: dict, described: dict, attrs: dict) -> None:
    """A history as a NetCDF-3 file, through scipy's writer.

    A campaign writes one small history per case, in its main process, while the
    workers fly the next ones: xarray's ``to_netcdf`` (HDF5 through netCDF4) took
    about 17 ms of that process's CPU per history, scipy's NetCDF-3 writer about
    1.2 ms (CHANGELOG.md, 'Histories in NetCDF-3'). Text attributes are
    stored as UTF-8 bytes (NetCDF-3 characters), which the readers decode.
    """
    from scipy.io import netcdf_file

    time = np.asarray(data.get("time", []), dtype=float)
    with netcdf_file(path, "w", version=2) as nc:
        for key, value in attrs.items():
            setattr(nc, key, _utf8(value))
        nc.createDimension("time", time.size)
        nc.createDimension("axis", 3)
        nc.createDimension("axis_strlen", 1)
        variable = nc.createVariable("time", "f8", ("time",))
        variable[:] = time
        variable.units = _utf8(HISTORY_UNITS["time"])
        axis = nc.createVariable("axis", "S1", ("axis", "axis_strlen"))
        axis[:] = np.array([[b"x"], [b"y"], [b"z"]])
        axis._Encoding = b"utf-8"  # read back as the strings 'x', 'y', 'z'
        for name, described_attrs in described.items():
            if name == "time" or name not in data:
                continue
            values = np.asarray(data[name], dtype=float)
            dims = ("time", "axis") if values.ndim == 2 else ("time",)
            variable = nc.createVariable(name, "f8", dims)
            variable[:] = values
            for key, value in described_attrs.items():
                setattr(variable, key, _utf8(value))
            variable._FillValue = np.nan  # a gap reads as missing, as xarray writes it


def _utf8(text: str) -> bytes:
    return str(text).encode("utf-8")


def _write_atomic(path: Path, text: str) -> None:
    with replacing(path, "w") as handle:  # a link at path is replaced, never followed
        handle.write(text)
        handle.flush()
        os.fsync(handle.fileno())
