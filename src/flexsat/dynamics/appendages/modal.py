"""Modal (hybrid-coordinate) appendage: a rigid body plus n interface-clamped modes.

An appendage given by its modal data (:mod:`flexsat.config.modal_data`): its rigid
mass properties about the interface point and n mass-normalized modes of the
structure clamped there, each with frequency omega_k, damping ratio zeta_k and
participation factors l_k = (l_t,k, l_r,k) at the interface. The interface is rigidly
fixed to the hub at the mount point r_m (frame M = R_BM, as for the plate).

Coordinates: the modal coordinates eta_k [sqrt(kg) m], one per mode.

Kinetic energy (docs/model.md, "Modal appendages"), v the interface velocity and
omega the hub rate, both in B, c~ = m c + L_t^T eta the first moment about the
interface::

    T = 1/2 m v.v + v.(omega x c~) + 1/2 omega.J_I omega
        + eta_dot^T (L_t v + L_r omega) + 1/2 eta_dot^T eta_dot
    U = 1/2 sum_k omega_k^2 eta_k^2,   2 D = sum_k 2 zeta_k omega_k eta_dot_k^2

Its equations (Euler-Poincare for the hub, Lagrange for eta)::

    eta_ddot_k = f_k - l_t,k . a_I - l_r,k . alpha
    f_k = Q_k - omega_k^2 eta_k - 2 zeta_k omega_k eta_dot_k
    F_a = m a_I + alpha x c~ + omega x (omega x c~) + 2 omega x s_dot + L_t^T eta_ddot
    N_a = c~ x a_I + J_I alpha + omega x J_I omega + omega x (L_r^T eta_dot) + L_r^T eta_ddot

with a_I = a_hub + alpha x r_m + omega x (omega x r_m) the interface acceleration and
(F_a, N_a) the wrench the hub exerts on the appendage at the interface. Eliminating
eta_ddot leaves the residual mass M_rr(c~) - L^T L at the interface: the articulated
inertia this model transmits to the hub. The hub receives -F_a and, about its centre
of mass, -(N_a + r_m x F_a) at the plant's accelerations: tau_flex, the whole interface
load (:func:`joint_wrench`). Every sum is over the modes once: cost is linear in n.

On a solar-array drive (the config's ``drive`` and ``drive_axis``) the interface frame
turns about the axis u through I by the drive angle alpha, coordinate 0 (named
``drive_angle``): the body's equations above hold in that floating frame F with omega
replaced by Omega = omega + alpha_dot u, the rotor (mass on the axis at I, inertia J_r)
is part of its rigid body, and the drive equation u . N_a = tau (tau the generalized
force on alpha, the ``sadm_drive`` motor) is eliminated as one more articulated-body
step; the hub receives the whole wrench, the motor's reaction included (docs/model.md,
'Modal appendage on a drive', eqs. D.1-D.8).
"""

from __future__ import annotations

from math import cos, sin
from pathlib import Path
from typing import Annotated, Any, ClassVar, Literal

import numpy as np
from numba import njit
from pydantic import (
    AllowInfNan,
    BaseModel,
    ConfigDict,
    Field,
    Strict,
    model_validator,
)

from flexsat.compiled.linalg3 import (
    add,
    add_block,
    cross,
    dot,
    euler_rate_bias,
    euler_rate_matrix,
    load_block33,
    load_m33_at,
    load_seg,
    mm,
    mtm,
    mtv,
    mv,
    rot_zyx,
    scale,
    skew,
    sub,
    transpose,
)
from flexsat.compiled.status import STATUS_OK
from flexsat.config.modal_data import ModalData, load_modal_data
from flexsat.config.models import Angle, DriveConfig, Matrix3, Name, Point3
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

__all__ = ["DRIVE_COORDINATE", "ModalAppendageConfig", "ModalModel"]

# Packed parameter row of one modal appendage (everything in hub frame B unless noted).
P_MOUNT = 0  # (3) r_m, interface point from the hub centre of mass [m]
P_R_BM = 3  # (9) R_BM, mount frame M -> B, row-major
P_MASS = 12  # (1) m [kg]
P_FIRST = 13  # (3) m c, first moment about the interface [kg m]
P_J_I = 16  # (9) J_I, inertia about the interface point [kg m^2]
P_RES = 25  # (36) M_rr - L^T L at eta = 0, about the interface, row-major 6 x 6
P_N = 61  # (1) number of modes n
P_DAMP_AT = 62  # (1) offset of the n x n modal damping matrix [1/s]; 0: diagonal (MODE_C)
P_SECOND_AT = 63  # (1) offset of the (SO_SIZE n) x n matrix A (large motion); 0: none
# On a solar-array drive (docs/model.md, 'Modal appendage on a drive'): coordinate 0 is
# the drive angle alpha, the modes follow; every slot above is then in the floating
# frame F (the data's frame M turned by alpha about the axis), the rotor included in
# P_MASS, P_J_I and P_RES, and P_R_BM is R_BM0, the mount at alpha = 0.
P_DRIVE = 64  # (1) 1: on a drive, 0: rigidly mounted
P_AXIS = 65  # (3) drive axis u, a unit vector, frame F (= frame M) [-]
P_ALPHA0 = 68  # (1) the drive's initial angle alpha(0) [rad]
P_MODES = 69  # n blocks of MODE_SIZE
MODE_K = 0  # omega_k^2 [1/s^2]
MODE_C = 1  # 2 zeta_k omega_k [1/s]
MODE_LT = 2  # (3) l_t,k [sqrt(kg)]
MODE_LR = 5  # (3) l_r,k [sqrt(kg) m]
MODE_TIP = 8  # (3) tip mode-shape row, frame M [m / (sqrt(kg) m)]
MODE_DJ = 11  # (9) J'_k = dJ_I / d eta_k, B, row-major [sqrt(kg) m]
MODE_SIZE = 20
# The large-motion invariants, frame B, as one row-major matrix A of SO_SIZE n rows and
# n columns: A[r n + k, l] is component r of mode pair (k, l), so that the rows that
# meet eta (J'', C, E) and those that meet eta_dot (C, E, E^T) hold every mode's sums
# over l in two matrix-vector products (BLAS): 21 n^2 multiply-adds (docs/model.md,
# 'Large motion').
SO_J = 0  # (6) J''_kl = d^2 J_I / d eta_k d eta_l, symmetric: xx, yy, zz, xy, xz, yz [-]
SO_C = 6  # (3) C_kl = d^2 c~ / d eta_k d eta_l [1/m]
SO_E = 9  # (3) E_kl = d h_k / d eta_l [-]
SO_ET = 12  # (3) E_lk [-]
SO_SIZE = 15
SO_ETA = 12  # rows r < SO_ETA of A are multiplied by eta
SO_RATE = 9  # rows r >= SO_C of A (SO_RATE of them) are multiplied by eta_dot
WORK_MODE = 7  # per mode in pass 1's scratch: L_t,k(eta) (3), h_k(eta) (3), its force (1)
# after those n WORK_MODE columns: A[:SO_ETA n] eta, then A[SO_C n:] eta_dot
# On a drive, DRIVE_WORK more columns after those (at 0 for the first-order model):
WD_R = 0  # (9) R_BF(alpha), row-major
WD_MS = 9  # (6) M_I S = [B u; D u], frame F
WD_CJ = 15  # (6) c_J = [w x (w x r); alpha_dot w x u], frame F
WD_K = 21  # (1) tau - u . (M_I c_J + b)_rot [N m]
WD_D = 22  # (1) d = u . D u [kg m^2]
DRIVE_WORK = 23
DRIVE_COORDINATE = "drive_angle"
"""Name of a modal appendage's drive angle alpha [rad] (coordinate 0 on a drive)."""

Scale = Annotated[float, Strict(), AllowInfNan(False), Field(gt=0.0, le=1e3)]


