"""What a slew costs and what it leaves: control energy and residual elastic energy.

The law-comparison figures of merit (``docs/control.md``, "Comparing the laws over
the campaigns"): the control energy int ‖tau . omega‖ dt that the hub actuators
spend (absolute power: a wheel spends energy braking too), and the residual
elastic energy, the largest elastic energy U over the last
:data:`RESIDUAL_WINDOW_S` of the run (U oscillates between 0 and its envelope at
twice each mode's frequency; the window spans more than two periods of the
slowest coupled mode of the nominal satellite, 0.26 Hz).
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

if TYPE_CHECKING:
    import xarray as xr

    from flexsat.analysis.run_records import RunRecords

__all__ = ["RESIDUAL_WINDOW_S", "effort_metrics"]

RESIDUAL_WINDOW_S = 10.0
"""Length of the run's final window the residual elastic energy is taken over [s]."""


def effort_metrics(ds: xr.Dataset | RunRecords) -> dict[str, float]:
    """Control energy [J] and residual elastic energy [J] of a closed-loop run.

    Parameters
    ----------
    ds : xarray.Dataset or RunRecords
        A closed-loop result, or its records
        (:class:`~flexsat.analysis.run_records.RunRecords`: read alike):
        ``tau_applied`` and ``omega`` (time, axis), frame B; ``elastic_energy`` (time,).

    Returns
    -------
    dict
        ``control_energy_j``: int_0^T ‖tau_applied . omega‖ dt (trapezoid over the
        records); ``residual_elastic_energy_j``: max U over the last
        :data:`RESIDUAL_WINDOW_S` [J].
    """
    v = ds.variables  # the arrays (a dataset's: without building a DataArray per lookup)
    t = np.asarray(v["time"].values, dtype=float)
    power = np.abs(np.sum(v["tau_applied"].values * v["omega"].values, axis=1))
    elastic = np.asarray(v["elastic_energy"].values, dtype=float)
    last = t >= t[-1] - RESIDUAL_WINDOW_S - 1e-9
    return {
        "control_energy_j": float(np.trapezoid(power, t)) if t.size > 1 else 0.0,
        "residual_elastic_energy_j": float(elastic[last].max()),
    }
