"""Singularity-free hub attitude: ZYX Euler angles relative to a switching reference frame.

The integrated hub attitude stays the thesis's ZYX Euler angles Theta = q[3:6], so the
state layout, M(q), h(q, q_dot) and every kernel are unchanged, but Theta is measured
from a reference frame F that the integrator holds, ``frame`` = R_NF (row-major, 9
floats, F components to inertial N components)::

    R_NB = R_NF R_FB(Theta),   R_FB(Theta) = Rz(psi) Ry(theta) Rx(phi)   (eq. 2.25)

and the hub position and velocity q[0:3], q_dot[0:3] are F components. Between two
steps, when the pitch coordinate leaves +-``SWITCH_PITCH`` (60 deg),
:func:`rebase` moves F onto the hub's current body frame: R_NF <- R_NF R_FB(Theta),
Theta <- 0, Theta_dot <- S(0)^-1 omega_B = omega_B (eq. 2.28), r_F and v_F rotated
into the new F. This is the Euler-angle analogue of switching MRPs: the coordinates
never come closer to their singularity than 60 deg pitch, whatever the motion.

The change is exact, not an approximation: F is a constant rotation of N about its
origin between switches, the plant has no gravity and every external load is either a
body torque (frame B) or zero in the inertial frame, so the equations of motion are
the same in F as in N. Energies, body rates, joint states and tip displacements do not
depend on F; positions, velocities and angular momenta map to N by R_NF. A run whose
pitch never leaves +-60 deg never switches: R_NF stays the identity and the run is
bit-for-bit the same as without the frame. See docs/model.md, 'Attitude
parametrization'.
"""

from __future__ import annotations

import warnings
from math import atan2, hypot, pi

import numpy as np
from numba import njit

from flexsat.compiled.linalg3 import (
    copy_into,
    euler_rate_matrix,
    euler_rate_matrix_inv,
    load_m33_at,
    load_seg,
    mm,
    mtv,
    mv,
    rot_zyx,
)

__all__ = [
    "SWITCH_PITCH",
    "euler_zyx",
    "identity_frame",
    "inertial_records",
    "inertial_view",
    "is_identity",
    "rebase",
    "vectors_to_inertial",
]

SWITCH_PITCH = pi / 3.0
"""Re-base the attitude when ‖pitch‖ > 60 deg [rad]: far enough from the singularity
that ‖cos(pitch)‖ >= 0.5 (S(Theta)^-1 stays well conditioned), far enough from the
thesis's slews (pitch up to 45 deg) that they never switch. A test on the coordinate
itself, not on cos(pitch): the pitch coordinate grows continuously from 0 after each
re-base, so an adaptive solver's event on it cannot be stepped over."""


def identity_frame() -> np.ndarray:
    """R_NF = I as the flat (9,) array the integrators hold."""
    return np.eye(3).ravel()


@njit(cache=True, error_model="numpy")
def is_identity(frame):
    """True if ``frame`` is exactly the identity (the run has not switched).

    Parameters
    ----------
    frame : ndarray, shape (9,)
        R_NF, row-major [-].

    Returns
    -------
    bool
        Whether R_NF = I exactly.
    """
    return frame[0] == 1.0 and frame[4] == 1.0 and frame[8] == 1.0


@njit(cache=True, error_model="numpy")
def euler_zyx(R):
    """ZYX Euler angles of a rotation matrix.

    The inverse of :func:`flexsat.compiled.linalg3.rot_zyx`, with theta in
    [-pi/2, pi/2]; at theta = +-pi/2 only phi - psi (or phi + psi) is defined.

    Parameters
    ----------
    R : tuple of 3 rows of 3 float
        The rotation matrix, child to parent components [-].

    Returns
    -------
    phi, theta, psi : float
        Roll, pitch and yaw [rad].
    """
    theta = atan2(-R[2][0], hypot(R[0][0], R[1][0]))
    return atan2(R[2][1], R[2][2]), theta, atan2(R[1][0], R[0][0])


@njit(cache=True, error_model="numpy")
def _store_m33(a, R):
    for r in range(3):
        for c in range(3):
            a[3 * r + c] = R[r][c]


@njit(cache=True, error_model="numpy")
def rebase(x, n_dof, frame, threshold=SWITCH_PITCH):
    """Move the reference frame onto the hub's body frame if ‖pitch‖ > ``threshold``.

    Parameters
    ----------
    x : ndarray, shape (2 n_dof + 2,)
        Augmented state [q, q_dot, W_in, W_diss] relative to F; re-based in place.
    n_dof : int
        Number of generalized coordinates.
    frame : ndarray, shape (9,)
        R_NF, row-major [-]; updated in place.
    threshold : float
        ``SWITCH_PITCH`` [rad]; an adaptive solver that located the switch as an event
        (where ‖pitch‖ = ``SWITCH_PITCH`` up to round-off) passes 0.0.

    Returns
    -------
    bool
        Whether it switched. Work, dissipation and appendage coordinates are frame-
        independent and left as they are.
    """
    phi, theta, psi = x[3], x[4], x[5]
    if abs(theta) <= threshold:
        return False
    R_FB = rot_zyx(phi, theta, psi)
    omega_B = mv(euler_rate_matrix(phi, theta), load_seg(x, n_dof + 3))  # eq. 2.28
    r_new = mtv(R_FB, load_seg(x, 0))  # r_F' = R_FB^T r_F (F' = B now)
    v_new = mtv(R_FB, load_seg(x, n_dof))
    _store_m33(frame, mm(load_m33_at(frame, 0), R_FB))  # R_NF' = R_NF R_FB
    x[0], x[1], x[2] = r_new
    x[n_dof], x[n_dof + 1], x[n_dof + 2] = v_new
    x[3], x[4], x[5] = 0.0, 0.0, 0.0
    x[n_dof + 3], x[n_dof + 4], x[n_dof + 5] = omega_B  # S(0) = I
    return True