class ModalAppendageConfig(BaseModel):
    """An appendage given by its interface-clamped modal data (hybrid coordinates).

    Give the data inline (``data``, a table of the modal data format) or as a file
    (``file``, ``.toml`` or ``.npz``; in a satellite TOML file a relative path is
    relative to that file's folder, :func:`flexsat.config.load.load_config`). The
    mount frame is the hub frame rotated by ``mount_yaw_deg`` about Z_B and then
    ``sadm_angle_deg`` about Y, as for the plate; the data's frame M is it.
    The ``*_scale`` factors are campaign handles on every mode at once. With ``drive``
    the appendage turns about ``drive_axis`` (frame M, through the interface point)
    by the drive angle, a generalized coordinate starting at ``sadm_angle_deg``, and the
    mount is ``mount_yaw_deg`` (or ``mount_matrix``) alone (docs/model.md, 'Modal
    appendage on a drive').
    """

    model_config = ConfigDict(frozen=True, extra="forbid", validate_default=True)

    name: Name = Field(description="unique name of the appendage")
    model: Literal["modal"] = Field("modal", description="appendage model (registry key)")
    mount_point_m: Point3 = Field(description="interface point from hub centre of mass, B [m]")
    mount_yaw_deg: Angle = Field(0.0, description="mount frame rotation about Z_B [deg]")
    sadm_angle_deg: Angle = Field(0.0, description="SADM angle about Y_M [deg]")
    mount_matrix: Matrix3 | None = Field(
        None, description="R_BM (mount -> hub) [-], instead of the two angles"
    )
    file: str | None = Field(None, description="modal data file (.toml or .npz)")
    data: ModalData | None = Field(None, description="modal data (the file's content)")
    frequency_scale: Scale = Field(1.0, description="factor on every modal frequency [-]")
    damping_scale: Scale = Field(1.0, description="factor on every damping ratio [-]")
    participation_scale: Scale = Field(1.0, description="factor on every participation [-]")
    drive: DriveConfig | None = Field(
        None, description="put the appendage on a solar-array drive turning it about "
        "drive_axis; sadm_angle_deg is then the drive's initial angle"
    )  # fmt: skip
    drive_axis: Point3 | None = Field(
        None, description="the drive's axis through the interface point, frame M (the "
        "data's frame), any nonzero length [-]"
    )  # fmt: skip

    @model_validator(mode="before")
    @classmethod
    def _read_file(cls, value: Any) -> Any:
        if isinstance(value, dict) and value.get("file") is not None and value.get("data") is None:
            value = {**value, "data": load_modal_data(Path(value["file"])).model_dump()}
        return value

    @model_validator(mode="after")
    def _scaled_valid(self) -> ModalAppendageConfig:
        if self.mount_matrix is not None:
            if self.mount_yaw_deg or self.sadm_angle_deg:
                raise ValueError("give either mount_yaw_deg/sadm_angle_deg or mount_matrix")
            R = np.array(self.mount_matrix, dtype=float)
            if not np.allclose(R @ R.T, np.eye(3), atol=1e-9) or np.linalg.det(R) < 0.0:
                raise ValueError("mount_matrix must be a rotation (orthonormal, det +1)")
        if self.data is None:
            raise ValueError("give the modal data: file = '<path>' or a data table")
        if self.drive is None and self.drive_axis is not None:
            raise ValueError("drive_axis: only an appendage on a drive (its drive key) takes "
                             "a drive axis")  # fmt: skip
        if self.drive is not None:
            if self.drive_axis is None:
                raise ValueError(
                    "drive_axis: a modal appendage on a drive needs its axis, a "
                    "nonzero vector in the data's frame M (e.g. [0, 1, 0]) [-]"
                )
            if float(np.linalg.norm(self.drive_axis)) < 1e-9:
                raise ValueError(f"drive_axis: the drive axis must be a nonzero vector "
                                 f"(norm >= 1e-9, got {list(self.drive_axis)})")  # fmt: skip
        self.modal()  # the scaled data must be valid too (effective masses, damping)
        return self

    def modal(self) -> ModalData:
        """The modal data with the campaign scale factors applied."""
        d = self.data
        unscaled = (self.frequency_scale, self.damping_scale, self.participation_scale)
        if unscaled == (1.0, 1.0, 1.0):
            return d
        p = self.participation_scale
        # A full damping matrix (2 zeta omega off the diagonal too) follows both factors.
        c = self.damping_scale * self.frequency_scale
        return ModalData.model_validate({
            **d.model_dump(),
            "frequencies_hz": [f * self.frequency_scale for f in d.frequencies_hz],
            "damping_ratios": [z * self.damping_scale for z in d.damping_ratios],
            "participation": [[p * x for x in row] for row in d.participation],
            "damping_matrix": [[c * x for x in row] for row in d.damping_matrix],
        })  # fmt: skip

    def mount_rotation(self) -> np.ndarray:
        """R_BM: ``mount_matrix``, else Rz(yaw) Ry(sadm) (intrinsic Z then Y, as for the
        plate), shape (3, 3); on a drive, R_BM0 Rot(u, alpha(0)) (:meth:`drive_mount`)."""
        from scipy.spatial.transform import Rotation  # here: scipy.spatial costs 0.25 s to import

        if self.drive is not None:
            R0, u, alpha = self.drive_mount()
            return R0 @ Rotation.from_rotvec(alpha * u).as_matrix()
        if self.mount_matrix is not None:
            return np.array(self.mount_matrix, dtype=float)
        angles = np.radians([self.mount_yaw_deg, self.sadm_angle_deg])
        return Rotation.from_euler("ZY", angles).as_matrix()

    def drive_mount(self) -> tuple[np.ndarray, np.ndarray, float]:
        """On a drive: R_BM0 (3, 3), the mount at drive angle 0 (``mount_matrix``, else
        Rz(yaw)); the unit axis u (3,), frame M; the initial angle alpha(0) [rad]."""
        from scipy.spatial.transform import Rotation  # here: scipy.spatial costs 0.25 s to import

        if self.mount_matrix is not None:
            R0 = np.array(self.mount_matrix, dtype=float)
        else:
            R0 = Rotation.from_euler("Z", np.radians(self.mount_yaw_deg)).as_matrix()
        u = np.asarray(self.drive_axis, dtype=float)
        return R0, u / np.linalg.norm(u), float(np.radians(self.sadm_angle_deg))

    def tip(self) -> int | None:
        """Index of the output point called 'tip', else the first one; None: no points."""
        points = self.data.output_points
        names = [pt.name for pt in points]
        return names.index("tip") if "tip" in names else (0 if points else None)


@njit(cache=True, error_model="numpy")
def _modal_sums(q, qd, o, p):
    """s = L_t^T eta [kg m], s_dot = L_t^T eta_dot and h_r = L_r^T eta_dot (B)."""
    s, s_dot, h_r = (0.0, 0.0, 0.0), (0.0, 0.0, 0.0), (0.0, 0.0, 0.0)
    for k in range(int(p[P_N])):
        b = P_MODES + MODE_SIZE * k
        l_t, l_r = load_seg(p, b + MODE_LT), load_seg(p, b + MODE_LR)
        s = add(s, scale(q[o + k], l_t))
        s_dot = add(s_dot, scale(qd[o + k], l_t))
        h_r = add(h_r, scale(qd[o + k], l_r))
    return s, s_dot, h_r


@njit(cache=True, error_model="numpy")
def _madd(a, b, s):
    """a + s b for 3 x 3 matrices."""
    return (add(a[0], scale(s, b[0])), add(a[1], scale(s, b[1])), add(a[2], scale(s, b[2])))


@njit(cache=True, error_model="numpy")
def _outer(a, b):
    """a b^T for 3-vectors."""
    return (scale(a[0], b), scale(a[1], b), scale(a[2], b))


@njit(cache=True, error_model="numpy")
def _add_inertia(hub, r0, c0, A):
    for a in range(3):
        for b in range(3):
            hub[HUB_INERTIA + 6 * (r0 + a) + c0 + b] += A[a][b]


@njit(cache=True, error_model="numpy")
def _inertia(q, qd, o, p):
    """J(eta) = J_I + sum_k eta_k J'_k and its rate sum_k eta_dot_k J'_k (B)."""
    J, J_dot = load_m33_at(p, P_J_I), ((0.0, 0.0, 0.0), (0.0, 0.0, 0.0), (0.0, 0.0, 0.0))
    for k in range(int(p[P_N])):
        dJ = load_m33_at(p, P_MODES + MODE_SIZE * k + MODE_DJ)
        J = _madd(J, dJ, q[o + k])
        J_dot = _madd(J_dot, dJ, qd[o + k])
    return J, J_dot


@njit(cache=True, error_model="numpy")
def _centrifugal(p, k, omega):
    """1/2 omega^T J'_k omega: the centrifugal generalized force on mode k (-dT/d eta_k)."""
    return 0.5 * dot(omega, mv(load_m33_at(p, P_MODES + MODE_SIZE * k + MODE_DJ), omega))


