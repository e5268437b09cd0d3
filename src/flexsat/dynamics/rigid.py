"""Rigid design model: the satellite with its appendages frozen (thesis appendix A.4).

The controller knows only this model: the total inertia of the undeformed
satellite about the hub centre of mass, J_tot(alpha_sadm), and its gyroscopic
torque. A solar-array drive's angle is a free coordinate: the model freezes it at
its initial angle (:func:`design_coordinates`), or a ``sadm_drive`` stage with
``design_model = "measured"`` has the law follow it.
"""

from __future__ import annotations

import numpy as np

from flexsat.dynamics.plant import Plant

__all__ = ["design_coordinates", "gyroscopic_torque", "rigid_inertia"]


def rigid_inertia(plant: Plant, q: np.ndarray | None = None) -> np.ndarray:
    """Total inertia of the rigidized satellite about the hub centre of mass, frame B.

    Each appendage, frozen undeformed (its model's ``rigid_body``: for a plate, the
    centroidal inertia rotated into B, R_BM J_p R_BM^T), is carried to the hub centre of
    mass by the parallel-axis theorem in matrix form, m (‖r‖^2 I - r r^T), with r its
    undeformed centre of mass. The reference point is the hub centre of mass (the
    origin of B), not the satellite's: a moving appendage moves no term but its own.

    Parameters
    ----------
    plant : Plant
        The satellite.
    q : ndarray, shape (n_dof,), optional
        Coordinates the appendages are frozen at (``rigid_body_at``: a drive's angle)
        [m, rad]; default undeformed, q = 0. The hub's six are not read.

    Returns
    -------
    ndarray, shape (3, 3)
        J_tot [kg m^2]; diag(189.99, 44.16, 177.90) for the nominal case.
    """
    j_tot = plant.hub_J.copy()
    for model, params, block in zip(plant.models, plant.params, plant.layout.blocks, strict=True):
        at = None if q is None else np.asarray(q, dtype=float)[block.slice]
        body = model.rigid_body(params) if at is None else model.rigid_body_at(params, at)
        r = body.r_B
        j_tot += body.J_B
        j_tot += body.mass * (np.dot(r, r) * np.eye(3) - np.outer(r, r))
    return j_tot


def design_coordinates(plant: Plant, q0: np.ndarray) -> np.ndarray:
    """The coordinates the rigid design model freezes a run at [m, rad], shape (n_dof,).

    An elastic coordinate at its spring's rest (0, undeformed), a free one (no
    stiffness: a solar-array drive's angle) where the run starts it, ``q0``: a drive
    has no rest angle, and the design model holds it at its initial one.

    Parameters
    ----------
    plant : Plant
        The satellite.
    q0 : ndarray, shape (n_dof,)
        The run's initial coordinates [m, rad].

    Returns
    -------
    ndarray, shape (n_dof,)
        Zero but at the free coordinates [m, rad].
    """
    q = np.zeros(plant.n_dof)
    flexible = plant.layout.flexible
    index = np.arange(flexible.start, flexible.stop)[plant.stiffness == 0.0]
    q[index] = np.asarray(q0, dtype=float)[index]
    return q


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
