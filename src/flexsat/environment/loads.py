"""The environment's loads in the closed loop: every model summed, mapped onto the hub
torque and each appendage's generalized forces (numba, allocation-free).

At a control instant the loop interpolates the ephemeris at t
(:func:`ephemeris_row`), takes C_BN from the hub attitude (:func:`attitude_cbn`)
and calls :func:`environment_loads`: each registered model's kernel adds its forces
on the load points and its torque on the hub; every point adds r_k x F_k to the hub
torque (the virtual work of a rotation of the hub, which carries the appendages), and
a point of an appendage also adds G_k^T F_k to that appendage's generalized forces
(:mod:`flexsat.environment.geometry`; docs/environment.md, 'Appendage loads').
They are evaluated every ``period_s`` of the ``[environment]`` table (a whole number of
control periods) and held in between, like the actuators' torque: they turn at the
orbit's rate n and the attitude's ‖omega‖, so a hold of T moves them by about
(n + ‖omega‖) T of their size, 1e-4 for n T at 0.1 s in low Earth orbit
(docs/environment.md, 'When the loads are evaluated').
"""

from __future__ import annotations

from dataclasses import dataclass
from math import sqrt
from typing import NamedTuple

import numpy as np
from numba import njit

from flexsat.compiled.first_class import first_class
from flexsat.compiled.linalg3 import load_m33_at, mm, rot_zyx
from flexsat.environment.geometry import LoadGeometry, load_geometry
from flexsat.environment.magnetorquers import DUMP_SIZE, dump_momentum
from flexsat.environment.registry import (
    EPH_LIT,
    EPH_R,
    EPH_S,
    EPH_T,
    EPH_V,
    LOAD_SIGNATURE,
    environment_model,
)
from flexsat.errors import ConfigError

__all__ = [
    "MODEL_SLOTS",
    "EnvironmentData",
    "LoadContext",
    "applied_forces",
    "attitude_cbn",
    "environment_data",
    "environment_loads",
    "ephemeris_row",
    "idle_environment",
]

MODEL_SLOTS = 4
"""Entries of the padded model tuples: every set of up to this many models shares one
compiled loop."""


@dataclass(frozen=True)
class LoadContext:
    """What a model's ``packed`` may read besides its own table.

    Attributes
    ----------
    plant : flexsat.dynamics.plant.Plant
        The satellite.
    ephemeris : ndarray, shape (n, 13)
        The run's ephemeris table (ECI) [s, m, m/s, -, m, -, rad].
    epoch : str
        Its epoch, ISO 8601 UTC.
    hub_inertia : ndarray, shape (3, 3)
        The hub's inertia about its centre of mass, frame B [kg m^2].
    """

    plant: object
    ephemeris: np.ndarray
    epoch: str
    hub_inertia: np.ndarray


