"""Compiled kernels of the chain appendage: an O(N) articulated-body recursion.

Spatial vectors (Featherstone's notation, docs/model.md, 'Chain appendages') are
pairs of 3-tuples: a motion vector [omega; v] (angular velocity; velocity of the point
at the frame's origin), a force vector [n; f] (moment about the origin; force). Every
segment's quantities are in its own frame P_k at its joint origin; the hub's in B at
the hub centre of mass, with the hub's linear velocity taken as zero (a Galilean
boost: accelerations do not depend on it).

Joint k connects the parent (the hub for k = 0, else segment k - 1) to segment k. Its
parent-side frame J_k is the mount frame M (k = 0) or the parent's frame moved to the
parent's next-joint point; relative to it the segment's origin is at t = (x, y, z) and
its axes turned by R_JP = Rz(rz) Ry(ry) Rx(rx), with relative body rate S(rho)
rho_dot, exactly as the plate's root joint (eq. 2.31). Locked DOFs stay zero. The
motion subspace S_k (6 x n_k) holds the columns [0; R_JP^T e_i] of the translations
and [S(rho) e_i; 0] of the rotations.

Articulated-body algorithm per chain (eqs. of docs/model.md, 'Chain appendages'):
pass 1 runs outward for the velocities v_k = X_k v_{k-1} + S_k qd_k and bias
accelerations c_k, then inward for the articulated inertias I^A_k and bias forces
p^A_k, handing the hub X_0^T I^a_0 X_0 and X_0^T p^a_0; pass 2 runs outward for
q_ddot_k = D_k^-1 (u_k - U_k^T (X_k a_{k-1} + c_k)). A hinge (one free rotation,
slot G_KIND) takes a specialized step of both passes (``_hinge_outward``,
``_hinge_inward``, the hinge branch of pass 2): scalar D_k, elementary rotations,
I^a in registers; every other joint the general one. Cost is linear in N. M(q) and
h(q, q_dot) (analysis only, not in the integration loop) are the composite-rigid-body
and recursive Newton-Euler algorithms and allocate one scratch row per chain. The
root's wrench on the hub (tau_flex, :func:`joint_wrench`) is the Newton-Euler sum of
the segments' inertial forces at the plant's q_ddot, so it holds the root joint's
constraint reactions; one outward pass, nothing allocated.
"""

from __future__ import annotations

from math import cos, sin

import numpy as np
from numba import njit

from flexsat.compiled.linalg3 import (
    add,
    cross,
    dot,
    euler_rate_bias,
    euler_rate_bias_cs,
    euler_rate_matrix,
    euler_rate_matrix_cs,
    load_m33_at,
    load_seg,
    mm,
    mtv,
    mv,
    rot_zyx,
    rot_zyx_cs,
    scale,
    skew,
    sub,
    transpose,
)
from flexsat.compiled.status import STATUS_JOINT_GIMBAL_LOCK, STATUS_OK
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
    "G_C",
    "G_COM",
    "G_FREE",
    "G_J",
    "G_K",
    "G_KIND",
    "G_MASS",
    "G_NEXT",
    "G_NF",
    "G_OFF",
    "HEADER",
    "H_MOUNT",
    "H_N",
    "H_R_BM",
    "H_TIP",
    "H_TIP0",
    "JOINT_GENERAL",
    "JOINT_HINGE_X",
    "SEG",
    "WSEG",
    "bias_forces",
    "joint_wrench",
    "mass_matrix",
    "observe",
    "pass1",
    "pass2",
    "tips",
]

# Packed parameter row of one chain: a header, then SEG columns per segment.
H_MOUNT = 0  # (3) r_m, root joint position in B [m]
H_R_BM = 3  # (9) R_BM, mount frame -> hub frame, row-major
H_N = 12  # (1) segment count N
H_TIP = 13  # (3) tip point in the last segment's frame [m]
H_TIP0 = 16  # (3) undeformed tip, mount frame [m]
HEADER = 19
G_MASS = 0  # (1) segment mass, tip mass included [kg]
G_J = 1  # (9) inertia about its centre of mass, segment frame [kg m^2]
G_COM = 10  # (3) joint -> centre of mass, segment frame [m]
G_NEXT = 13  # (3) joint -> next joint, segment frame [m]
G_FREE = 16  # (6) 1.0 where the DOF (x, y, z, rx, ry, rz) is free
G_K = 22  # (6) stiffness per DOF [N/m, N m/rad] (0 where locked)
G_C = 28  # (6) damping per DOF [N s/m, N m s/rad]
G_OFF = 34  # (1) offset of the joint's first coordinate in the chain's block
G_NF = 35  # (1) number of free DOFs n_k
G_KIND = 36  # (1) joint kind: JOINT_GENERAL, or JOINT_HINGE_X + a for a hinge about axis a
SEG = 37

# Joint kinds (slot G_KIND). A hinge frees one rotation (rx, ry or rz) and nothing else:
# its axis is constant in the parent-side frame, S_k = [e_a; 0], c_J = 0, and its
# recursion step has a scalar D_k and elementary rotations (docs/model.md, 'Chain
# appendages', paragraph 'Hinges'). Every other joint takes the general step.
JOINT_GENERAL = 0
JOINT_HINGE_X = 1  # + a: hinge about the parent-side frame's axis a = 0, 1, 2 (x, y, z)

# Scratch per segment in a work row (pass 1 -> pass 2).
W_R = 0  # (9) R_{parent, P_k}, row-major
W_POS = 9  # (3) segment origin in parent coordinates [m]
W_CA = 12  # (6) bias acceleration c_k [angular; linear]
W_S = 18  # (36) motion subspace, column a at W_S + 6 a
W_IA = 54  # (36) articulated inertia I^A_k, row-major [n; f] x [omega; v]
W_PA = 90  # (6) bias force p^A_k [n; f]
W_U = 96  # (36) U_k = I^A_k S_k, column a at W_U + 6 a
W_DI = 132  # (36) D_k^-1, row-major, stride 6
W_TAU = 168  # (6) tau_k, then u_k = tau_k - S_k^T p^A_k
W_CS = 174  # (2) a hinge's cos and sin of its angle
WSEG = 176

MIN_COS = 1e-9  # |cos(ry)| below this is a gimbal lock when rx and rz are both free
_ZERO = (0.0, 0.0, 0.0)


@njit(cache=True, error_model="numpy")
def _xm(R, pos, ua, ul):
    """Motion vector from parent to child coordinates: (R^T ua, R^T (ul - pos x ua))."""
    return mtv(R, ua), mtv(R, sub(ul, cross(pos, ua)))


@njit(cache=True, error_model="numpy")
def _xft(R, pos, n, f):
    """Force vector from child to parent coordinates (X^T): (R n + pos x R f, R f)."""
    Rf = mv(R, f)
    return add(mv(R, n), cross(pos, Rf)), Rf


@njit(cache=True, error_model="numpy")
def _crm(va, vl, ua, ul):
    """v x_m u (motion cross product)."""
    return cross(va, ua), add(cross(va, ul), cross(vl, ua))


