"""Compiled dynamics of a rigid hub carrying N flexible appendages (numba).

The kernels know nothing of configs or units beyond SI: they take the packed
float64 arrays built by :mod:`flexsat.dynamics.plant` and write into output
arrays the caller owns, so nothing is allocated per call.

Generalized coordinates (thesis eq. 2.1, generalized to N appendages)::

    q[0:3]          r_N      hub centre-of-mass position, inertial frame N [m]
    q[3:6]          Theta    hub ZYX Euler angles (phi, theta, psi) [rad]
    q[6+6i:9+6i]    eta_i    root translation of appendage i, mount frame M_i [m]
    q[9+6i:12+6i]   rho_i    root rotation of appendage i, ZYX angles (eta_r) [rad]

Packed plant arrays (``n`` appendages)::

    hub_mass ()            hub_J (3, 3)      hub_J_inv (3, 3)       [kg], [kg m^2]
    mount_point (n, 3)     r_m, root position in B [m]
    R_BM (n, 3, 3)         mount frame M_i -> hub frame B (includes the SADM angle)
    com_offset (n, 3)      d_Gp, root -> panel centre of mass, panel frame P_i [m]
    panel_mass (n,)        panel_J (n, 3, 3), panel_J_inv (n, 3, 3)   about G_p in P_i
    stiffness (n, 6)       damping (n, 6)    per joint DOF [N/m, N m/rad], [N s/m, N m s/rad]

Kinematics are exact: the panel rotation relative to its mount is
R_MP = Rz(rho_z) Ry(rho_y) Rx(rho_x) with relative body rate S(rho) rho_dot (the
thesis writes rho_dot, the small-angle form of eq. 2.31; see docs/model.md).

Structure (docs/model.md, 'Exploit the structure'): M(q) is block-arrow, and since each
appendage hangs on a full 6-DOF joint the Schur complement of the appendage
blocks equals the bare hub's mass matrix. :func:`accelerations` therefore needs
no factorization: each panel's absolute accelerations follow from its own
Newton-Euler equations under the joint wrench, the hub's from its own equations
under the reaction, and q_ddot from the relative kinematics. Cost is linear in N.

Every kernel here and in :mod:`flexsat.dynamics.linalg3` is compiled with
``error_model="numpy"``: a float division by zero would give inf/nan (which the RK4
loops report as a non-finite state) instead of raising, so no zero test guards each
division. No divisor can be zero: masses are validated positive and
``cos(pitch)``/``cos(rho_y)`` are checked against ``_MIN_COS`` before any
``euler_rate_matrix_inv``. Results are bit-for-bit those of the default error model;
one q_ddot evaluation is about 10 % faster (docs/performance.md).
"""

from __future__ import annotations

from math import cos

from numba import njit

from flexsat.dynamics.linalg3 import (
    add,
    cross,
    dot,
    euler_rate_bias,
    euler_rate_matrix,
    euler_rate_matrix_inv,
    load_m33,
    load_seg,
    load_v3,
    mm,
    mtm,
    mtv,
    mv,
    rot_zyx,
    scale,
    scale_m,
    skew,
    sub,
    transpose,
)

__all__ = [
    "STATUS_HUB_GIMBAL_LOCK",
    "STATUS_JOINT_GIMBAL_LOCK",
    "STATUS_OK",
    "accelerations",
    "bias_forces",
    "hub_joint_wrench",
    "kinetic_energy",
    "locked_inertia",
    "mass_matrix",
    "system_angular_momentum",
    "tip_displacement",
]

STATUS_OK = 0
STATUS_HUB_GIMBAL_LOCK = 1  # hub pitch at +-90 deg: S(Theta) singular
STATUS_JOINT_GIMBAL_LOCK = 2  # a root rotation rho_y at +-90 deg: S(rho) singular

_MIN_COS = 1e-9  # |cos(pitch)| below this is treated as gimbal lock


