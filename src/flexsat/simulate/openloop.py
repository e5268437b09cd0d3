"""Open-loop simulation: a torque profile applied to the flexible plant (thesis section 3.3)."""

from __future__ import annotations

import itertools
import time

import numpy as np
from scipy.integrate import solve_ivp

from flexsat.dynamics.attitude import SWITCH_PITCH, identity_frame, rebase
from flexsat.dynamics.integrators import (
    STATUS_NOT_FINITE,
    applied_torque,
    augmented_derivative,
    rk4_open_loop,
)
from flexsat.dynamics.kernels import STATUS_OK
from flexsat.dynamics.linalg3 import euler_rate_matrix_inv
from flexsat.dynamics.plant import Plant
from flexsat.errors import ConfigError
from flexsat.simulate.common import (
    PROGRESS_MIN_STEPS,
    check_run_size,
    chunk_steps,
    progress_bar,
    run_attributes,
)
from flexsat.simulate.result import Result, build_dataset
from flexsat.simulate.scenario import OpenLoopScenario, thesis_openloop

__all__ = ["initial_state", "run_openloop"]



def initial_state(plant: Plant, scenario: OpenLoopScenario) -> tuple[np.ndarray, np.ndarray]:
    """q(0) and q_dot(0) from the scenario's initial state (degrees converted to radians).

    Parameters
    ----------
    plant : Plant
        The satellite.
    scenario : OpenLoopScenario or SlewScenario
        Its ``initial`` table.

    Returns
    -------
    q : ndarray, shape (n_dof,)
        Generalized coordinates [m, rad].
    q_dot : ndarray, shape (n_dof,)
        Their rates [m/s, rad/s].

    Raises
    ------
    ConfigError
        If an initial state names an appendage the satellite does not have.
    """
    init = scenario.initial
    q = plant.zeros()
    qd = plant.zeros()
    q[3:6] = np.radians(init.attitude_deg)
    omega_B = np.radians(init.rate_deg_s)
    qd[3:6] = np.array(euler_rate_matrix_inv(q[3], q[4])) @ omega_B  # Theta_dot = S^-1 omega
    configs = {a.name: (a, m) for a, m in zip(plant.config.appendages, plant.models, strict=True)}
    for (config, model), block in zip(configs.values(), plant.layout.blocks, strict=True):
        q[block.slice], qd[block.slice] = model.default_state(config)
    for entry in init.appendages:
        try:
            block = plant.layout.block(entry.name)
        except KeyError as exc:
            raise ConfigError(f"initial.appendages: {exc.args[0]}") from None
        config, model = configs[entry.name]
        try:
            q[block.slice], qd[block.slice] = model.initial_state(config, entry)
        except ValueError as exc:
            raise ConfigError(str(exc)) from None
    names = plant.dof_names()
    for index in plant.locked_coordinates():  # held at q(0): they cannot move
        if qd[index] != 0.0:
            raise ConfigError(
                f"initial.appendages: {names[index]} is locked (locked_dofs): its initial "
                "rate must be 0"
            )
    return q, qd


def _profile(scenario: OpenLoopScenario):
    end = scenario.duration_s + 1.0
    seg_start = np.array([s.start_s for s in scenario.torque], dtype=float)
    seg_end = np.array([end if s.end_s is None else s.end_s for s in scenario.torque], dtype=float)
    seg_torque = np.array([s.torque_nm for s in scenario.torque], dtype=float).reshape(-1, 3)
    return seg_start, seg_end, seg_torque, np.array(scenario.disturbance_torque_nm, dtype=float)


def run_openloop(
    plant: Plant, scenario: OpenLoopScenario | None = None, progress: bool | None = None
) -> Result:
    """Simulate the plant under the scenario's torque profile.

    Parameters
    ----------
    plant : Plant
        The satellite.
    scenario : OpenLoopScenario, optional
        Default: the thesis's scenario (1 N m about Z for 10 s, free to 120 s).
    progress : bool, optional
        Show a progress bar; default: only for runs of at least 200 000 steps.

    Returns
    -------
    Result
        Recorded every ``record_dt_s``. A diverging run stops at the failing step and
        returns its history up to there with ``status = "failed"`` and a message
        that names the time; it does not raise.

    Raises
    ------
    ConfigError
        Before it starts, if its records would not fit in memory
        (:func:`flexsat.simulate.common.check_run_size`).
    """
    scenario = scenario or thesis_openloop()
    check_run_size(plant.n_dof, scenario)
    q0, qd0 = initial_state(plant, scenario)
    profile = _profile(scenario)
    start = time.perf_counter()
    if scenario.solver == "rk4":
        t, X, F, tau, status, t_fail, steps = _run_rk4(plant, scenario, q0, qd0, profile,
                                                       progress)  # fmt: skip
    else:
        t, X, F, tau, status, t_fail, steps = _run_dop853(plant, scenario, q0, qd0, profile)
    wall = time.perf_counter() - start
    lay = plant.layout
    seg_start, seg_end, seg_torque, _ = profile
    tau_cmd = np.array(
        [applied_torque(tk, seg_start, seg_end, seg_torque, np.zeros(3)) for tk in t]
    ).reshape(-1, 3)
    attrs = run_attributes(plant, scenario, "open-loop", status, t_fail, wall, steps)
    attrs["solver"] = scenario.solver
    dataset = build_dataset(
        plant, t, X[:, lay.q], X[:, lay.qd], X[:, lay.work_in], X[:, lay.dissipated], tau_cmd,
        tau, attrs, frames=F,
    )  # fmt: skip
    return Result(dataset)