@njit(cache=True, error_model="numpy")
def inertial_view(x, n_dof, frame, view):
    """``view`` = ``x`` with the hub's state relative to the inertial frame N.

    What a loop stage reads when the run has switched: hub position and velocity in N,
    ZYX Euler angles of R_NB = R_NF R_FB and their rates S(Theta_N)^-1 omega_B. Within
    about 1e-6 rad of pitch +-90 deg in N those rates, and a body rate formed back from
    them, lose eps / ‖cos(pitch)‖ of their relative accuracy (docs/model.md, 'Attitude
    parametrization'); the integration itself does not.

    Parameters
    ----------
    x : ndarray, shape (2 n_dof + 2,)
        Augmented state [q, q_dot, W_in, W_diss] relative to F (SI: m, rad, J).
    n_dof : int
        Number of generalized coordinates.
    frame : ndarray, shape (9,)
        R_NF of x, row-major [-].
    view : ndarray, shape (2 n_dof + 2,)
        Output: x with its hub part relative to N [SI, as x].
    """
    copy_into(view, x)
    R_NF = load_m33_at(frame, 0)
    omega_B = mv(euler_rate_matrix(x[3], x[4]), load_seg(x, n_dof + 3))
    phi, theta, psi = euler_zyx(mm(R_NF, rot_zyx(x[3], x[4], x[5])))
    view[0], view[1], view[2] = mv(R_NF, load_seg(x, 0))
    view[n_dof], view[n_dof + 1], view[n_dof + 2] = mv(R_NF, load_seg(x, n_dof))
    view[3], view[4], view[5] = phi, theta, psi
    rates = mv(euler_rate_matrix_inv(phi, theta), omega_B)
    view[n_dof + 3], view[n_dof + 4], view[n_dof + 5] = rates


def inertial_records(
    q: np.ndarray, qd: np.ndarray, omega_B: np.ndarray, frames: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """Recorded hub states relative to N, from the states relative to each row's frame.

    Parameters
    ----------
    q, qd : ndarray, shape (m, n_dof)
        Recorded coordinates [m, rad] and rates [m/s, rad/s], hub part relative to F.
    omega_B : ndarray, shape (m, 3)
        Body rates of the records [rad/s] (frame-independent).
    frames : ndarray, shape (m, 9)
        R_NF of each record, row-major [-].

    Returns
    -------
    q_N, qd_N : ndarray, shape (m, n_dof)
        Copies with the hub position, velocity, ZYX Euler angles and their rates
        relative to N [m, rad, m/s, rad/s]. Rows whose frame is the identity are copied
        unchanged (bit-for-bit). Exactly at pitch +-90 deg in N the Euler rates are
        infinite.
    """
    q_N, qd_N = q.copy(), qd.copy()
    moved = _moved(frames)
    if not moved.any():
        return q_N, qd_N
    from scipy.spatial.transform import Rotation  # here: scipy.spatial costs 0.25 s to import

    R_NF = frames[moved].reshape(-1, 3, 3)
    R_FB = Rotation.from_euler("ZYX", q[moved, 5:2:-1])  # Rz(psi) Ry(theta) Rx(phi)
    with warnings.catch_warnings():  # at pitch +-90 deg only phi -+ psi is defined
        warnings.simplefilter("ignore", UserWarning)
        psi, theta, phi = (Rotation.from_matrix(R_NF) * R_FB).as_euler("ZYX").T
    q_N[:, 0:3] = vectors_to_inertial(q[:, 0:3], frames)
    qd_N[:, 0:3] = vectors_to_inertial(qd[:, 0:3], frames)
    q_N[moved, 3], q_N[moved, 4], q_N[moved, 5] = phi, theta, psi
    w = omega_B[moved]
    with np.errstate(divide="ignore", invalid="ignore"):  # S(Theta_N)^-1 omega_B, eq. 2.28
        c1, s1, c2, t2 = np.cos(phi), np.sin(phi), np.cos(theta), np.tan(theta)
        rate_y = c1 * w[:, 1] - s1 * w[:, 2]
        rate_z = (s1 * w[:, 1] + c1 * w[:, 2]) / c2
        qd_N[moved, 3] = w[:, 0] + t2 * (s1 * w[:, 1] + c1 * w[:, 2])
        qd_N[moved, 4] = rate_y
        qd_N[moved, 5] = rate_z
    return q_N, qd_N


def vectors_to_inertial(v_F: np.ndarray, frames: np.ndarray) -> np.ndarray:
    """v_N = R_NF v_F for each record; identity rows unchanged.

    Parameters
    ----------
    v_F : ndarray, shape (m, 3)
        Vectors in each record's frame F [any].
    frames : ndarray, shape (m, 9)
        R_NF of each record, row-major [-].

    Returns
    -------
    ndarray, shape (m, 3)
        The vectors in N [unit of v_F].
    """
    v_N = v_F.copy()
    moved = _moved(frames)
    v_N[moved] = np.einsum("kij,kj->ki", frames[moved].reshape(-1, 3, 3), v_F[moved])
    return v_N


def _moved(frames: np.ndarray) -> np.ndarray:
    """Rows whose frame is not the identity, shape (m,) bool."""
    return ~np.all(frames == identity_frame(), axis=1)