@njit(cache=True, error_model="numpy")
def _panel_pose(q, i, mount_point, R_BM, com_offset):
    """Pose of appendage i relative to the hub, in hub frame B.

    Returns R_MP (panel -> mount), R_BP (panel -> hub), S(rho), r_P (root
    position) and r_G (panel centre of mass), both from the hub centre of mass [m].
    """
    o = 6 + 6 * i
    rho = load_seg(q, o + 3)
    R_BMi = load_m33(R_BM, i)
    R_MP = rot_zyx(rho[0], rho[1], rho[2])
    R_BP = mm(R_BMi, R_MP)
    S_rho = euler_rate_matrix(rho[0], rho[1])
    r_P = add(load_v3(mount_point, i), mv(R_BMi, load_seg(q, o)))
    r_G = add(r_P, mv(R_BP, load_v3(com_offset, i)))
    return R_MP, R_BP, S_rho, r_P, r_G


@njit(cache=True, error_model="numpy")
def _panel_rates(qd, i, R_BM, com_offset, R_BP, S_rho):
    """Relative rates of appendage i: omega_rel_P (panel frame) and the B-frame rate of r_G."""
    o = 6 + 6 * i
    omega_rel_P = mv(S_rho, load_seg(qd, o + 3))
    rdot_G_rel = add(
        mv(load_m33(R_BM, i), load_seg(qd, o)),
        mv(R_BP, cross(omega_rel_P, load_v3(com_offset, i))),
    )
    return omega_rel_P, rdot_G_rel


@njit(cache=True, error_model="numpy")
def _joint_wrench(q, qd, Q, i, stiffness, damping, R_MP):
    """Joint wrench on appendage i from its elastic, damping and external generalized forces.

    By virtual work the 6 generalized forces on (eta, rho) are a force F_M at the
    root (mount frame) and a torque N_P (panel frame) on the panel, with the
    opposite pair on the hub: F_M = Q_eta, N_P = S(rho)^-T Q_rho.
    Returns F_M, N_P and a status flag.
    """
    o = 6 + 6 * i
    Q_eta = (
        Q[o] - stiffness[i, 0] * q[o] - damping[i, 0] * qd[o],
        Q[o + 1] - stiffness[i, 1] * q[o + 1] - damping[i, 1] * qd[o + 1],
        Q[o + 2] - stiffness[i, 2] * q[o + 2] - damping[i, 2] * qd[o + 2],
    )
    Q_rho = (
        Q[o + 3] - stiffness[i, 3] * q[o + 3] - damping[i, 3] * qd[o + 3],
        Q[o + 4] - stiffness[i, 4] * q[o + 4] - damping[i, 4] * qd[o + 4],
        Q[o + 5] - stiffness[i, 5] * q[o + 5] - damping[i, 5] * qd[o + 5],
    )
    if abs(cos(q[o + 4])) < _MIN_COS:
        return Q_eta, Q_rho, STATUS_JOINT_GIMBAL_LOCK
    N_P = mtv(euler_rate_matrix_inv(q[o + 3], q[o + 4]), Q_rho)
    return Q_eta, N_P, STATUS_OK


