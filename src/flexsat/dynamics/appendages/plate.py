"""The thesis's appendage: a rigid thin plate on a 6-DOF elastic root joint.

Coordinates (six per plate, thesis eq. 2.1)::

    eta (3)   root translation, mount frame M_i [m]
    rho (3)   root rotation, ZYX angles (eta_r) [rad]

Kinematics are exact: the panel rotation relative to its mount is
R_MP = Rz(rho_z) Ry(rho_y) Rx(rho_x) with relative body rate S(rho) rho_dot (the
thesis writes rho_dot, the small-angle form of eq. 2.31; see docs/model.md).

Because the plate hangs on a full 6-DOF joint, its joint wrench does not depend on
the hub's acceleration: it transmits no articulated inertia, and each plate's
absolute accelerations follow from its own Newton-Euler equations under the joint
wrench (pass 1), the hub's from its own equations (the engine), and q_ddot from the
relative kinematics (pass 2). Cost is linear in the number of plates.

A plate with locked joint DOFs (``locked_dofs``) holds them itself
(``holds_locked``): its joint then has fewer than 6 DOFs and transmits the
articulated inertia of its locked directions; pass 1 and 2 solve the joint's
Newton-Euler equations on its free DOFs (docs/model.md, 'Locked coordinates').

Compiled with ``error_model="numpy"`` (see :mod:`flexsat.dynamics.kernels`): no
divisor can be zero, masses are validated positive and ``cos(rho_y)`` is checked
against ``MIN_COS`` before any ``euler_rate_matrix_inv``.
"""

from __future__ import annotations

from collections.abc import Sequence
from math import cos, sin
from typing import ClassVar

import numpy as np
from numba import njit

from flexsat.compiled.linalg3 import (
    add,
    add_block,
    cross,
    dot,
    euler_rate_bias_cs,
    euler_rate_matrix,
    euler_rate_matrix_cs,
    euler_rate_matrix_inv_cs,
    load_m33_at,
    load_seg,
    mm,
    mtm,
    mtv,
    mv,
    rot_zyx,
    rot_zyx_cs,
    scale,
    scale_m,
    skew,
    sub,
    transpose,
)
from flexsat.compiled.status import STATUS_JOINT_GIMBAL_LOCK, STATUS_OK
from flexsat.dynamics.appendages.chain_config import ChainConfig
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
    AppendageKernels,
    AppendageModel,
    Coordinate,
    DerivedPath,
    RigidBody,
)
from flexsat.dynamics.appendages.plate_config import PlateConfig
from flexsat.dynamics.appendages.sadm import driven_plate
from flexsat.dynamics.rotation import EulerRotation as Rotation
from flexsat.dynamics.tuning import tune_joints

__all__ = ["JOINT_DOFS", "PlateModel"]

JOINT_DOFS = ("eta_x", "eta_y", "eta_z", "eta_rx", "eta_ry", "eta_rz")
_UNITS = ("m", "m", "m", "rad", "rad", "rad")

# Packed parameter row of one plate.
P_MOUNT = 0  # (3) r_m, root position in B [m]
P_R_BM = 3  # (9) R_BM, mount frame M_i -> hub frame B (includes the SADM angle), row-major
P_COM = 12  # (3) d_Gp, root -> panel centre of mass, panel frame P_i [m]
P_MASS = 15  # (1) panel mass M_p [kg]
P_J = 16  # (9) panel inertia about G_p in P_i [kg m^2]
P_J_INV = 25  # (9) its inverse
P_K = 34  # (6) joint stiffness per DOF [N/m, N m/rad] (eq. 2.14)
P_C = 40  # (6) joint damping per DOF [N s/m, N m s/rad] (eq. 2.15)
P_TIP = 46  # (3) panel tip (mid-chord of the free edge), panel frame [m]
P_LOCKED = 49  # (6) 1.0 where the joint DOF is locked (``locked_dofs``), else 0.0
P_IP = 55  # (9) I_P, panel inertia about the root, panel frame [kg m^2]
P_IP_INV = 64  # (9) its inverse
P_M_ROOT = 73  # (9) M_P = m 1 + m^2 [d]x I_P^-1 [d]x, the effective mass at the root [kg]
P_JOINT = 82  # (1) the joint's locks, from P_LOCKED: JOINT_FREE, JOINT_SPHERICAL or JOINT_LOCKED
N_PARAMS = 83

# Joint kinds (P_JOINT): which pass-1 and pass-2 equations a plate's joint takes, read
# once per plate and evaluation instead of scanning its six lock flags. The passes
# inline what they call on every evaluation (``inline="always"``: _pose and the
# spherical joint's equations); LLVM left them as calls, each passing every array's
# fields as arguments (docs/performance.md, 'Campaign cases').
JOINT_FREE = 0.0  # nothing locked: the 6-DOF joint
JOINT_SPHERICAL = 1.0  # exactly the translations locked (the reduced plant's set)
JOINT_LOCKED = 2.0  # any other set of locks: the general elimination over the free rows

MIN_COS = 1e-9  # |cos(rho_y)| below this is treated as gimbal lock


@njit(cache=True, error_model="numpy", inline="always")
def _rho_cs(q, o):
    """Cosines and sines of the joint angles rho = q[o+3:o+6]: (c1, s1, c2, s2, c3, s3).

    A pass computes them once for the pose, S(rho), S(rho)^-1 and the rate bias (the
    ``_cs`` forms of :mod:`flexsat.compiled.linalg3`, the same arithmetic) instead of
    once per helper: four sines and cosines fewer per plate and evaluation.
    """
    return cos(q[o + 3]), sin(q[o + 3]), cos(q[o + 4]), sin(q[o + 4]), cos(q[o + 5]), sin(q[o + 5])


@njit(cache=True, error_model="numpy", inline="always")
def _rho_bias(cs, qd, o):
    """S_dot(rho) rho_dot of the joint angles, from :func:`_rho_cs` [rad/s^2]."""
    return euler_rate_bias_cs(cs[0], cs[1], cs[2], cs[3], qd[o + 3], qd[o + 4], qd[o + 5])