@njit(cache=True, error_model="numpy")
def _mode_rows(q, qd, o, p, k):
    """Mode k's rows at eta (large motion): L_t,k(eta) = l_t,k + sum_l C_kl eta_l,
    h_k(eta) = l_r,k + sum_l E_kl eta_l, J_k(eta) = J'_k + sum_l J''_kl eta_l, and
    sum_l C_kl eta_dot_l, sum_l E_kl eta_dot_l, sum_l E_lk eta_dot_l (B)."""
    n = int(p[P_N])
    b = P_MODES + MODE_SIZE * k
    l_t, h, J_k = load_seg(p, b + MODE_LT), load_seg(p, b + MODE_LR), load_m33_at(p, b + MODE_DJ)
    c_d, e_d, et_d = (0.0, 0.0, 0.0), (0.0, 0.0, 0.0), (0.0, 0.0, 0.0)
    at, nn = int(p[P_SECOND_AT]) + n * k, n * n  # A[r n + k, l] = p[at + r n^2 + l]
    for m in range(n):
        e, e_dot = q[o + m], qd[o + m]
        c = at + m
        C = (p[c + SO_C * nn], p[c + (SO_C + 1) * nn], p[c + (SO_C + 2) * nn])
        E = (p[c + SO_E * nn], p[c + (SO_E + 1) * nn], p[c + (SO_E + 2) * nn])
        ET = (p[c + SO_ET * nn], p[c + (SO_ET + 1) * nn], p[c + (SO_ET + 2) * nn])
        c = at + m + SO_J * nn
        J2 = _symmetric(p[c], p[c + nn], p[c + 2 * nn], p[c + 3 * nn], p[c + 4 * nn],
                        p[c + 5 * nn])  # fmt: skip
        l_t = add(l_t, scale(e, C))
        h = add(h, scale(e, E))
        c_d = add(c_d, scale(e_dot, C))
        e_d = add(e_d, scale(e_dot, E))
        et_d = add(et_d, scale(e_dot, ET))
        J_k = _madd(J_k, J2, e)
    return l_t, h, J_k, c_d, e_d, et_d


@njit(cache=True, error_model="numpy")
def _symmetric(xx, yy, zz, xy, xz, yz):
    """The symmetric 3 x 3 matrix of six distinct entries."""
    return ((xx, xy, xz), (xy, yy, yz), (xz, yz, zz))


@njit(cache=True, error_model="numpy")
def _rows_at(p, k, ye, e0, es, yd, d0, ds):
    """Mode k's rows from the products y_e = A[:SO_ETA n] eta (entry r at ye[e0 + r es])
    and y_d = A[SO_C n:] eta_dot (entry r at yd[d0 + (r - SO_C) ds]): see
    :func:`_mode_rows`."""
    b = P_MODES + MODE_SIZE * k
    l_t, h, J_k = load_seg(p, b + MODE_LT), load_seg(p, b + MODE_LR), load_m33_at(p, b + MODE_DJ)
    c, e, t = d0, d0 + (SO_E - SO_C) * ds, d0 + (SO_ET - SO_C) * ds
    c_d = (yd[c], yd[c + ds], yd[c + 2 * ds])
    e_d = (yd[e], yd[e + ds], yd[e + 2 * ds])
    et_d = (yd[t], yd[t + ds], yd[t + 2 * ds])
    l_t = add(l_t, (ye[e0 + SO_C * es], ye[e0 + (SO_C + 1) * es], ye[e0 + (SO_C + 2) * es]))
    h = add(h, (ye[e0 + SO_E * es], ye[e0 + (SO_E + 1) * es], ye[e0 + (SO_E + 2) * es]))
    j = e0 + SO_J * es
    J2 = _symmetric(ye[j], ye[j + es], ye[j + 2 * es], ye[j + 3 * es], ye[j + 4 * es],
                    ye[j + 5 * es])  # fmt: skip
    return l_t, h, _madd(J_k, J2, 1.0), c_d, e_d, et_d


@njit(cache=True, error_model="numpy")
def _second_sums(q, qd, o, p, omega, work, j, store):
    """The sums of the large-motion model (docs/model.md, eqs. M.8-M.10), B:
    s = c~ - m c = sum_k eta_k (l_t,k + L_t,k(eta)) / 2, s_dot = sum_k eta_dot_k
    L_t,k(eta), h_r = sum_k eta_dot_k h_k(eta), J(eta) = J_I + sum_k eta_k (J'_k +
    J_k(eta)) / 2, J_dot = sum_k eta_dot_k J_k(eta), and the velocity-quadratic terms
    eta_dot^T C eta_dot and eta_dot^T E eta_dot. With ``store``, row ``j`` of ``work``
    keeps each mode's L_t,k(eta), h_k(eta) and its inertia force
    1/2 omega^T J_k(eta) omega - sum_l (E_kl - E_lk) . omega eta_dot_l."""
    z = (0.0, 0.0, 0.0)
    s, s_dot, h_r, quad_t, quad_r = z, z, z, z, z
    J, J_dot = load_m33_at(p, P_J_I), (z, z, z)
    n = int(p[P_N])
    w0 = WORK_MODE * n
    ye = work[j, w0 : w0 + SO_ETA * n]
    yd = work[j, w0 + SO_ETA * n : w0 + (SO_ETA + SO_RATE) * n]
    if store:  # A[:SO_ETA n] eta and A[SO_C n:] eta_dot into the scratch, by BLAS
        at = int(p[P_SECOND_AT])
        A = p[at : at + SO_SIZE * n * n].reshape((SO_SIZE * n, n))
        np.dot(A[: SO_ETA * n], q[o : o + n], ye)
        np.dot(A[SO_C * n :], qd[o : o + n], yd)
    for k in range(n):
        b = P_MODES + MODE_SIZE * k
        if store:
            l_t, h, J_k, c_d, e_d, et_d = _rows_at(p, k, ye, k, n, yd, k, n)
        else:
            l_t, h, J_k, c_d, e_d, et_d = _mode_rows(q, qd, o, p, k)
        e, e_dot = q[o + k], qd[o + k]
        s = add(s, scale(0.5 * e, add(load_seg(p, b + MODE_LT), l_t)))
        J = _madd(_madd(J, load_m33_at(p, b + MODE_DJ), 0.5 * e), J_k, 0.5 * e)
        s_dot = add(s_dot, scale(e_dot, l_t))
        h_r = add(h_r, scale(e_dot, h))
        J_dot = _madd(J_dot, J_k, e_dot)
        quad_t = add(quad_t, scale(e_dot, c_d))
        quad_r = add(quad_r, scale(e_dot, e_d))
        if store:
            w = WORK_MODE * k
            for a in range(3):
                work[j, w + a] = l_t[a]
                work[j, w + 3 + a] = h[a]
            work[j, w + 6] = 0.5 * dot(omega, mv(J_k, omega)) - dot(sub(e_d, et_d), omega)
    return s, s_dot, h_r, J, J_dot, quad_t, quad_r


@njit(cache=True, error_model="numpy")
def _sums(q, qd, o, p, omega, work, j, store):
    """s, s_dot, h_r, J(eta), J_dot and the velocity-quadratic terms (zero for the
    first-order model, whose sums are :func:`_modal_sums` and :func:`_inertia`)."""
    if p[P_SECOND_AT] > 0.0:
        return _second_sums(q, qd, o, p, omega, work, j, store)
    s, s_dot, h_r = _modal_sums(q, qd, o, p)
    J, J_dot = _inertia(q, qd, o, p)
    z = (0.0, 0.0, 0.0)
    return s, s_dot, h_r, J, J_dot, z, z


@njit(cache=True, error_model="numpy")
def _mode(q, qd, o, p, k, omega):
    """Mode k's L_t,k(eta), h_k(eta) and its inertia force beyond -L_t,k . a_I -
    h_k . alpha: 1/2 omega^T J'_k omega (first order), with the large-motion terms
    1/2 omega^T J_k(eta) omega - sum_l (E_kl - E_lk) . omega eta_dot_l."""
    b = P_MODES + MODE_SIZE * k
    if p[P_SECOND_AT] > 0.0:
        l_t, h, J_k, _, e_d, et_d = _mode_rows(q, qd, o, p, k)
        return l_t, h, 0.5 * dot(omega, mv(J_k, omega)) - dot(sub(e_d, et_d), omega)
    return load_seg(p, b + MODE_LT), load_seg(p, b + MODE_LR), _centrifugal(p, k, omega)


@njit(cache=True, error_model="numpy")
def _damping(qd, o, p, k):
    """Mode k's damping force: 2 zeta_k omega_k eta_dot_k, or row k of the full modal
    damping matrix times eta_dot."""
    at = int(p[P_DAMP_AT])
    if at == 0:
        return p[P_MODES + MODE_SIZE * k + MODE_C] * qd[o + k]
    n = int(p[P_N])
    f = 0.0
    for m in range(n):
        f += p[at + n * k + m] * qd[o + m]
    return f


@njit(cache=True, error_model="numpy")
def _inertia_about_hub(p, J, r, c1):
    """Inertia about the hub centre of mass (at -r from the interface) of a body with
    inertia J about the interface and first moment c1 there:
    J - m [r]x [r]x - [r]x [c1]x - [c1]x [r]x (parallel axes)."""
    R, C = skew(r), skew(c1)
    J = _madd(J, mm(R, R), -p[P_MASS])
    return _madd(_madd(J, mm(R, C), -1.0), mm(C, R), -1.0)


_I3 = ((1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0))


@njit(cache=True, error_model="numpy")
def _drive_rotation(p, alpha):
    """R_BF(alpha) = R_BM0 Rot(u, alpha), Rot(u, a) = I + sin a [u]x + (1 - cos a) [u]x^2
    (eq. D.1): the floating frame F of an appendage on a drive, F -> B."""
    U = skew(load_seg(p, P_AXIS))
    turn = _madd(_madd(_I3, U, sin(alpha)), mm(U, U), 1.0 - cos(alpha))
    return mm(load_m33_at(p, P_R_BM), turn)