@njit(cache=True, error_model="numpy")
def accelerations(
    q, qd, Q, hub_mass, hub_J, hub_J_inv, mount_point, R_BM, com_offset,
    panel_mass, panel_J, panel_J_inv, stiffness, damping, qdd,
):  # fmt: skip
    """Solve M(q) q_ddot = Q - h(q, q_dot) - C q_dot - k_el(q) for q_ddot (eq. 2.50).

    Parameters
    ----------
    q, qd : ndarray, shape (6 + 6n,)
        Generalized coordinates and their rates (SI, rad).
    Q : ndarray, shape (6 + 6n,)
        External generalized forces (see :func:`flexsat.dynamics.plant.Plant.generalized_forces`).
    hub_mass ... damping
        Packed plant arrays (module docstring).
    qdd : ndarray, shape (6 + 6n,)
        Output: generalized accelerations.

    Returns
    -------
    int
        ``STATUS_OK`` or a gimbal-lock status (``qdd`` is then undefined).
    """
    n = panel_mass.shape[0]
    phi, theta, psi = q[3], q[4], q[5]
    if abs(cos(theta)) < _MIN_COS:
        return STATUS_HUB_GIMBAL_LOCK
    R_NB = rot_zyx(phi, theta, psi)
    S_inv = euler_rate_matrix_inv(phi, theta)
    omega_B = mv(euler_rate_matrix(phi, theta), load_seg(qd, 3))
    force_B = mtv(R_NB, load_seg(Q, 0))  # Q_r is an inertial force
    torque_B = mtv(S_inv, load_seg(Q, 3))  # Q_Theta = S^T tau  =>  tau = S^-T Q_Theta
    J_h = hub_J

    # Pass 1: joint wrenches -> panel absolute accelerations and the reaction on the hub.
    for i in range(n):
        o = 6 + 6 * i
        R_MP, R_BP, S_rho, r_P, r_G = _panel_pose(q, i, mount_point, R_BM, com_offset)
        omega_rel_P, rdot_G_rel = _panel_rates(qd, i, R_BM, com_offset, R_BP, S_rho)
        F_M, N_P, status = _joint_wrench(q, qd, Q, i, stiffness, damping, R_MP)
        if status != STATUS_OK:
            return status
        R_BMi = load_m33(R_BM, i)
        F_B = mv(R_BMi, F_M)
        force_B = sub(force_B, F_B)
        torque_B = sub(sub(torque_B, cross(r_P, F_B)), mv(R_BP, N_P))
        # Panel Newton-Euler about its centre of mass G (the root force acts at -d from G).
        d = load_v3(com_offset, i)
        J_p = load_m33(panel_J, i)
        omega_P = add(mtv(R_BP, omega_B), omega_rel_P)
        moment_P = add(N_P, cross(scale(-1.0, d), mtv(R_MP, F_M)))
        alpha_P = mv(load_m33(panel_J_inv, i), sub(moment_P, cross(omega_P, mv(J_p, omega_P))))
        a_G = scale(1.0 / panel_mass[i], F_B)
        qdd[o], qdd[o + 1], qdd[o + 2] = a_G
        qdd[o + 3], qdd[o + 4], qdd[o + 5] = alpha_P

    # Hub Newton-Euler in B (the Schur complement is the bare hub's mass matrix).
    a_hub_B = scale(1.0 / hub_mass, force_B)
    omega_dot_B = mv(hub_J_inv, sub(torque_B, cross(omega_B, mv(J_h, omega_B))))
    qdd[0], qdd[1], qdd[2] = mv(R_NB, a_hub_B)
    s_bias = euler_rate_bias(phi, theta, qd[3], qd[4], qd[5])
    qdd[3], qdd[4], qdd[5] = mv(S_inv, sub(omega_dot_B, s_bias))

    # Pass 2: relative accelerations of each joint from the absolute ones.
    for i in range(n):
        o = 6 + 6 * i
        R_MP, R_BP, S_rho, r_P, r_G = _panel_pose(q, i, mount_point, R_BM, com_offset)
        omega_rel_P, rdot_G_rel = _panel_rates(qd, i, R_BM, com_offset, R_BP, S_rho)
        a_G = load_seg(qdd, o)
        alpha_P = load_seg(qdd, o + 3)
        omega_dot_rel = add(
            sub(alpha_P, mtv(R_BP, omega_dot_B)), cross(omega_rel_P, mtv(R_BP, omega_B))
        )
        rho_bias = euler_rate_bias(q[o + 3], q[o + 4], qd[o + 3], qd[o + 4], qd[o + 5])
        rho_dd = mv(euler_rate_matrix_inv(q[o + 3], q[o + 4]), sub(omega_dot_rel, rho_bias))
        d = load_v3(com_offset, i)
        a_rel_rot = mv(
            R_BP, add(cross(omega_dot_rel, d), cross(omega_rel_P, cross(omega_rel_P, d)))
        )
        transport = add(
            add(a_hub_B, cross(omega_dot_B, r_G)),
            add(cross(omega_B, cross(omega_B, r_G)), scale(2.0, cross(omega_B, rdot_G_rel))),
        )
        eta_dd = mtv(load_m33(R_BM, i), sub(sub(a_G, transport), a_rel_rot))
        qdd[o], qdd[o + 1], qdd[o + 2] = eta_dd
        qdd[o + 3], qdd[o + 4], qdd[o + 5] = rho_dd
    return STATUS_OK


