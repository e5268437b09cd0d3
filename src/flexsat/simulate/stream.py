"""Long records streamed to disk: a NetCDF file that grows block by block along time.

A run whose records would not fit in memory (:func:`flexsat.simulate.run_setup.check_run_size`)
is recorded into a bounded buffer; each full buffer becomes a dataset block
(:func:`flexsat.simulate.result.build_dataset`) appended to one NetCDF file, whose
``time`` dimension is unlimited. The first block creates the file with xarray (so
its variables, coordinates, CF attributes and encodings are those of any flexsat
result), later blocks are appended with netCDF4, and the run's final attributes
(status, message, wall time, steps) are written when it ends. The result then reads
the file lazily: memory holds one block while running, and one variable at a time
when its metrics are computed.
"""

from __future__ import annotations

import os
import shutil
import tempfile
from pathlib import Path

import xarray as xr

from flexsat.errors import ConfigError
from flexsat.files import ensure_dir

__all__ = ["RecordStream", "check_disk_space"]

_CHUNK_RECORDS = 4096  # records per HDF5 chunk (about 1-150 kB per variable)


def check_disk_space(folder: Path, needed_bytes: float) -> None:
    """Refuse a streamed run whose records would not fit on the disk of ``folder``.

    Parameters
    ----------
    folder : Path
        Where the records are written.
    needed_bytes : float
        The records' estimated size [bytes].

    Raises
    ------
    ConfigError
        With the estimate, the free space and the fix.
    """
    free = float(shutil.disk_usage(folder).free)
    if needed_bytes > 0.9 * free:
        raise ConfigError(
            f"record_dt_s: the run would write about {needed_bytes / 2**30:.3g} GiB of records "
            f"to {folder} ({free / 2**30:.3g} GiB free there); record less often (a larger "
            "record_dt_s) or shorten duration_s"
        )


class RecordStream:
    """One NetCDF file that dataset blocks are appended to, in time order.

    Parameters
    ----------
    path : Path
        The file (replaced if it exists, a symbolic link there too: never followed);
        written under a new temporary name beside it until :meth:`finish` moves it there.
    """

    def __init__(self, path: str | Path) -> None:
        self.path = Path(path)
        self.partial: Path | None = None  # a new temporary file beside path, at the first block
        self.records = 0
        self.energy0: float | None = None  # E(0) of the run, for every block's balance
        self._file = None  # the netCDF4 handle blocks after the first are appended through

    def append(self, block: xr.Dataset) -> None:
        """Append a block (a dataset of consecutive records after those written)."""
        if self.records == 0:
            ensure_dir(self.path.parent)
            fd, name = tempfile.mkstemp(dir=self.path.parent, prefix=f".{self.path.name}.",
                                        suffix=".partial")  # fmt: skip
            os.close(fd)
            self.partial = Path(name)
            # HDF5 chunks of _CHUNK_RECORDS along time: the default along an unlimited
            # dimension is one record per chunk, 10-100 times slower to write and read.
            encoding = {
                name: {"chunksizes": tuple(_CHUNK_RECORDS if d == "time" else block.sizes[d]
                                           for d in var.dims)}
                for name, var in block.variables.items() if "time" in var.dims
            }  # fmt: skip
            block.to_netcdf(self.partial, unlimited_dims=["time"], encoding=encoding)
            self.energy0 = float(block["total_energy"].values[0])
        else:
            if self._file is None:
                self._file = _open_appending(self.partial)
            start, stop = self.records, self.records + block.sizes["time"]
            for name, var in block.variables.items():
                if "time" in var.dims:
                    self._file[name][start:stop] = var.transpose("time", ...).values
        self.records += block.sizes["time"]

    def finish(self, attrs: dict) -> xr.Dataset:
        """Write the run's final attributes, move the file in place, open it lazily."""
        nc = self._file if self._file is not None else _open_appending(self.partial)
        self._file = None
        with nc:
            nc.setncatts({k: v for k, v in attrs.items() if v is not None})
        self.partial.replace(self.path)
        return xr.open_dataset(self.path)


def _open_appending(path: Path):
    """The netCDF4 handle of ``path``, opened to append. netCDF4 is imported here:
    only a streamed run needs it, and every process importing the simulator (a
    campaign worker, any CLI command) would otherwise pay for it."""
    import netCDF4

    return netCDF4.Dataset(path, "a")