@njit(cache=True, error_model="numpy")
def _crf(va, vl, n, f):
    """v x_f f (force cross product)."""
    return add(cross(va, n), cross(vl, f)), cross(va, f)


@njit(cache=True, error_model="numpy")
def _inertia_mul(m, c, J, ua, ul):
    """I u for the spatial inertia at the origin of a body of mass m, centre of mass c,
    centroidal inertia J: l = m (v + omega x c), n = J omega + c x l."""
    lin = scale(m, add(ul, cross(ua, c)))
    return add(mv(J, ua), cross(c, lin)), lin


@njit(cache=True, error_model="numpy")
def _mul6(a, k, ua, ul):
    """(a[k:k+36] as a row-major 6 x 6) @ [ua; ul]."""
    n0 = (a[k] * ua[0] + a[k + 1] * ua[1] + a[k + 2] * ua[2]
          + a[k + 3] * ul[0] + a[k + 4] * ul[1] + a[k + 5] * ul[2])  # fmt: skip
    n1 = (a[k + 6] * ua[0] + a[k + 7] * ua[1] + a[k + 8] * ua[2]
          + a[k + 9] * ul[0] + a[k + 10] * ul[1] + a[k + 11] * ul[2])  # fmt: skip
    n2 = (a[k + 12] * ua[0] + a[k + 13] * ua[1] + a[k + 14] * ua[2]
          + a[k + 15] * ul[0] + a[k + 16] * ul[1] + a[k + 17] * ul[2])  # fmt: skip
    f0 = (a[k + 18] * ua[0] + a[k + 19] * ua[1] + a[k + 20] * ua[2]
          + a[k + 21] * ul[0] + a[k + 22] * ul[1] + a[k + 23] * ul[2])  # fmt: skip
    f1 = (a[k + 24] * ua[0] + a[k + 25] * ua[1] + a[k + 26] * ua[2]
          + a[k + 27] * ul[0] + a[k + 28] * ul[1] + a[k + 29] * ul[2])  # fmt: skip
    f2 = (a[k + 30] * ua[0] + a[k + 31] * ua[1] + a[k + 32] * ua[2]
          + a[k + 33] * ul[0] + a[k + 34] * ul[1] + a[k + 35] * ul[2])  # fmt: skip
    return (n0, n1, n2), (f0, f1, f2)


@njit(cache=True, error_model="numpy")
def _put3(x, k, v):
    x[k], x[k + 1], x[k + 2] = v


@njit(cache=True, error_model="numpy")
def _put_m33(x, k, m):
    for a in range(3):
        x[k + 3 * a], x[k + 3 * a + 1], x[k + 3 * a + 2] = m[a]


@njit(cache=True, error_model="numpy")
def _store_inertia(w, k, m, c, J):
    """w[k:k+36] = the spatial inertia at the origin, row-major, in closed form:
    [[J + m (|c|^2 1 - c c^T), m [c]x], [-m [c]x, m 1]] (the matrix of _inertia_mul)."""
    c2 = dot(c, c)
    mc = scale(m, c)
    mcx = skew(mc)
    for r in range(3):
        for e in range(3):
            w[k + 6 * r + e] = J[r][e] - mc[r] * c[e]
            w[k + 6 * r + 3 + e] = mcx[r][e]
            w[k + 6 * (r + 3) + e] = -mcx[r][e]
            w[k + 6 * (r + 3) + 3 + e] = 0.0
        w[k + 7 * r] += m * c2
        w[k + 7 * (r + 3)] = m


@njit(cache=True, error_model="numpy")
def _block(a, k, r0, c0):
    """The 3 x 3 block at (r0, c0) of the row-major 6 x 6 a[k:k+36]."""
    b = k + 6 * r0 + c0
    return ((a[b], a[b + 1], a[b + 2]), (a[b + 6], a[b + 7], a[b + 8]),
            (a[b + 12], a[b + 13], a[b + 14]))  # fmt: skip


@njit(cache=True, error_model="numpy")
def _msum(a, b, sign):
    """a + sign * b for 3 x 3 matrices."""
    return (add(a[0], scale(sign, b[0])), add(a[1], scale(sign, b[1])),
            add(a[2], scale(sign, b[2])))  # fmt: skip


@njit(cache=True, error_model="numpy")
def _add_block(dst, d, r0, c0, m, swap):
    top = d + 6 * ((r0 + swap) % 6) + (c0 + swap) % 6
    for r in range(3):
        for c in range(3):
            dst[top + 6 * r + c] += m[r][c]


@njit(cache=True, error_model="numpy")
def _shift_add(A, B, D, pos, dst, d, swap):
    """dst[d:d+36] += T^T [[A, B], [B^T, D]] T, T = [[1, 0], [-[pos]x, 1]].

    The blocks are a spatial inertia's in the parent's axes; the result is
    [[A + [p]B^T - (B + [p]D)[p], B + [p]D], [C - D[p], D]] ([p] = [pos]x), the lower
    left block the transposed upper right one. [p]M and M[p] are written as cross
    products, column by column and row by row (the products with skew(pos) without
    their zero terms). ``swap`` = 3 writes it in the hub exchange order
    [force; torque] x [a; omega_dot].
    """
    Dc = transpose(D)
    pD = transpose((cross(pos, Dc[0]), cross(pos, Dc[1]), cross(pos, Dc[2])))
    pBt = transpose((cross(pos, B[0]), cross(pos, B[1]), cross(pos, B[2])))
    upper_right = _msum(B, pD, 1.0)
    up_p = (cross(upper_right[0], pos), cross(upper_right[1], pos),
            cross(upper_right[2], pos))  # fmt: skip
    upper_left = _msum(_msum(A, pBt, 1.0), up_p, -1.0)
    _add_block(dst, d, 0, 0, upper_left, swap)
    _add_block(dst, d, 0, 3, upper_right, swap)
    _add_block(dst, d, 3, 0, transpose(upper_right), swap)
    _add_block(dst, d, 3, 3, D, swap)


@njit(cache=True, error_model="numpy")
def _add_congruence(src, s, R, pos, dst, d, swap):
    """dst[d:d+36] += X^T (src[s:s+36]) X, X the parent -> child motion transform.

    X = diag(R^T, R^T) T with T = [[1, 0], [-[pos]x, 1]]: the blocks of src rotated
    to the parent's axes (R M R^T), then moved by :func:`_shift_add`. src is a spatial
    inertia, symmetric: its lower-left block is the transposed upper-right one and is
    never rotated.
    """
    _congruence_blocks(_block(src, s, 0, 0), _block(src, s, 0, 3), _block(src, s, 3, 3),
                       R, pos, dst, d, swap)  # fmt: skip


@njit(cache=True, error_model="numpy")
def _congruence_blocks(A, B, D, R, pos, dst, d, swap):
    """:func:`_add_congruence` of the spatial inertia [[A, B], [B^T, D]] given by blocks."""
    Rt = transpose(R)
    _shift_add(mm(R, mm(A, Rt)), mm(R, mm(B, Rt)), mm(R, mm(D, Rt)), pos, dst, d, swap)


