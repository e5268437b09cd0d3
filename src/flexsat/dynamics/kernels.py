"""Compiled dynamics of a rigid hub carrying N appendages of any registered model (numba).

The kernels know nothing of configs or units beyond SI: they take the
:class:`~flexsat.dynamics.packed.PackedPlant` built by :mod:`flexsat.dynamics.plant`
and write into output arrays the caller owns, so nothing is allocated per call.

Generalized coordinates (thesis eq. 2.1, generalized to N appendages)::

    q[0:3]     r_N      hub centre-of-mass position, inertial frame N [m]
    q[3:6]     Theta    hub ZYX Euler angles (phi, theta, psi) [rad]
    q[6:]      each appendage's coordinates (:class:`flexsat.dynamics.layout.StateLayout`)

Structure (see docs/model.md): M(q) is block-arrow. :func:`accelerations` runs the
articulated-body form of the appendage contract
(:mod:`flexsat.dynamics.appendages.contract`): pass 1 collects each appendage's
wrench on the hub and its articulated inertia, the hub is solved, and pass 2 gives
each appendage's coordinate accelerations. Appendages on a full 6-DOF joint (the
thesis plate) transmit no inertia, so the Schur complement is the bare hub's mass
matrix and no factorization is needed; the 6 x 6 solve runs only when an appendage
transmits inertia. Cost is linear in N.

Every kernel here, in the appendage models and in :mod:`flexsat.compiled.linalg3` is
compiled with ``error_model="numpy"``: a float division by zero would give inf/nan
(which the RK4 loops report as a non-finite state) instead of raising, so no zero
test guards each division. No divisor can be zero: masses are validated positive and
``cos(pitch)`` is checked against ``_MIN_COS`` before any ``euler_rate_matrix_inv``.
Results are bit-for-bit those of the default error model, without a branch per
division (docs/performance.md, 'Why it is fast').
"""

from __future__ import annotations

from math import cos, sin

from numba import njit

from flexsat.compiled.linalg3 import (
    add,
    add_block,
    copy_into,
    cross,
    dot,
    euler_rate_bias,
    euler_rate_bias_cs,
    euler_rate_matrix,
    euler_rate_matrix_cs,
    euler_rate_matrix_inv_cs,
    inverse3,
    load_block33,
    load_seg,
    mm,
    mtm,
    mtv,
    mv,
    rot_zyx,
    rot_zyx_cs,
    scale,
    sub,
)
from flexsat.compiled.status import (
    STATUS_HUB_GIMBAL_LOCK,
    STATUS_JOINT_GIMBAL_LOCK,
    STATUS_OK,
)
from flexsat.dynamics.appendages.contract import (
    HUB_ACC,
    HUB_ALPHA,
    HUB_DISSIPATION,
    HUB_FORCE,
    HUB_INERTIA,
    HUB_OMEGA,
    HUB_SBIAS,
    HUB_TORQUE,
    OBS_DISSIPATION,
    OBS_ELASTIC,
    OBS_KINETIC,
    OBS_LOCKED_INERTIA,
    OBS_MOMENTUM,
)

__all__ = [
    "STATUS_HUB_GIMBAL_LOCK",
    "STATUS_JOINT_GIMBAL_LOCK",
    "STATUS_OK",
    "accelerations",
    "accelerations_cs",
    "bias_forces",
    "hub_cs",
    "hub_joint_wrench",
    "joint_forces",
    "keep_solution",
    "mass_matrix",
    "observe",
    "tip_displacement",
]

_MIN_COS = 1e-9  # |cos(pitch)| below this is treated as gimbal lock


@njit(cache=True, error_model="numpy")
def _put(x, k, v):
    x[k], x[k + 1], x[k + 2] = v