@njit(cache=True, error_model="numpy")
def _add_block(M, r0, c0, A, s):
    """M[r0:r0+3, c0:c0+3] += s A and, off the diagonal, the transposed block."""
    for a in range(3):
        for b in range(3):
            M[r0 + a, c0 + b] += s * A[a][b]
            if r0 != c0:
                M[c0 + b, r0 + a] += s * A[a][b]


@njit(cache=True, error_model="numpy")
def mass_matrix(
    q, hub_mass, hub_J, mount_point, R_BM, com_offset, panel_mass, panel_J, M,
):  # fmt: skip
    """Mass matrix M(q) (eq. 2.39), written into ``M``, shape (6 + 6n, 6 + 6n).

    Assembled from the bodies' velocity Jacobians: M = sum_b m_b Jv_b^T Jv_b +
    Jw_b^T J_b Jw_b, with the panel centre-of-mass velocity in B::

        v_G = R_BN r_dot - [r_G]x S Theta_dot + R_BM eta_dot - R_BP [d]x S(rho) rho_dot
        w_P = R_BP^T S Theta_dot + S(rho) rho_dot
    """
    n = panel_mass.shape[0]
    M[:, :] = 0.0
    phi, theta, psi = q[3], q[4], q[5]
    R_NB = rot_zyx(phi, theta, psi)
    S = euler_rate_matrix(phi, theta)
    identity = ((1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0))
    _add_block(M, 0, 0, identity, hub_mass)
    _add_block(M, 3, 3, mtm(S, mm(hub_J, S)), 1.0)
    for i in range(n):
        o = 6 + 6 * i
        m = panel_mass[i]
        J_p = load_m33(panel_J, i)
        R_MP, R_BP, S_rho, r_P, r_G = _panel_pose(q, i, mount_point, R_BM, com_offset)
        R_BMi = load_m33(R_BM, i)
        A_theta = scale_m(-1.0, mm(skew(r_G), S))
        A_rho = scale_m(-1.0, mm(R_BP, mm(skew(load_v3(com_offset, i)), S_rho)))
        B_theta = mtm(R_BP, S)
        _add_block(M, 0, 0, identity, m)
        _add_block(M, 0, 3, mm(R_NB, A_theta), m)
        _add_block(M, 0, o, mm(R_NB, R_BMi), m)
        _add_block(M, 0, o + 3, mm(R_NB, A_rho), m)
        _add_block(M, 3, 3, mtm(A_theta, A_theta), m)
        _add_block(M, 3, 3, mtm(B_theta, mm(J_p, B_theta)), 1.0)
        _add_block(M, 3, o, mtm(A_theta, R_BMi), m)
        _add_block(M, 3, o + 3, mtm(A_theta, A_rho), m)
        _add_block(M, 3, o + 3, mtm(B_theta, mm(J_p, S_rho)), 1.0)
        _add_block(M, o, o, identity, m)
        _add_block(M, o, o + 3, mtm(R_BMi, A_rho), m)
        _add_block(M, o + 3, o + 3, mtm(A_rho, A_rho), m)
        _add_block(M, o + 3, o + 3, mtm(S_rho, mm(J_p, S_rho)), 1.0)