@njit(cache=True, error_model="numpy", inline="always")
def _pose(q, o, p, cs):
    """Pose of the plate whose coordinates start at q[o], relative to the hub, in B.

    ``cs`` is :func:`_rho_cs` ``(q, o)``. Returns R_BM, R_MP (panel -> mount), R_BP
    (panel -> hub), S(rho), r_P (root position) and r_G (panel centre of mass), both
    from the hub centre of mass [m].
    """
    R_BM = load_m33_at(p, P_R_BM)
    R_MP = rot_zyx_cs(cs[0], cs[1], cs[2], cs[3], cs[4], cs[5])
    R_BP = mm(R_BM, R_MP)
    S_rho = euler_rate_matrix_cs(cs[0], cs[1], cs[2], cs[3])
    r_P = add(load_seg(p, P_MOUNT), mv(R_BM, load_seg(q, o)))
    r_G = add(r_P, mv(R_BP, load_seg(p, P_COM)))
    return R_BM, R_MP, R_BP, S_rho, r_P, r_G


@njit(cache=True, error_model="numpy", inline="always")
def _rates(qd, o, p, R_BM, R_BP, S_rho):
    """Relative rates: omega_rel_P (panel frame) and the B-frame rate of r_G."""
    omega_rel_P = mv(S_rho, load_seg(qd, o + 3))
    rdot_G_rel = add(
        mv(R_BM, load_seg(qd, o)),
        mv(R_BP, cross(omega_rel_P, load_seg(p, P_COM))),
    )
    return omega_rel_P, rdot_G_rel


@njit(cache=True, error_model="numpy", inline="always")
def _joint_forces(q, qd, Q, o, p):
    """Elastic, damping and external generalized forces on the joint (Q_eta, Q_rho)."""
    k, c = P_K, P_C
    Q_eta = (
        Q[o] - p[k] * q[o] - p[c] * qd[o],
        Q[o + 1] - p[k + 1] * q[o + 1] - p[c + 1] * qd[o + 1],
        Q[o + 2] - p[k + 2] * q[o + 2] - p[c + 2] * qd[o + 2],
    )
    Q_rho = (
        Q[o + 3] - p[k + 3] * q[o + 3] - p[c + 3] * qd[o + 3],
        Q[o + 4] - p[k + 4] * q[o + 4] - p[c + 4] * qd[o + 4],
        Q[o + 5] - p[k + 5] * q[o + 5] - p[c + 5] * qd[o + 5],
    )
    return Q_eta, Q_rho


@njit(cache=True, error_model="numpy", inline="always")
def _joint_wrench(q, qd, Q, o, p, cs):
    """Joint wrench on the plate from its elastic, damping and external generalized forces.

    By virtual work the 6 generalized forces on (eta, rho) are a force F_M at the
    root (mount frame) and a torque N_P (panel frame) on the panel, with the
    opposite pair on the hub: F_M = Q_eta, N_P = S(rho)^-T Q_rho.
    Returns F_M, N_P, S(rho)^-1 and a status flag (S(rho)^-1 is undefined on a
    gimbal lock). ``cs`` is :func:`_rho_cs` ``(q, o)``.
    """
    Q_eta, Q_rho = _joint_forces(q, qd, Q, o, p)
    if abs(cs[2]) < MIN_COS:
        undefined = ((0.0, 0.0, 0.0), (0.0, 0.0, 0.0), (0.0, 0.0, 0.0))
        return Q_eta, Q_rho, undefined, STATUS_JOINT_GIMBAL_LOCK
    S_inv = euler_rate_matrix_inv_cs(cs[0], cs[1], cs[2], cs[3])
    return Q_eta, mtv(S_inv, Q_rho), S_inv, STATUS_OK


@njit(cache=True, error_model="numpy", inline="always")
def _add_hub_wrench(out, f, r_P, R_BM, R_BP, F_M, N_P):
    """Subtract the joint's reaction from the hub wrench at out[f:f+6]; returns F_B.

    out[f:f+3] -= F_B and out[f+3:f+6] -= r_P x F_B + R_BP N_P (in that order).
    """
    F_B = mv(R_BM, F_M)
    arm = cross(r_P, F_B)
    turn = mv(R_BP, N_P)
    for a in range(3):
        out[f + a] = out[f + a] - F_B[a]
        out[f + 3 + a] = (out[f + 3 + a] - arm[a]) - turn[a]
    return F_B


# Scratch row that pass 1 leaves for pass 2 (terms that depend on q and q_dot only).
W_R_BP = 0  # (9) R_BP, row-major
W_R_G = 9  # (3) r_G [m], frame B
W_OMEGA_REL = 12  # (3) omega_rel_P [rad/s]
W_RDOT_G = 15  # (3) B-frame rate of r_G [m/s]
W_S_INV = 18  # (9) S(rho)^-1, row-major
W_RHO_BIAS = 27  # (3) S_dot(rho) rho_dot


@njit(cache=True, error_model="numpy")
def _store(w, k, v):
    w[k], w[k + 1], w[k + 2] = v


@njit(cache=True, error_model="numpy")
def _store_m33(w, k, m):
    for a in range(3):
        w[k + 3 * a], w[k + 3 * a + 1], w[k + 3 * a + 2] = m[a]


# Scratch of a member with locked joint DOFs (docs/model.md, 'Locked coordinates'):
# z = (eta_ddot, rho_ddot) of its joint, J^T I_P J z + K A_hub = r + E lambda.
W_MZ = 30  # (36) Mz = J^T I_P J, the joint's generalized mass, row-major 6 x 6
W_K = 66  # (36) K = J^T I_P X, its coupling to the hub acceleration A_hub, row-major
W_RV = 102  # (6) r = tau + J^T (b - I_P c): joint forces and velocity terms
W_FREE = 108  # (6) the free DOFs' indices (0-5), as floats
W_NF = 114  # (1) number of free DOFs
W_SOLVE = 115  # (78) [Mz_FF | K_F | r_F], n_free rows, then D^-1 [K_F | r_F] in place
W_WRENCH = 193  # (6) its wrench on the hub at A_hub = 0, [force_B, torque_B]
WORK_SIZE = 199


@njit(cache=True, error_model="numpy")
def _add6(w, k, r0, c0, A, s):
    """w[k + 6 (r0 + a) + c0 + b] += s A[a][b]: a 3 x 3 block of a row-major 6 x 6 at w[k]."""
    for a in range(3):
        for b in range(3):
            w[k + 6 * (r0 + a) + c0 + b] += s * A[a][b]


def _joint_kind(locked: np.ndarray) -> float:
    """The packed joint kind (``P_JOINT``) of a plate's six lock flags (``P_LOCKED``)."""
    if not np.any(locked):
        return JOINT_FREE
    if np.all(locked[:3]) and not np.any(locked[3:]):
        return JOINT_SPHERICAL
    return JOINT_LOCKED


