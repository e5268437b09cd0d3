"""A moving target's errors: the reference re-evaluated at the records, the attitude against it.

A reference whose target moves (``moving_target``: nadir, Sun pointing) is a function
of time alone (its state is scratch), so evaluating its compiled step at a record's
time gives the q_d and omega_d the law tracked at that instant (the loop runs the
reference at every control instant; a record that falls between two instants sees
the target up to one control period later than the law held it). The run's pointing
error is then the attitude's angle from that q_d and its residual rate
omega - C_BD omega_d (docs/orbit.md, 'Pointing targets').
"""

from __future__ import annotations

import numpy as np
from scipy.spatial.transform import Rotation

__all__ = ["reference_track", "tracking_errors"]


def reference_track(step, times: np.ndarray, data) -> tuple[np.ndarray, np.ndarray]:
    """The reference's q_d and omega_d at each time.

    Parameters
    ----------
    step : numba dispatcher
        The reference stage's compiled step (``StageSpec.step``).
    times : ndarray, shape (m,)
        Record times [s].
    data : LoopData
        The run's loop data (the reference's packed parameters and state).

    Returns
    -------
    q_d : ndarray, shape (m, 4)
        Reference attitude, scalar first [-].
    omega_d : ndarray, shape (m, 3)
        Reference rate in the reference frame D [rad/s].
    """
    params = np.ascontiguousarray(data.reference_params)
    state = np.array(data.reference_state, dtype=float)  # scratch: the run's is left alone
    record = np.array(data.reference_record, dtype=float)
    q_d = np.empty((times.size, 4))
    omega_d = np.empty((times.size, 3))
    omega_dot_d = np.empty(3)
    for k, t in enumerate(times):
        step(float(t), params, state, q_d[k], omega_d[k], omega_dot_d, record)
    return q_d, omega_d


def tracking_errors(
    q_d: np.ndarray, omega_d: np.ndarray, euler: np.ndarray, omega: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """Pointing error and residual rate of the attitude against a moving reference.

    Parameters
    ----------
    q_d : ndarray, shape (m, 4)
        Reference attitude, scalar first [-].
    omega_d : ndarray, shape (m, 3)
        Reference rate, frame D [rad/s].
    euler : ndarray, shape (m, 3)
        True hub attitude as ZYX Euler angles roll, pitch, yaw (R_NB) [rad].
    omega : ndarray, shape (m, 3)
        True hub body rate, frame B [rad/s].

    Returns
    -------
    pointing : ndarray, shape (m,)
        2 asin ‖q_v,e‖ of q_e = q_d^-1 (x) q [rad].
    omega_error : ndarray, shape (m, 3)
        omega - C_BD omega_d, frame B [rad/s].
    """
    finite = np.isfinite(euler).all(axis=1) & np.isfinite(q_d).all(axis=1)
    pointing = np.full(euler.shape[0], np.nan)
    omega_error = np.full(omega.shape, np.nan)
    if finite.any():
        body = Rotation.from_euler("ZYX", euler[finite][:, ::-1])  # R_NB
        reference = Rotation.from_quat(q_d[finite][:, [1, 2, 3, 0]])  # R_ND, scalar last
        error = reference.inv() * body  # R_DB
        pointing[finite] = error.magnitude()
        omega_error[finite] = omega[finite] - error.inv().apply(omega_d[finite])
    return pointing, omega_error
