"""Rigid design model: the satellite with its appendages frozen (thesis appendix A.4).

The controller knows only this model: the total inertia of the undeformed
satellite about the hub centre of mass, J_tot(alpha_sadm), and its gyroscopic
torque.
"""

from __future__ import annotations

import numpy as np

from flexsat.dynamics.plant import Plant

__all__ = ["gyroscopic_torque", "rigid_inertia"]


def rigid_inertia(plant: Plant) -> np.ndarray:
    """Total inertia of the rigidized satellite about the hub centre of mass, frame B.

    Each appendage, frozen undeformed (its model's ``rigid_body``: for a plate, the
    centroidal inertia rotated into B, R_BM J_p R_BM^T), is carried to the hub centre of
    mass by the parallel-axis theorem in matrix form, m (‖r‖^2 I - r r^T), with r its
    undeformed centre of mass.

    Parameters
    ----------
    plant : Plant
        The satellite.

    Returns
    -------
    ndarray, shape (3, 3)
        J_tot [kg m^2]; diag(189.99, 44.16, 177.90) for the nominal case.
    """
    j_tot = plant.hub_J.copy()
    for model, params in zip(plant.models, plant.params, strict=True):
        body = model.rigid_body(params)
        r = body.r_B
        j_tot += body.J_B
        j_tot += body.mass * (np.dot(r, r) * np.eye(3) - np.outer(r, r))
    return j_tot


def gyroscopic_torque(inertia: np.ndarray, omega_B: np.ndarray) -> np.ndarray:
    """Gyroscopic torque omega x (J omega), shape (3,) [N m] (appendix A.4).

    Parameters
    ----------
    inertia : ndarray, shape (3, 3)
        J_tot [kg m^2].
    omega_B : ndarray, shape (3,)
        Body rate, hub frame B [rad/s].
    """
    omega_B = np.asarray(omega_B, dtype=float)
    return np.cross(omega_B, inertia @ omega_B)