# -- hinges: elementary rotations -------------------------------------------------------


@njit(cache=True, error_model="numpy")
def _rot_axis(axis, c, s, u):
    """R_a u, R_a the rotation about coordinate axis a (0, 1, 2: Rx, Ry, Rz) by the
    angle of cosine c and sine s; two components change. R_a^T u is _rot_axis(a, c, -s, u)."""
    if axis == 0:
        return u[0], c * u[1] - s * u[2], s * u[1] + c * u[2]
    if axis == 1:
        return c * u[0] + s * u[2], u[1], c * u[2] - s * u[0]
    return c * u[0] - s * u[1], s * u[0] + c * u[1], u[2]


@njit(cache=True, error_model="numpy")
def _rot_rows(axis, c, s, m):
    """R_a m for a 3 x 3 m: two of its rows combined."""
    r0, r1, r2 = m
    if axis == 0:
        return r0, _comb(c, r1, -s, r2), _comb(s, r1, c, r2)
    if axis == 1:
        return _comb(c, r0, s, r2), r1, _comb(c, r2, -s, r0)
    return _comb(c, r0, -s, r1), _comb(s, r0, c, r1), r2


@njit(cache=True, error_model="numpy")
def _comb(x, u, y, v):
    """x u + y v for 3-vectors."""
    return x * u[0] + y * v[0], x * u[1] + y * v[1], x * u[2] + y * v[2]


@njit(cache=True, error_model="numpy")
def _sandwich(axis, c, s, m):
    """R_a m R_a^T = (R_a (R_a m)^T)^T: 24 products instead of the 54 of two 3 x 3 products."""
    return transpose(_rot_rows(axis, c, s, transpose(_rot_rows(axis, c, s, m))))


@njit(cache=True, error_model="numpy")
def _add_axis(u, axis, x):
    """u + x e_a."""
    if axis == 0:
        return u[0] + x, u[1], u[2]
    if axis == 1:
        return u[0], u[1] + x, u[2]
    return u[0], u[1], u[2] + x


@njit(cache=True, error_model="numpy")
def _cross_axis(u, axis, x):
    """u x (x e_a)."""
    if axis == 0:
        return 0.0, u[2] * x, -u[1] * x
    if axis == 1:
        return -u[2] * x, 0.0, u[0] * x
    return u[1] * x, -u[0] * x, 0.0


@njit(cache=True, error_model="numpy")
def _xm_hinge(axis, c, s, pos, ua, ul):
    """:func:`_xm` for a hinge's R = R_a (joint k > 0, parallel to the parent's frame)."""
    return _rot_axis(axis, c, -s, ua), _rot_axis(axis, c, -s, sub(ul, cross(pos, ua)))


@njit(cache=True, error_model="numpy")
def _rotation_axis(axis, c, s):
    """R_a as a 3 x 3 matrix (for the root, whose R = R_BM R_a is a general rotation)."""
    if axis == 0:
        return (1.0, 0.0, 0.0), (0.0, c, -s), (0.0, s, c)
    if axis == 1:
        return (c, 0.0, s), (0.0, 1.0, 0.0), (-s, 0.0, c)
    return (c, -s, 0.0), (s, c, 0.0), (0.0, 0.0, 1.0)


@njit(cache=True, error_model="numpy")
def _cos_sin(angle, free):
    """(cos, sin) of a joint angle; (1, 0), without evaluating either, where it is locked."""
    if free != 0.0:
        return cos(angle), sin(angle)
    return 1.0, 0.0


@njit(cache=True, error_model="numpy")
def _joint_values(x, o, p, g):
    """The six DOF values (x, y, z), (rx, ry, rz) of the joint whose segment's columns
    start at p[g], read from the plant vector ``x`` (q, q_dot or q_ddot); 0 where locked."""
    c = o + int(p[g + G_OFF])
    v0 = v1 = v2 = v3 = v4 = v5 = 0.0
    for i in range(6):
        if p[g + G_FREE + i] != 0.0:
            v = x[c]
            c += 1
            if i == 0:
                v0 = v
            elif i == 1:
                v1 = v
            elif i == 2:
                v2 = v
            elif i == 3:
                v3 = v
            elif i == 4:
                v4 = v
            else:
                v5 = v
    return (v0, v1, v2), (v3, v4, v5)


@njit(cache=True, error_model="numpy")
def _joint_pose(q, qd, o, p, g, first):
    """Pose and relative motion of the joint whose segment's columns start at p[g].

    Returns R (parent <- segment), pos (segment origin, parent coordinates), R_JP,
    S(rho), the joint velocity v_J = S_k qd_k and its bias c_J = S_dot_k qd_k (both in
    segment coordinates), and a status.
    """
    t, (rx, ry, rz) = _joint_values(q, o, p, g)
    (dx, dy, dz), (drx, dry, drz) = _joint_values(qd, o, p, g)
    free_x, free_z = p[g + G_FREE + 3], p[g + G_FREE + 5]
    c1, s1 = _cos_sin(rx, free_x)
    c2, s2 = _cos_sin(ry, p[g + G_FREE + 4])
    c3, s3 = _cos_sin(rz, free_z)
    status = STATUS_OK
    if free_x != 0.0 and free_z != 0.0 and abs(c2) < MIN_COS:
        status = STATUS_JOINT_GIMBAL_LOCK
    R_JP = rot_zyx_cs(c1, s1, c2, s2, c3, s3)
    S_rho = euler_rate_matrix_cs(c1, s1, c2, s2)
    if first:  # J_0 is the mount frame M
        R_PJ = load_m33_at(p, H_R_BM)
        pos = add(load_seg(p, H_MOUNT), mv(R_PJ, t))
        R = mm(R_PJ, R_JP)
    else:  # J_k is parallel to the parent's frame
        pos = add(load_seg(p, g - SEG + G_NEXT), t)
        R = R_JP
    omega_rel = mv(S_rho, (drx, dry, drz))
    v_lin = mtv(R_JP, (dx, dy, dz))
    c_ang = euler_rate_bias_cs(c1, s1, c2, s2, drx, dry, drz)
    c_lin = scale(-1.0, cross(omega_rel, v_lin))
    return R, pos, R_JP, S_rho, omega_rel, v_lin, c_ang, c_lin, status


@njit(cache=True, error_model="numpy")
def _store_subspace(w, b, p, g, R_JP, S_rho):
    """Columns of S_k (free DOFs only) at w[b + W_S + 6 a]."""
    a = 0
    for i in range(6):
        if p[g + G_FREE + i] == 0.0:
            continue
        k = b + W_S + 6 * a
        for r in range(6):
            w[k + r] = 0.0
        if i < 3:  # translation: [0; R_JP^T e_i] = [0; row i of R_JP]
            w[k + 3], w[k + 4], w[k + 5] = R_JP[i]
        else:  # rotation: [S(rho) e_i; 0]
            w[k], w[k + 1], w[k + 2] = S_rho[0][i - 3], S_rho[1][i - 3], S_rho[2][i - 3]
        a += 1