@njit(cache=True, error_model="numpy")
def _solve_hub(packed, force_B, torque_B):
    """Hub accelerations (a_hub_B, omega_dot_B) under the summed articulated inertia.

    Solves [[P, B], [C, D]] [a; omega_dot] = [F; T - omega x J_h omega], the hub's
    mass matrix diag(m_h 1, J_h) plus the appendages' articulated inertia, by block
    elimination on 3 x 3 blocks: X = P^-1 B, y = P^-1 F, then the Schur complement
    (D - C X) omega_dot = T - C y and a = y - X omega_dot. The matrix is symmetric
    positive definite, so P and the Schur complement are too and both 3 x 3 inverses
    (:func:`~flexsat.compiled.linalg3.inverse3`) exist. Straight-line code on
    3 x 3 blocks instead of a 6 x 6 Gaussian elimination's loops.
    """
    hub = packed.hub
    m = packed.hub_mass
    P = load_block33(hub, HUB_INERTIA, 0, 0)
    P = ((P[0][0] + m, P[0][1], P[0][2]), (P[1][0], P[1][1] + m, P[1][2]),
         (P[2][0], P[2][1], P[2][2] + m))  # fmt: skip
    J = packed.hub_J
    D = load_block33(hub, HUB_INERTIA, 3, 3)
    D = (
        (D[0][0] + J[0, 0], D[0][1] + J[0, 1], D[0][2] + J[0, 2]),
        (D[1][0] + J[1, 0], D[1][1] + J[1, 1], D[1][2] + J[1, 2]),
        (D[2][0] + J[2, 0], D[2][1] + J[2, 1], D[2][2] + J[2, 2]),
    )
    C = load_block33(hub, HUB_INERTIA, 3, 0)
    P_inv = inverse3(P)
    X = mm(P_inv, load_block33(hub, HUB_INERTIA, 0, 3))
    y = mv(P_inv, force_B)
    CX = mm(C, X)
    schur = (sub(D[0], CX[0]), sub(D[1], CX[1]), sub(D[2], CX[2]))
    omega_dot = mv(inverse3(schur), sub(torque_B, mv(C, y)))
    return sub(y, mv(X, omega_dot)), omega_dot


@njit(cache=True, error_model="numpy", inline="always")
def hub_cs(q):
    """Cosines and sines of the hub's ZYX Euler angles, for the ``_cs`` kernels.

    Parameters
    ----------
    q : ndarray, shape (n_dof,) or longer
        Generalized coordinates (or the augmented state, which starts with them);
        the angles (phi, theta, psi) are q[3:6] [rad].

    Returns
    -------
    tuple of 6 float
        (cos phi, sin phi, cos theta, sin theta, cos psi, sin psi) [-].
    """
    return cos(q[3]), sin(q[3]), cos(q[4]), sin(q[4]), cos(q[5]), sin(q[5])


@njit(cache=True, error_model="numpy")
def accelerations(q, qd, Q, packed, qdd):
    """Solve M(q) q_ddot = Q - h(q, q_dot) - C q_dot - k_el(q) for q_ddot (eq. 2.50).

    Parameters
    ----------
    q, qd : ndarray, shape (n_dof,)
        Generalized coordinates and their rates: hub position [m], ZYX Euler angles
        [rad], appendage coordinates [m or rad]; rates [m/s, rad/s].
    Q : ndarray, shape (n_dof,)
        External generalized forces [N, N m per coordinate] (see
        :func:`flexsat.dynamics.plant.Plant.generalized_forces`).
    packed : PackedPlant
        The plant's packed arrays and kernels (:class:`flexsat.dynamics.packed.PackedPlant`).
    qdd : ndarray, shape (n_dof,)
        Output: generalized accelerations [m/s^2, rad/s^2].

    Returns
    -------
    int
        ``STATUS_OK`` or a gimbal-lock status (``qdd`` is then undefined). As a side
        result ``packed.hub[HUB_DISSIPATION]`` holds the damper power q_dot^T C q_dot.
    """
    return accelerations_cs(hub_cs(q), q, qd, Q, packed, qdd)


