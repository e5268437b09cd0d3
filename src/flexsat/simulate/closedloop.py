"""Closed-loop slews: a control law flies the flexible plant (thesis section 5.1)."""

from __future__ import annotations

import time

import numpy as np

from flexsat.config import nominal
from flexsat.control.laws import ASMC, DIAG_NAMES, PD, SMC
from flexsat.control.quaternion import target_quaternion
from flexsat.dynamics.plant import Plant
from flexsat.dynamics.rigid import rigid_inertia
from flexsat.simulate.common import PROGRESS_MIN_STEPS, chunk_steps, progress_bar, run_attributes
from flexsat.simulate.loops import CTRL_RECORD_SIZE, rk4_closed_loop
from flexsat.simulate.openloop import initial_state
from flexsat.simulate.result import Result, build_dataset
from flexsat.simulate.scenario import SlewScenario

__all__ = ["design_inertia", "run_slew"]

_KINDS = {"asmc": ASMC, "smc": SMC, "pd": PD}


def design_inertia() -> np.ndarray:
    """J_tot of the rigidized nominal satellite: the only model the controllers know."""
    return rigid_inertia(Plant.from_config(nominal()))


def run_slew(
    plant: Plant,
    scenario: SlewScenario | None = None,
    design_J: np.ndarray | None = None,
    progress: bool | None = None,
) -> Result:
    """Simulate a closed-loop slew of the flexible plant.

    Parameters
    ----------
    plant : Plant
        The truth model (may differ from the design model: uncertainty studies).
    scenario : SlewScenario, optional
        Default: the thesis's 45/45/45 deg ASMC slew with disturbances at maximum.
    design_J : ndarray, shape (3, 3), optional
        The controller's inertia; default :func:`design_inertia` (nominal, rigid).
    progress : bool, optional
        Progress bar; default only for runs of at least 200 000 steps.

    Returns
    -------
    Result
        As :func:`flexsat.simulate.run_openloop`, plus the control variables
        (sliding variable, Lambda, JK, torque breakdown, pointing error). A
        diverging run stops cleanly with its history and ``status = "failed"``.
    """
    scenario = scenario or SlewScenario()
    J = np.ascontiguousarray(design_inertia() if design_J is None else design_J, dtype=float)
    q0, qd0 = initial_state(plant, scenario)
    n = plant.n_dof
    steps, every, control = scenario.n_steps, scenario.record_every, scenario.control_every
    n_records = steps // every + 1
    rec_t = np.full(n_records, np.nan)
    rec_x = np.full((n_records, 2 * n + 2), np.nan)
    rec_ctrl = np.full((n_records, CTRL_RECORD_SIZE), np.nan)
    x = np.concatenate([q0, qd0, [0.0, 0.0]])
    gains = scenario.controller.gains(scenario.actuator)
    dist = scenario.disturbances.packed(scenario.actuator)
    q_d = tuple(target_quaternion(scenario.target_euler_deg))
    memory = np.zeros(2)
    held = np.zeros(CTRL_RECORD_SIZE)
    kind = _KINDS[scenario.controller.kind]
    chunk = chunk_steps(every, control)
    show = steps >= PROGRESS_MIN_STEPS if progress is None else progress
    done, rows, status = 0, 0, 0
    start = time.perf_counter()
    with progress_bar(show, scenario.duration_s) as (bar, task):
        while status == 0:
            n_chunk = min(chunk, steps - done)
            final = done + n_chunk == steps
            status, ran, written = rk4_closed_loop(
                x, done * scenario.dt_s, scenario.dt_s, n_chunk, final, control, every, kind,
                gains, J, q_d, dist, memory, held, plant.dynamics_args, rec_t, rec_x,
                rec_ctrl, rows,
            )  # fmt: skip
            done += ran
            rows += written
            if bar is not None:
                bar.update(task, completed=done * scenario.dt_s)
            if final:
                break
    wall = time.perf_counter() - start
    t_fail = done * scenario.dt_s if status else -1.0
    if status:  # keep the last good state as the final record
        rec_t[rows], rec_x[rows], rec_ctrl[rows] = t_fail, x, held
        rows += 1
    rec_t, rec_x, rec_ctrl = rec_t[:rows], rec_x[:rows], rec_ctrl[:rows]
    attrs = run_attributes(plant, scenario, "closed-loop", status, t_fail, wall, done)
    attrs["controller"] = scenario.controller.kind
    attrs["design_inertia"] = J.ravel().tolist()
    attrs["target_quaternion"] = list(q_d)
    ds = build_dataset(
        plant, rec_t, rec_x[:, :n], rec_x[:, n : 2 * n], rec_x[:, 2 * n], rec_x[:, 2 * n + 1],
        rec_ctrl[:, 0:3], rec_ctrl[:, 3:6], attrs,
    )  # fmt: skip
    diag = rec_ctrl[:, 6:]
    column = {name: diag[:, k] for k, name in enumerate(DIAG_NAMES)}

    def axes(prefix: str) -> np.ndarray:
        return np.column_stack([column[f"{prefix}_{a}"] for a in "xyz"])

    ta = ("time", "axis")
    ds["sliding_variable"] = (ta, axes("s"), {"units": "rad/s", "description": "s = w_e + L q_v,e"})
    ds["lambda_act"] = ("time", column["lambda"], {"units": "rad/s", "description": "Lambda_act"})
    ds["jk"] = (ta, axes("jk"), {"units": "N m", "description": "robust torque gain JK per axis"})
    ds["tau_gyro"] = (ta, axes("tau_gyro"), {"units": "N m", "description": "w x J w"})
    ds["tau_guide"] = (ta, axes("tau_guide"), {"units": "N m", "description": "-J L q_v,e_dot"})
    ds["tau_rob"] = (ta, axes("tau_rob"), {"units": "N m", "description": "-JK sat(s/Phi)"})
    ds["pointing_error_deg"] = (
        "time", np.degrees(column["theta_err"]),
        {"units": "deg", "description": "2 asin |q_v,e|: absolute pointing error"},
    )  # fmt: skip
    ds["rate_error_deg_s"] = (
        "time", np.degrees(np.linalg.norm(ds["omega"].values, axis=1)),
        {"units": "deg/s", "description": "|omega - omega_d|: residual rate (jitter)"},
    )  # fmt: skip
    return Result(ds)