@njit(cache=True, error_model="numpy")
def _drive_work(p):
    """First scratch column of the drive's entries (after the large-motion ones)."""
    return (WORK_MODE + SO_ETA + SO_RATE) * int(p[P_N]) if p[P_SECOND_AT] > 0.0 else 0


@njit(cache=True, error_model="numpy")
def _driven_pass1(q, qd, Q, o, p, work, j, hub, qdd, omega):
    """Pass 1 of a member on a drive (eqs. D.2-D.6), everything in F until the wrench.

    The body's equations are the rigid mount's in its floating frame F (rate
    Omega = w + alpha_dot u, w the hub rate in F): W_a = M_I A_F + b. With A_F =
    X A_hub + S alpha_ddot + c_J, S = [0; u], and the drive equation S^T W_a = tau,
    alpha_ddot = (k - (M_I S) . X A_hub) / d, k = tau - S^T (M_I c_J + b), d = u . D u,
    and the hub sees the articulated inertia M_I - (M_I S)(M_I S)^T / d and the wrench
    M_I c_J + b + M_I S k / d, both turned to B by R_BF."""
    o1 = o + 1
    u, r = load_seg(p, P_AXIS), load_seg(p, P_MOUNT)
    R = _drive_rotation(p, q[o])
    w = mtv(R, omega)
    Om = add(w, scale(qd[o], u))  # eq. D.2
    s, s_dot, h_r, J, J_dot, quad_t, quad_r = _sums(q, qd, o1, p, Om, work, j, True)
    g_t, g_r, d_tt, d_tr, d_rr = _modal_forces(q, qd, Q, o1, p, work, j, hub, qdd, Om)
    c1 = add(load_seg(p, P_FIRST), s)
    A, B, C, D = _interface_inertia(p, s, J, d_tt, d_tr, d_rr)
    # b: the wrench at a_I = 0, Omega_dot = 0 (eq. D.3), then y = M_I c_J + b.
    F = add(add(cross(Om, cross(Om, c1)), scale(2.0, cross(Om, s_dot))), add(g_t, quad_t))
    N = add(add(cross(Om, mv(J, Om)), cross(Om, h_r)), add(g_r, quad_r))
    N = add(N, mv(J_dot, Om))
    c_l = mtv(R, cross(omega, cross(omega, r)))
    c_a = scale(qd[o], cross(w, u))
    F = add(add(F, mv(A, c_l)), mv(B, c_a))
    N = add(add(N, mv(C, c_l)), mv(D, c_a))
    ms_l, ms_a = mv(B, u), mv(D, u)  # M_I S
    d = dot(u, ms_a)
    k = Q[o] - dot(u, N)  # eq. D.5
    F, N = add(F, scale(k / d, ms_l)), add(N, scale(k / d, ms_a))  # eq. D.6
    A = _madd(A, _outer(ms_l, ms_l), -1.0 / d)
    B = _madd(B, _outer(ms_l, ms_a), -1.0 / d)
    C = _madd(C, _outer(ms_a, ms_l), -1.0 / d)
    D = _madd(D, _outer(ms_a, ms_a), -1.0 / d)
    F, N = mv(R, F), mv(R, N)
    T = add(N, cross(r, F))
    for a in range(3):
        hub[HUB_FORCE + a] -= F[a]
        hub[HUB_TORQUE + a] -= T[a]
    Rt = transpose(R)
    _add_articulated(hub, r, mm(R, mm(A, Rt)), mm(R, mm(B, Rt)), mm(R, mm(C, Rt)),
                     mm(R, mm(D, Rt)))  # fmt: skip
    at = _drive_work(p)
    for a in range(3):
        for b in range(3):
            work[j, at + WD_R + 3 * a + b] = R[a][b]
        work[j, at + WD_MS + a] = ms_l[a]
        work[j, at + WD_MS + 3 + a] = ms_a[a]
        work[j, at + WD_CJ + a] = c_l[a]
        work[j, at + WD_CJ + 3 + a] = c_a[a]
    work[j, at + WD_K] = k
    work[j, at + WD_D] = d


@njit(cache=True, error_model="numpy")
def _driven_pass2(o, p, work, j, qdd, a_hub, alpha):
    """alpha_ddot (eq. D.5), then eta_ddot_k = f_k - L_t,k . a_I - h_k . Omega_dot in F,
    a_I and Omega_dot the interface's and the frame's accelerations (eq. D.4)."""
    o1 = o + 1
    at = _drive_work(p)
    u, r = load_seg(p, P_AXIS), load_seg(p, P_MOUNT)
    R = load_m33_at(work[j], at + WD_R)
    z_l, z_a = mtv(R, add(a_hub, cross(alpha, r))), mtv(R, alpha)
    ms_l, ms_a = load_seg(work[j], at + WD_MS), load_seg(work[j], at + WD_MS + 3)
    acc = (work[j, at + WD_K] - dot(ms_l, z_l) - dot(ms_a, z_a)) / work[j, at + WD_D]
    qdd[o] = acc
    a_I = add(z_l, load_seg(work[j], at + WD_CJ))
    Om_dot = add(add(z_a, scale(acc, u)), load_seg(work[j], at + WD_CJ + 3))
    second = p[P_SECOND_AT] > 0.0
    for k in range(int(p[P_N])):
        if second:
            w = WORK_MODE * k
            l_t = (work[j, w], work[j, w + 1], work[j, w + 2])
            l_r = (work[j, w + 3], work[j, w + 4], work[j, w + 5])
        else:
            b = P_MODES + MODE_SIZE * k
            l_t, l_r = load_seg(p, b + MODE_LT), load_seg(p, b + MODE_LR)
        qdd[o1 + k] -= dot(l_t, a_I) + dot(l_r, Om_dot)


@njit(cache=True, error_model="numpy")
def _driven_mass_matrix(q, o, p, params, j, M, R_NB, S):
    """A driven member's share of M(q): T = 1/2 V^T M_body V + eta_dot^T L V + 1/2
    eta_dot^T eta_dot with V = [v_I; Omega] = G q_dot in F (eq. D.7), column by column."""
    o1, n = o + 1, int(p[P_N])
    m, r, u = p[P_MASS], load_seg(p, P_MOUNT), load_seg(p, P_AXIS)
    R = _drive_rotation(p, q[o])
    s, _, _, J, _, _, _ = _sums(q, q, o1, p, _I3[0], params, j, False)
    c1 = add(load_seg(p, P_FIRST), s)
    E = mm(R_NB, R)  # F -> N: row i is the velocity r_dot_N,i in F
    G_a = transpose(mtm(R, S))  # row i: R^T S e_i
    G_l = transpose(mtm(R, mm(skew(r), S)))  # row i: R^T [r]x S e_i
    z = (0.0, 0.0, 0.0)
    lin = (E[0], E[1], E[2], scale(-1.0, G_l[0]), scale(-1.0, G_l[1]), scale(-1.0, G_l[2]), z)
    ang = (z, z, z, G_a[0], G_a[1], G_a[2], u)
    for a in range(7):
        ia = a if a < 6 else o
        f_l = add(scale(m, lin[a]), cross(ang[a], c1))
        f_a = add(cross(c1, lin[a]), mv(J, ang[a]))
        for b in range(7):
            ib = b if b < 6 else o
            M[ia, ib] += dot(lin[b], f_l) + dot(ang[b], f_a)
    for k in range(n):
        l_t, l_r, _ = _mode(q, q, o1, p, k, _I3[0])
        for a in range(7):
            ia = a if a < 6 else o
            v = dot(l_t, lin[a]) + dot(l_r, ang[a])
            M[o1 + k, ia] += v
            M[ia, o1 + k] += v
        M[o1 + k, o1 + k] += 1.0


@njit(cache=True, error_model="numpy")
def _driven_wrench(q, qd, o, p, omega, alpha, a_hub, acc, params, j, g, with_g):
    """The wrench (F_a, N_a) on a driven member at its interface, frame F (eq. D.3 with
    A_F of eq. D.4), the hub's omega, alpha = omega_dot and a_hub in B, acc the drive's
    alpha_ddot; ``g`` the plant's q_ddot when ``with_g`` (else the modes' are zero);
    also R_BF, a_I, Omega and Omega_dot (F)."""
    o1 = o + 1
    u, r = load_seg(p, P_AXIS), load_seg(p, P_MOUNT)
    R = _drive_rotation(p, q[o])
    w = mtv(R, omega)
    Om = add(w, scale(qd[o], u))
    a_I = mtv(R, add(add(a_hub, cross(alpha, r)), cross(omega, cross(omega, r))))
    Om_dot = add(add(mtv(R, alpha), scale(acc, u)), scale(qd[o], cross(w, u)))
    s, s_dot, h_r, J, J_dot, quad_t, quad_r = _sums(q, qd, o1, p, Om, params, j, False)
    c1 = add(load_seg(p, P_FIRST), s)
    F = add(add(scale(p[P_MASS], a_I), cross(Om_dot, c1)), cross(Om, cross(Om, c1)))
    F = add(add(F, scale(2.0, cross(Om, s_dot))), quad_t)
    N = add(add(cross(c1, a_I), mv(J, Om_dot)), mv(J_dot, Om))
    N = add(add(add(N, cross(Om, mv(J, Om))), cross(Om, h_r)), quad_r)
    if with_g:
        for k in range(int(p[P_N])):
            l_t, l_r, _ = _mode(q, qd, o1, p, k, Om)
            F = add(F, scale(g[o1 + k], l_t))
            N = add(N, scale(g[o1 + k], l_r))
    return F, N, R, a_I, Om, Om_dot