@njit(cache=True, error_model="numpy")
def bias_forces(
    q, qd, hub_mass, hub_J, mount_point, R_BM, com_offset, panel_mass, panel_J, h,
):  # fmt: skip
    """Coriolis and centrifugal vector h(q, q_dot) (eq. 2.43), written into ``h``.

    Computed as Kane's generalized inertia forces at q_ddot = 0, which equal
    M_dot q_dot - (dT/dq)^T for this holonomic system: h = sum_b Jv_b^T m_b a0_b +
    Jw_b^T (J_b alpha0_b + w_b x J_b w_b), with a0, alpha0 the accelerations
    at zero q_ddot.
    """
    n = panel_mass.shape[0]
    phi, theta, psi = q[3], q[4], q[5]
    R_NB = rot_zyx(phi, theta, psi)
    S = euler_rate_matrix(phi, theta)
    omega_B = mv(S, load_seg(qd, 3))
    s_bias = euler_rate_bias(phi, theta, qd[3], qd[4], qd[5])
    torque_B = add(mv(hub_J, s_bias), cross(omega_B, mv(hub_J, omega_B)))
    force_N = (0.0, 0.0, 0.0)
    for i in range(n):
        o = 6 + 6 * i
        R_MP, R_BP, S_rho, r_P, r_G = _panel_pose(q, i, mount_point, R_BM, com_offset)
        omega_rel_P, rdot_G_rel = _panel_rates(qd, i, R_BM, com_offset, R_BP, S_rho)
        d = load_v3(com_offset, i)
        J_p = load_m33(panel_J, i)
        rho_bias = euler_rate_bias(q[o + 3], q[o + 4], qd[o + 3], qd[o + 4], qd[o + 5])
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
        f_B = scale(panel_mass[i], a0)
        g_P = add(mv(J_p, alpha0), cross(omega_P, mv(J_p, omega_P)))
        force_N = add(force_N, mv(R_NB, f_B))
        torque_B = add(torque_B, add(cross(r_G, f_B), mv(R_BP, g_P)))
        h[o], h[o + 1], h[o + 2] = mtv(load_m33(R_BM, i), f_B)
        h[o + 3], h[o + 4], h[o + 5] = mtv(S_rho, add(cross(d, mtv(R_BP, f_B)), g_P))
    h[0], h[1], h[2] = force_N
    h[3], h[4], h[5] = mtv(S, torque_B)


@njit(cache=True, error_model="numpy")
def hub_joint_wrench(
    q, qd, Q, mount_point, R_BM, com_offset, stiffness, damping, out,
):  # fmt: skip
    """Wrench the appendages' joints exert on the hub, written into ``out``, shape (6,).

    ``out[0:3]`` is the force and ``out[3:6]`` the torque tau_flex about the hub
    centre of mass, both in hub frame B [N], [N m] (elastic + damping, plus any
    external generalized force on the joint coordinates). Returns a status.
    """
    n = stiffness.shape[0]
    force_B = (0.0, 0.0, 0.0)
    torque_B = (0.0, 0.0, 0.0)
    for i in range(n):
        R_MP, R_BP, S_rho, r_P, r_G = _panel_pose(q, i, mount_point, R_BM, com_offset)
        F_M, N_P, status = _joint_wrench(q, qd, Q, i, stiffness, damping, R_MP)
        if status != STATUS_OK:
            return status
        F_B = mv(load_m33(R_BM, i), F_M)
        force_B = sub(force_B, F_B)
        torque_B = sub(sub(torque_B, cross(r_P, F_B)), mv(R_BP, N_P))
    out[0], out[1], out[2] = force_B
    out[3], out[4], out[5] = torque_B
    return STATUS_OK


@njit(cache=True, error_model="numpy")
def _body_states(q, qd, i, mount_point, R_BM, com_offset):
    """Panel i: centre of mass position and velocity (B components), R_BP, omega_P."""
    phi, theta = q[3], q[4]
    R_NB = rot_zyx(phi, theta, q[5])
    omega_B = mv(euler_rate_matrix(phi, theta), load_seg(qd, 3))
    R_MP, R_BP, S_rho, r_P, r_G = _panel_pose(q, i, mount_point, R_BM, com_offset)
    omega_rel_P, rdot_G_rel = _panel_rates(qd, i, R_BM, com_offset, R_BP, S_rho)
    v_G = add(add(mtv(R_NB, load_seg(qd, 0)), cross(omega_B, r_G)), rdot_G_rel)
    omega_P = add(mtv(R_BP, omega_B), omega_rel_P)
    return r_G, v_G, R_BP, omega_P