@njit(cache=True, error_model="numpy")
def _col(w, k):
    return (w[k], w[k + 1], w[k + 2]), (w[k + 3], w[k + 4], w[k + 5])


@njit(cache=True, error_model="numpy")
def _pose_of(w, b):
    return load_m33_at(w, b + W_R), load_seg(w, b + W_POS)


@njit(cache=True, error_model="numpy")
def _invert_spd(w, k, n):
    """Invert the n x n symmetric positive definite w[k + 6 r + c] in place (Gauss-Jordan)."""
    for e in range(n):
        pivot = w[k + 7 * e]
        w[k + 7 * e] = 1.0
        for c in range(n):
            w[k + 6 * e + c] /= pivot
        for r in range(n):
            if r == e:
                continue
            f = w[k + 6 * r + e]
            w[k + 6 * r + e] = 0.0
            for c in range(n):
                w[k + 6 * r + c] -= f * w[k + 6 * e + c]


@njit(cache=True, error_model="numpy")
def _outward(q, qd, o, p, g, first, va, vl, aa, al):
    """One outward step of the recursive Newton-Euler algorithm (eqs. C.1, C.6).

    From the parent's spatial velocity (va, vl) and acceleration (aa, al) in its own
    coordinates, the segment's: v_k = X_k v_{k-1} + S_k qd_k and
    a_k = X_k a_{k-1} + c_J + v_k x_m S_k qd_k, the acceleration at q_ddot_k = 0 (the
    caller adds S_k q_ddot_k). Returns R, pos, R_JP, S(rho) as :func:`_joint_pose`,
    then va, vl, aa, al and the status.
    """
    R, pos, R_JP, S_rho, ja, jl, ca, cl, status = _joint_pose(q, qd, o, p, g, first)
    xa, xl = _xm(R, pos, va, vl)
    va, vl = add(xa, ja), add(xl, jl)
    xa, xl = _xm(R, pos, aa, al)
    ba, bl = _crm(va, vl, ja, jl)
    aa, al = add(add(xa, ca), ba), add(add(xl, cl), bl)
    return R, pos, R_JP, S_rho, va, vl, aa, al, status


@njit(cache=True, error_model="numpy")
def _body_force(p, g, va, vl, aa, al):
    """The force f_k = I_k a_k + v_k x_f I_k v_k that moves segment k (eq. C.8), [n; f]
    in its frame about its joint origin."""
    m, c, J = p[g + G_MASS], load_seg(p, g + G_COM), load_m33_at(p, g + G_J)
    fn, ff = _inertia_mul(m, c, J, aa, al)
    hn, hf = _inertia_mul(m, c, J, va, vl)
    gn, gf = _crf(va, vl, hn, hf)
    return add(fn, gn), add(ff, gf)


@njit(cache=True, error_model="numpy")
def _hinge_outward(q, qd, Q, o, p, g, w, b, first, axis, va, vl, hub):
    """Pass 1's outward step (eq. C.1) for a hinge about axis a of its parent-side frame.

    S_k = [e_a; 0] and c_J = 0 (the axis does not move in the parent-side frame), so
    v_k = X_k v_{k-1} + q_dot e_a and c_k = v_k x_m [q_dot e_a; 0]; R = R_a(q) for
    k > 0, an elementary rotation (R_BM R_a at the root). Stores the pose, c_k, I_k,
    p_k = v_k x_f I_k v_k and tau_k as the general step does; returns v_k.
    """
    col = o + int(p[g + G_OFF])
    angle, rate = q[col], qd[col]
    c, s = cos(angle), sin(angle)
    w[b + W_CS], w[b + W_CS + 1] = c, s
    if first:  # J_0 is the mount frame M: R = R_BM R_a, a general rotation
        R = mm(load_m33_at(p, H_R_BM), _rotation_axis(axis, c, s))
        pos = load_seg(p, H_MOUNT)
        _put_m33(w, b + W_R, R)
        xa, xl = _xm(R, pos, va, vl)
    else:
        pos = load_seg(p, g - SEG + G_NEXT)
        xa, xl = _xm_hinge(axis, c, s, pos, va, vl)
    _put3(w, b + W_POS, pos)
    va, vl = _add_axis(xa, axis, rate), xl
    _put3(w, b + W_CA, _cross_axis(va, axis, rate))
    _put3(w, b + W_CA + 3, _cross_axis(vl, axis, rate))
    m, cm, J = p[g + G_MASS], load_seg(p, g + G_COM), load_m33_at(p, g + G_J)
    _store_inertia(w, b + W_IA, m, cm, J)
    hn, hf = _inertia_mul(m, cm, J, va, vl)
    pn, pf = _crf(va, vl, hn, hf)
    _put3(w, b + W_PA, pn)
    _put3(w, b + W_PA + 3, pf)
    damping = p[g + G_C + 3 + axis]
    w[b + W_TAU] = Q[col] - p[g + G_K + 3 + axis] * angle - damping * rate
    hub[HUB_DISSIPATION] += damping * rate * rate  # eq. 2.36
    return va, vl


@njit(cache=True, error_model="numpy")
def _hinge_inward(w, b, k, axis, hub):
    """Pass 1's inward step (eqs. C.3, C.4) for a hinge about axis a: U = I^A e_a (a
    column of I^A), D = I^A_aa (a scalar, no inverse), u = tau - p^A_a; then
    I^a = I^A - U U^T / D, p^a = p^A + I^a c + U u / D, and both moved to the parent
    (X^T I^a X by elementary rotations, or to the hub). I^a is symmetric: it is kept
    in registers as its blocks [[A, B], [B^T, D]], never stored. Leaves U, 1 / D and u
    for pass 2 at W_U, W_DI and W_TAU.
    """
    ia = b + W_IA
    d_inv = 1.0 / w[ia + 7 * axis]
    u = w[b + W_TAU] - w[b + W_PA + axis]
    w[b + W_DI], w[b + W_TAU] = d_inv, u
    un = (w[ia + axis], w[ia + 6 + axis], w[ia + 12 + axis])
    uf = (w[ia + 18 + axis], w[ia + 24 + axis], w[ia + 30 + axis])
    _put3(w, b + W_U, un)
    _put3(w, b + W_U + 3, uf)
    # I^a = I^A - U D^-1 U^T by blocks
    vn = scale(d_inv, un)
    A0, B0, D0 = _block(w, ia, 0, 0), _block(w, ia, 0, 3), _block(w, ia, 3, 3)
    A = (sub(A0[0], scale(vn[0], un)), sub(A0[1], scale(vn[1], un)),
         sub(A0[2], scale(vn[2], un)))  # fmt: skip
    B = (sub(B0[0], scale(vn[0], uf)), sub(B0[1], scale(vn[1], uf)),
         sub(B0[2], scale(vn[2], uf)))  # fmt: skip
    vf = scale(d_inv, uf)
    D = (sub(D0[0], scale(vf[0], uf)), sub(D0[1], scale(vf[1], uf)),
         sub(D0[2], scale(vf[2], uf)))  # fmt: skip
    # p^a = p^A + I^a c + U D^-1 u
    y = d_inv * u
    ca, cl = load_seg(w, b + W_CA), load_seg(w, b + W_CA + 3)
    pn = add(add(load_seg(w, b + W_PA), scale(y, un)), add(mv(A, ca), mv(B, cl)))
    pf = add(add(load_seg(w, b + W_PA + 3), scale(y, uf)), add(mtv(B, ca), mv(D, cl)))
    if k > 0:
        up = b - WSEG
        c, s, pos = w[b + W_CS], w[b + W_CS + 1], load_seg(w, b + W_POS)
        _shift_add(_sandwich(axis, c, s, A), _sandwich(axis, c, s, B),
                   _sandwich(axis, c, s, D), pos, w, up + W_IA, 0)  # fmt: skip
        Rf = _rot_axis(axis, c, s, pf)
        pn = add(_rot_axis(axis, c, s, pn), cross(pos, Rf))
        for r in range(3):
            w[up + W_PA + r] += pn[r]
            w[up + W_PA + 3 + r] += Rf[r]
    else:
        R, pos = _pose_of(w, b)
        _congruence_blocks(A, B, D, R, pos, hub, HUB_INERTIA, 3)
        pn, pf = _xft(R, pos, pn, pf)
        for r in range(3):
            hub[HUB_FORCE + r] -= pf[r]
            hub[HUB_TORQUE + r] -= pn[r]