@njit(cache=True, error_model="numpy")
def _driven_bias(q, qd, o, p, params, j, omega, alpha, R_NB, hub, h):
    """A driven member's share of h(q, q_dot): its inertia forces at q_ddot = 0 (alpha =
    S_dot Theta_dot, alpha_ddot = 0); the drive row is u . N_a (eq. D.5)."""
    o1, r, u = o + 1, load_seg(p, P_MOUNT), load_seg(p, P_AXIS)
    F, N, R, a_I, Om, Om_dot = _driven_wrench(q, qd, o, p, omega, alpha, (0.0, 0.0, 0.0),
                                              0.0, params, j, h, False)  # fmt: skip
    h[o] = dot(u, N)
    F_B = mv(R, F)
    F_N = mv(R_NB, F_B)
    T = add(mv(R, N), cross(r, F_B))
    for a in range(3):
        hub[HUB_FORCE + a] += F_N[a]
        hub[HUB_TORQUE + a] += T[a]
    full_damping = p[P_DAMP_AT] > 0.0
    for k in range(int(p[P_N])):
        b = P_MODES + MODE_SIZE * k
        l_t, l_r, force = _mode(q, qd, o1, p, k, Om)
        h[o1 + k] = dot(l_t, a_I) + dot(l_r, Om_dot) - force
        if full_damping:
            h[o1 + k] += _damping(qd, o1, p, k) - p[b + MODE_C] * qd[o1 + k]


@njit(cache=True, error_model="numpy")
def _driven_observe(q, qd, o, p, params, j, omega, v_hub, r_hub, R_NB, out):
    """A driven member's T, momentum, locked inertia, U and 2 D (eq. D.8): the rigid
    mount's in F with Omega = w + alpha_dot u, turned to B and N."""
    o1, m, r, u = o + 1, p[P_MASS], load_seg(p, P_MOUNT), load_seg(p, P_AXIS)
    R = _drive_rotation(p, q[o])
    Om = add(mtv(R, omega), scale(qd[o], u))
    v = mtv(R, add(v_hub, cross(omega, r)))
    s, s_dot, h_r, J, _, _, _ = _sums(q, qd, o1, p, Om, params, j, False)
    c1 = add(load_seg(p, P_FIRST), s)
    kinetic = 0.5 * m * dot(v, v) + dot(v, cross(Om, c1)) + 0.5 * dot(Om, mv(J, Om))
    kinetic += dot(v, s_dot) + dot(Om, h_r)
    for k in range(int(p[P_N])):
        b = P_MODES + MODE_SIZE * k
        kinetic += 0.5 * qd[o1 + k] ** 2
        out[OBS_ELASTIC] += 0.5 * p[b + MODE_K] * q[o1 + k] ** 2
        if p[P_DAMP_AT] > 0.0:
            out[OBS_DISSIPATION] += _damping(qd, o1, p, k) * qd[o1 + k]
        else:
            out[OBS_DISSIPATION] += p[b + MODE_C] * qd[o1 + k] ** 2
    out[OBS_KINETIC] += kinetic
    P = add(add(scale(m, v), cross(Om, c1)), s_dot)
    H_I = add(add(cross(c1, v), mv(J, Om)), h_r)
    E = mm(R_NB, R)
    H = add(cross(add(r_hub, mv(R_NB, r)), mv(E, P)), mv(E, H_I))
    J_O = _inertia_about_hub(p, mm(R, mm(J, transpose(R))), r, mv(R, c1))
    for a in range(3):
        out[OBS_MOMENTUM + a] += H[a]
        for b in range(3):
            out[OBS_LOCKED_INERTIA + 3 * a + b] += J_O[a][b]


@njit(cache=True, error_model="numpy")
def _modal_forces(q, qd, Q, o, p, work, j, hub, qdd, omega):
    """Each mode's force f_k (eq. M.4 without its acceleration terms) into ``qdd[o + k]``,
    the damper power into ``hub``; returns g_t = sum_k f_k L_t,k(eta), g_r = sum_k f_k
    h_k(eta) and L(eta)^T L(eta) - L^T L (zero for the first-order model), blocks tt, tr,
    rr. ``o`` is the first mode's index in q, ``omega`` the floating frame's rate."""
    z3 = (0.0, 0.0, 0.0)
    second, full_damping = p[P_SECOND_AT] > 0.0, p[P_DAMP_AT] > 0.0
    g_t, g_r = z3, z3
    d_tt, d_tr, d_rr = (z3, z3, z3), (z3, z3, z3), (z3, z3, z3)  # L(eta)^T L(eta) - L^T L
    for k in range(int(p[P_N])):
        b = P_MODES + MODE_SIZE * k
        damping = _damping(qd, o, p, k)
        f = Q[o + k] - p[b + MODE_K] * q[o + k] - damping
        if second:
            w = WORK_MODE * k
            l_t = (work[j, w], work[j, w + 1], work[j, w + 2])
            l_r = (work[j, w + 3], work[j, w + 4], work[j, w + 5])
            f += work[j, w + 6]
            t0, r0 = load_seg(p, b + MODE_LT), load_seg(p, b + MODE_LR)
            d_tt = _madd(_madd(d_tt, _outer(l_t, l_t), 1.0), _outer(t0, t0), -1.0)
            d_tr = _madd(_madd(d_tr, _outer(l_t, l_r), 1.0), _outer(t0, r0), -1.0)
            d_rr = _madd(_madd(d_rr, _outer(l_r, l_r), 1.0), _outer(r0, r0), -1.0)
        else:
            l_t, l_r = load_seg(p, b + MODE_LT), load_seg(p, b + MODE_LR)
            f += _centrifugal(p, k, omega)
        qdd[o + k] = f
        g_t = add(g_t, scale(f, l_t))
        g_r = add(g_r, scale(f, l_r))
        if full_damping:
            hub[HUB_DISSIPATION] += damping * qd[o + k]
        else:
            hub[HUB_DISSIPATION] += p[b + MODE_C] * qd[o + k] ** 2  # eq. 2.36
    return g_t, g_r, d_tt, d_tr, d_rr


@njit(cache=True, error_model="numpy")
def _interface_inertia(p, s, J, d_tt, d_tr, d_rr):
    """M_I = [[A, B], [C, D]] = M_res + [[0, -[s]x], [[s]x, J(eta) - J_I]] about I, minus
    L(eta)^T L(eta) - L^T L when the modes' rows follow eta (large motion)."""
    S = skew(s)
    A = load_block33(p, P_RES, 0, 0)
    D = _madd(_madd(load_block33(p, P_RES, 3, 3), J, 1.0), load_m33_at(p, P_J_I), -1.0)
    B = _madd(load_block33(p, P_RES, 0, 3), S, -1.0)
    C = _madd(load_block33(p, P_RES, 3, 0), S, 1.0)
    if p[P_SECOND_AT] > 0.0:  # the modes' rows follow eta: M_res - (L(eta)^T L(eta) - L^T L)
        A, B, D = _madd(A, d_tt, -1.0), _madd(B, d_tr, -1.0), _madd(D, d_rr, -1.0)
        C = _madd(C, transpose(d_tr), -1.0)
    return A, B, C, D


@njit(cache=True, error_model="numpy")
def _add_articulated(hub, r, A, B, C, D):
    """Add X^T M_I X with X = [[I, -[r]x], [0, I]] to the hub's 6 x 6 inertia:
    [[A, B - A R], [R A + C, R (B - A R) + D - C R]], R = [r]x."""
    R = skew(r)
    top_right = _madd(B, mm(A, R), -1.0)
    _add_inertia(hub, 0, 0, A)
    _add_inertia(hub, 0, 3, top_right)
    _add_inertia(hub, 3, 0, _madd(C, mm(R, A), 1.0))
    _add_inertia(hub, 3, 3, _madd(_madd(D, mm(R, top_right), 1.0), mm(C, R), -1.0))