@njit(cache=True, error_model="numpy")
def _axpy(a, s, b):
    """a + s b for 3 x 3 matrices."""
    return (add(a[0], scale(s, b[0])), add(a[1], scale(s, b[1])), add(a[2], scale(s, b[2])))


# Scratch of a plate on a spherical joint (root translations locked, rotations free),
# after the pass-1 rows above: what pass 2 reads.
W_SPH_R_P = W_MZ  # (3) r_P, the root, frame B [m]
W_SPH_B_P = W_MZ + 3  # (3) omega_B x (omega_B x r_P): the root's acceleration at A_hub = 0, B
W_SPH_H = W_MZ + 6  # (3) N_P - omega_P x I_P omega_P, frame P [N m]
W_SPH_SPIN = W_MZ + 9  # (3) omega_P x (omega_P x d), frame P [m/s^2]
W_SPH_Q_ETA = W_MZ + 12  # (3) Q_eta, the translations' joint forces, frame M [N]


@njit(cache=True, error_model="numpy", inline="always")
def _spherical_pass1(q, qd, Q, o, p, w, hub):
    """Pass 1 of a plate whose root translations are locked (the reduced plant's set).

    The joint is then spherical: the panel turns freely about its root P, which moves
    with the hub. Euler's equations about P, I_P alpha + omega x I_P omega
    + m d x a_P = N_P (d = P -> G, the joint torque N_P), give alpha from the root's
    acceleration a_P, and m a_G = f the root force::

        f = M_P a_P + m (omega x (omega x d) - d x I_P^-1 (N_P - omega x I_P omega))
        M_P = m 1 + m^2 [d]x I_P^-1 [d]x

    (panel frame; I_P, its inverse and M_P are constants of the panel, packed). M_P,
    the effective mass at the root, is all the articulated inertia the panel hands
    the hub: with a_P = a_hub + omega_dot x r_P + b_P it adds
    [[M, -M [r_P]x], [[r_P]x M, -[r_P]x M [r_P]x]] (M = R_BP M_P R_BP^T) to the hub's
    inertia, and the wrench -f0, -r_P x f0 - R_BP N_P at A_hub = 0: four 3 x 3
    products instead of the general elimination over the free rows (docs/model.md,
    'Locked coordinates'). Returns a status.
    """
    cs = _rho_cs(q, o)
    R_BM, R_MP, R_BP, S_rho, r_P, r_G = _pose(q, o, p, cs)
    if abs(cs[2]) < MIN_COS:
        return STATUS_JOINT_GIMBAL_LOCK
    Q_eta, Q_rho = _joint_forces(q, qd, Q, o, p)
    S_inv = euler_rate_matrix_inv_cs(cs[0], cs[1], cs[2], cs[3])
    N_P = mtv(S_inv, Q_rho)  # S(rho)^-T Q_rho
    omega_B = load_seg(hub, HUB_OMEGA)
    omega_rel_P = mv(S_rho, load_seg(qd, o + 3))
    omega_P = add(mtv(R_BP, omega_B), omega_rel_P)
    m = p[P_MASS]
    d = load_seg(p, P_COM)
    I_P = load_m33_at(p, P_IP)
    h_P = sub(N_P, cross(omega_P, mv(I_P, omega_P)))
    spin = cross(omega_P, cross(omega_P, d))
    f_bias = scale(m, sub(spin, cross(d, mv(load_m33_at(p, P_IP_INV), h_P))))
    M_P = load_m33_at(p, P_M_ROOT)
    M_B = mm(R_BP, mm(M_P, transpose(R_BP)))
    b_P = cross(omega_B, cross(omega_B, r_P))
    f0 = add(mv(M_B, b_P), mv(R_BP, f_bias))
    Rr = skew(r_P)
    MR = mm(M_B, Rr)
    H = HUB_INERTIA
    _add6(hub, H, 0, 0, M_B, 1.0)
    _add6(hub, H, 0, 3, MR, -1.0)
    _add6(hub, H, 3, 0, transpose(MR), -1.0)  # [r_P]x M = -(M [r_P]x)^T
    _add6(hub, H, 3, 3, mm(Rr, MR), -1.0)
    _store(w, W_WRENCH, scale(-1.0, f0))
    _store(w, W_WRENCH + 3, scale(-1.0, add(cross(r_P, f0), mv(R_BP, N_P))))
    _store_m33(w, W_R_BP, R_BP)
    _store(w, W_OMEGA_REL, omega_rel_P)
    _store_m33(w, W_S_INV, S_inv)
    _store(w, W_RHO_BIAS, _rho_bias(cs, qd, o))
    _store(w, W_SPH_R_P, r_P)
    _store(w, W_SPH_B_P, b_P)
    _store(w, W_SPH_H, h_P)
    _store(w, W_SPH_SPIN, spin)
    _store(w, W_SPH_Q_ETA, Q_eta)
    return STATUS_OK


@njit(cache=True, error_model="numpy", inline="always")
def _spherical_pass2(o, p, w, hub, qdd):
    """rho_ddot of a plate on a spherical joint given the hub's accelerations, and in
    the locked rows the constraint force lambda = R_MB f - Q_eta (mount frame; the
    engine moves it out of ``qdd``): :func:`_spherical_pass1`'s equations."""
    m = p[P_MASS]
    d = load_seg(p, P_COM)
    R_BP = load_m33_at(w, W_R_BP)
    omega_B = load_seg(hub, HUB_OMEGA)
    alpha_B = load_seg(hub, HUB_ALPHA)
    a_P_B = add(sub(load_seg(hub, HUB_ACC), cross(load_seg(w, W_SPH_R_P), alpha_B)),
                load_seg(w, W_SPH_B_P))  # fmt: skip
    a_P = mtv(R_BP, a_P_B)
    alpha_P = mv(load_m33_at(p, P_IP_INV), sub(load_seg(w, W_SPH_H), scale(m, cross(d, a_P))))
    f_P = scale(m, add(add(a_P, cross(alpha_P, d)), load_seg(w, W_SPH_SPIN)))
    lam = sub(mtv(load_m33_at(p, P_R_BM), mv(R_BP, f_P)), load_seg(w, W_SPH_Q_ETA))
    omega_rel_P = load_seg(w, W_OMEGA_REL)
    omega_dot_rel = add(sub(alpha_P, mtv(R_BP, alpha_B)), cross(omega_rel_P, mtv(R_BP, omega_B)))
    rho_dd = mv(load_m33_at(w, W_S_INV), sub(omega_dot_rel, load_seg(w, W_RHO_BIAS)))
    qdd[o], qdd[o + 1], qdd[o + 2] = lam
    qdd[o + 3], qdd[o + 4], qdd[o + 5] = rho_dd


