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
    plane : {"xz", "yz"}
        Hub coordinate plane of the reflection.
    rtol : float
        Relative tolerance when matching appendage geometry and properties.

    Returns
    -------
    ndarray, shape (n_dof, n_dof) or None
        P with P @ P = I, M(P q) = P M(q) P and h(P q, P q_dot) = P h(q, q_dot) when
        the plant is mirror symmetric; None otherwise.
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
    for i in range(n):
        j = _partner(plant, i, reflect, rtol)
        if j is None:
            return None
        paired.add(j)
        T_eta = plant.R_BM[j].T @ reflect @ plant.R_BM[i]
        T_rho = -T_eta  # axial vectors: det(T_eta) = -1
        if not _is_signed_identity(T_eta, rtol):
            return None
        oi, oj = 6 + 6 * i, 6 + 6 * j
        P[oj : oj + 3, oi : oi + 3] = T_eta
        P[oj + 3 : oj + 6, oi + 3 : oi + 6] = T_rho
    return P if len(paired) == n else None


def _partner(plant: Plant, i: int, reflect: np.ndarray, rtol: float) -> int | None:
    """Index of the appendage that is the mirror image of appendage i, if any."""
    scale = max(1.0, float(np.max(np.abs(plant.mount_point))))
    target_root = reflect @ plant.mount_point[i]
    target_com = reflect @ (plant.R_BM[i] @ plant.com_offset[i])
    for j in range(plant.n_appendages):
        same = (
            np.allclose(plant.mount_point[j], target_root, atol=rtol * scale)
            and np.allclose(plant.R_BM[j] @ plant.com_offset[j], target_com, atol=rtol * scale)
            and np.isclose(plant.panel_mass[j], plant.panel_mass[i], rtol=rtol)
            and np.allclose(plant.panel_J[j], plant.panel_J[i], rtol=rtol)
            and np.allclose(plant.stiffness[j], plant.stiffness[i], rtol=rtol)
            and np.allclose(plant.damping[j], plant.damping[i], rtol=rtol)
        )
        if same:
            return j
    return None


def _is_signed_identity(T: np.ndarray, rtol: float) -> bool:
    """True when T is diagonal with entries +-1 (joint axes map onto joint axes)."""
    return bool(np.allclose(np.abs(T), np.eye(3), atol=rtol))