@njit(cache=True, error_model="numpy")  # compiled with PASS1_SIGNATURE on first use
def pass1(q, qd, Q, members, params, work, hub, qdd):
    """Wrench on the hub at zero hub acceleration and the articulated inertia X^T M_I X.

    Leaves the modal forces f_k in the member's rows of ``qdd`` for :func:`pass2`; a
    member on a drive eliminates its drive angle too (:func:`_driven_pass1`).
    """
    omega = load_seg(hub, HUB_OMEGA)
    for j in range(members.shape[0]):
        o, p = members[j, 1], params[j]
        if p[P_DRIVE] > 0.0:
            _driven_pass1(q, qd, Q, o, p, work, j, hub, qdd, omega)
            continue
        r = load_seg(p, P_MOUNT)
        s, s_dot, h_r, J, J_dot, quad_t, quad_r = _sums(q, qd, o, p, omega, work, j, True)
        g_t, g_r, d_tt, d_tr, d_rr = _modal_forces(q, qd, Q, o, p, work, j, hub, qdd, omega)
        c1 = add(load_seg(p, P_FIRST), s)  # c~ = m c + L_t^T eta (+ 1/2 eta^T C eta)
        A, B, C, D = _interface_inertia(p, s, J, d_tt, d_tr, d_rr)
        # Wrench on the appendage at a_hub = 0, alpha = 0: M_I [w x (w x r); 0] + b_a.
        w2r = cross(omega, cross(omega, r))
        F = add(add(cross(omega, cross(omega, c1)), scale(2.0, cross(omega, s_dot))), g_t)
        F = add(add(F, mv(A, w2r)), quad_t)
        N = add(add(cross(omega, mv(J, omega)), cross(omega, h_r)), g_r)
        N = add(add(add(N, mv(C, w2r)), mv(J_dot, omega)), quad_r)
        T = add(N, cross(r, F))
        for a in range(3):
            hub[HUB_FORCE + a] -= F[a]
            hub[HUB_TORQUE + a] -= T[a]
        _add_articulated(hub, r, A, B, C, D)
    return STATUS_OK


@njit(cache=True, error_model="numpy")  # compiled with PASS2_SIGNATURE on first use
def pass2(q, qd, members, params, work, hub, qdd):
    """eta_ddot_k = f_k - l_t,k . a_I - l_r,k . alpha, a_I the interface acceleration."""
    omega = load_seg(hub, HUB_OMEGA)
    a_hub = load_seg(hub, HUB_ACC)
    alpha = load_seg(hub, HUB_ALPHA)
    for j in range(members.shape[0]):
        o, p = members[j, 1], params[j]
        if p[P_DRIVE] > 0.0:
            _driven_pass2(o, p, work, j, qdd, a_hub, alpha)
            continue
        r = load_seg(p, P_MOUNT)
        a_I = add(add(a_hub, cross(alpha, r)), cross(omega, cross(omega, r)))
        if p[P_SECOND_AT] > 0.0:  # the rows at eta, left by pass 1
            for k in range(int(p[P_N])):
                w = WORK_MODE * k
                qdd[o + k] -= dot((work[j, w], work[j, w + 1], work[j, w + 2]), a_I) + dot(
                    (work[j, w + 3], work[j, w + 4], work[j, w + 5]), alpha
                )
            continue
        for k in range(int(p[P_N])):
            b = P_MODES + MODE_SIZE * k
            qdd[o + k] -= dot(load_seg(p, b + MODE_LT), a_I) + dot(load_seg(p, b + MODE_LR), alpha)
    return STATUS_OK


@njit(cache=True, error_model="numpy")  # compiled with MASS_SIGNATURE on first use
def mass_matrix(q, members, params, M):
    """The modal appendages' share of M(q), from T with v = R_BN r_dot - [r]x S Theta_dot
    and omega = S Theta_dot (module notes)."""
    R_NB = rot_zyx(q[3], q[4], q[5])
    S = euler_rate_matrix(q[3], q[4])
    identity = ((1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0))
    for j in range(members.shape[0]):
        o, p = members[j, 1], params[j]
        if p[P_DRIVE] > 0.0:
            _driven_mass_matrix(q, o, p, params, j, M, R_NB, S)
            continue
        m, r = p[P_MASS], load_seg(p, P_MOUNT)
        s, _, _, J, _, _, _ = _sums(q, q, o, p, identity[0], params, j, False)
        c1 = add(load_seg(p, P_FIRST), s)
        first_hub = add(scale(m, r), c1)  # first moment about the hub centre of mass
        add_block(M, 0, 0, identity, m)
        add_block(M, 0, 3, mm(R_NB, mm(skew(first_hub), S)), -1.0)
        add_block(M, 3, 3, mtm(S, mm(_inertia_about_hub(p, J, r, c1), S)), 1.0)
        for k in range(int(p[P_N])):
            l_t, l_r, _ = _mode(q, q, o, p, k, identity[0])
            row_r = mv(R_NB, l_t)
            row_theta = mtv(S, add(cross(r, l_t), l_r))
            for a in range(3):
                M[o + k, a] += row_r[a]
                M[a, o + k] += row_r[a]
                M[o + k, 3 + a] += row_theta[a]
                M[3 + a, o + k] += row_theta[a]
            M[o + k, o + k] += 1.0


@njit(cache=True, error_model="numpy")  # compiled with BIAS_SIGNATURE on first use
def bias_forces(q, qd, members, params, hub, h):
    """The modal appendages' share of h(q, q_dot): their inertia forces at q_ddot = 0
    (a_hub = 0, alpha = S_dot Theta_dot, eta_ddot = 0)."""
    R_NB = rot_zyx(q[3], q[4], q[5])
    omega = load_seg(hub, HUB_OMEGA)
    alpha = load_seg(hub, HUB_SBIAS)
    for j in range(members.shape[0]):
        o, p = members[j, 1], params[j]
        if p[P_DRIVE] > 0.0:
            _driven_bias(q, qd, o, p, params, j, omega, alpha, R_NB, hub, h)
            continue
        m, r = p[P_MASS], load_seg(p, P_MOUNT)
        s, s_dot, h_r, J, J_dot, quad_t, quad_r = _sums(q, qd, o, p, omega, params, j, False)
        c1 = add(load_seg(p, P_FIRST), s)
        a_I = add(cross(alpha, r), cross(omega, cross(omega, r)))
        F = add(
            add(scale(m, a_I), cross(alpha, c1)),
            add(cross(omega, cross(omega, c1)), scale(2.0, cross(omega, s_dot))),
        )
        N = add(add(add(cross(c1, a_I), mv(J, alpha)), mv(J_dot, omega)),
                add(cross(omega, mv(J, omega)), cross(omega, h_r)))  # fmt: skip
        F, N = add(F, quad_t), add(N, quad_r)
        F_N = mv(R_NB, F)
        T = add(N, cross(r, F))
        for a in range(3):
            hub[HUB_FORCE + a] += F_N[a]
            hub[HUB_TORQUE + a] += T[a]
        full_damping = p[P_DAMP_AT] > 0.0
        for k in range(int(p[P_N])):
            b = P_MODES + MODE_SIZE * k
            l_t, l_r, force = _mode(q, qd, o, p, k, omega)
            h[o + k] = dot(l_t, a_I) + dot(l_r, alpha) - force
            if full_damping:  # the diagonal is in C_damp; the rest is held here
                h[o + k] += _damping(qd, o, p, k) - p[b + MODE_C] * qd[o + k]


@njit(cache=True, error_model="numpy")  # compiled with OBSERVE_SIGNATURE on first use
def observe(q, qd, members, params, out):
    """Kinetic energy T, momentum about the inertial origin, locked inertia, U and 2 D."""
    R_NB = rot_zyx(q[3], q[4], q[5])
    omega = mv(euler_rate_matrix(q[3], q[4]), load_seg(qd, 3))
    v_hub = mtv(R_NB, load_seg(qd, 0))
    r_hub = load_seg(q, 0)
    for j in range(members.shape[0]):
        o, p = members[j, 1], params[j]
        if p[P_DRIVE] > 0.0:
            _driven_observe(q, qd, o, p, params, j, omega, v_hub, r_hub, R_NB, out)
            continue
        m, r = p[P_MASS], load_seg(p, P_MOUNT)
        s, s_dot, h_r, J, _, _, _ = _sums(q, qd, o, p, omega, params, j, False)
        c1 = add(load_seg(p, P_FIRST), s)
        v = add(v_hub, cross(omega, r))
        kinetic = 0.5 * m * dot(v, v) + dot(v, cross(omega, c1)) + 0.5 * dot(omega, mv(J, omega))
        kinetic += dot(v, s_dot) + dot(omega, h_r)
        for k in range(int(p[P_N])):
            b = P_MODES + MODE_SIZE * k
            kinetic += 0.5 * qd[o + k] ** 2
            out[OBS_ELASTIC] += 0.5 * p[b + MODE_K] * q[o + k] ** 2
            if p[P_DAMP_AT] > 0.0:
                out[OBS_DISSIPATION] += _damping(qd, o, p, k) * qd[o + k]
            else:
                out[OBS_DISSIPATION] += p[b + MODE_C] * qd[o + k] ** 2
        out[OBS_KINETIC] += kinetic
        # Momentum at the interface: P = m v + omega x c~ + s_dot, H_I = c~ x v + J_I omega
        # + h_r; about the inertial origin: p_I x P + H_I (frame N).
        P = add(add(scale(m, v), cross(omega, c1)), s_dot)
        H_I = add(add(cross(c1, v), mv(J, omega)), h_r)
        p_I = add(r_hub, mv(R_NB, r))
        H = add(cross(p_I, mv(R_NB, P)), mv(R_NB, H_I))
        J_O = _inertia_about_hub(p, J, r, c1)
        for a in range(3):
            out[OBS_MOMENTUM + a] += H[a]
            for b in range(3):
                out[OBS_LOCKED_INERTIA + 3 * a + b] += J_O[a][b]