@njit(cache=True, error_model="numpy")
def accelerations_cs(cs, q, qd, Q, packed, qdd):
    """:func:`accelerations` given the cosines and sines of the hub angles, ``hub_cs(q)``.

    A caller that needs them too (the body rate S(Theta) Theta_dot of the coupled
    actuation stages, :mod:`flexsat.simulate.coupled`) computes them once for both.

    Parameters
    ----------
    cs : tuple of 6 float
        :func:`hub_cs` of ``q`` [-].
    q, qd : ndarray, shape (n_dof,)
        Generalized coordinates and their rates [m, rad; m/s, rad/s].
    Q : ndarray, shape (n_dof,)
        External generalized forces [N, N m per coordinate].
    packed : PackedPlant
        The plant's packed arrays and kernels.
    qdd : ndarray, shape (n_dof,)
        Output: generalized accelerations [m/s^2, rad/s^2].

    Returns
    -------
    int
        As for :func:`accelerations`.
    """
    c1, s1, c2, s2, c3, s3 = cs
    if abs(c2) < _MIN_COS:
        return STATUS_HUB_GIMBAL_LOCK
    R_NB = rot_zyx_cs(c1, s1, c2, s2, c3, s3)
    S_inv = euler_rate_matrix_inv_cs(c1, s1, c2, s2)
    omega_B = mv(euler_rate_matrix_cs(c1, s1, c2, s2), load_seg(qd, 3))
    hub = packed.hub
    _put(hub, HUB_OMEGA, omega_B)
    _put(hub, HUB_FORCE, mtv(R_NB, load_seg(Q, 0)))  # Q_r is an inertial force
    _put(hub, HUB_TORQUE, mtv(S_inv, load_seg(Q, 3)))  # Q_Theta = S^T tau => tau = S^-T Q_Theta
    hub[HUB_DISSIPATION] = 0.0
    if packed.articulated:
        hub[HUB_INERTIA : HUB_INERTIA + 36] = 0.0

    # Pass 1: each appendage's wrench on the hub (and articulated inertia).
    for g in range(len(packed.pass1)):
        status = packed.pass1[g](
            q, qd, Q, packed.members[g], packed.params[g], packed.work[g], hub, qdd
        )
        if status != STATUS_OK:
            return status

    # Hub Newton-Euler in B; the Schur complement is the bare hub's mass matrix unless
    # an appendage transmits inertia.
    force_B = load_seg(hub, HUB_FORCE)
    torque_B = load_seg(hub, HUB_TORQUE)
    J_h = packed.hub_J
    gyro_free = sub(torque_B, cross(omega_B, mv(J_h, omega_B)))
    if packed.articulated:
        a_hub_B, omega_dot_B = _solve_hub(packed, force_B, gyro_free)
    else:
        a_hub_B = scale(1.0 / packed.hub_mass, force_B)
        omega_dot_B = mv(packed.hub_J_inv, gyro_free)
    _put(hub, HUB_ACC, a_hub_B)
    _put(hub, HUB_ALPHA, omega_dot_B)
    qdd[0], qdd[1], qdd[2] = mv(R_NB, a_hub_B)
    s_bias = euler_rate_bias_cs(c1, s1, c2, s2, qd[3], qd[4], qd[5])
    qdd[3], qdd[4], qdd[5] = mv(S_inv, sub(omega_dot_B, s_bias))

    # Pass 2: each appendage's coordinate accelerations given the hub's.
    for g in range(len(packed.pass2)):
        status = packed.pass2[g](
            q, qd, packed.members[g], packed.params[g], packed.work[g], hub, qdd
        )
        if status != STATUS_OK:
            return status
    if packed.constrained:
        _constraint_forces(packed, qdd)
    if packed.locked:
        _hold_locked(q, packed, qdd)
    return STATUS_OK


