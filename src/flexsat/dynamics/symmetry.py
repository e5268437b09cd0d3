"""Mirror symmetry of a plant: the operator that reflects generalized coordinates.

A reflection through a hub coordinate plane (XZ: y -> -y, or YZ: x -> -x) maps the
satellite onto itself when the appendages come in mirror pairs (or lie in the
plane). Its action on q is linear and exact, even for finite rotations: a ZYX
rotation reflects to ZYX angles with two of the three signs flipped, and joint
coordinates map between the mount frames of the paired appendages.

An appendage may be its own mirror image (one lying in the plane, such as a third
panel on the X axis beside a mirrored pair): the reflection then maps its coordinates
onto themselves. :func:`mirror_partners` says which appendage is whose image, so that
an analysis can tell the motion of mirror pairs from that of such appendages.
"""

from __future__ import annotations

import numpy as np

from flexsat.dynamics.plant import Plant

__all__ = ["mirror_operator", "mirror_partners"]

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
    found = _mirror(plant, plane, rtol)
    return None if found is None else found[0]


def mirror_partners(plant: Plant, plane: str = "xz", rtol: float = 1e-9) -> list[int] | None:
    """Which appendage is the mirror image of which, or None if not a symmetry.

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
    list of int or None
        ``partners[i]``: the index of the appendage that is the mirror image of
        appendage ``i`` (``i`` itself for one that is its own image, lying in the
        plane); None when the reflection is not a symmetry of the plant
        (:func:`mirror_operator` is then None too).
    """
    found = _mirror(plant, plane, rtol)
    return None if found is None else found[1]


def _mirror(plant: Plant, plane: str, rtol: float) -> tuple[np.ndarray, list[int]] | None:
    """(P, partners) of :func:`mirror_operator` and :func:`mirror_partners`, or None."""
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
    partners = []
    blocks = plant.layout.blocks
    for i in range(n):
        found = _partner(plant, i, reflect, rtol)
        if found is None:
            return None
        j, T = found
        partners.append(j)
        P[blocks[j].slice, blocks[i].slice] = T
    return (P, partners) if len(set(partners)) == n else None


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