@njit(cache=True, error_model="numpy")  # compiled with WRENCH_SIGNATURE on first use
def joint_wrench(q, qd, qdd, Q, members, params, out):
    """Add the whole wrench each modal appendage's interface exerts on the hub (eq. M.7).

    The hub moves the appendage through its interface I, so the wrench (F_a, N_a) the
    hub exerts on it there is what it needs to move as it does (eqs. M.5-M.6, at the
    plant's accelerations)::

        F_a = m a_I + alpha x c~ + omega x (omega x c~) + 2 omega x s_dot + L_t^T eta_ddot
        N_a = c~ x a_I + J alpha + J_dot omega + omega x J omega + omega x L_r^T eta_dot
              + L_r^T eta_ddot
        a_I = a_hub + alpha x r_m + omega x (omega x r_m),
        alpha = S(Theta) Theta_ddot + S_dot(Theta) Theta_dot,   a_hub = R_NB^T r_ddot_N,

    and the hub receives -F_a and, about its centre of mass, -(N_a + r_m x F_a): the
    modes' elastic, damping and external forces (the eta_ddot terms hold them, eq. M.4)
    and the inertia of the residual mass M_rr - L^T L, which a truncated mode set does
    not carry. ``Q`` is not read: its effect (joint actuation, the constraint forces of
    coordinates the engine locks) is in ``qdd``. One pass over the modes, nothing
    allocated.

    Parameters
    ----------
    q, qd : ndarray, shape (n_dof,)
        Generalized coordinates [m, rad, sqrt(kg) m] and rates of the whole plant.
    qdd : ndarray, shape (n_dof,)
        Generalized accelerations of the whole plant at (q, qd), hub rows included.
    Q : ndarray, shape (n_dof,)
        External generalized forces [N, N m, sqrt(kg) m/s^2 per coordinate]; not read.
    members : ndarray, shape (k, 2), int64
        Per appendage: appendage index and offset of its first coordinate in q [-].
    params : ndarray, shape (k, p)
        Per appendage: its packed row (``P_*`` slots) [SI].
    out : ndarray, shape (6,)
        The hub wrench, added to: force [N] and torque about the hub centre of mass
        [N m], hub frame B.

    Returns
    -------
    int
        ``STATUS_OK``.
    """
    phi, theta = q[3], q[4]
    omega = mv(euler_rate_matrix(phi, theta), load_seg(qd, 3))
    alpha = add(mv(euler_rate_matrix(phi, theta), load_seg(qdd, 3)),
                euler_rate_bias(phi, theta, qd[3], qd[4], qd[5]))  # fmt: skip
    a_hub = mtv(rot_zyx(phi, theta, q[5]), load_seg(qdd, 0))
    for j in range(members.shape[0]):
        o, p = members[j, 1], params[j]
        r = load_seg(p, P_MOUNT)
        if p[P_DRIVE] > 0.0:  # eq. D.3 at the plant's accelerations, turned to B
            F, N, R, _, _, _ = _driven_wrench(q, qd, o, p, omega, alpha, a_hub, qdd[o],
                                              params, j, qdd, True)  # fmt: skip
            F = mv(R, F)
            T = add(mv(R, N), cross(r, F))
            for a in range(3):
                out[a] -= F[a]
                out[3 + a] -= T[a]
            continue
        s, s_dot, h_r, J, J_dot, quad_t, quad_r = _sums(q, qd, o, p, omega, params, j, False)
        c1 = add(load_seg(p, P_FIRST), s)  # c~ = m c + L_t^T eta (+ 1/2 eta^T C eta)
        a_I = add(add(a_hub, cross(alpha, r)), cross(omega, cross(omega, r)))
        g_t, g_r = (0.0, 0.0, 0.0), (0.0, 0.0, 0.0)  # L_t^T eta_ddot, L_r^T eta_ddot
        for k in range(int(p[P_N])):
            l_t, l_r, _ = _mode(q, qd, o, p, k, omega)
            g_t = add(g_t, scale(qdd[o + k], l_t))
            g_r = add(g_r, scale(qdd[o + k], l_r))
        F = add(add(scale(p[P_MASS], a_I), cross(alpha, c1)), cross(omega, cross(omega, c1)))
        F = add(add(add(F, scale(2.0, cross(omega, s_dot))), g_t), quad_t)
        N = add(add(cross(c1, a_I), mv(J, alpha)), mv(J_dot, omega))
        N = add(add(add(N, cross(omega, mv(J, omega))), add(cross(omega, h_r), g_r)), quad_r)
        T = add(N, cross(r, F))
        for a in range(3):
            out[a] -= F[a]
            out[3 + a] -= T[a]
    return STATUS_OK


@njit(cache=True, error_model="numpy")  # compiled with TIPS_SIGNATURE on first use
def tips(q, members, params, out):
    """Tip displacement sum_k psi_tip,k eta_k, mount frame [m]."""
    for j in range(members.shape[0]):
        o, p = members[j, 1], params[j]
        o += int(p[P_DRIVE])  # the modes follow a drive's angle
        d = (0.0, 0.0, 0.0)
        for k in range(int(p[P_N])):
            d = add(d, scale(q[o + k], load_seg(p, P_MODES + MODE_SIZE * k + MODE_TIP)))
        i = members[j, 0]
        out[i, 0], out[i, 1], out[i, 2] = d


def _set_damping_ratio(table: dict, ratio: float) -> None:
    """Campaign path ``appendages[*].damping_ratio`` on a modal appendage: the damping
    ratio of every mode (``damping_scale`` back to 1), as the plate's ``damping_ratio``
    sets its joints'. The data is in the table once the config is validated (a file's
    content is read into ``data``); a full damping matrix gives way to the diagonal."""
    if table.get("data") is None:
        raise KeyError("damping_ratio: the modal data is not in the config (validate it first)")
    table["data"]["damping_ratios"] = [ratio] * len(table["data"]["damping_ratios"])
    table["data"]["damping_matrix"] = []  # every mode that ratio: diagonal damping
    table["damping_scale"] = 1.0