class EnvironmentData(NamedTuple):
    """Every array the environment's loads read or write in the loop (float64, C order).

    Attributes
    ----------
    active : bool
        Whether any model acts (False: the loop never calls the environment).
    ephemeris : ndarray, shape (n, 13)
        The ephemeris table (ECI) [s, m, m/s, -, m, -, rad].
    row : ndarray, shape (13,)
        The ephemeris at the current instant [s, m, m/s, -, m, -, rad].
    C_BN : ndarray, shape (3, 3)
        ECI to hub frame B at the current instant [-].
    points, surfaces, positions, owner, jacobian : ndarray
        The load geometry (:class:`~flexsat.environment.geometry.LoadGeometry`, its
        units) [m, kg, m^2, -].
    kernels : tuple
        The models' load kernels (first-class, :data:`LOAD_SIGNATURE`), padded to
        :data:`MODEL_SLOTS`.
    params : tuple of ndarray
        Each model's packed parameters, padded [SI].
    n_models : int
        Models that act.
    force : ndarray, shape (k + s, 3)
        The forces on the load points, frame B [N].
    torque : ndarray, shape (3,)
        The environment's torque on the hub, frame B [N m]: held between instants.
    Q : ndarray, shape (n_dof,)
        Its generalized forces on the appendage coordinates (zero on the hub's):
        held between instants [N, N m per coordinate].
    applied : ndarray, shape (n_dof,)
        What the plant steps under: the joint actuator's generalized forces plus
        ``Q`` (:func:`applied_forces`) [N, N m per coordinate].
    dumping : bool
        Magnetorquers dump the wheels' momentum
        (:mod:`flexsat.environment.magnetorquers`).
    dump : ndarray, shape (5,)
        Their packed parameters (:func:`~flexsat.environment.magnetorquers.dump_momentum`)
        [1/s, A m^2, A m^2, -, -].
    dipole : ndarray, shape (3,)
        Their dipole, held between instants, hub frame B [A m^2].
    every : int
        Loop steps between two evaluations, a whole number of control periods (the
        ``[environment]`` table's ``period_s``; 1 outside a loop).
    record : int
        Where in the loop's record row the torque (3) and, when dumping, the dipole
        (3) are written at each evaluation; -1: not recorded.
    """

    active: bool
    ephemeris: np.ndarray
    row: np.ndarray
    C_BN: np.ndarray
    points: np.ndarray
    surfaces: np.ndarray
    positions: np.ndarray
    owner: np.ndarray
    jacobian: np.ndarray
    kernels: tuple
    params: tuple
    n_models: int
    force: np.ndarray
    torque: np.ndarray
    Q: np.ndarray
    applied: np.ndarray
    dumping: bool
    dump: np.ndarray
    dipole: np.ndarray
    every: int
    record: int


@njit(cache=True)
def _no_load(eph, C_BN, points, surfaces, params, force, torque):
    """No load: the kernel an environment without models is padded with."""
    return 0


