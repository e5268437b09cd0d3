"""The plant packed for the compiled code: one named, numba-typeable structure.

:class:`PackedPlant` replaces the positional argument tuples of earlier versions.
numba types it as a named tuple of arrays and of tuples of first-class functions
(typed by signature, see :mod:`flexsat.dynamics.appendages.contract`), so the RK4
loops compile once per number of appendage groups and are cached on disk.

Appendages are grouped by model: one kernel call processes a whole group.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

__all__ = ["PackedPlant"]


class PackedPlant(NamedTuple):
    """Hub, groups of appendages and their kernels, for :mod:`flexsat.dynamics.kernels`.

    Fields
    ------
    n_dof : int
        Number of generalized coordinates.
    hub_mass : float
        [kg].
    hub_J, hub_J_inv : ndarray, shape (3, 3)
        Hub inertia about its centre of mass, frame B, and its inverse [kg m^2].
    articulated : bool
        True if an appendage transmits articulated inertia (then the hub solve is the
        6 x 6 system; else the bare hub's Newton-Euler equations).
    hub : ndarray, shape (HUB_SIZE,)
        Exchange array between the engine and the kernels (scratch, overwritten by
        every evaluation; slots in the contract module).
    solve : ndarray, shape (6, 7)
        Scratch of the 6 x 6 hub solve.
    members : tuple of ndarray, shape (k_g, 2), int64
        Per group: appendage index and offset of its first coordinate in q.
    params : tuple of ndarray, shape (k_g, p_g)
        Per group: each member's packed parameter row.
    pass1, pass2, mass_matrix, bias_forces, observe, joint_wrench, tips : tuple
        Per group: the model's compiled kernels.
    """

    n_dof: int
    hub_mass: float
    hub_J: np.ndarray
    hub_J_inv: np.ndarray
    articulated: bool
    hub: np.ndarray
    solve: np.ndarray
    members: tuple
    params: tuple
    pass1: tuple
    pass2: tuple
    mass_matrix: tuple
    bias_forces: tuple
    observe: tuple
    joint_wrench: tuple
    tips: tuple