@njit(cache=True, error_model="numpy")
def _locked_pass1(q, qd, Q, o, p, w, hub):
    """Pass 1 of a plate whose joint has locked DOFs: articulated inertia and bias wrench.

    The panel's absolute acceleration A_P = (a_G in B, alpha_P in P) is
    X A_hub + J z + c, with A_hub = (a_hub_B, omega_dot_B), z = (eta_ddot, rho_ddot),
    X = [[I, -[r_G]x], [0, R_BP^T]], J = [[R_BM, -R_BP [d]x S(rho)], [0, S(rho)]] and c
    the velocity terms. Its Newton-Euler equations I_P A_P = J^-T (tau + E lambda) + b
    (b the gyroscopic moment), projected by J^T, give Mz z + K A_hub = r + E lambda.
    On the free rows F (z_L = 0): z_F = D^-1 (r_F - K_F A_hub), D = Mz_FF, so the hub
    sees the articulated inertia X^T I_P X - K_F^T D^-1 K_F (added to ``hub``) and, at
    A_hub = 0, the wrench X^T u - K_F^T D^-1 r_F with u = b - I_P c (into
    ``w[W_WRENCH:]``). Root translations locked alone: :func:`_spherical_pass1`.
    Returns a status.
    """
    cs = _rho_cs(q, o)
    R_BM, R_MP, R_BP, S_rho, r_P, r_G = _pose(q, o, p, cs)
    omega_rel_P, rdot_G_rel = _rates(qd, o, p, R_BM, R_BP, S_rho)
    if abs(cs[2]) < MIN_COS:
        return STATUS_JOINT_GIMBAL_LOCK
    Q_eta, Q_rho = _joint_forces(q, qd, Q, o, p)
    omega_B = load_seg(hub, HUB_OMEGA)
    m = p[P_MASS]
    d = load_seg(p, P_COM)
    J_p = load_m33_at(p, P_J)
    omega_B_P = mtv(R_BP, omega_B)
    omega_P = add(omega_B_P, omega_rel_P)
    rho_bias = _rho_bias(cs, qd, o)
    c_a = add(
        add(cross(omega_B, cross(omega_B, r_G)), scale(2.0, cross(omega_B, rdot_G_rel))),
        mv(R_BP, add(cross(rho_bias, d), cross(omega_rel_P, cross(omega_rel_P, d)))),
    )
    c_alpha = sub(rho_bias, cross(omega_rel_P, omega_B_P))
    u_a = scale(-m, c_a)
    u_w = scale(-1.0, add(cross(omega_P, mv(J_p, omega_P)), mv(J_p, c_alpha)))
    J_t = scale_m(-1.0, mm(R_BP, mm(skew(d), S_rho)))  # d v_G / d rho_dot
    G = skew(r_G)
    R_MB = transpose(R_BM)
    identity = ((1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0))
    g_eta = mtv(R_BM, u_a)
    g_rho = add(mtv(J_t, u_a), mtv(S_rho, u_w))
    for a in range(3):
        w[W_RV + a] = Q_eta[a] + g_eta[a]
        w[W_RV + 3 + a] = Q_rho[a] + g_rho[a]
    # The panel's spatial inertia about the hub centre of mass, X^T I_P X; the free
    # rows' Schur term K_F^T D^-1 K_F comes off it below.
    H = HUB_INERTIA
    _add6(hub, H, 0, 0, identity, m)
    _add6(hub, H, 0, 3, G, -m)
    _add6(hub, H, 3, 0, G, m)
    _add6(hub, H, 3, 3, mm(G, G), -m)
    _add6(hub, H, 3, 3, mm(R_BP, mm(J_p, transpose(R_BP))), 1.0)
    Xu = add(cross(r_G, u_a), mv(R_BP, u_w))
    w[W_MZ : W_MZ + 72] = 0.0  # Mz and K
    _add6(w, W_MZ, 0, 0, identity, m)
    _add6(w, W_MZ, 0, 3, mm(R_MB, J_t), m)
    _add6(w, W_MZ, 3, 0, mtm(J_t, R_BM), m)
    _add6(w, W_MZ, 3, 3, mtm(J_t, J_t), m)
    _add6(w, W_MZ, 3, 3, mtm(S_rho, mm(J_p, S_rho)), 1.0)
    _add6(w, W_K, 0, 0, R_MB, m)
    _add6(w, W_K, 0, 3, mm(R_MB, G), -m)
    _add6(w, W_K, 3, 0, transpose(J_t), m)
    _add6(w, W_K, 3, 3, mtm(J_t, G), -m)
    _add6(w, W_K, 3, 3, mtm(S_rho, mm(J_p, transpose(R_BP))), 1.0)
    nf = 0
    for k in range(6):
        if p[P_LOCKED + k] == 0.0:
            w[W_FREE + nf] = k
            nf += 1
    w[W_NF] = nf
    # [D | K_F | r_F], eliminated without pivoting (D is symmetric positive definite).
    nc = nf + 7
    A = W_SOLVE
    for r in range(nf):
        i = int(w[W_FREE + r])
        for c in range(nf):
            w[A + nc * r + c] = w[W_MZ + 6 * i + int(w[W_FREE + c])]
        for b in range(6):
            w[A + nc * r + nf + b] = w[W_K + 6 * i + b]
        w[A + nc * r + nf + 6] = w[W_RV + i]
    for piv in range(nf):
        for r in range(piv + 1, nf):
            f = w[A + nc * r + piv] / w[A + nc * piv + piv]
            for c in range(piv, nc):
                w[A + nc * r + c] -= f * w[A + nc * piv + c]
    for r in range(nf - 1, -1, -1):
        for j in range(nf, nc):
            s = w[A + nc * r + j]
            for c in range(r + 1, nf):
                s -= w[A + nc * r + c] * w[A + nc * c + j]
            w[A + nc * r + j] = s / w[A + nc * r + r]
    wrench = (u_a[0], u_a[1], u_a[2], Xu[0], Xu[1], Xu[2])
    for a in range(6):
        s = wrench[a]
        for r in range(nf):
            k_ra = w[W_K + 6 * int(w[W_FREE + r]) + a]
            s -= k_ra * w[A + nc * r + nf + 6]
            for b in range(6):
                hub[H + 6 * a + b] -= k_ra * w[A + nc * r + nf + b]
        w[W_WRENCH + a] = s
    return STATUS_OK


