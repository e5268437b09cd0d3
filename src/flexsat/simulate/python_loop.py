"""A plain-Python control law flown between the compiled sensing and actuation chains."""

from __future__ import annotations

import math

import numpy as np
from numba import njit

from flexsat.compiled.status import STATUS_CONTROL_FAILED
from flexsat.compiled.typed_call import TypedOnce, typed_list
from flexsat.dynamics.attitude import inertial_view, is_identity, rebase
from flexsat.dynamics.integrators import rk4_hold
from flexsat.errors import SimulationError
from flexsat.simulate.coupled import rk4_coupled_hold
from flexsat.simulate.loops import run_actuators, run_sensors

__all__ = ["python_loop"]


@njit(cache=True)
def _listed_sensors(x, n, t, loop):
    """:func:`~flexsat.simulate.loops.run_sensors` on the structures in ``loop``, a typed
    list of one (stages, data, packed plant) tuple: unboxed as one pointer, where
    the structures themselves would unbox every array and first-class function at
    every call (:mod:`flexsat.compiled.typed_call`)."""
    stages, d, _ = loop[0]
    return run_sensors(x, n, t, stages, d)


@njit(cache=True)
def _listed_actuators(x, n, t, control_dt, continuous, loop):
    """:func:`~flexsat.simulate.loops.run_actuators` on ``loop`` (:func:`_listed_sensors`)."""
    stages, d, _ = loop[0]
    return run_actuators(x, n, t, control_dt, continuous, stages, d)


@njit(cache=True)
def _listed_coupled_hold(x, t0, dt, n_steps, loop):
    """:func:`~flexsat.simulate.coupled.rk4_coupled_hold` on ``loop`` (:func:`_listed_sensors`)."""
    stages, d, packed = loop[0]
    return rk4_coupled_hold(x, t0, dt, n_steps, stages.derivative, d.actuator_params, d.flow,
                            packed)  # fmt: skip


@njit(cache=True)
def _listed_hold(x, dt, n_steps, frame, loop):
    """:func:`~flexsat.dynamics.integrators.rk4_hold` under the held ``tau_applied``, on
    ``loop`` (:func:`_listed_sensors`)."""
    _, d, packed = loop[0]
    torque = (d.tau_applied[0], d.tau_applied[1], d.tau_applied[2])
    return rk4_hold(x, dt, n_steps, torque, packed, frame)


def python_loop(plant, scenario, x, frame, stages, d, rec_t, rec_x, rec_ctrl, rec_frame, bar,
                task, controller, continuous) -> tuple[int, int, int]:  # fmt: skip
    """Python controller at each control instant between the compiled stages; the plant
    steps compiled in between.

    Parameters
    ----------
    plant : Plant
        The truth plant.
    scenario : SlewScenario
        The slew (its step, control and record periods, torque limit).
    x : ndarray, shape (x_size,)
        Plant state [m, rad, m/s, rad/s, J], advanced in place.
    frame : ndarray, shape (9,)
        Attitude reference R_NF of ``x`` [-], updated in place.
    stages : LoopStages
        The compiled stages (:func:`~flexsat.simulate.stage_chain.loop_stages`).
    d : LoopData
        The loop's arrays (:func:`~flexsat.simulate.stage_chain.loop_data`).
    rec_t : ndarray, shape (m,)
        Record times [s], filled in place.
    rec_x : ndarray, shape (m, x_size)
        Recorded plant states [m, rad, m/s, rad/s, J], filled in place.
    rec_ctrl : ndarray, shape (m, record_size)
        Recorded control rows [SI units of each channel], filled in place.
    rec_frame : ndarray, shape (m, 9)
        Recorded attitude references R_NF [-], filled in place.
    bar : rich.progress.Progress or None
        Progress bar to update, or None.
    task : rich.progress.TaskID or None
        Its task.
    controller : callable
        ``controller(t, q, omega_B)`` -> commanded body torque [N m], shape (3,)
        (:class:`~flexsat.simulate.closedloop.Controller`).
    continuous : bool
        The actuation chain has continuous states (the coupled RK4 step).

    Returns
    -------
    status : int
        0 when finished, else a status of :mod:`flexsat.compiled.status`.
    done : int
        Steps taken.
    rows : int
        Record rows written.

    Raises
    ------
    SimulationError
        The controller returned anything but three finite numbers.
    """
    n = plant.n_dof
    steps, every, control = scenario.n_steps, scenario.record_every, scenario.control_every
    block = math.gcd(every, control)
    control_dt = control * scenario.dt_s
    limit = scenario.actuator.reduction_factor * scenario.actuator.t_max_nm
    d.law_diag[:] = np.nan
    view = np.empty_like(x)
    # the same arguments at every instant: typed once, and the loop's structures in a
    # typed list, unboxed as one pointer (flexsat.compiled.typed_call)
    loop = typed_list((stages, d, plant.packed))
    sensors, actuators = TypedOnce(_listed_sensors), TypedOnce(_listed_actuators)
    coupled_hold, hold = TypedOnce(_listed_coupled_hold), TypedOnce(_listed_hold)
    rows, status, k = 0, 0, 0
    while True:
        t = k * scenario.dt_s
        if k % control == 0:
            sensed = x
            if not is_identity(frame):  # re-based between steps: the sensors read N
                inertial_view(x, n, frame, view)
                sensed = view
            status = sensors(sensed, n, t, loop)
            tau_cmd = np.asarray(controller(t, d.q_meas.copy(), d.omega_meas.copy()), dtype=float)
            if tau_cmd.shape != (3,) or not np.all(np.isfinite(tau_cmd)):
                raise SimulationError(f"controller returned {tau_cmd!r} at t = {t:.6g} s")
            d.tau_cmd[:] = np.clip(tau_cmd, -limit, limit)
            status |= actuators(x, n, t, control_dt, continuous, loop)
            if status:
                return STATUS_CONTROL_FAILED, k, rows
        if k % every == 0:
            rec_t[rows], rec_x[rows], rec_ctrl[rows], rec_frame[rows] = t, x, d.held, frame
            rows += 1
        if k == steps:
            return 0, k, rows
        if continuous:  # re-based once per block (a few steps: far from the pole)
            rebase(x, n, frame)
            status, ran = coupled_hold(x, t, scenario.dt_s, block, loop)
        else:
            status, ran = hold(x, scenario.dt_s, block, frame, loop)
        k += ran
        if status:
            return status, k, rows
        if bar is not None and k % 10_000 < block:
            bar.update(task, completed=t)