def _padded(entries: tuple, filler) -> tuple:
    """``entries`` padded with ``filler`` to a non-zero multiple of :data:`MODEL_SLOTS`."""
    return entries + (filler,) * (MODEL_SLOTS * max(1, -(-len(entries) // MODEL_SLOTS))
                                  - len(entries))  # fmt: skip


def environment_data(
    plant,
    config,
    ephemeris: np.ndarray,
    epoch: str,
    momentum_column: int | None = None,
    every: int = 1,
    record_column: int | None = None,
) -> EnvironmentData:
    """The environment of a run, packed for the loop.

    Parameters
    ----------
    plant : flexsat.dynamics.plant.Plant
        The satellite.
    config : flexsat.environment.config.EnvironmentConfig
        The ``[environment]`` table.
    ephemeris : ndarray, shape (n, 13)
        The run's ephemeris (ECI, uniform in time from t = 0, n >= 2)
        [s, m, m/s, -, m, -, rad].
    epoch : str
        Its epoch, ISO 8601 UTC.
    momentum_column : int, optional
        Where the loop's record row holds the wheels' ``wheel_momentum_B`` (3): needed
        by the magnetorquers.
    every : int, optional
        Loop steps between two evaluations of the loads (a whole number of control
        periods) [-].
    record_column : int, optional
        Where the loop's record row holds the environment's channels (its torque, then
        the magnetorquers' dipole when they dump); none: not recorded.

    Returns
    -------
    EnvironmentData
        The loop's environment arrays and kernels.
    """
    geometry: LoadGeometry = load_geometry(plant, config)
    eph = np.ascontiguousarray(ephemeris, dtype=float)
    context = LoadContext(plant, eph, epoch, geometry.hub_inertia)
    models = config.active()
    kernels = tuple(first_class(environment_model(name).load, LOAD_SIGNATURE) for name in models)
    params = tuple(np.ascontiguousarray(c.packed(context), dtype=float) for c in models.values())
    filler = first_class(_no_load, LOAD_SIGNATURE)
    rows = geometry.positions.shape[0]
    dump = np.zeros(DUMP_SIZE)
    if config.magnetorquers is not None:
        if momentum_column is None:
            raise ConfigError("environment.magnetorquers: they dump the reaction wheels' "
                              "momentum: the [actuator] must be kind = 'wheels'")  # fmt: skip
        mt = config.magnetorquers
        dump[:] = (mt.gain_1_s, mt.dipole_max_a_m2, mt.quantum_a_m2, momentum_column,
                   list(models).index("magnetic"))  # fmt: skip
    return EnvironmentData(
        active=bool(models), ephemeris=eph, row=eph[0].copy(), C_BN=np.eye(3),
        points=geometry.points, surfaces=geometry.surfaces, positions=geometry.positions,
        owner=geometry.owner, jacobian=np.ascontiguousarray(geometry.jacobian),
        kernels=_padded(kernels, filler), params=_padded(params, np.zeros(0)),
        n_models=len(models), force=np.zeros((rows, 3)), torque=np.zeros(3),
        Q=np.zeros(plant.n_dof), applied=np.zeros(plant.n_dof),
        dumping=config.magnetorquers is not None, dump=dump, dipole=np.zeros(3),
        every=max(1, int(every)), record=-1 if record_column is None else int(record_column),
    )  # fmt: skip


def idle_environment(n_dof: int) -> EnvironmentData:
    """The environment of a run without ``[environment]``: no model, never called.

    Parameters
    ----------
    n_dof : int
        Generalized coordinates of the plant.

    Returns
    -------
    EnvironmentData
        Inactive, with zero loads (the loop adds nothing).
    """
    filler = first_class(_no_load, LOAD_SIGNATURE)
    eph = np.zeros((2, 13))
    return EnvironmentData(
        active=False, ephemeris=eph, row=np.zeros(13), C_BN=np.eye(3),
        points=np.zeros((0, 4)), surfaces=np.zeros((0, 10)), positions=np.zeros((0, 3)),
        owner=np.zeros((0, 2), dtype=np.int64), jacobian=np.zeros((0, 3, 1)),
        kernels=(filler,) * MODEL_SLOTS, params=(np.zeros(0),) * MODEL_SLOTS, n_models=0,
        force=np.zeros((0, 3)), torque=np.zeros(3), Q=np.zeros(n_dof),
        applied=np.zeros(n_dof), dumping=False, dump=np.zeros(DUMP_SIZE), dipole=np.zeros(3),
        every=1, record=-1,
    )  # fmt: skip


@njit(cache=True)
def ephemeris_row(eph, t, out):
    """The ephemeris at time ``t`` into ``out`` (13,): cubic Hermite in the position
    (with the velocity), linear elsewhere, the Sun direction renormalized.

    Parameters
    ----------
    eph : ndarray, shape (n, 13)
        Ephemeris table, uniform in time from eph[0, 0] (ECI, SI).
    t : float
        Time [s]; held at the table's ends outside it.
    out : ndarray, shape (13,)
        Written [SI].
    """
    n = eph.shape[0]
    t0, step = eph[0, EPH_T], eph[1, EPH_T] - eph[0, EPH_T]
    u = max(0.0, (t - t0) / step)
    i = min(int(u), n - 2)
    w = min(1.0, u - i)
    a, b = eph[i], eph[i + 1]
    for j in range(13):
        out[j] = (1.0 - w) * a[j] + w * b[j]
    h00 = (1.0 + 2.0 * w) * (1.0 - w) ** 2
    h10 = w * (1.0 - w) ** 2
    h01 = w * w * (3.0 - 2.0 * w)
    h11 = w * w * (w - 1.0)
    for j in range(3):
        out[EPH_R + j] = (h00 * a[EPH_R + j] + h10 * step * a[EPH_V + j] + h01 * b[EPH_R + j]
                          + h11 * step * b[EPH_V + j])  # fmt: skip
    norm = sqrt(out[EPH_S] ** 2 + out[EPH_S + 1] ** 2 + out[EPH_S + 2] ** 2)
    if norm > 0.0:
        for j in range(3):
            out[EPH_S + j] /= norm
    out[EPH_LIT] = min(1.0, max(0.0, out[EPH_LIT]))
    out[EPH_T] = t


@njit(cache=True)
def attitude_cbn(x, frame, C_BN):
    """C_BN = (R_NF R_FB(Theta))^T from the plant state and the attitude reference frame.

    Parameters
    ----------
    x : ndarray, shape (2 n_dof,)
        The plant state, its ZYX Euler angles Theta = x[3:6] relative to F [m, rad, ...].
    frame : ndarray, shape (9,)
        R_NF, the attitude reference frame F in ECI, row-major [-].
    C_BN : ndarray, shape (3, 3)
        ECI to hub frame B [-], written.
    """
    R = mm(load_m33_at(frame, 0), rot_zyx(x[3], x[4], x[5]))
    for i in range(3):
        for j in range(3):
            C_BN[i, j] = R[j][i]


@njit(cache=True)
def environment_loads(env, held):
    """Every model's loads at ``env.row`` and ``env.C_BN``, into ``env.torque`` and
    ``env.Q`` (module docstring), and the magnetorquers' torque when they act.

    Parameters
    ----------
    env : EnvironmentData
        Its ``force``, ``torque``, ``Q`` and ``dipole`` are overwritten.
    held : ndarray
        The loop's record row, where the wheels' momentum is read and, when
        ``env.record >= 0``, the torque and the dipole are written [per channel].

    Returns
    -------
    int
        0, or the OR of the models' non-zero statuses.
    """
    force, torque, Q = env.force, env.torque, env.Q
    for i in range(force.shape[0]):
        force[i, 0], force[i, 1], force[i, 2] = 0.0, 0.0, 0.0
    torque[0], torque[1], torque[2] = 0.0, 0.0, 0.0
    for j in range(Q.shape[0]):
        Q[j] = 0.0
    status = 0
    for m in range(env.n_models):
        status |= env.kernels[m](env.row, env.C_BN, env.points, env.surfaces, env.params[m],
                                 force, torque)  # fmt: skip
    pos, G = env.positions, env.jacobian
    for i in range(force.shape[0]):
        fx, fy, fz = force[i, 0], force[i, 1], force[i, 2]
        # every point's moment reaches the hub's attitude (Q_Theta = S^T sum r_k x F_k):
        # an appendage's coordinates are relative to the hub, which carries it
        torque[0] += pos[i, 1] * fz - pos[i, 2] * fy
        torque[1] += pos[i, 2] * fx - pos[i, 0] * fz
        torque[2] += pos[i, 0] * fy - pos[i, 1] * fx
        offset, count = env.owner[i, 0], env.owner[i, 1]
        for c in range(count if offset >= 0 else 0):
            Q[offset + c] += G[i, 0, c] * fx + G[i, 1, c] * fy + G[i, 2, c] * fz
    if env.dumping:
        dump_momentum(env.dump, env.row, env.C_BN, env.params[int(env.dump[4])], held, torque,
                      env.dipole)  # fmt: skip
    if env.record >= 0:
        r = env.record
        held[r], held[r + 1], held[r + 2] = torque[0], torque[1], torque[2]
        if env.dumping:
            held[r + 3], held[r + 4], held[r + 5] = env.dipole[0], env.dipole[1], env.dipole[2]
    return status


@njit(cache=True)
def applied_forces(env, Q_joint, held, continuous):
    """What the plant steps under until the next instant: ``env.applied`` = the joint
    actuator's ``Q_joint`` + ``env.Q``; with continuous actuation stages the
    environment's torque is added to the chain's held output ``held`` (3,) [N m] (without,
    the loop adds ``env.torque`` to the held torque itself).

    Parameters
    ----------
    env : EnvironmentData
        Its ``applied`` is written.
    Q_joint : ndarray, shape (n_dof,)
        The joint actuator's held generalized forces [N, N m per coordinate].
    held : ndarray, shape (3,)
        The actuation chain's held output, hub frame B [N m], added to if ``continuous``.
    continuous : bool
        Some actuation stage integrates states (the coupled RK4 step reads ``held``).
    """
    for j in range(Q_joint.shape[0]):
        env.applied[j] = Q_joint[j] + env.Q[j]
    if continuous:
        for a in range(3):
            held[a] += env.torque[a]
