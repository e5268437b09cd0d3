"""A run's records as plain arrays: what the metrics read, without an xarray dataset.

:class:`RunRecords` holds what a run's :class:`~flexsat.simulate.result.Result` dataset
holds (every variable: its dimension names, its array, its attributes; the run's
attributes) as numpy arrays in a frozen container. The metrics
(:func:`~flexsat.analysis.requirements.slew_metrics`,
:func:`~flexsat.analysis.effort.effort_metrics`) and a campaign case's history read
only ``.variables[name].values``, ``.variables[name].attrs``, ``.attrs`` and
``name in``, which an ``xarray.Dataset`` and a :class:`RunRecords` both offer under
those names: one metric code reads either. A campaign case computes its row from the
records and never builds the dataset (docs/performance.md, "Campaign cases").
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np

__all__ = ["Record", "RunRecords"]


@dataclass(frozen=True)
class Record:
    """One recorded variable: the names of its dimensions, its array, its attributes.

    The names of ``xarray.Variable``'s own fields, so that a metric reads a record of
    either kind alike.

    Attributes
    ----------
    dims : tuple of str
        Dimension names, one per axis of ``values`` (``("time", "axis")``) [-].
    values : ndarray
        The array, in the variable's ``units`` [SI or as ``attrs["units"]`` says].
    attrs : Mapping
        ``units`` and ``long_name`` (CF), or nothing for a label coordinate [-].
    """

    dims: tuple[str, ...]
    values: np.ndarray
    attrs: Mapping[str, Any]


@dataclass(frozen=True)
class RunRecords:
    """A run's variables and attributes as numpy arrays: a dataset's content, unbuilt.

    A dimension coordinate (``time``, ``axis``...) is the record whose only dimension
    bears its name, as in xarray; every other record is a data variable.

    Attributes
    ----------
    variables : Mapping of str to Record
        Every variable by name, dimension coordinates included (``time`` [s]) [-].
    attrs : Mapping
        The run's attributes (configs as JSON, status, message...) [-].
    """

    variables: Mapping[str, Record]
    attrs: Mapping[str, Any]

    def __contains__(self, name: object) -> bool:
        return name in self.variables

    def finite_part(self) -> RunRecords:
        """The records before the first one where a data variable is not finite.

        The cut of :func:`flexsat.analysis.openloop.finite_part` on a dataset: the
        float data variables over time are scanned (coordinates are not); a column
        not finite from the first record on (a quantity the model does not have) is
        not a divergence; the first record is always kept.

        Returns
        -------
        RunRecords
            Itself when every record is finite (no copy); else the leading finite
            records, each variable over time cut along its time axis (views).
        """
        n = self.variables["time"].values.shape[0]
        bad = np.zeros(n, dtype=bool)
        for name, var in self.variables.items():
            values = var.values
            if var.dims == (name,) or "time" not in var.dims or values.dtype.kind != "f":
                continue  # a coordinate, or not a float series over time
            axis = var.dims.index("time")
            by_time = (values if axis == 0 else np.moveaxis(values, axis, 0)).reshape(n, -1)
            if np.isfinite(by_time.sum()):  # all finite (a NaN or inf propagates; an
                continue  # overflowing sum only sends the variable to the full test)
            by_time = by_time[:, np.isfinite(by_time[0])]
            bad |= ~np.isfinite(by_time).all(axis=1)
        if not bad.any():
            return self
        keep = max(int(np.argmax(bad)), 1)
        return RunRecords({name: _head(var, keep) for name, var in self.variables.items()},
                          self.attrs)  # fmt: skip


def _head(var: Record, keep: int) -> Record:
    """``var``'s first ``keep`` records along its time axis (a view); as is without one."""
    if "time" not in var.dims:
        return var
    index = tuple(slice(0, keep) if dim == "time" else slice(None) for dim in var.dims)
    return Record(var.dims, var.values[index], var.attrs)