@njit(cache=True, error_model="numpy")
def _locked_pass2(o, p, w, hub, qdd):
    """z_F = D^-1 (r_F - K_F A_hub) on the free rows; on the locked rows the constraint
    force lambda_L = (Mz z)_L + K_L A_hub - r_L (the engine moves it out of ``qdd``).
    Root translations locked alone: :func:`_spherical_pass2`."""
    nf = int(w[W_NF])
    nc = nf + 7
    A = W_SOLVE
    for k in range(6):
        qdd[o + k] = 0.0
    for r in range(nf):
        z = w[A + nc * r + nf + 6]
        for b in range(6):  # A_hub = hub[HUB_ACC : HUB_ACC + 6] (HUB_ALPHA follows HUB_ACC)
            z -= w[A + nc * r + nf + b] * hub[HUB_ACC + b]
        qdd[o + int(w[W_FREE + r])] = z
    free = 0
    for k in range(6):
        if free < nf and int(w[W_FREE + free]) == k:
            free += 1
            continue
        s = -w[W_RV + k]
        for c in range(6):
            s += w[W_K + 6 * k + c] * hub[HUB_ACC + c]
        for r in range(nf):
            i = int(w[W_FREE + r])
            s += w[W_MZ + 6 * k + i] * qdd[o + i]
        qdd[o + k] = s


def _passes(holds_locks: bool) -> tuple:
    """Pass 1 and pass 2 of a group of plates (numba closures, cached apiece).

    With ``holds_locks`` False numba prunes the locked-joint branches before typing:
    the passes of a group whose plates lock nothing compile without
    :func:`_locked_pass1` and :func:`_locked_pass2` (about 6 s less compilation).
    """

    @njit(cache=True, error_model="numpy")  # compiled with PASS1_SIGNATURE on first use
    def pass1(q, qd, Q, members, params, work, hub, qdd):
        """Joint wrenches -> panel absolute accelerations and the reaction on the hub.

        Writes the panel's absolute accelerations a_G (B) and alpha_P (P) into its rows
        of ``qdd`` and its pose and rate terms into its ``work`` row for :func:`pass2`.
        """
        omega_B = load_seg(hub, HUB_OMEGA)
        force_B = load_seg(hub, HUB_FORCE)
        torque_B = load_seg(hub, HUB_TORQUE)
        dissipated = hub[HUB_DISSIPATION]
        for j in range(members.shape[0]):
            o = members[j, 1]
            p = params[j]
            w = work[j]
            if holds_locks and p[P_JOINT] != JOINT_FREE:  # pruned before typing when False
                if p[P_JOINT] == JOINT_SPHERICAL:
                    status = _spherical_pass1(q, qd, Q, o, p, w, hub)
                else:
                    status = _locked_pass1(q, qd, Q, o, p, w, hub)
                if status != STATUS_OK:
                    return status
                force_B = add(force_B, load_seg(w, W_WRENCH))
                torque_B = add(torque_B, load_seg(w, W_WRENCH + 3))
                for k in range(6):
                    v = qd[o + k]
                    dissipated += p[P_C + k] * v * v  # q_dot^T C q_dot (eq. 2.36)
                continue
            cs = _rho_cs(q, o)
            R_BM, R_MP, R_BP, S_rho, r_P, r_G = _pose(q, o, p, cs)
            omega_rel_P, rdot_G_rel = _rates(qd, o, p, R_BM, R_BP, S_rho)
            F_M, N_P, S_inv, status = _joint_wrench(q, qd, Q, o, p, cs)
            if status != STATUS_OK:
                return status
            F_B = mv(R_BM, F_M)
            force_B = sub(force_B, F_B)
            torque_B = sub(sub(torque_B, cross(r_P, F_B)), mv(R_BP, N_P))
            # Panel Newton-Euler about its centre of mass G (the root force acts at -d from G).
            d = load_seg(p, P_COM)
            J_p = load_m33_at(p, P_J)
            omega_P = add(mtv(R_BP, omega_B), omega_rel_P)
            moment_P = add(N_P, cross(scale(-1.0, d), mtv(R_MP, F_M)))
            alpha_P = mv(load_m33_at(p, P_J_INV), sub(moment_P, cross(omega_P, mv(J_p, omega_P))))
            a_G = scale(1.0 / p[P_MASS], F_B)
            qdd[o], qdd[o + 1], qdd[o + 2] = a_G
            qdd[o + 3], qdd[o + 4], qdd[o + 5] = alpha_P
            for k in range(6):
                v = qd[o + k]
                dissipated += p[P_C + k] * v * v  # q_dot^T C q_dot (eq. 2.36)
            _store_m33(w, W_R_BP, R_BP)
            _store(w, W_R_G, r_G)
            _store(w, W_OMEGA_REL, omega_rel_P)
            _store(w, W_RDOT_G, rdot_G_rel)
            _store_m33(w, W_S_INV, S_inv)
            rho_bias = _rho_bias(cs, qd, o)
            _store(w, W_RHO_BIAS, rho_bias)
        hub[HUB_FORCE], hub[HUB_FORCE + 1], hub[HUB_FORCE + 2] = force_B
        hub[HUB_TORQUE], hub[HUB_TORQUE + 1], hub[HUB_TORQUE + 2] = torque_B
        hub[HUB_DISSIPATION] = dissipated
        return STATUS_OK

    @njit(cache=True, error_model="numpy")  # compiled with PASS2_SIGNATURE on first use
    def pass2(q, qd, members, params, work, hub, qdd):
        """Relative accelerations of each joint from the absolute ones left by :func:`pass1`."""
        omega_B = load_seg(hub, HUB_OMEGA)
        a_hub_B = load_seg(hub, HUB_ACC)
        omega_dot_B = load_seg(hub, HUB_ALPHA)
        for j in range(members.shape[0]):
            o = members[j, 1]
            p = params[j]
            w = work[j]
            if holds_locks and p[P_JOINT] != JOINT_FREE:  # pruned before typing when False
                if p[P_JOINT] == JOINT_SPHERICAL:
                    _spherical_pass2(o, p, w, hub, qdd)
                else:
                    _locked_pass2(o, p, w, hub, qdd)
                continue
            R_BM = load_m33_at(p, P_R_BM)
            R_BP = load_m33_at(w, W_R_BP)
            r_G = load_seg(w, W_R_G)
            omega_rel_P = load_seg(w, W_OMEGA_REL)
            rdot_G_rel = load_seg(w, W_RDOT_G)
            a_G = load_seg(qdd, o)
            alpha_P = load_seg(qdd, o + 3)
            omega_dot_rel = add(
                sub(alpha_P, mtv(R_BP, omega_dot_B)), cross(omega_rel_P, mtv(R_BP, omega_B))
            )
            rho_bias = load_seg(w, W_RHO_BIAS)
            rho_dd = mv(load_m33_at(w, W_S_INV), sub(omega_dot_rel, rho_bias))
            d = load_seg(p, P_COM)
            a_rel_rot = mv(
                R_BP, add(cross(omega_dot_rel, d), cross(omega_rel_P, cross(omega_rel_P, d)))
            )
            transport = add(
                add(a_hub_B, cross(omega_dot_B, r_G)),
                add(cross(omega_B, cross(omega_B, r_G)), scale(2.0, cross(omega_B, rdot_G_rel))),
            )
            eta_dd = mtv(R_BM, sub(sub(a_G, transport), a_rel_rot))
            qdd[o], qdd[o + 1], qdd[o + 2] = eta_dd
            qdd[o + 3], qdd[o + 4], qdd[o + 5] = rho_dd
        return STATUS_OK

    return pass1, pass2


