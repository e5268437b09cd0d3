"""Inverse tuning of the joint stiffness and damping from target frequencies (thesis 2.2.3)."""

from __future__ import annotations

import numpy as np

__all__ = ["tune_joints"]


def tune_joints(
    mass_matrix_0: np.ndarray, frequencies_hz: np.ndarray, damping_ratio: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """Joint stiffness and damping that place each joint DOF at its target frequency.

    Parameters
    ----------
    mass_matrix_0 : ndarray, shape (6 + 6n, 6 + 6n)
        System mass matrix in the undeformed configuration, M(0).
    frequencies_hz : ndarray, shape (n, 6)
        Target cantilever frequencies f_n,j per joint DOF [Hz].
    damping_ratio : ndarray, shape (n,)
        Damping ratio zeta of each appendage's joints [-].

    Returns
    -------
    stiffness : ndarray, shape (n, 6)
        k_j = J_eq,j (2 pi f_n,j)^2 [N/m or N m/rad] (eq. 2.14).
    damping : ndarray, shape (n, 6)
        c_j = 2 zeta_j (2 pi f_n,j) J_eq,j [N s/m or N m s/rad] (eq. 2.15).

    Notes
    -----
    J_eq,j is the diagonal entry of M(0) of joint DOF j: the inertia the joint sees
    with the hub clamped, so f_n,j is the clamped-root frequency of that DOF alone.
    """
    n = frequencies_hz.shape[0]
    j_eq = np.diag(mass_matrix_0)[6:].reshape(n, 6)
    omega_n = 2.0 * np.pi * np.asarray(frequencies_hz, dtype=float)
    stiffness = j_eq * omega_n**2  # eq. 2.14
    damping = 2.0 * np.asarray(damping_ratio, dtype=float)[:, None] * omega_n * j_eq  # eq. 2.15
    return stiffness, damping
