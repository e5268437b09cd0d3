"""Closed-loop slews: a control law flies the flexible plant (thesis section 5.1)."""

from __future__ import annotations

import math
import time
from typing import Protocol

import numpy as np

from flexsat.config import nominal
from flexsat.control.actuation import applied_torque
from flexsat.control.laws import ASMC, DIAG_NAMES, PD, SMC
from flexsat.control.quaternion import (
    euler_zyx_to_quaternion,
    quaternion_error,
    target_quaternion,
)
from flexsat.dynamics.integrators import rk4_hold
from flexsat.dynamics.linalg3 import euler_rate_matrix
from flexsat.dynamics.plant import Plant
from flexsat.dynamics.rigid import rigid_inertia
from flexsat.errors import SimulationError
from flexsat.simulate.common import PROGRESS_MIN_STEPS, chunk_steps, progress_bar, run_attributes
from flexsat.simulate.loops import CTRL_RECORD_SIZE, rk4_closed_loop
from flexsat.simulate.openloop import initial_state
from flexsat.simulate.result import Result, build_dataset
from flexsat.simulate.scenario import SlewScenario

__all__ = ["Controller", "design_inertia", "run_slew"]


class Controller(Protocol):
    """A plain-Python control law, for prototyping your own (slower than the built-ins).

    Called at every control instant with the time [s], the measured attitude
    quaternion ``q`` (scalar first, shape (4,)) and body rate ``omega_B`` [rad/s],
    shape (3,); returns the commanded body torque [N m], shape (3,). The loop clips
    it to the software limit RF * T_max, then applies the actuator and disturbance
    model of the scenario. Keep any state you need on the object. See
    ``examples/python_controller.py``.
    """

    def __call__(self, t: float, q: np.ndarray, omega_B: np.ndarray) -> np.ndarray: ...

_KINDS = {"asmc": ASMC, "smc": SMC, "pd": PD}


def design_inertia() -> np.ndarray:
    """J_tot of the rigidized nominal satellite: the only model the controllers know."""
    return rigid_inertia(Plant.from_config(nominal()))


def run_slew(
    plant: Plant,
    scenario: SlewScenario | None = None,
    design_J: np.ndarray | None = None,
    progress: bool | None = None,
    controller: Controller | None = None,
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
    controller : Controller, optional
        A plain-Python law used instead of ``scenario.controller`` (whose compiled
        form runs inside the RK4 loop). Its diagnostics (s, Lambda, JK, breakdown)
        are recorded as NaN.

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
    steps, every = scenario.n_steps, scenario.record_every
    n_records = steps // every + 2  # + the last good state of a failed run
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
    show = steps >= PROGRESS_MIN_STEPS if progress is None else progress
    start = time.perf_counter()
    with progress_bar(show, scenario.duration_s) as (bar, task):
        run = _compiled_loop if controller is None else _python_loop
        status, done, rows = run(
            plant, scenario, x, kind, gains, J, q_d, dist, memory, held, rec_t, rec_x,
            rec_ctrl, bar, task, controller,
        )  # fmt: skip
    wall = time.perf_counter() - start
    t_fail = done * scenario.dt_s if status else -1.0
    if status:  # keep the last good state as the final record
        rec_t[rows], rec_x[rows], rec_ctrl[rows] = t_fail, x, held
        rows += 1
    rec_t, rec_x, rec_ctrl = rec_t[:rows], rec_x[:rows], rec_ctrl[:rows]
    attrs = run_attributes(plant, scenario, "closed-loop", status, t_fail, wall, done)
    attrs["controller"] = scenario.controller.kind if controller is None else "python"
    attrs["design_inertia"] = J.ravel().tolist()
    attrs["target_quaternion"] = list(q_d)
    # gain (3), environment (3), sloshing ratio and Hz, residual (3), T_max
    attrs["realised_disturbances"] = dist.tolist()
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
    with np.errstate(over="ignore", invalid="ignore"):  # a diverged run's last state
        rate_error = np.degrees(np.linalg.norm(ds["omega"].values, axis=1))
    ds["rate_error_deg_s"] = (
        "time", rate_error,
        {"units": "deg/s", "description": "|omega - omega_d|: residual rate (jitter)"},
    )  # fmt: skip
    return Result(ds)


def _compiled_loop(plant, scenario, x, kind, gains, J, q_d, dist, memory, held, rec_t, rec_x,
                   rec_ctrl, bar, task, controller):  # fmt: skip
    """The whole loop, controller included, in compiled chunks."""
    steps, every, control = scenario.n_steps, scenario.record_every, scenario.control_every
    chunk = chunk_steps(every, control)
    done, rows, status = 0, 0, 0
    while status == 0:
        n_chunk = min(chunk, steps - done)
        final = done + n_chunk == steps
        status, ran, written = rk4_closed_loop(
            x, done * scenario.dt_s, scenario.dt_s, n_chunk, final, control, every, kind,
            gains, J, q_d, dist, memory, held, plant.packed, rec_t, rec_x, rec_ctrl, rows,
        )  # fmt: skip
        done += ran
        rows += written
        if bar is not None:
            bar.update(task, completed=done * scenario.dt_s)
        if final:
            break
    return status, done, rows


def _python_loop(plant, scenario, x, kind, gains, J, q_d, dist, memory, held, rec_t, rec_x,
                 rec_ctrl, bar, task, controller):  # fmt: skip
    """Python controller at each control instant; the plant steps compiled in between."""
    n = plant.n_dof
    steps, every, control = scenario.n_steps, scenario.record_every, scenario.control_every
    block = math.gcd(every, control)
    limit = scenario.actuator.reduction_factor * scenario.actuator.t_max_nm
    held[6:] = np.nan
    rows, status, k = 0, 0, 0
    while True:
        t = k * scenario.dt_s
        if k % control == 0:
            q_meas = np.array(euler_zyx_to_quaternion(x[3], x[4], x[5]))
            omega_B = np.array(euler_rate_matrix(x[3], x[4])) @ x[n + 3 : n + 6]
            tau_cmd = np.asarray(controller(t, q_meas, omega_B), dtype=float)
            if tau_cmd.shape != (3,) or not np.all(np.isfinite(tau_cmd)):
                raise SimulationError(f"controller returned {tau_cmd!r} at t = {t:.6g} s")
            tau_cmd = np.clip(tau_cmd, -limit, limit)
            held[0:3] = tau_cmd
            held[3:6] = applied_torque(tuple(tau_cmd), t, dist)
            e = quaternion_error(q_d, tuple(q_meas))
            held[6 + DIAG_NAMES.index("theta_err")] = 2.0 * math.asin(min(1.0, math.hypot(*e[1:])))
        if k % every == 0:
            rec_t[rows], rec_x[rows], rec_ctrl[rows] = t, x, held
            rows += 1
        if k == steps:
            return 0, k, rows
        status, ran = rk4_hold(x, scenario.dt_s, block, (held[3], held[4], held[5]),
                               plant.packed)  # fmt: skip
        k += ran
        if status:
            return status, k, rows
        if bar is not None and k % 10_000 < block:
            bar.update(task, completed=t)