pass1, pass2 = _passes(holds_locks=True)
free_pass1, free_pass2 = _passes(holds_locks=False)


@njit(cache=True, error_model="numpy")  # compiled with MASS_SIGNATURE on first use
def mass_matrix(q, members, params, M):
    """The plates' share of M(q) (eq. 2.39), from their velocity Jacobians::

    v_G = R_BN r_dot - [r_G]x S Theta_dot + R_BM eta_dot - R_BP [d]x S(rho) rho_dot
    w_P = R_BP^T S Theta_dot + S(rho) rho_dot
    """
    R_NB = rot_zyx(q[3], q[4], q[5])
    S = euler_rate_matrix(q[3], q[4])
    identity = ((1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0))
    for j in range(members.shape[0]):
        o = members[j, 1]
        p = params[j]
        m = p[P_MASS]
        J_p = load_m33_at(p, P_J)
        cs = _rho_cs(q, o)
        R_BM, R_MP, R_BP, S_rho, r_P, r_G = _pose(q, o, p, cs)
        A_theta = scale_m(-1.0, mm(skew(r_G), S))
        A_rho = scale_m(-1.0, mm(R_BP, mm(skew(load_seg(p, P_COM)), S_rho)))
        B_theta = mtm(R_BP, S)
        add_block(M, 0, 0, identity, m)
        add_block(M, 0, 3, mm(R_NB, A_theta), m)
        add_block(M, 0, o, mm(R_NB, R_BM), m)
        add_block(M, 0, o + 3, mm(R_NB, A_rho), m)
        add_block(M, 3, 3, mtm(A_theta, A_theta), m)
        add_block(M, 3, 3, mtm(B_theta, mm(J_p, B_theta)), 1.0)
        add_block(M, 3, o, mtm(A_theta, R_BM), m)
        add_block(M, 3, o + 3, mtm(A_theta, A_rho), m)
        add_block(M, 3, o + 3, mtm(B_theta, mm(J_p, S_rho)), 1.0)
        add_block(M, o, o, identity, m)
        add_block(M, o, o + 3, mtm(R_BM, A_rho), m)
        add_block(M, o + 3, o + 3, mtm(A_rho, A_rho), m)
        add_block(M, o + 3, o + 3, mtm(S_rho, mm(J_p, S_rho)), 1.0)


@njit(cache=True, error_model="numpy")  # compiled with BIAS_SIGNATURE on first use
def bias_forces(q, qd, members, params, hub, h):
    """The plates' share of h(q, q_dot) (eq. 2.43): Kane's inertia forces at q_ddot = 0."""
    R_NB = rot_zyx(q[3], q[4], q[5])
    omega_B = load_seg(hub, HUB_OMEGA)
    s_bias = load_seg(hub, HUB_SBIAS)
    for j in range(members.shape[0]):
        o = members[j, 1]
        p = params[j]
        cs = _rho_cs(q, o)
        R_BM, R_MP, R_BP, S_rho, r_P, r_G = _pose(q, o, p, cs)
        omega_rel_P, rdot_G_rel = _rates(qd, o, p, R_BM, R_BP, S_rho)
        d = load_seg(p, P_COM)
        J_p = load_m33_at(p, P_J)
        rho_bias = _rho_bias(cs, qd, o)
        a0 = add(
            add(cross(s_bias, r_G), cross(omega_B, cross(omega_B, r_G))),
            add(
                scale(2.0, cross(omega_B, rdot_G_rel)),
                mv(R_BP, add(cross(rho_bias, d), cross(omega_rel_P, cross(omega_rel_P, d)))),
            ),
        )
        omega_B_P = mtv(R_BP, omega_B)
        alpha0 = sub(add(mtv(R_BP, s_bias), rho_bias), cross(omega_rel_P, omega_B_P))
        omega_P = add(omega_B_P, omega_rel_P)
        f_B = scale(p[P_MASS], a0)
        g_P = add(mv(J_p, alpha0), cross(omega_P, mv(J_p, omega_P)))
        f_N = mv(R_NB, f_B)
        t_B = add(cross(r_G, f_B), mv(R_BP, g_P))
        for a in range(3):
            hub[HUB_FORCE + a] += f_N[a]
            hub[HUB_TORQUE + a] += t_B[a]
        h[o], h[o + 1], h[o + 2] = mtv(R_BM, f_B)
        h[o + 3], h[o + 4], h[o + 5] = mtv(S_rho, add(cross(d, mtv(R_BP, f_B)), g_P))