def _run_rk4(plant, scenario, q0, qd0, profile, progress):
    n_steps, every, dt = scenario.n_steps, scenario.record_every, scenario.dt_s
    n_records = n_steps // every + 1
    rec_t = np.empty(n_records)
    rec_x = np.empty((n_records, plant.layout.size))
    rec_tau = np.empty((n_records, 3))
    rec_frame = np.empty((n_records, 9))
    x = np.concatenate([q0, qd0, [0.0, 0.0]])
    frame = identity_frame()
    rec_t[0], rec_x[0], rec_frame[0] = 0.0, x, frame
    rec_tau[0] = applied_torque(0.0, *profile)
    show = n_steps >= PROGRESS_MIN_STEPS if progress is None else progress
    chunk = chunk_steps(every)
    done, status = 0, 0
    with progress_bar(show, scenario.duration_s) as (bar, task):
        while done < n_steps and status == 0:
            steps = min(chunk, n_steps - done)
            status, ran = rk4_open_loop(
                x, done * dt, dt, steps, every, *profile, plant.packed, frame,
                rec_t, rec_x, rec_tau, rec_frame, done // every + 1,
            )  # fmt: skip
            done += ran
            if bar is not None:
                bar.update(task, completed=done * dt)
    kept = done // every + 1
    t_fail = done * dt if status else -1.0
    if status:
        # Keep the last good state too, even between two records.
        rec_t[kept - 1 : kept] = done * dt
        rec_x[kept - 1], rec_frame[kept - 1] = x, frame
        rec_tau[kept - 1] = applied_torque(done * dt, *profile)
        rec_t, rec_x, rec_tau = rec_t[:kept], rec_x[:kept], rec_tau[:kept]
        rec_frame = rec_frame[:kept]
    return rec_t, rec_x, rec_frame, rec_tau, status, t_fail, done


def _run_dop853(plant, scenario, q0, qd0, profile):
    """Adaptive DOP853 (scipy), integrated piecewise between torque switching times.

    Each piece also ends where |pitch| reaches ``SWITCH_PITCH`` (a terminal event):
    the attitude is re-based there (:func:`flexsat.dynamics.attitude.rebase`) and the
    piece continues from the event. A run that diverges stops there, like RK4: the
    records up to the failure and the last good state are kept, with its status.
    """
    n = plant.n_dof
    seg_start, seg_end, _, _ = profile
    every = scenario.record_every
    t_rec = np.arange(scenario.n_steps // every + 1) * scenario.record_dt_s
    breaks = np.unique(
        np.clip(np.concatenate([[0.0, scenario.duration_s], seg_start, seg_end]), 0.0, t_rec[-1])
    )
    x = np.concatenate([q0, qd0, [0.0, 0.0]])
    X = np.empty((t_rec.size, x.size))
    X[0] = x
    frame = identity_frame()
    F = np.empty((t_rec.size, 9))
    Q = np.zeros(n)  # no joint actuators
    evaluations = 0
    kernel_status = STATUS_OK

    def switch(t, y, torque=None):  # positive after each rebase
        return SWITCH_PITCH - abs(y[4])

    switch.terminal = True
    switch.direction = -1.0
    status, t_fail = STATUS_OK, -1.0
    pieces = list(itertools.pairwise(breaks))
    while pieces and not status:
        a, b = pieces.pop(0)
        rebase(x, n, frame)
        torque = applied_torque(0.5 * (a + b), *profile)

        def rhs(t, y, torque=torque):
            nonlocal evaluations, kernel_status
            evaluations += 1
            dy = np.empty_like(y)
            code = augmented_derivative(y, torque, n, Q, dy, plant.packed)
            if code != STATUS_OK:  # a joint's singularity: make the step fail here
                kernel_status = code
                dy[:] = np.nan
            return dy

        sol = solve_ivp(
            rhs, (a, b), x, method="DOP853", rtol=scenario.rtol, atol=scenario.atol,
            dense_output=True, events=switch,
        )  # fmt: skip
        t_end = float(sol.t[-1])
        inside = (t_rec >= a) & (t_rec <= t_end)
        if inside.any():  # a piece cut short by a switch may hold no record
            X[inside] = sol.sol(t_rec[inside]).T
            F[inside] = frame
        x = sol.y[:, -1].copy()
        if sol.status == 1:  # the switching event: re-base, go on to b
            rebase(x, n, frame, 0.0)
            if t_end < b:
                pieces.insert(0, (t_end, b))
        elif sol.status == -1:  # the steps failed (diverged)
            status = kernel_status or STATUS_NOT_FINITE
            t_fail = t_end
    if status:
        kept = int(np.searchsorted(t_rec, t_fail, side="right"))
        t_rec = np.append(t_rec[:kept], t_fail) if t_fail > t_rec[kept - 1] else t_rec[:kept]
        X = np.vstack([X[:kept], x]) if t_rec.size > kept else X[:kept]
        F = np.vstack([F[:kept], frame]) if t_rec.size > kept else F[:kept]
    tau = np.array([applied_torque(t, *profile) for t in t_rec]).reshape(-1, 3)
    return t_rec, X, F, tau, status, t_fail, evaluations