@njit(cache=True, error_model="numpy")  # compiled with PASS1_SIGNATURE on first use
def pass1(q, qd, Q, members, params, work, hub, qdd):
    """Velocities outward, articulated inertias inward; the root's share to the hub.

    Parameters
    ----------
    q, qd : ndarray, shape (n_dof,)
        Generalized coordinates [m, rad] and rates [m/s, rad/s] of the whole plant.
    Q : ndarray, shape (n_dof,)
        External generalized forces [N, N m per coordinate].
    members : ndarray, shape (k, 2), int64
        Per chain: appendage index and offset of its first coordinate in q [-].
    params : ndarray, shape (k, p)
        Per chain: its packed row (``HEADER`` then the segments' ``G_*`` slots) [SI].
    work : ndarray, shape (k, w)
        Per chain: scratch pass 1 leaves for pass 2 [SI].
    hub : ndarray, shape (HUB_SIZE,)
        The hub exchange array (slots ``HUB_*`` of the contract module) [SI per
        slot]; the wrench and articulated inertia are added to it.
    qdd : ndarray, shape (n_dof,)
        Not written in pass 1 [m/s^2, rad/s^2].

    Returns
    -------
    int
        ``STATUS_OK`` or a joint gimbal-lock status.
    """
    omega_B = load_seg(hub, HUB_OMEGA)
    for j in range(members.shape[0]):
        o = members[j, 1]
        p = params[j]
        w = work[j]
        n_seg = int(p[H_N])
        va, vl = omega_B, _ZERO
        for k in range(n_seg):
            g, b = HEADER + k * SEG, k * WSEG
            kind = int(p[g + G_KIND])
            if kind != JOINT_GENERAL:
                va, vl = _hinge_outward(q, qd, Q, o, p, g, w, b, k == 0, kind - JOINT_HINGE_X,
                                        va, vl, hub)  # fmt: skip
                continue
            R, pos, R_JP, S_rho, ja, jl, ca, cl, status = _joint_pose(q, qd, o, p, g, k == 0)
            if status != STATUS_OK:
                return status
            _put_m33(w, b + W_R, R)
            _put3(w, b + W_POS, pos)
            _store_subspace(w, b, p, g, R_JP, S_rho)
            xa, xl = _xm(R, pos, va, vl)
            va, vl = add(xa, ja), add(xl, jl)
            ba, bl = _crm(va, vl, ja, jl)
            _put3(w, b + W_CA, add(ca, ba))
            _put3(w, b + W_CA + 3, add(cl, bl))
            m, c, J = p[g + G_MASS], load_seg(p, g + G_COM), load_m33_at(p, g + G_J)
            _store_inertia(w, b + W_IA, m, c, J)
            hn, hf = _inertia_mul(m, c, J, va, vl)
            pn, pf = _crf(va, vl, hn, hf)
            _put3(w, b + W_PA, pn)
            _put3(w, b + W_PA + 3, pf)
            a, col = 0, o + int(p[g + G_OFF])
            for i in range(6):
                if p[g + G_FREE + i] != 0.0:
                    rate = qd[col + a]
                    w[b + W_TAU + a] = (
                        Q[col + a] - p[g + G_K + i] * q[col + a] - p[g + G_C + i] * rate
                    )
                    hub[HUB_DISSIPATION] += p[g + G_C + i] * rate * rate  # eq. 2.36
                    a += 1
        for k in range(n_seg - 1, -1, -1):
            g, b = HEADER + k * SEG, k * WSEG
            kind = int(p[g + G_KIND])
            if kind != JOINT_GENERAL:
                _hinge_inward(w, b, k, kind - JOINT_HINGE_X, hub)
                continue
            nf = int(p[g + G_NF])
            # U = I^A S, D = S^T U, u = tau - S^T p^A
            for a in range(nf):
                sa, sl = _col(w, b + W_S + 6 * a)
                un, uf = _mul6(w, b + W_IA, sa, sl)
                _put3(w, b + W_U + 6 * a, un)
                _put3(w, b + W_U + 6 * a + 3, uf)
                w[b + W_TAU + a] -= dot(sa, load_seg(w, b + W_PA)) + dot(
                    sl, load_seg(w, b + W_PA + 3)
                )
            for a in range(nf):
                sa, sl = _col(w, b + W_S + 6 * a)
                for e in range(nf):
                    un, uf = _col(w, b + W_U + 6 * e)
                    w[b + W_DI + 6 * a + e] = dot(sa, un) + dot(sl, uf)
            _invert_spd(w, b + W_DI, nf)
            # I^a = I^A - U D^-1 U^T; p^a = p^A + I^a c + U D^-1 u
            for a in range(nf):
                y = 0.0
                for e in range(nf):
                    y += w[b + W_DI + 6 * a + e] * w[b + W_TAU + e]
                for r in range(6):
                    w[b + W_PA + r] += w[b + W_U + 6 * a + r] * y
            # A joint free in all six directions (S square, invertible) hands its parent
            # no inertia: I^a = I^A - I^A S (S^T I^A S)^-1 S^T I^A = 0, and p^a = S^-T tau
            # (the sum above). Only a joint with fewer DOFs transmits I^a.
            transmits = nf < 6
            if transmits:
                for r in range(6):
                    # row r of U D^-1 (D^-1 symmetric), then I^A[r, :] -= (U D^-1)[r, :] U^T
                    for e in range(nf):
                        v = 0.0
                        for a in range(nf):
                            v += w[b + W_U + 6 * a + r] * w[b + W_DI + 6 * a + e]
                        if v != 0.0:
                            for s in range(6):
                                w[b + W_IA + 6 * r + s] -= v * w[b + W_U + 6 * e + s]
                ia_n, ia_f = _mul6(w, b + W_IA, load_seg(w, b + W_CA),
                                   load_seg(w, b + W_CA + 3))  # fmt: skip
                for r in range(3):
                    w[b + W_PA + r] += ia_n[r]
                    w[b + W_PA + 3 + r] += ia_f[r]
            R, pos = _pose_of(w, b)
            pn, pf = _xft(R, pos, load_seg(w, b + W_PA), load_seg(w, b + W_PA + 3))
            if k > 0:
                up = b - WSEG
                if transmits:
                    _add_congruence(w, b + W_IA, R, pos, w, up + W_IA, 0)
                for r in range(3):
                    w[up + W_PA + r] += pn[r]
                    w[up + W_PA + 3 + r] += pf[r]
            else:
                if transmits:
                    _add_congruence(w, b + W_IA, R, pos, hub, HUB_INERTIA, 3)
                for r in range(3):
                    hub[HUB_FORCE + r] -= pf[r]
                    hub[HUB_TORQUE + r] -= pn[r]
    return STATUS_OK


