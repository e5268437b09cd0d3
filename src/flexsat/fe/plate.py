"""A thin rectangular plate as a 3D solid finite-element model (scikit-fem).

The plate spans ``length_m`` along Y_M from its root edge (y = 0, the clamped edge),
``width_m`` along X_M (centred) and ``thickness_m`` along Z_M (centred): one layer of
27-node quadratic hexahedra through the thickness (quadratic elements do not lock in
bending at that aspect ratio, linear ones would), isotropic linear elasticity. The
root face is the interface: rigidly linked to the interface point, the middle of the
root edge (:func:`flexsat.fe.craig_bampton.rigid_interface_map`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp

from flexsat.errors import ConfigError
from flexsat.fe.craig_bampton import rigid_interface_map

__all__ = ["SolidPlateModel", "solid_plate"]


@dataclass(frozen=True)
class SolidPlateModel:
    """FE matrices of a free-free plate and its interface.

    Attributes
    ----------
    M, K : scipy.sparse.csr_matrix, shape (n, n)
        Mass and stiffness matrices, the arguments of :func:`flexsat.fe.craig_bampton`
        [kg; N/m].
    interface_dofs : ndarray, shape (n_b,)
        The boundary DOFs rigidly linked to the interface point (indices) [-].
    interface_map : ndarray, shape (n_b, 6)
        T_b, boundary displacement per unit interface motion [m/m, m/rad].
    rigid_modes : ndarray, shape (n, 6)
        Every DOF's rigid motion about the interface point [m/m, m/rad].
    tip_dofs : ndarray, shape (3,)
        Translations x, y, z of the DOF nearest the middle of the free edge
        (indices) [-].
    tip_position_m : tuple of float
        That DOF's place from the interface, frame M [m].
    """

    M: sp.csr_matrix
    K: sp.csr_matrix
    interface_dofs: np.ndarray
    interface_map: np.ndarray
    rigid_modes: np.ndarray
    tip_dofs: np.ndarray
    tip_position_m: tuple[float, float, float]


def solid_plate(length_m: float, width_m: float, thickness_m: float, *, density_kg_m3: float,
                youngs_modulus_pa: float, poisson_ratio: float, elements_span: int,
                elements_chord: int) -> SolidPlateModel:  # fmt: skip
    """Assemble the plate with scikit-fem.

    Parameters
    ----------
    length_m, width_m, thickness_m : float
        Span (Y_M), chord (X_M) and thickness (Z_M) [m].
    density_kg_m3 : float
        rho [kg/m^3].
    youngs_modulus_pa, poisson_ratio : float
        E [Pa] and nu [-].
    elements_span, elements_chord : int
        Hexahedra along the span and the chord (one through the thickness).

    Returns
    -------
    SolidPlateModel
    """
    try:
        from skfem import Basis, BilinearForm, ElementHex2, ElementVector, MeshHex
        from skfem.helpers import dot
        from skfem.models.elasticity import lame_parameters, linear_elasticity
    except ImportError:  # pragma: no cover - the fe extra is not installed
        raise ConfigError("solid_plate needs scikit-fem: pip install 'flexsat[fe]'") from None
    if elements_span < 1 or elements_chord < 1:
        raise ConfigError("elements_span, elements_chord: must be >= 1")
    mesh = MeshHex.init_tensor(
        np.linspace(-0.5 * width_m, 0.5 * width_m, elements_chord + 1),
        np.linspace(0.0, length_m, elements_span + 1),
        np.linspace(-0.5 * thickness_m, 0.5 * thickness_m, 2),
    )
    # 3 x 3 x 3 Gauss points integrate the triquadratic mass and stiffness integrands
    # exactly (degree <= 4 per direction); the default order would use 7 x 7 x 7.
    basis = Basis(mesh, ElementVector(ElementHex2()), intorder=4)

    @BilinearForm
    def mass(u, v, w):
        return density_kg_m3 * dot(u, v)

    K = linear_elasticity(*lame_parameters(youngs_modulus_pa, poisson_ratio)).assemble(basis)
    M = mass.assemble(basis)
    component = np.empty(basis.N, dtype=int)
    for axis, dofs in enumerate(basis.split_indices()):
        component[dofs] = axis
    where = basis.doflocs
    root = np.nonzero(np.isclose(where[1], 0.0))[0]
    rigid = rigid_interface_map(where.T, component)
    T_b = rigid[root]
    tip_point = np.array([0.0, length_m, 0.0])
    distance = np.linalg.norm(where.T - tip_point, axis=1)
    nearest = np.isclose(distance, distance.min())
    tip = np.array([np.nonzero(nearest & (component == a))[0][0] for a in range(3)])
    return SolidPlateModel(M.tocsr(), K.tocsr(), root, T_b, rigid, tip, tuple(tip_point))
