"""Mirror symmetry of a plant: the operator that reflects generalized coordinates.

A reflection through a hub coordinate plane (XZ: y -> -y, or YZ: x -> -x) maps the
satellite onto itself when the appendages come in mirror pairs (or lie in the
plane). Its action on q is linear and exact, even for finite rotations: a ZYX
rotation reflects to ZYX angles with two of the three signs flipped, and joint
coordinates map between the mount frames of the paired appendages.
"""

from __future__ import annotations

import numpy as np

from flexsat.dynamics.plant import Plant

__all__ = ["mirror_operator"]

_PLANES = {"xz": 1, "yz": 0}  # the axis the reflection flips


def mirror_operator(plant: Plant, plane: str = "xz", rtol: float = 1e-9) -> np.ndarray | None:
    """Linear map P on q for a reflection through a hub plane, or None if not a symmetry.

    Parameters
    ----------
    plant : Plant
        The satellite.
    plane : {"xz", "yz"}
        Hub coordinate plane of the reflection.
    rtol : float
        Relative tolerance when matching appendage geometry and properties [-].

    Returns
    -------
    ndarray, shape (n_dof, n_dof) or None
        P [-] with P @ P = I, M(P q) = P M(q) P and h(P q, P q_dot) = P h(q, q_dot)
        when the plant is mirror symmetric; None otherwise.
    """
    flip = np.ones(3)
    flip[_PLANES[plane]] = -1.0
    reflect = np.diag(flip)  # acts on polar vectors; axial vectors pick up det = -1
    hub_tol = rtol * np.abs(plant.hub_J).max()
    if not np.allclose(reflect @ plant.hub_J @ reflect, plant.hub_J, atol=hub_tol):
        return None
    n = plant.n_appendages
    P = np.zeros((plant.n_dof, plant.n_dof))
    P[0:3, 0:3] = reflect
    P[3:6, 3:6] = -reflect
    # Euler angles: R -> F R F with F the reflection; for ZYX angles this is the
    # axial-vector rule applied component-wise (exact, see module docstring).
    paired = set()
    blocks = plant.layout.blocks
    for i in range(n):
        found = _partner(plant, i, reflect, rtol)
        if found is None:
            return None
        j, T = found
        paired.add(j)
        P[blocks[j].slice, blocks[i].slice] = T
    return P if len(paired) == n else None


def _partner(plant: Plant, i: int, reflect: np.ndarray, rtol: float
             ) -> tuple[int, np.ndarray] | None:  # fmt: skip
    """The appendage that is the mirror image of appendage i and the map of its
    coordinates, asked of the model (same model only)."""
    model = plant.models[i]
    for j in range(plant.n_appendages):
        if plant.models[j] is not model:
            continue
        T = model.mirror_block(plant.params[i], plant.params[j], reflect, rtol)
        if T is not None:
            return j, T
    return None