@njit(cache=True, error_model="numpy")  # compiled with PASS2_SIGNATURE on first use
def pass2(q, qd, members, params, work, hub, qdd):
    """Joint accelerations outward from the hub's: q_ddot_k = D^-1 (u - U^T a'_k).

    Parameters
    ----------
    q, qd : ndarray, shape (n_dof,)
        Generalized coordinates [m, rad] and rates [m/s, rad/s] of the whole plant.
    members : ndarray, shape (k, 2), int64
        Per chain: appendage index and offset of its first coordinate in q [-].
    params : ndarray, shape (k, p)
        Per chain: its packed row (``HEADER`` then the segments' ``G_*`` slots) [SI].
    work : ndarray, shape (k, w)
        Per chain: scratch pass 1 leaves for pass 2 [SI].
    hub : ndarray, shape (HUB_SIZE,)
        The hub exchange array (slots ``HUB_*`` of the contract module) [SI per
        slot]; the hub's accelerations are read from it.
    qdd : ndarray, shape (n_dof,)
        Output: the chains' coordinate accelerations [m/s^2, rad/s^2].

    Returns
    -------
    int
        ``STATUS_OK``.
    """
    for j in range(members.shape[0]):
        o = members[j, 1]
        p = params[j]
        w = work[j]
        aa, al = load_seg(hub, HUB_ALPHA), load_seg(hub, HUB_ACC)
        for k in range(int(p[H_N])):
            g, b = HEADER + k * SEG, k * WSEG
            col = o + int(p[g + G_OFF])
            kind = int(p[g + G_KIND])
            if kind != JOINT_GENERAL:  # q_ddot = D^-1 (u - U^T a'), a = a' + q_ddot e_a
                axis = kind - JOINT_HINGE_X
                if k == 0:
                    R, pos = _pose_of(w, b)
                    xa, xl = _xm(R, pos, aa, al)
                else:
                    xa, xl = _xm_hinge(axis, w[b + W_CS], w[b + W_CS + 1],
                                       load_seg(w, b + W_POS), aa, al)  # fmt: skip
                aa = add(xa, load_seg(w, b + W_CA))
                al = add(xl, load_seg(w, b + W_CA + 3))
                un, uf = _col(w, b + W_U)
                x = w[b + W_DI] * (w[b + W_TAU] - dot(un, aa) - dot(uf, al))
                qdd[col] = x
                aa = _add_axis(aa, axis, x)
                continue
            nf = int(p[g + G_NF])
            R, pos = _pose_of(w, b)
            xa, xl = _xm(R, pos, aa, al)
            aa = add(xa, load_seg(w, b + W_CA))
            al = add(xl, load_seg(w, b + W_CA + 3))
            for a in range(nf):
                un, uf = _col(w, b + W_U + 6 * a)
                w[b + W_PA + a] = w[b + W_TAU + a] - dot(un, aa) - dot(uf, al)
            for a in range(nf):
                y = 0.0
                for e in range(nf):
                    y += w[b + W_DI + 6 * a + e] * w[b + W_PA + e]
                qdd[col + a] = y
            for a in range(nf):
                sa, sl = _col(w, b + W_S + 6 * a)
                aa = add(aa, scale(qdd[col + a], sa))
                al = add(al, scale(qdd[col + a], sl))
    return STATUS_OK


@njit(cache=True, error_model="numpy")
def _subspace_pass(q, o, p, w):
    """Poses and motion subspaces of every segment into the scratch row ``w``."""
    for k in range(int(p[H_N])):
        g, b = HEADER + k * SEG, k * WSEG
        R, pos, R_JP, S_rho, ja, jl, ca, cl, status = _joint_pose(q, q, o, p, g, k == 0)
        _put_m33(w, b + W_R, R)
        _put3(w, b + W_POS, pos)
        _store_subspace(w, b, p, g, R_JP, S_rho)