@njit(cache=True, error_model="numpy")
def _constraint_forces(packed, qdd):
    """Move the constraint forces the models that hold their locked coordinates left
    in those rows of q_ddot to ``packed.reaction[1]`` (the other rows zero) and hold
    the rows at 0 (docs/model.md, 'Locked coordinates')."""
    reaction = packed.reaction[1]
    reaction[:] = 0.0
    for i in packed.held:
        reaction[i] = qdd[i]
        qdd[i] = 0.0


@njit(cache=True, error_model="numpy")
def _hold_locked(q, packed, qdd):
    """Project the unconstrained q_ddot on the free coordinates (locked ones held).

    With the locked coordinates' rows of q_ddot zero and a constraint force on those
    rows only, the free rows of M q_ddot + h = F + E lambda give
    M_ff q_ddot_f = F_f - h_f = (M q_ddot_u)_f, where q_ddot_u (in ``qdd``) solved the
    unconstrained M q_ddot_u + h = F at the same state: no model term beyond M(q) is
    needed. M_ff is symmetric positive definite: Gaussian elimination without pivoting.
    The same holds when ``qdd`` already has the coordinates of models that hold their
    locks at zero (their constraint forces act on locked rows only). As a side result
    the constraint forces lambda are added to ``packed.reaction[1]``.
    """
    M, A, free, unconstrained = packed.mass, packed.reduced, packed.free, packed.reaction[0]
    mass_matrix(q, packed, M)
    n, m = qdd.shape[0], free.shape[0]
    copy_into(unconstrained, qdd)
    for r in range(m):
        i = free[r]
        s = 0.0
        for j in range(n):
            s += M[i, j] * qdd[j]
        A[r, m] = s
        for c in range(m):
            A[r, c] = M[i, free[c]]
    for p in range(m):
        for r in range(p + 1, m):
            f = A[r, p] / A[p, p]
            for c in range(p, m + 1):
                A[r, c] -= f * A[p, c]
    for r in range(m - 1, -1, -1):
        s = A[r, m]
        for c in range(r + 1, m):
            s -= A[r, c] * A[c, m]
        A[r, m] = s / A[r, r]
    qdd[:] = 0.0
    for r in range(m):
        qdd[free[r]] = A[r, m]
    # lambda = M (q_ddot - q_ddot_u) on the locked rows (zero on the free ones, to
    # within rounding): the force the locked joints carry, reported in tau_flex.
    reaction = packed.reaction[1]
    for i in range(n):
        if not packed.is_free[i]:
            s = 0.0
            for j in range(n):
                s += M[i, j] * (qdd[j] - unconstrained[j])
            reaction[i] += s


@njit(cache=True, error_model="numpy")
def mass_matrix(q, packed, M):
    """Mass matrix M(q) (eq. 2.39), written into ``M``.

    Assembled from the bodies' velocity Jacobians, M = sum_b m_b Jv_b^T Jv_b +
    Jw_b^T J_b Jw_b: the hub's here, each appendage's by its model.

    Parameters
    ----------
    q : ndarray, shape (n_dof,)
        Generalized coordinates [m, rad].
    packed : PackedPlant
        The plant's packed arrays and kernels.
    M : ndarray, shape (n_dof, n_dof)
        Output: the mass matrix [kg, kg m, kg m^2 per entry].
    """
    M[:, :] = 0.0
    S = euler_rate_matrix(q[3], q[4])
    identity = ((1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0))
    add_block(M, 0, 0, identity, packed.hub_mass)
    J_h = packed.hub_J
    J_hub = (
        (J_h[0, 0], J_h[0, 1], J_h[0, 2]),
        (J_h[1, 0], J_h[1, 1], J_h[1, 2]),
        (J_h[2, 0], J_h[2, 1], J_h[2, 2]),
    )
    add_block(M, 3, 3, mtm(S, mm(J_hub, S)), 1.0)
    for g in range(len(packed.mass_matrix)):
        packed.mass_matrix[g](q, packed.members[g], packed.params[g], M)