class ModalModel(AppendageModel):
    """A hybrid-coordinate appendage (:class:`ModalAppendageConfig`) rigidly mounted."""

    name = "modal"
    config_class = ModalAppendageConfig
    kernels = AppendageKernels(pass1, pass2, mass_matrix, bias_forces, observe, joint_wrench, tips)
    transmits_inertia = True
    holds_drive = True
    modifiers: ClassVar[dict] = {
        "damping_ratio": DerivedPath(_set_damping_ratio, ops=("set",), factor=False),
    }

    def coordinates(self, config: ModalAppendageConfig) -> tuple[Coordinate, ...]:
        drive = (Coordinate(DRIVE_COORDINATE, "rad"),) if config.drive is not None else ()
        modes = tuple(Coordinate(f"q{k + 1}", "kg^0.5 m") for k in range(config.data.n_modes))
        return drive + modes

    def pack(self, config: ModalAppendageConfig) -> np.ndarray:
        data = config.modal()
        n = data.n_modes
        row = np.zeros(P_MODES + MODE_SIZE * n)
        rotor_mass, rotor_inertia = 0.0, 0.0
        if config.drive is None:
            R = config.mount_rotation()
            row[P_R_BM : P_R_BM + 9] = R.ravel()
        else:  # everything in the floating frame F, the rotor part of the body (eq. D.1)
            R0, u, alpha0 = config.drive_mount()
            R = np.eye(3)
            row[P_R_BM : P_R_BM + 9] = R0.ravel()
            row[P_DRIVE], row[P_AXIS : P_AXIS + 3], row[P_ALPHA0] = 1.0, u, alpha0
            rotor_mass = config.drive.rotor_mass_kg
            rotor_inertia = config.drive.rotor_inertia_kg_m2
        R6 = np.kron(np.eye(2), R)
        L_M = data.participation_matrix()
        row[P_MOUNT : P_MOUNT + 3] = config.mount_point_m
        row[P_MASS] = data.mass_kg + rotor_mass
        row[P_FIRST : P_FIRST + 3] = data.mass_kg * R @ np.asarray(data.center_of_mass_m)
        J_I = R @ np.asarray(data.inertia_interface_kg_m2) @ R.T + rotor_inertia * np.eye(3)
        row[P_J_I : P_J_I + 9] = J_I.ravel()
        rotor = np.diag([rotor_mass] * 3 + [rotor_inertia] * 3)
        residual = data.rigid_mass_matrix() - L_M.T @ L_M
        row[P_RES : P_RES + 36] = (R6 @ residual @ R6.T + rotor).ravel()
        row[P_N] = n
        omega = 2.0 * np.pi * np.asarray(data.frequencies_hz, dtype=float)
        modes = row[P_MODES:].reshape(n, MODE_SIZE)
        modes[:, MODE_K] = omega**2
        modes[:, MODE_C] = 2.0 * np.asarray(data.damping_ratios, dtype=float) * omega
        modes[:, MODE_LT : MODE_LT + 3] = L_M[:, :3] @ R.T
        modes[:, MODE_LR : MODE_LR + 3] = L_M[:, 3:] @ R.T
        tip = config.tip()
        if tip is not None:
            modes[:, MODE_TIP : MODE_TIP + 3] = data.output_points[tip].mode_shapes
        modes[:, MODE_DJ : MODE_DJ + 9] = (R @ data.inertia_derivative_array() @ R.T).reshape(n, 9)
        blocks = [row]
        at = row.size
        if data.damping_matrix:
            row[P_DAMP_AT] = at
            blocks.append(data.damping_matrix_array().ravel())
            at += n * n
        if data.second_order:
            row[P_SECOND_AT] = at
            pairs = np.zeros((n, n, SO_SIZE))  # [k, l, r], packed as A[r n + k, l]
            C, E = data.first_moment_hessian_array(), data.coupling_gradient_array()
            pairs[:, :, SO_C : SO_C + 3] = C @ R.T
            pairs[:, :, SO_E : SO_E + 3] = E @ R.T
            pairs[:, :, SO_ET : SO_ET + 3] = (E @ R.T).transpose(1, 0, 2)
            J2 = R @ data.inertia_hessian_array() @ R.T
            J2 = 0.5 * (J2 + J2.transpose(0, 1, 3, 2))  # symmetric: its six entries
            rows, cols = (0, 1, 2, 0, 0, 1), (0, 1, 2, 1, 2, 2)  # xx, yy, zz, xy, xz, yz
            pairs[:, :, SO_J : SO_J + 6] = J2[:, :, rows, cols]
            blocks.append(pairs.transpose(2, 0, 1).ravel())
        return np.concatenate(blocks) if len(blocks) > 1 else row

    def work_columns(self, params: np.ndarray) -> int:
        # Pass 1 leaves each mode's rows at eta for pass 2 when the large-motion terms
        # are on, after the products A eta and A eta_dot.
        n = int(params[P_N])
        columns = (WORK_MODE + SO_ETA + SO_RATE) * n if params[P_SECOND_AT] > 0.0 else 0
        return columns + (DRIVE_WORK if params[P_DRIVE] > 0.0 else 0)

    @staticmethod
    def _modes(params: np.ndarray) -> np.ndarray:
        n = int(params[P_N])
        return params[P_MODES : P_MODES + MODE_SIZE * n].reshape(n, MODE_SIZE)

    @staticmethod
    def _frame(params: np.ndarray, alpha: float | None = None) -> np.ndarray:
        """R_BF, the frame of the packed invariants -> B, shape (3, 3): identity when
        rigidly mounted (they are packed in B), R_BM0 Rot(u, alpha) on a drive (eq. D.1;
        ``alpha`` default its initial angle)."""
        from scipy.spatial.transform import Rotation  # here: scipy.spatial costs 0.25 s to import

        if params[P_DRIVE] == 0.0:
            return np.eye(3)
        alpha = params[P_ALPHA0] if alpha is None else alpha
        turn = Rotation.from_rotvec(alpha * params[P_AXIS : P_AXIS + 3]).as_matrix()
        return params[P_R_BM : P_R_BM + 9].reshape(3, 3) @ turn

    def rigid_body(self, params: np.ndarray) -> RigidBody:
        m = float(params[P_MASS])
        c = params[P_FIRST : P_FIRST + 3] / m
        C = np.array(skew(tuple(c)))
        J_cm = params[P_J_I : P_J_I + 9].reshape(3, 3) + m * C @ C
        R = self._frame(params)
        return RigidBody(m, params[P_MOUNT : P_MOUNT + 3] + R @ c, R @ J_cm @ R.T)

    def rigid_body_at(self, params: np.ndarray, q_block: np.ndarray) -> RigidBody:
        drive = int(params[P_DRIVE])
        if np.any(q_block[drive:]):
            raise ValueError("the 'modal' model freezes only undeformed (modal coordinates 0)")
        if not drive:
            return self.rigid_body(params)
        frozen = params.copy()
        frozen[P_ALPHA0] = q_block[0]
        return self.rigid_body(frozen)

    def stiffness(self, params: np.ndarray) -> np.ndarray:
        return np.concatenate([np.zeros(int(params[P_DRIVE])), self._modes(params)[:, MODE_K]])

    def damping(self, params: np.ndarray) -> np.ndarray:
        return np.concatenate([np.zeros(int(params[P_DRIVE])), self._modes(params)[:, MODE_C]])

    def damping_block(self, params: np.ndarray) -> np.ndarray:
        block = np.diag(self.damping(params))
        at, n, drive = int(params[P_DAMP_AT]), int(params[P_N]), int(params[P_DRIVE])
        if at:  # the full modal damping matrix (its off-diagonal terms are in _damping)
            block[drive:, drive:] = params[at : at + n * n].reshape(n, n)
        return block

    def with_joints(self, params: np.ndarray, stiffness: np.ndarray, damping: np.ndarray
                    ) -> np.ndarray:  # fmt: skip
        drive = int(params[P_DRIVE])
        stiffness, damping = np.asarray(stiffness, float), np.asarray(damping, float)
        if drive and (stiffness[0] != 0.0 or damping[0] != 0.0):
            raise ValueError("a modal appendage's drive angle has no stiffness or damping (its "
                             "motor is the sadm_drive joint actuator)")  # fmt: skip
        row = params.copy()
        modes = self._modes(row)
        modes[:, MODE_K] = stiffness[drive:]
        modes[:, MODE_C] = damping[drive:]
        return row

    def default_state(self, config: ModalAppendageConfig) -> tuple[np.ndarray, np.ndarray]:
        q, qd = super().default_state(config)
        if config.drive is not None:
            q[0] = config.drive_mount()[2]
        return q, qd

    def describe(self, config: ModalAppendageConfig, params: np.ndarray) -> dict:
        data = config.modal()
        described = {
            "mass_kg": data.mass_kg,
            "n_modes": data.n_modes,
            "frequencies_hz": list(data.frequencies_hz),
            "damping_ratios": list(data.damping_ratios),
        }
        if config.drive is not None:
            described["drive_axis_M"] = config.drive_mount()[1].tolist()
        return described

    def shape_points(self, config: ModalAppendageConfig, params: np.ndarray,
                     q_block: np.ndarray) -> np.ndarray:  # fmt: skip
        # A segment from the interface to the tip output point (deformed), drawn as a
        # degenerate outline; without output points, from the interface to twice the
        # centre of mass.
        drive = int(params[P_DRIVE])
        if drive:
            R = self._frame(params, float(q_block[0]))
            q_block = q_block[1:]
        else:
            R = params[P_R_BM : P_R_BM + 9].reshape(3, 3)
        root = params[P_MOUNT : P_MOUNT + 3]
        tip = config.tip()
        if tip is None:
            end = root + 2.0 * R @ np.asarray(config.data.center_of_mass_m)
        else:
            point = config.data.output_points[tip]
            rows = self._modes(params)[:, MODE_TIP : MODE_TIP + 3]
            moved = np.asarray(point.position_m) + rows.T @ q_block
            end = root + R @ moved
        return np.array([root, root, end, end, root, end])

    def extent(self, config: ModalAppendageConfig) -> float:
        tip = config.tip()
        if tip is None:
            return 2.0 * float(np.linalg.norm(config.data.center_of_mass_m))
        return float(np.linalg.norm(config.data.output_points[tip].position_m))

    @staticmethod
    def mount_rotation(params: np.ndarray) -> np.ndarray:
        """R_BM of a packed row, shape (3, 3); on a drive, at its initial angle."""
        if params[P_DRIVE] > 0.0:
            return ModalModel._frame(params)
        return params[P_R_BM : P_R_BM + 9].reshape(3, 3)

    def mode_kinds(self, config: ModalAppendageConfig) -> tuple[str, ...]:
        drive = (DRIVE_COORDINATE,) if config.drive is not None else ()
        return drive + tuple(f"mode_{k + 1}" for k in range(config.data.n_modes))