@njit(cache=True, error_model="numpy")  # compiled with MASS_SIGNATURE on first use
def mass_matrix(q, members, params, M):
    """The chains' share of M(q) (eq. 2.39): composite-rigid-body algorithm.

    Parameters
    ----------
    q : ndarray, shape (n_dof,)
        Generalized coordinates of the whole plant [m, rad].
    members : ndarray, shape (k, 2), int64
        Per chain: appendage index and offset of its first coordinate in q [-].
    params : ndarray, shape (k, p)
        Per chain: its packed row (``HEADER`` then the segments' ``G_*`` slots) [SI].
    M : ndarray, shape (n_dof, n_dof)
        The mass matrix, the chains' blocks added [kg, kg m, kg m^2 per entry].
    """
    R_NB = rot_zyx(q[3], q[4], q[5])
    S = euler_rate_matrix(q[3], q[4])
    ic_hub = np.zeros(36)
    for j in range(members.shape[0]):
        o = members[j, 1]
        p = params[j]
        n_seg = int(p[H_N])
        w = np.zeros(n_seg * WSEG)
        _subspace_pass(q, o, p, w)
        for k in range(n_seg):
            g = HEADER + k * SEG
            _store_inertia(w, k * WSEG + W_IA, p[g + G_MASS], load_seg(p, g + G_COM),
                           load_m33_at(p, g + G_J))  # fmt: skip
        ic_hub[:] = 0.0
        for k in range(n_seg - 1, -1, -1):
            b = k * WSEG
            R, pos = _pose_of(w, b)
            if k > 0:
                _add_congruence(w, b + W_IA, R, pos, w, b - WSEG + W_IA, 0)
            else:
                _add_congruence(w, b + W_IA, R, pos, ic_hub, 0, 0)
        for k in range(n_seg):
            g, b = HEADER + k * SEG, k * WSEG
            col = o + int(p[g + G_OFF])
            for a in range(int(p[g + G_NF])):
                sa, sl = _col(w, b + W_S + 6 * a)
                fn, ff = _mul6(w, b + W_IA, sa, sl)
                for e in range(int(p[g + G_NF])):
                    sa, sl = _col(w, b + W_S + 6 * e)
                    M[col + e, col + a] += dot(sa, fn) + dot(sl, ff)
                for i in range(k - 1, -2, -1):
                    R, pos = _pose_of(w, (i + 1) * WSEG)
                    fn, ff = _xft(R, pos, fn, ff)
                    if i < 0:
                        break
                    gi = HEADER + i * SEG
                    ci = o + int(p[gi + G_OFF])
                    for e in range(int(p[gi + G_NF])):
                        sa, sl = _col(w, i * WSEG + W_S + 6 * e)
                        v = dot(sa, fn) + dot(sl, ff)
                        M[ci + e, col + a] += v
                        M[col + a, ci + e] += v
                lin, ang = mv(R_NB, ff), mtv(S, fn)
                for r in range(3):
                    M[r, col + a] += lin[r]
                    M[col + a, r] += lin[r]
                    M[3 + r, col + a] += ang[r]
                    M[col + a, 3 + r] += ang[r]
        # Hub block: [r_dot_N; Theta_dot] -> [omega_B; v_B] is [[0, S], [R_NB^T, 0]].
        for r in range(3):
            for c in range(3):
                inn = ic_hub[6 * r + c]
                for a in range(3):
                    for e in range(3):
                        M[3 + a, 3 + e] += S[r][a] * inn * S[c][e]
                        M[a, e] += R_NB[a][r] * ic_hub[6 * (r + 3) + c + 3] * R_NB[e][c]
                        v = R_NB[a][r] * ic_hub[6 * (r + 3) + c] * S[c][e]
                        M[a, 3 + e] += v
                        M[3 + e, a] += v


@njit(cache=True, error_model="numpy")  # compiled with BIAS_SIGNATURE on first use
def bias_forces(q, qd, members, params, hub, h):
    """The chains' share of h(q, q_dot) (eq. 2.43): recursive Newton-Euler at q_ddot = 0.

    Parameters
    ----------
    q, qd : ndarray, shape (n_dof,)
        Generalized coordinates [m, rad] and rates [m/s, rad/s] of the whole plant.
    members : ndarray, shape (k, 2), int64
        Per chain: appendage index and offset of its first coordinate in q [-].
    params : ndarray, shape (k, p)
        Per chain: its packed row (``HEADER`` then the segments' ``G_*`` slots) [SI].
    hub : ndarray, shape (HUB_SIZE,)
        The hub exchange array (slots ``HUB_*`` of the contract module) [SI per
        slot]; the chains' force and torque on the hub are added to it.
    h : ndarray, shape (n_dof,)
        The bias vector, the chains' coordinates written [N, N m per coordinate].
    """
    R_NB = rot_zyx(q[3], q[4], q[5])
    omega_B = load_seg(hub, HUB_OMEGA)
    s_bias = load_seg(hub, HUB_SBIAS)
    for j in range(members.shape[0]):
        o = members[j, 1]
        p = params[j]
        n_seg = int(p[H_N])
        w = np.zeros(n_seg * WSEG)
        va, vl, aa, al = omega_B, _ZERO, s_bias, _ZERO
        for k in range(n_seg):
            g, b = HEADER + k * SEG, k * WSEG
            R, pos, R_JP, S_rho, va, vl, aa, al, status = _outward(
                q, qd, o, p, g, k == 0, va, vl, aa, al
            )
            _put_m33(w, b + W_R, R)
            _put3(w, b + W_POS, pos)
            _store_subspace(w, b, p, g, R_JP, S_rho)
            fn, ff = _body_force(p, g, va, vl, aa, al)
            _put3(w, b + W_PA, fn)
            _put3(w, b + W_PA + 3, ff)
        for k in range(n_seg - 1, -1, -1):
            g, b = HEADER + k * SEG, k * WSEG
            fn, ff = load_seg(w, b + W_PA), load_seg(w, b + W_PA + 3)
            col = o + int(p[g + G_OFF])
            for a in range(int(p[g + G_NF])):
                sa, sl = _col(w, b + W_S + 6 * a)
                h[col + a] = dot(sa, fn) + dot(sl, ff)
            R, pos = _pose_of(w, b)
            pn, pf = _xft(R, pos, fn, ff)
            if k > 0:
                for r in range(3):
                    w[b - WSEG + W_PA + r] += pn[r]
                    w[b - WSEG + W_PA + 3 + r] += pf[r]
            else:
                f_N = mv(R_NB, pf)
                for r in range(3):
                    hub[HUB_FORCE + r] += f_N[r]
                    hub[HUB_TORQUE + r] += pn[r]


@njit(cache=True, error_model="numpy")  # compiled with OBSERVE_SIGNATURE on first use
def observe(q, qd, members, params, out):
    """Add the chains' kinetic energy, momentum, locked inertia, elastic energy, damper power.

    Parameters
    ----------
    q, qd : ndarray, shape (n_dof,)
        Generalized coordinates [m, rad] and rates [m/s, rad/s] of the whole plant.
    members : ndarray, shape (k, 2), int64
        Per chain: appendage index and offset of its first coordinate in q [-].
    params : ndarray, shape (k, p)
        Per chain: its packed row (``HEADER`` then the segments' ``G_*`` slots) [SI].
    out : ndarray, shape (OBS_SIZE,)
        The observation slots (``OBS_*``: [J], [N m s], [kg m^2], [J], [W]), added to.
    """
    R_NB = rot_zyx(q[3], q[4], q[5])
    r_hub = load_seg(q, 0)
    omega_B = mv(euler_rate_matrix(q[3], q[4]), load_seg(qd, 3))
    v_hub_B = mtv(R_NB, load_seg(qd, 0))
    for j in range(members.shape[0]):
        o = members[j, 1]
        p = params[j]
        va, vl = omega_B, v_hub_B
        R_BP = ((1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0))
        r_O = _ZERO
        for k in range(int(p[H_N])):
            g = HEADER + k * SEG
            R, pos, R_JP, S_rho, ja, jl, ca, cl, status = _joint_pose(q, qd, o, p, g, k == 0)
            r_O = add(r_O, mv(R_BP, pos))
            R_BP = mm(R_BP, R)
            xa, xl = _xm(R, pos, va, vl)
            va, vl = add(xa, ja), add(xl, jl)
            m, c, J = p[g + G_MASS], load_seg(p, g + G_COM), load_m33_at(p, g + G_J)
            v_G = add(vl, cross(va, c))
            out[OBS_KINETIC] += 0.5 * m * dot(v_G, v_G) + 0.5 * dot(va, mv(J, va))  # eq. 2.32
            r_G = add(r_O, mv(R_BP, c))
            R_NP = mm(R_NB, R_BP)
            linear = cross(add(r_hub, mv(R_NB, r_G)), scale(m, mv(R_NP, v_G)))
            spin = mv(R_NP, mv(J, va))
            for a in range(3):
                out[OBS_MOMENTUM + a] += linear[a] + spin[a]
            J_B = mm(R_BP, mm(J, transpose(R_BP)))
            r2 = dot(r_G, r_G)
            for a in range(3):
                for e in range(3):
                    out[OBS_LOCKED_INERTIA + 3 * a + e] += J_B[a][e] - m * r_G[a] * r_G[e]
                out[OBS_LOCKED_INERTIA + 4 * a] += m * r2
            a, col = 0, o + int(p[g + G_OFF])
            for i in range(6):
                if p[g + G_FREE + i] != 0.0:
                    out[OBS_ELASTIC] += 0.5 * p[g + G_K + i] * q[col + a] ** 2  # eq. 2.35
                    out[OBS_DISSIPATION] += p[g + G_C + i] * qd[col + a] ** 2  # eq. 2.36
                    a += 1