@njit(cache=True, error_model="numpy")
def kinetic_energy(
    q, qd, hub_mass, hub_J, mount_point, R_BM, com_offset, panel_mass, panel_J,
):  # fmt: skip
    """Total kinetic energy T (eqs. 2.32-2.34) from the bodies' velocities [J]."""
    v_hub = load_seg(qd, 0)
    omega_B = mv(euler_rate_matrix(q[3], q[4]), load_seg(qd, 3))
    energy = 0.5 * hub_mass * dot(v_hub, v_hub) + 0.5 * dot(omega_B, mv(hub_J, omega_B))
    for i in range(panel_mass.shape[0]):
        r_G, v_G, R_BP, omega_P = _body_states(q, qd, i, mount_point, R_BM, com_offset)
        energy += 0.5 * panel_mass[i] * dot(v_G, v_G)
        energy += 0.5 * dot(omega_P, mv(load_m33(panel_J, i), omega_P))
    return energy


@njit(cache=True, error_model="numpy")
def system_angular_momentum(
    q, qd, hub_mass, hub_J, mount_point, R_BM, com_offset, panel_mass, panel_J, out,
):  # fmt: skip
    """Total angular momentum about the inertial origin, inertial components [N m s].

    Written into ``out``, shape (3,). Exactly conserved without external torque.
    """
    R_NB = rot_zyx(q[3], q[4], q[5])
    r_hub = load_seg(q, 0)
    v_hub = load_seg(qd, 0)
    omega_B = mv(euler_rate_matrix(q[3], q[4]), load_seg(qd, 3))
    H = add(cross(r_hub, scale(hub_mass, v_hub)), mv(R_NB, mv(hub_J, omega_B)))
    for i in range(panel_mass.shape[0]):
        r_G, v_G, R_BP, omega_P = _body_states(q, qd, i, mount_point, R_BM, com_offset)
        p_G = add(r_hub, mv(R_NB, r_G))
        H = add(H, cross(p_G, scale(panel_mass[i], mv(R_NB, v_G))))
        H = add(H, mv(R_NB, mv(R_BP, mv(load_m33(panel_J, i), omega_P))))
    out[0], out[1], out[2] = H


@njit(cache=True, error_model="numpy")
def tip_displacement(q, tip_point, out):
    """Displacement of each panel tip from its undeformed position, mount frame [m].

    ``tip_point`` (n, 3) is the tip in panel frame P_i; ``out`` (n, 3) receives
    eta + (R_MP - I) tip.
    """
    for i in range(tip_point.shape[0]):
        o = 6 + 6 * i
        tip = load_v3(tip_point, i)
        R_MP = rot_zyx(q[o + 3], q[o + 4], q[o + 5])
        moved = add(load_seg(q, o), sub(mv(R_MP, tip), tip))
        out[i, 0], out[i, 1], out[i, 2] = moved


@njit(cache=True, error_model="numpy")
def locked_inertia(q, hub_J, mount_point, R_BM, com_offset, panel_mass, panel_J, out):
    """Inertia of the satellite frozen in its current shape, about the hub centre of mass.

    J(eta) in hub frame B, written into ``out`` (3, 3) [kg m^2]; J(eta) omega_B is the
    rigid part of the angular momentum the thesis plots.
    """
    out[:, :] = hub_J
    for i in range(panel_mass.shape[0]):
        R_MP, R_BP, S_rho, r_P, r_G = _panel_pose(q, i, mount_point, R_BM, com_offset)
        J_B = mm(R_BP, mm(load_m33(panel_J, i), transpose(R_BP)))
        r2 = dot(r_G, r_G)
        m = panel_mass[i]
        for a in range(3):
            for b in range(3):
                out[a, b] += J_B[a][b] - m * r_G[a] * r_G[b]
            out[a, a] += m * r2
