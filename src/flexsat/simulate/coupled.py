"""RK4 step of the plant coupled with the actuation chain's continuous states (numba).

An actuation stage with a ``derivative`` (``DERIVATIVE_SIGNATURE``, contract in
:mod:`flexsat.control.stages.registry`) integrates entries of its own state with
the plant inside each RK4 step: at every RK4 stage the derivatives are evaluated
with the plant state and the chain's state at that stage, they return the state
rates and the wrench on the hub, and the plant sees the held torque plus that
wrench. A reaction wheel's momentum, whose reaction torque depends on the body
rate within the step, is integrated this way (``docs/control.md``, 'Continuous
actuator states'). The ideal loop (no derivative) never calls this module: its
plant step is :func:`flexsat.dynamics.integrators.rk4_step`, bit for bit.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
from numba import njit

from flexsat.compiled.linalg3 import euler_rate_matrix_cs, load_seg, mv
from flexsat.compiled.no_refcount import borrowed
from flexsat.compiled.status import STATUS_NOT_FINITE, STATUS_OK
from flexsat.dynamics.integrators import augmented_derivative, rk4_combine, rk4_stage
from flexsat.dynamics.kernels import hub_cs

__all__ = ["CHAIN_SLOTS", "LoopFlow", "chain_wrench", "rk4_coupled_hold", "rk4_coupled_step"]

CHAIN_SLOTS = 4
"""Entries per block of a chain's padded tuples: every chain of up to this many stages
shares one compiled loop (the built-in stages make at most 4 per chain)."""

LITERAL_STAGES = 4  # stages 0-3 of a chain are called by literal index (see _derive)


class LoopFlow(NamedTuple):
    """Work arrays of the coupled step (float64, C order), allocated once per run.

    Attributes
    ----------
    state : ndarray, shape (m,)
        The actuation chain's state block, a view into the control state [per stage].
    eval, dot : ndarray, shape (m,)
        The chain's state at an RK4 stage and its rate [per stage, per stage per s].
    eval_views, dot_views : tuple of ndarray
        Each stage's piece of ``eval`` and ``dot`` [per stage] (padded like the
        chain's tuples, :data:`CHAIN_SLOTS`).
    rates : ndarray, shape (m,)
        The RK4 stages' weighted sum k1 + 2 k2 + 2 k3 + k4 of the chain's state
        rate, accumulated as the stages are evaluated [per stage per s].
    wrench : ndarray, shape (3,)
        The stages' torque on the hub, hub frame B [N m].
    held : ndarray, shape (3,)
        The chain's held output [N m].
    omega : ndarray, shape (3,)
        The hub's body rate omega_BN at the RK4 stage, hub frame B, that the
        derivatives read [rad/s].
    n_derivative : int
        Derivatives evaluated: the actuation stages up to the last one with a
        derivative (0 without any) [-].
    """

    state: np.ndarray
    eval: np.ndarray
    eval_views: tuple
    dot: np.ndarray
    dot_views: tuple
    rates: np.ndarray
    wrench: np.ndarray
    held: np.ndarray
    omega: np.ndarray
    n_derivative: int


@njit(cache=True, inline="always")
def chain_wrench(x, n, t, cs, derivatives, params, flow):
    """Evaluate every stage's derivative at (x, flow.eval): flow.dot and flow.wrench.

    Each derivative reads the hub's body rate omega = S(Theta) Theta_dot (eq. 2.28)
    from ``flow.omega``, computed here from the cosines and sines ``cs`` the plant's
    derivative takes too: at every RK4 stage they are computed once for both.
    Inlined where it is called, with element loops instead of slice assignments: the
    RK4 stages evaluate it four times per step (``CHANGELOG.md``, "After the
    reference-counting change (avionics chain)"). The stages are called by literal
    index (:func:`_derive`).

    Parameters
    ----------
    x : ndarray, shape (2 n + 2,)
        Plant state at the RK4 stage [q, q_dot, W_in, W_diss] [SI].
    n : int
        Number of generalized coordinates.
    t : float
        Time of the RK4 stage [s].
    cs : tuple of 6 float
        :func:`~flexsat.dynamics.kernels.hub_cs` of ``x`` [-].
    derivatives : tuple of first-class functions
        One ``DERIVATIVE_SIGNATURE`` function per actuation stage (padded); the first
        ``flow.n_derivative`` are evaluated.
    params : tuple of ndarray
        Each stage's packed parameters [per stage].
    flow : LoopFlow
        Its ``omega``, ``dot`` and ``wrench`` are overwritten.

    Returns
    -------
    int
        0, or the OR of the stages' non-zero statuses.
    """
    dot, wrench, omega = flow.dot, flow.wrench, flow.omega
    for j in range(dot.shape[0]):
        dot[j] = 0.0
    wrench[0], wrench[1], wrench[2] = 0.0, 0.0, 0.0
    S = euler_rate_matrix_cs(cs[0], cs[1], cs[2], cs[3])
    omega[0], omega[1], omega[2] = mv(S, load_seg(x, n + 3))
    count = flow.n_derivative
    status = 0
    if count > 0:  # by literal index (see _derive)
        status |= _derive(0, x, n, t, derivatives, params, flow)
    if count > 1:
        status |= _derive(1, x, n, t, derivatives, params, flow)
    if count > 2:
        status |= _derive(2, x, n, t, derivatives, params, flow)
    if count > 3:
        status |= _derive(3, x, n, t, derivatives, params, flow)
    for i in range(LITERAL_STAGES, count):
        status |= _derive(i, x, n, t, derivatives, params, flow)
    return status


@njit(cache=True, inline="always")
def _derive(i, x, n, t, derivatives, params, flow):
    """Stage ``i``'s derivative. Inlined, a literal ``i`` makes every tuple access
    static: indexing the padded tuples with a loop variable copies each tuple to the
    stack on every access, about 0.2 us per coupled step with one continuous stage
    (CHANGELOG.md, 'Stages by literal index')."""
    return derivatives[i](x, n, t, flow.omega, params[i], flow.eval_views[i],
                          flow.dot_views[i], flow.wrench)  # fmt: skip


@njit(cache=True, inline="always")
def _rates(x, n, t, derivatives, params, flow, Q, k, packed, evaluate=True):
    cs = hub_cs(x)
    status = chain_wrench(x, n, t, cs, derivatives, params, flow) if evaluate else 0
    h, w = flow.held, flow.wrench
    torque = (h[0] + w[0], h[1] + w[1], h[2] + w[2])
    status |= augmented_derivative(x, torque, n, Q, k, packed, cs)
    return status


@njit(cache=True)
def rk4_coupled_step(x, t, dt, n, Q, scratch, derivatives, params, flow, packed, fresh):
    """One RK4 step of the plant state ``x`` and the chain state ``flow.state``, in place.

    The held torque is ``flow.held``. On a non-zero status both states are left
    unchanged.

    Parameters
    ----------
    x : ndarray, shape (2 n + 2,)
        Plant state [q, q_dot, W_in, W_diss] (SI: m, rad, m/s, rad/s, J).
    t : float
        Time of x [s].
    dt : float
        Step [s].
    n : int
        Number of generalized coordinates.
    Q : ndarray, shape (n,)
        Generalized forces, as for :func:`~flexsat.dynamics.integrators.rk4_step`
        [N, N m per coordinate].
    scratch : ndarray, shape (5, len(x))
        Work array [-].
    derivatives : tuple of first-class functions
        One ``DERIVATIVE_SIGNATURE`` function per actuation stage (padded); the first
        ``flow.n_derivative`` are evaluated.
    params : tuple of ndarray
        Each stage's packed parameters [per stage].
    flow : LoopFlow
        The chain's state and work arrays.
    packed : PackedPlant
        ``Plant.packed``.
    fresh : bool
        ``flow.dot`` and ``flow.wrench`` already hold the derivatives at
        (x, ``flow.state``, t) (the control instant's
        :func:`~flexsat.simulate.loops.run_actuators` left them), so the first RK4
        stage reuses them instead of evaluating them again (the same numbers).

    Returns
    -------
    int
        ``STATUS_OK``, a kernel or stage status, or ``STATUS_NOT_FINITE``.
    """
    x, Q, scratch, packed = borrowed(x), borrowed(Q), borrowed(scratch), borrowed(packed)
    params, flow = borrowed(params), borrowed(flow)
    size, m = x.shape[0], flow.state.shape[0]
    c, ce, dot, acc = flow.state, flow.eval, flow.dot, flow.rates
    k1, k2, k3, k4, stage = scratch[0], scratch[1], scratch[2], scratch[3], scratch[4]
    for j in range(m):
        ce[j] = c[j]
    status = _rates(x, n, t, derivatives, params, flow, Q, k1, packed, not fresh)
    rk4_stage(x, 0.5 * dt, k1, stage)
    # The chain's rate at each RK4 stage is flow.dot; it is folded into the next stage's
    # state and the weighted sum at once (no copy per stage), in the order the plant's sum is taken.
    for j in range(m):
        acc[j] = dot[j]
        ce[j] = c[j] + 0.5 * dt * dot[j]
    status |= _rates(stage, n, t + 0.5 * dt, derivatives, params, flow, Q, k2, packed)
    rk4_stage(x, 0.5 * dt, k2, stage)
    for j in range(m):
        acc[j] += 2.0 * dot[j]
        ce[j] = c[j] + 0.5 * dt * dot[j]
    status |= _rates(stage, n, t + 0.5 * dt, derivatives, params, flow, Q, k3, packed)
    rk4_stage(x, dt, k3, stage)
    for j in range(m):
        acc[j] += 2.0 * dot[j]
        ce[j] = c[j] + dt * dot[j]
    status |= _rates(stage, n, t + dt, derivatives, params, flow, Q, k4, packed)
    if status != STATUS_OK:
        return status
    if not rk4_combine(x, dt, k1, k2, k3, k4, stage):
        return STATUS_NOT_FINITE
    for j in range(m):
        ce[j] = c[j] + dt / 6.0 * (acc[j] + dot[j])
        if not np.isfinite(ce[j]):
            return STATUS_NOT_FINITE
    for j in range(size):
        x[j] = stage[j]
    for j in range(m):
        c[j] = ce[j]
    return STATUS_OK


@njit(cache=True)
def rk4_coupled_hold(x, t0, dt, n_steps, derivatives, params, flow, packed):
    """``n_steps`` coupled RK4 steps under the held ``flow.held``.

    Parameters
    ----------
    x : ndarray, shape (2 n_dof + 2,)
        Plant state [SI], advanced in place.
    t0 : float
        Time of x [s].
    dt : float
        Step [s].
    n_steps : int
        Number of steps.
    derivatives : tuple of first-class functions
        One ``DERIVATIVE_SIGNATURE`` function per actuation stage (padded); the first
        ``flow.n_derivative`` are evaluated.
    params : tuple of ndarray
        Each stage's packed parameters [per stage].
    flow : LoopFlow
        The chain's state, advanced in place, and work arrays.
    packed : PackedPlant
        ``Plant.packed``.

    Returns
    -------
    status : int
        ``STATUS_OK`` or the failing step's status.
    done : int
        Steps completed without error.
    """
    x, params, flow, packed = borrowed(x), borrowed(params), borrowed(flow), borrowed(packed)
    n = packed.n_dof
    scratch = np.empty((5, x.shape[0]))
    Q = np.zeros(n)  # no joint actuators: Q[6:] is read, never written
    for k in range(n_steps):
        status = rk4_coupled_step(x, t0 + k * dt, dt, n, Q, scratch, derivatives, params, flow,
                                  packed, False)  # fmt: skip
        if status != STATUS_OK:
            return status, k
    return STATUS_OK, n_steps
