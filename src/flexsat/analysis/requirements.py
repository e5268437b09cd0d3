"""Pointing requirements of a slew (thesis sec. 5.1.1): R1 pointing, R2 jitter, R3 torque."""

from __future__ import annotations

import numpy as np
import xarray as xr

__all__ = ["settling_time", "slew_metrics"]


def settling_time(t: np.ndarray, values: np.ndarray, bound: float) -> float:
    """First time after which ``values`` stays below ``bound`` to the end [s]; NaN if never."""
    above = np.nonzero(~(values < bound))[0]
    if above.size == 0:
        return float(t[0])
    if above[-1] == values.size - 1:
        return float("nan")
    return float(t[above[-1] + 1])


def slew_metrics(ds: xr.Dataset, pointing_deg: float, jitter_deg_s: float, t_max_nm: float) -> dict:
    """Requirement verdicts and figures of merit of a closed-loop run.

    R1: pointing error below ``pointing_deg`` at the end; R2: residual rate below
    ``jitter_deg_s`` at the end; R3: |applied torque| <= T_max on every axis at every
    record. Settling times are when each quantity enters its band for good (NaN if
    it does not by the end): ``settling_time_s`` is R1's, ``r2_settling_time_s`` R2's.
    ``max_abs_torque_nm`` is the applied torque's (R3), ``lambda_switch_time_s`` when
    Lambda first leaves its initial value. Keys end in their unit.
    """
    t = ds["time"].values
    pointing = ds["pointing_error_deg"].values
    jitter = ds["rate_error_deg_s"].values
    # a law without an adaptive slope records no lambda_act: no switch time
    lam = ds["lambda_act"].values if "lambda_act" in ds else np.zeros(t.size)
    applied = np.abs(ds["tau_applied"].values)
    commanded = np.abs(ds["tau_cmd"].values)
    leaves = np.nonzero(lam > lam[0] * (1 + 1e-9))[0]
    r1_time = settling_time(t, pointing, pointing_deg)
    r2_time = settling_time(t, jitter, jitter_deg_s)
    return {
        "controller": str(ds.attrs.get("controller", "")),
        "final_pointing_error_deg": float(pointing[-1]),
        "final_rate_error_deg_s": float(jitter[-1]),
        "settling_time_s": r1_time,
        "r2_settling_time_s": r2_time,
        "r1_pass": bool(pointing[-1] < pointing_deg),
        "r2_pass": bool(jitter[-1] < jitter_deg_s),
        "max_abs_torque_nm": applied.max(axis=0).tolist(),
        "max_commanded_torque_nm": commanded.max(axis=0).tolist(),
        "r3_pass": bool(np.all(applied <= t_max_nm * (1 + 1e-12))),
        "lambda_switch_time_s": float(t[leaves[0]]) if leaves.size else float("nan"),
        "final_euler_deg": ds["euler_deg"].values[-1].tolist(),
        "peak_flex_torque_nm": np.abs(ds["tau_flex"].values).max(axis=0).tolist(),
        "peak_tip_displacement_m": float(
            np.linalg.norm(ds["tip_displacement"].values, axis=-1).max()
        ),
        "wall_time_s": float(ds.attrs["wall_time_s"]),
        "steps": int(ds.attrs["steps"]),
        "status": str(ds.attrs["status"]),
        "message": str(ds.attrs["message"]),
    }