@njit(cache=True, error_model="numpy")  # compiled with WRENCH_SIGNATURE on first use
def joint_wrench(q, qd, qdd, Q, members, params, out):
    """Add the wrench each chain's root joint transmits to the hub (tau_flex in out[3:6]).

    The hub moves the chain through its root joint, so the wrench [n_0; f_0] the joint
    puts on segment 0 is what the chain needs to move as it does: the sum of the
    segments' inertial forces (recursive Newton-Euler, eq. C.9)

        f_0 = sum_k (0X_k)^T (I_k a_k + v_k x_f I_k v_k),
        a_k = X_k a_{k-1} + S_k q_ddot_k + c_k,   a_{-1} = [omega_dot_B; a_hub],
        omega_dot_B = S(Theta) Theta_ddot + S_dot(Theta) Theta_dot,
        a_hub = R_NB^T r_ddot_N,

    with (0X_k)^T the force transform from segment k's frame to segment 0's; the
    segments carry no other applied load (a generalized force Q on a chain coordinate
    is a joint actuation, internal to the chain but at the root, where it is in f_0
    through the accelerations). On the hub acts -X_0^T f_0. Its components along the
    root's motion subspace are the joint's generalized forces, S_0^T f_0 = Q_0 - K_0 q_0
    - C_0 q_dot_0 (the joint's equation of motion); the other components are the
    constraint reaction of the directions the joint does not free. On a full 6-DOF root
    S_0 is invertible and f_0 = S_0^-T (Q_0 - K_0 q_0 - C_0 q_dot_0), the plate's
    (F_M, N_P). The constraint forces of coordinates the engine locks are in q_ddot too,
    so ``Q`` is not read. One outward pass, each segment's force moved straight to the
    hub centre of mass: O(N), nothing allocated.

    Parameters
    ----------
    q, qd : ndarray, shape (n_dof,)
        Generalized coordinates [m, rad] and rates [m/s, rad/s] of the whole plant.
    qdd : ndarray, shape (n_dof,)
        Generalized accelerations of the whole plant at (q, qd) [m/s^2, rad/s^2].
    Q : ndarray, shape (n_dof,)
        External generalized forces [N, N m per coordinate]; not read (above).
    members : ndarray, shape (k, 2), int64
        Per chain: appendage index and offset of its first coordinate in q [-].
    params : ndarray, shape (k, p)
        Per chain: its packed row (``HEADER`` then the segments' ``G_*`` slots) [SI].
    out : ndarray, shape (6,)
        The hub wrench, added to: force [N] and torque about the hub centre of mass
        [N m], hub frame B.

    Returns
    -------
    int
        ``STATUS_OK`` or a joint gimbal-lock status.
    """
    phi, theta = q[3], q[4]
    omega_B = mv(euler_rate_matrix(phi, theta), load_seg(qd, 3))
    alpha_B = add(mv(euler_rate_matrix(phi, theta), load_seg(qdd, 3)),
                  euler_rate_bias(phi, theta, qd[3], qd[4], qd[5]))  # fmt: skip
    a_hub_B = mtv(rot_zyx(phi, theta, q[5]), load_seg(qdd, 0))
    for j in range(members.shape[0]):
        o = members[j, 1]
        p = params[j]
        va, vl, aa, al = omega_B, _ZERO, alpha_B, a_hub_B
        R_BP = ((1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0))
        r_O = _ZERO
        n_B, f_B = _ZERO, _ZERO
        for k in range(int(p[H_N])):
            g = HEADER + k * SEG
            R, pos, R_JP, S_rho, va, vl, aa, al, status = _outward(
                q, qd, o, p, g, k == 0, va, vl, aa, al
            )
            if status != STATUS_OK:
                return status
            t_dd, rho_dd = _joint_values(qdd, o, p, g)  # S_k q_ddot_k
            aa, al = add(aa, mv(S_rho, rho_dd)), add(al, mtv(R_JP, t_dd))
            fn, ff = _body_force(p, g, va, vl, aa, al)
            r_O = add(r_O, mv(R_BP, pos))
            R_BP = mm(R_BP, R)
            f = mv(R_BP, ff)
            f_B = add(f_B, f)
            n_B = add(n_B, add(mv(R_BP, fn), cross(r_O, f)))
        for r in range(3):
            out[r] -= f_B[r]
            out[3 + r] -= n_B[r]
    return STATUS_OK


@njit(cache=True, error_model="numpy")  # compiled with TIPS_SIGNATURE on first use
def tips(q, members, params, out):
    """Displacement of each chain's free end from its undeformed place, mount frame [m].

    Parameters
    ----------
    q : ndarray, shape (n_dof,)
        Generalized coordinates of the whole plant [m, rad].
    members : ndarray, shape (k, 2), int64
        Per chain: appendage index and offset of its first coordinate in q [-].
    params : ndarray, shape (k, p)
        Per chain: its packed row (``HEADER`` then the segments' ``G_*`` slots) [SI].
    out : ndarray, shape (n_appendages, 3)
        Output: one row per appendage, the chains' rows written [m].
    """
    for j in range(members.shape[0]):
        o = members[j, 1]
        p = params[j]
        R_BP = ((1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0))
        r_O = _ZERO
        for k in range(int(p[H_N])):
            R, pos, R_JP, S_rho, ja, jl, ca, cl, status = _joint_pose(
                q, q, o, p, HEADER + k * SEG, k == 0
            )
            r_O = add(r_O, mv(R_BP, pos))
            R_BP = mm(R_BP, R)
        r_tip = add(r_O, mv(R_BP, load_seg(p, H_TIP)))
        moved = sub(mtv(load_m33_at(p, H_R_BM), sub(r_tip, load_seg(p, H_MOUNT))),
                    load_seg(p, H_TIP0))  # fmt: skip
        i = members[j, 0]
        out[i, 0], out[i, 1], out[i, 2] = moved