@njit(cache=True, error_model="numpy")
def bias_forces(q, qd, packed, h):
    """Coriolis and centrifugal vector h(q, q_dot) (eq. 2.43), written into ``h``.

    Computed as Kane's generalized inertia forces at q_ddot = 0, which equal
    M_dot q_dot - (dT/dq)^T for this holonomic system: h = sum_b Jv_b^T m_b a0_b +
    Jw_b^T (J_b alpha0_b + w_b x J_b w_b), with a0, alpha0 the accelerations
    at zero q_ddot.

    Parameters
    ----------
    q, qd : ndarray, shape (n_dof,)
        Generalized coordinates [m, rad] and their rates [m/s, rad/s].
    packed : PackedPlant
        The plant's packed arrays and kernels.
    h : ndarray, shape (n_dof,)
        Output: h [N, N m per coordinate].
    """
    phi, theta = q[3], q[4]
    S = euler_rate_matrix(phi, theta)
    omega_B = mv(S, load_seg(qd, 3))
    s_bias = euler_rate_bias(phi, theta, qd[3], qd[4], qd[5])
    J_h = packed.hub_J
    hub = packed.hub
    _put(hub, HUB_OMEGA, omega_B)
    _put(hub, HUB_SBIAS, s_bias)
    _put(hub, HUB_FORCE, (0.0, 0.0, 0.0))
    _put(hub, HUB_TORQUE, add(mv(J_h, s_bias), cross(omega_B, mv(J_h, omega_B))))
    for g in range(len(packed.bias_forces)):
        packed.bias_forces[g](q, qd, packed.members[g], packed.params[g], hub, h)
    h[0], h[1], h[2] = load_seg(hub, HUB_FORCE)
    h[3], h[4], h[5] = mtv(S, load_seg(hub, HUB_TORQUE))


@njit(cache=True, error_model="numpy")
def joint_forces(Q, packed, out):
    """Generalized forces the joints carry at the state :func:`accelerations` last
    evaluated, written into ``out``: the external ones ``Q`` plus the constraint forces
    of the locked coordinates (``packed.reaction[1]``, if the plant has any).

    Parameters
    ----------
    Q : ndarray, shape (n_dof,)
        The external generalized forces that evaluation was given [N, N m per
        coordinate].
    packed : PackedPlant
        The plant's packed arrays and kernels.
    out : ndarray, shape (n_dof,)
        Output: the joints' generalized forces, the ``Q`` argument of
        :func:`hub_joint_wrench` [N, N m per coordinate].
    """
    copy_into(out, Q)
    if packed.constrained:
        reaction = packed.reaction[1]
        for i in range(out.shape[0]):
            out[i] += reaction[i]


@njit(cache=True, inline="always")
def keep_solution(qdd, packed, out):
    """Keep what the last :func:`accelerations` evaluation solved for, in ``out``:
    q_ddot and the constraint forces of the locked coordinates (zero without).

    Parameters
    ----------
    qdd : ndarray, shape (n_dof,)
        The q_ddot it returned [m/s^2, rad/s^2] (may be ``out[0]`` itself).
    packed : PackedPlant
        The plant's packed arrays and kernels.
    out : ndarray, shape (2, n_dof)
        Output: ``out[0]`` q_ddot [m/s^2, rad/s^2], ``out[1]`` the constraint forces
        lambda (``packed.reaction[1]``) [N, N m per coordinate]; ``Q + out[1]`` is
        what :func:`joint_forces` gives.
    """
    copy_into(out[0], qdd)
    if packed.constrained:
        copy_into(out[1], packed.reaction[1])
    else:
        out[1, :] = 0.0