@njit(cache=True, error_model="numpy")  # compiled with OBSERVE_SIGNATURE on first use
def observe(q, qd, members, params, out):
    """Add the plates' kinetic energy, momentum, locked inertia, elastic energy, damper power."""
    R_NB = rot_zyx(q[3], q[4], q[5])
    r_hub = load_seg(q, 0)
    omega_B = mv(euler_rate_matrix(q[3], q[4]), load_seg(qd, 3))
    v_hub_B = mtv(R_NB, load_seg(qd, 0))
    for j in range(members.shape[0]):
        o = members[j, 1]
        p = params[j]
        m = p[P_MASS]
        J_p = load_m33_at(p, P_J)
        cs = _rho_cs(q, o)
        R_BM, R_MP, R_BP, S_rho, r_P, r_G = _pose(q, o, p, cs)
        omega_rel_P, rdot_G_rel = _rates(qd, o, p, R_BM, R_BP, S_rho)
        v_G = add(add(v_hub_B, cross(omega_B, r_G)), rdot_G_rel)
        omega_P = add(mtv(R_BP, omega_B), omega_rel_P)
        out[OBS_KINETIC] += 0.5 * m * dot(v_G, v_G)  # eqs. 2.32-2.34
        out[OBS_KINETIC] += 0.5 * dot(omega_P, mv(J_p, omega_P))
        p_G = add(r_hub, mv(R_NB, r_G))
        linear = cross(p_G, scale(m, mv(R_NB, v_G)))
        spin = mv(R_NB, mv(R_BP, mv(J_p, omega_P)))
        for a in range(3):
            out[OBS_MOMENTUM + a] += linear[a]
        for a in range(3):
            out[OBS_MOMENTUM + a] += spin[a]
        J_B = mm(R_BP, mm(J_p, transpose(R_BP)))
        r2 = dot(r_G, r_G)
        for a in range(3):
            for b in range(3):
                out[OBS_LOCKED_INERTIA + 3 * a + b] += J_B[a][b] - m * r_G[a] * r_G[b]
            out[OBS_LOCKED_INERTIA + 4 * a] += m * r2
        for k in range(6):
            out[OBS_ELASTIC] += 0.5 * p[P_K + k] * q[o + k] ** 2  # eq. 2.35
            out[OBS_DISSIPATION] += p[P_C + k] * qd[o + k] ** 2  # eq. 2.36


@njit(cache=True, error_model="numpy")  # compiled with WRENCH_SIGNATURE on first use
def joint_wrench(q, qd, qdd, Q, members, params, out):
    """Add the wrench the plates' joints exert on the hub (tau_flex in out[3:6]).

    The joint frees all six DOFs and is massless, so the wrench is that of its
    generalized forces Q - K q - C q_dot alone (``_joint_wrench``; the constraint forces
    of locked DOFs arrive in ``Q``); ``qdd`` is not needed.
    """
    for j in range(members.shape[0]):
        o = members[j, 1]
        p = params[j]
        cs = _rho_cs(q, o)
        R_BM, R_MP, R_BP, S_rho, r_P, r_G = _pose(q, o, p, cs)
        F_M, N_P, S_inv, status = _joint_wrench(q, qd, Q, o, p, cs)
        if status != STATUS_OK:
            return status
        _add_hub_wrench(out, 0, r_P, R_BM, R_BP, F_M, N_P)
    return STATUS_OK


@njit(cache=True, error_model="numpy")  # compiled with TIPS_SIGNATURE on first use
def tips(q, members, params, out):
    """Tip displacement eta + (R_MP - I) tip of each plate, mount frame [m]."""
    for j in range(members.shape[0]):
        o = members[j, 1]
        tip = load_seg(params[j], P_TIP)
        R_MP = rot_zyx(q[o + 3], q[o + 4], q[o + 5])
        moved = add(load_seg(q, o), sub(mv(R_MP, tip), tip))
        i = members[j, 0]
        out[i, 0], out[i, 1], out[i, 2] = moved


def _scale_mass(table: dict, factor: float) -> None:
    """Campaign path ``appendages[*].inertia``: scale the panel mass and so its inertia
    (the joints are re-tuned to keep their target frequencies, as the thesis does)."""
    field = "mass_kg" if table.get("mass_kg") is not None else "surface_density_kg_m2"
    table[field] = table[field] * factor


