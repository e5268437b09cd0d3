"""Inverse tuning of joint stiffness and damping from target frequencies (thesis 2.2.3).

Each appendage model tunes its own coordinates with :func:`tune_joints`, given its
block of diag M(0) (:meth:`flexsat.dynamics.appendages.AppendageModel.tune`).
"""

from __future__ import annotations

import numpy as np

__all__ = ["tune_joints"]


def tune_joints(
    inertia_diag: np.ndarray, frequencies_hz: np.ndarray, damping_ratio: float
) -> tuple[np.ndarray, np.ndarray]:
    """Stiffness and damping that place each joint DOF at its target frequency.

    Parameters
    ----------
    inertia_diag : ndarray, shape (k,)
        J_eq,j: the diagonal entries of M(0) of the joint DOFs [kg or kg m^2], the
        inertia each joint sees with the hub clamped, so f_n,j is the clamped-root
        frequency of that DOF alone.
    frequencies_hz : ndarray, shape (k,)
        Target cantilever frequencies f_n,j per joint DOF [Hz].
    damping_ratio : float
        Damping ratio zeta of the joints [-].

    Returns
    -------
    stiffness : ndarray, shape (k,)
        k_j = J_eq,j (2 pi f_n,j)^2 [N/m or N m/rad] (eq. 2.14).
    damping : ndarray, shape (k,)
        c_j = 2 zeta_j (2 pi f_n,j) J_eq,j [N s/m or N m s/rad] (eq. 2.15).
    """
    omega_n = 2.0 * np.pi * np.asarray(frequencies_hz, dtype=float)
    stiffness = inertia_diag * omega_n**2  # eq. 2.14
    damping = 2.0 * float(damping_ratio) * omega_n * inertia_diag  # eq. 2.15
    return stiffness, damping