@njit(cache=True, error_model="numpy")
def hub_joint_wrench(q, qd, qdd, Q, packed, out):
    """Wrench the appendages' joints exert on the hub, written into ``out``.

    The whole wrench each root joint transmits: elastic + damping, plus any external
    generalized force on the joint coordinates, plus the constraint reaction of the
    directions the joint does not free (contract ``WRENCH_SIGNATURE``).

    Parameters
    ----------
    q, qd : ndarray, shape (n_dof,)
        Generalized coordinates [m, rad] and their rates [m/s, rad/s].
    qdd : ndarray, shape (n_dof,)
        Generalized accelerations at (q, qd) [m/s^2, rad/s^2], as :func:`accelerations`
        returns them (locked rows zero).
    Q : ndarray, shape (n_dof,)
        Generalized forces on the appendage coordinates: joint actuations and the
        constraint forces of locked coordinates [N, N m per coordinate].
    packed : PackedPlant
        The plant's packed arrays and kernels.
    out : ndarray, shape (6,)
        Output: ``out[0:3]`` the force [N] and ``out[3:6]`` the torque tau_flex about
        the hub centre of mass [N m], both in hub frame B.

    Returns
    -------
    int
        ``STATUS_OK`` or an appendage's failure status.
    """
    out[:] = 0.0
    for g in range(len(packed.joint_wrench)):
        status = packed.joint_wrench[g](q, qd, qdd, Q, packed.members[g], packed.params[g], out)
        if status != STATUS_OK:
            return status
    return STATUS_OK


@njit(cache=True, error_model="numpy")
def observe(q, qd, packed, out):
    """Energies, momentum and locked inertia at one state, into ``out``.

    Parameters
    ----------
    q, qd : ndarray, shape (n_dof,)
        Generalized coordinates [m, rad] and their rates [m/s, rad/s].
    packed : PackedPlant
        The plant's packed arrays and kernels.
    out : ndarray, shape (OBS_SIZE,)
        Output, slots ``OBS_*`` of the contract module: kinetic energy T (eqs.
        2.32-2.34) [J]; total angular momentum about the inertial origin, frame N
        [N m s] (exactly conserved without external torque); the locked inertia J(eta)
        of the satellite frozen in its current shape, about the hub centre of mass,
        frame B [kg m^2] (J(eta) omega_B is the rigid part of the angular momentum the
        thesis plots); elastic energy U (eq. 2.35) [J]; damper power q_dot^T C q_dot
        (eq. 2.36) [W].
    """
    R_NB = rot_zyx(q[3], q[4], q[5])
    r_hub = load_seg(q, 0)
    v_hub = load_seg(qd, 0)
    omega_B = mv(euler_rate_matrix(q[3], q[4]), load_seg(qd, 3))
    J_h = packed.hub_J
    m_h = packed.hub_mass
    out[OBS_KINETIC] = 0.5 * m_h * dot(v_hub, v_hub) + 0.5 * dot(omega_B, mv(J_h, omega_B))
    H = add(cross(r_hub, scale(m_h, v_hub)), mv(R_NB, mv(J_h, omega_B)))
    _put(out, OBS_MOMENTUM, H)
    for a in range(3):
        for b in range(3):
            out[OBS_LOCKED_INERTIA + 3 * a + b] = J_h[a, b]
    out[OBS_ELASTIC] = 0.0
    out[OBS_DISSIPATION] = 0.0
    for g in range(len(packed.observe)):
        packed.observe[g](q, qd, packed.members[g], packed.params[g], out)


@njit(cache=True, error_model="numpy")
def tip_displacement(q, packed, out):
    """Displacement of each appendage's tip from its undeformed place, mount frame.

    Parameters
    ----------
    q : ndarray, shape (n_dof,)
        Generalized coordinates [m, rad].
    packed : PackedPlant
        The plant's packed arrays and kernels.
    out : ndarray, shape (n_appendages, 3)
        Output: one row per appendage in config order [m].
    """
    for g in range(len(packed.tips)):
        packed.tips[g](q, packed.members[g], packed.params[g], out)