class PlateModel(AppendageModel):
    """The thesis plate (:class:`~flexsat.dynamics.appendages.plate_config.PlateConfig`)
    on its 6-DOF root joint."""

    name = "plate"
    config_class = PlateConfig
    kernels = AppendageKernels(pass1, pass2, mass_matrix, bias_forces, observe, joint_wrench, tips)
    transmits_inertia = False
    holds_locked = True
    modifiers: ClassVar[dict] = {"inertia": DerivedPath(_scale_mass)}
    work_size = WORK_SIZE

    def coordinates(self, config: PlateConfig) -> tuple[Coordinate, ...]:
        return tuple(Coordinate(n, u) for n, u in zip(JOINT_DOFS, _UNITS, strict=True))

    def group_kernels(self, rows: Sequence[np.ndarray]) -> AppendageKernels:
        if any(np.any(row[P_LOCKED : P_LOCKED + 6]) for row in rows):
            return self.kernels
        return self.kernels._replace(pass1=free_pass1, pass2=free_pass2)

    def pack(self, config: PlateConfig) -> np.ndarray:
        sign = config.span_sign()
        J = config.centroidal_inertia()
        # R_BM = Rz(yaw) Ry(alpha_sadm): intrinsic Z then Y.
        angles = np.radians([config.mount_yaw_deg, config.sadm_angle_deg])
        row = np.zeros(N_PARAMS)
        row[P_MOUNT : P_MOUNT + 3] = config.mount_point_m
        row[P_R_BM : P_R_BM + 9] = Rotation.from_euler("ZY", angles).as_matrix().ravel()
        row[P_COM : P_COM + 3] = (0.0, 0.5 * sign * config.length_m, 0.0)
        row[P_MASS] = config.mass
        row[P_J : P_J + 9] = J.ravel()
        row[P_J_INV : P_J_INV + 9] = np.linalg.inv(J).ravel()
        row[P_TIP : P_TIP + 3] = (0.0, sign * config.length_m, 0.0)
        d = row[P_COM : P_COM + 3]
        I_P = J + config.mass * (d @ d * np.eye(3) - np.outer(d, d))  # parallel axes
        I_P_inv = np.linalg.inv(I_P)
        D = np.array([[0.0, -d[2], d[1]], [d[2], 0.0, -d[0]], [-d[1], d[0], 0.0]])  # [d]x
        row[P_IP : P_IP + 9] = I_P.ravel()
        row[P_IP_INV : P_IP_INV + 9] = I_P_inv.ravel()
        row[P_M_ROOT : P_M_ROOT + 9] = (config.mass * np.eye(3)
                                        + config.mass**2 * D @ I_P_inv @ D).ravel()  # fmt: skip
        for name in config.locked_dofs:  # held by pass 1 and 2 themselves
            row[P_LOCKED + JOINT_DOFS.index(name)] = 1.0
        row[P_JOINT] = _joint_kind(row[P_LOCKED : P_LOCKED + 6])
        return row

    def on_drive(self, config: PlateConfig, params: np.ndarray) -> ChainConfig | None:
        if config.drive is None:
            return None
        drive = config.drive
        return driven_plate(config, self.stiffness(params), self.damping(params),
                            drive.rotor_inertia_kg_m2, drive.rotor_mass_kg)  # fmt: skip

    def tune(self, config: PlateConfig, params: np.ndarray, inertia_diag: np.ndarray
             ) -> np.ndarray:  # fmt: skip
        stiffness, damping = tune_joints(
            inertia_diag, config.target_frequencies_hz.per_dof(), config.damping_ratio
        )  # eqs. 2.14-2.15
        return self.with_joints(params, stiffness, damping)

    def stiffness(self, params: np.ndarray) -> np.ndarray:
        return params[P_K : P_K + 6].copy()

    def damping(self, params: np.ndarray) -> np.ndarray:
        return params[P_C : P_C + 6].copy()

    def with_joints(self, params: np.ndarray, stiffness: np.ndarray, damping: np.ndarray
                    ) -> np.ndarray:  # fmt: skip
        row = params.copy()
        row[P_K : P_K + 6] = stiffness
        row[P_C : P_C + 6] = damping
        return row

    def rigid_body(self, params: np.ndarray) -> RigidBody:
        R_BM = self.mount_rotation(params)
        r = params[P_MOUNT : P_MOUNT + 3] + R_BM @ params[P_COM : P_COM + 3]
        J = params[P_J : P_J + 9].reshape(3, 3)
        return RigidBody(float(params[P_MASS]), r, R_BM @ J @ R_BM.T)

    def initial_state(self, config: PlateConfig, entry) -> tuple[np.ndarray, np.ndarray]:
        q = np.concatenate([entry.eta_m, np.radians(entry.rho_deg)])
        # Relative rate given as ZYX angle rates [deg/s].
        qd = np.concatenate([entry.eta_rate_m_s, np.radians(entry.rho_rate_deg_s)])
        return q, qd

    def describe(self, config: PlateConfig, params: np.ndarray) -> dict:
        return {
            "mass_kg": float(params[P_MASS]),
            "centroidal_inertia_kg_m2": params[P_J : P_J + 9].reshape(3, 3).tolist(),
            "stiffness": self.stiffness(params).tolist(),
            "damping": self.damping(params).tolist(),
        }

    def shape_points(self, config: PlateConfig, params: np.ndarray, q_block: np.ndarray
                     ) -> np.ndarray:  # fmt: skip
        # x_B = r_m + R_BM (eta + R_MP x_P) for the corners, the root and the tip, with
        # the corners spanning 0..L along +-Y_P and -W/2..W/2 along X_P (mid-plane).
        w2, span = 0.5 * config.width_m, config.span_sign() * config.length_m
        local = np.zeros((6, 3))
        local[0:4, 0] = (-w2, w2, w2, -w2)
        local[0:4, 1] = (0.0, 0.0, span, span)
        local[5] = self.tip_point(params)
        R_MP = Rotation.from_euler("ZYX", q_block[5:2:-1]).as_matrix()
        in_mount = q_block[:3] + local @ R_MP.T
        return params[P_MOUNT : P_MOUNT + 3] + in_mount @ self.mount_rotation(params).T

    def target_frequencies(self, config: PlateConfig) -> tuple[tuple[str, float], ...]:
        t = config.target_frequencies_hz
        return (
            ("flapping", t.flapping), ("in-plane", t.in_plane), ("torsion", t.torsion),
            ("translation x", t.translation_x), ("translation y", t.translation_y),
            ("translation z", t.translation_z),
        )  # fmt: skip

    def extent(self, config: PlateConfig) -> float:
        return float(config.length_m)

    def mode_kinds(self, config: PlateConfig) -> tuple[str, ...]:
        return ("translation", "translation", "translation", "flapping", "torsion", "in_plane")

    def root_motion(self, q_block: np.ndarray, names: tuple[str, ...] = ()
                    ) -> tuple[np.ndarray, np.ndarray]:  # fmt: skip
        return q_block[:, :3], q_block[:, 3:]

    def mirror_block(self, params_i: np.ndarray, params_j: np.ndarray, reflect: np.ndarray,
                     rtol: float) -> np.ndarray | None:  # fmt: skip
        R_i, R_j = self.mount_rotation(params_i), self.mount_rotation(params_j)
        mount_i, mount_j = params_i[P_MOUNT : P_MOUNT + 3], params_j[P_MOUNT : P_MOUNT + 3]
        scale_ = max(1.0, float(np.max(np.abs(mount_i))), float(np.max(np.abs(mount_j))))
        com_i = R_i @ params_i[P_COM : P_COM + 3]
        com_j = R_j @ params_j[P_COM : P_COM + 3]
        same = (
            np.allclose(mount_j, reflect @ mount_i, atol=rtol * scale_)
            and np.allclose(com_j, reflect @ com_i, atol=rtol * scale_)
            and np.allclose(params_j[P_MASS : P_J + 9], params_i[P_MASS : P_J + 9], rtol=rtol)
            and np.allclose(params_j[P_K : P_C + 6], params_i[P_K : P_C + 6], rtol=rtol)
        )
        if not same:
            return None
        T_eta = R_j.T @ reflect @ R_i
        if not np.allclose(np.abs(T_eta), np.eye(3), atol=rtol):
            return None  # joint axes must map onto joint axes
        block = np.zeros((6, 6))
        block[:3, :3] = T_eta
        block[3:, 3:] = -T_eta  # axial vectors: det(T_eta) = -1
        return block

    @staticmethod
    def mount_rotation(params: np.ndarray) -> np.ndarray:
        """R_BM of a packed row, shape (3, 3)."""
        return params[P_R_BM : P_R_BM + 9].reshape(3, 3)

    @staticmethod
    def mount_point(params: np.ndarray) -> np.ndarray:
        """r_m, the root position in B of a packed row, shape (3,) [m]."""
        return params[P_MOUNT : P_MOUNT + 3]

    @staticmethod
    def tip_point(params: np.ndarray) -> np.ndarray:
        """The panel tip in panel frame, shape (3,) [m]."""
        return params[P_TIP : P_TIP + 3]

    @staticmethod
    def com_offset(params: np.ndarray) -> np.ndarray:
        """d_Gp, root -> panel centre of mass, panel frame, shape (3,) [m]."""
        return params[P_COM : P_COM + 3]
