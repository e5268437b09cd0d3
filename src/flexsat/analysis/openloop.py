"""Summary metrics of an open-loop run (thesis section 3.3), from its dataset."""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from flexsat.analysis.run_records import RunRecords
from flexsat.analysis.spectral import dominant_frequency

if TYPE_CHECKING:  # read through .variables and .attrs: no xarray at run time
    import xarray as xr

__all__ = ["finite_part", "openloop_metrics"]

_RIPPLE_MIN_HZ = 0.05  # below this a "line" is drift, not a structural ripple


def openloop_metrics(ds: xr.Dataset | RunRecords) -> dict:
    """Numbers a reviewer compares with the thesis, SI unless the key says otherwise.

    Keys: ``final_angular_momentum_nms`` (3, inertial), ``final_rate_deg_s`` (3, body),
    ``total_energy_j`` (final), ``peak_elastic_energy_j``, ``dissipated_energy_j``
    (final cumulative), ``peak_flex_torque_nm`` (3, max ‖tau_flex‖ per body axis),
    ``peak_tip_displacement_m``, ``peak_root_rotation_deg``, ``dominant_frequency_hz``
    (of the yaw-acceleration ripple after the commanded torque ends; NaN if the
    torque never ends or too little time is left), ``energy_balance_error_j``
    (max ‖E - E0 - W_in + W_diss‖), ``wall_time_s``, ``steps``, ``status``, ``message``.

    A diverged run's metrics are those of its finite part (:func:`finite_part`);
    ``finite_until_s`` says where that ends.

    Parameters
    ----------
    ds : xarray.Dataset or RunRecords
        An open-loop result's dataset (:attr:`Result.dataset`), or its records
        (``run_openloop(..., records=True)``): the same numbers from either.

    Returns
    -------
    dict
        The metrics above, each key naming its unit.
    """
    ds = finite_part(ds)
    var = ds.variables  # xarray.Variable or Record: .values alike
    t = var["time"].values
    commanded = np.abs(var["tau_cmd"].values).max(axis=1) > 0.0
    free_from = 0.0
    if commanded.any() and not commanded[-1]:
        free_from = t[np.nonzero(commanded)[0][-1] + 1]
    free = t >= free_from
    dominant = float("nan")
    if free.sum() >= 64:
        dt = float(t[1] - t[0])
        dominant = dominant_frequency(var["omega_dot"].values[free, 2], dt, _RIPPLE_MIN_HZ)
    return {
        "final_angular_momentum_nms": var["angular_momentum"].values[-1].tolist(),
        "final_rate_deg_s": np.degrees(var["omega"].values[-1]).tolist(),
        "total_energy_j": float(var["total_energy"].values[-1]),
        "peak_elastic_energy_j": float(var["elastic_energy"].values.max()),
        "dissipated_energy_j": float(var["dissipated_energy"].values[-1]),
        "peak_flex_torque_nm": np.abs(var["tau_flex"].values).max(axis=0).tolist(),
        "peak_tip_displacement_m": float(
            np.linalg.norm(var["tip_displacement"].values, axis=-1).max()
        ),
        "peak_root_rotation_deg": float(np.degrees(np.abs(var["rho"].values).max())),
        "dominant_frequency_hz": dominant,
        "energy_balance_error_j": float(np.abs(var["energy_balance_error"].values).max()),
        "finite_until_s": float(t[-1]),
        "wall_time_s": float(ds.attrs["wall_time_s"]),
        "steps": int(ds.attrs["steps"]),
        "status": str(ds.attrs["status"]),
        "message": str(ds.attrs["message"]),
    }


def finite_part(ds: xr.Dataset | RunRecords) -> xr.Dataset | RunRecords:
    """The records before the first one where any time-dependent variable is not finite.

    A diverging run's last records can overflow (energies, momenta of a state that
    blew up); metrics are computed on what came before. The first record is always
    kept. A column that is not finite from the first record on (a quantity the model
    does not have, such as the root rotation of a modal appendage) is not a divergence.

    Parameters
    ----------
    ds : xarray.Dataset or RunRecords
        A run's dataset, or its records.

    Returns
    -------
    xarray.Dataset or RunRecords
        Its finite leading records (a :class:`~flexsat.analysis.run_records.RunRecords`
        given: its own, :meth:`~flexsat.analysis.run_records.RunRecords.finite_part`).
    """
    if isinstance(ds, RunRecords):  # a campaign case's records, no dataset built
        return ds.finite_part()
    bad = np.zeros(ds.sizes["time"], dtype=bool)
    # the variables themselves: ds.data_vars.values() builds a DataArray for each
    for var in ds.data_vars.variables.values():
        if "time" in var.dims and np.issubdtype(var.dtype, np.floating):
            by_time = var if var.dims[0] == "time" else var.transpose("time", ...)
            values = by_time.values.reshape(ds.sizes["time"], -1)
            if np.isfinite(values.sum()):  # all finite (a NaN or inf propagates; an
                continue  # overflowing sum only sends the variable to the full test)
            values = values[:, np.isfinite(values[0])]
            bad |= ~np.isfinite(values).all(axis=1)
    if not bad.any():
        return ds  # a finite run: nothing to cut (and no copy)
    return ds.isel(time=slice(0, max(int(np.argmax(bad)), 1)))
