"""A thin rectangular plate as a 3D solid finite-element model (scikit-fem).

The plate spans ``length_m`` along Y_M from its root edge (y = 0, the clamped edge),
``width_m`` along X_M (centred) and ``thickness_m`` along Z_M (centred): one layer of
27-node quadratic hexahedra through the thickness (quadratic elements do not lock in
bending at that aspect ratio, linear ones would), isotropic linear elasticity. The
root face is the interface: rigidly linked to the interface point, the middle of the
root edge (:func:`flexsat.fe.craig_bampton.rigid_interface_map`).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp

from flexsat.errors import ConfigError
from flexsat.fe.craig_bampton import rigid_interface_map

__all__ = ["SolidPlateModel", "plate_invariants", "solid_plate"]


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
    large_motion : callable or None
        ``large_motion(phi)``: the large-motion invariants of modes ``phi`` (n, k)
        (:func:`plate_invariants`), the ``large_motion`` argument of
        :func:`flexsat.fe.craig_bampton`.
    """

    M: sp.csr_matrix
    K: sp.csr_matrix
    interface_dofs: np.ndarray
    interface_map: np.ndarray
    rigid_modes: np.ndarray
    tip_dofs: np.ndarray
    tip_position_m: tuple[float, float, float]
    large_motion: Callable[[np.ndarray], dict] | None = None


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
    lame = lame_parameters(youngs_modulus_pa, poisson_ratio)

    def large_motion(phi: np.ndarray) -> dict:
        return plate_invariants(basis, K.tocsr(), root, phi, density_kg_m3, *lame)

    return SolidPlateModel(M.tocsr(), K.tocsr(), root, T_b, rigid, tip, tuple(tip_point),
                           large_motion)  # fmt: skip


def plate_invariants(basis, K: sp.csr_matrix, clamped: np.ndarray, phi: np.ndarray,
                     density_kg_m3: float, lame_lambda_pa: float,
                     lame_mu_pa: float) -> dict:  # fmt: skip
    """The large-motion invariants of a solid's clamped modes, from its geometric stiffness.

    With Phi_k the modes' displacement fields about the interface point (the origin)
    and x0 the material point, sums over the mass rho dV (docs/model.md, 'Large
    motion'):

    - J'_k = sum m (2 x0.Phi_k I - x0 Phi_k^T - Phi_k x0^T);
    - the modes' second-order inertia S_kl = sum m Phi_k Phi_l^T: the antisymmetric
      part of E_kl, sum m Phi_l x Phi_k, and 2 (tr S_kl I - sym S_kl) in J''_kl;
    - the second-order displacement's part through the geometric stiffness of the
      prestress of each inertial load field, K_G(sigma)_kl = int sigma_ij
      (d_i Phi_k . d_j Phi_l) dV, sigma the static stress of the structure clamped at
      its interface under the d'Alembert load f: C_kl . e_c = K_G(f = -rho e_c)
      (unit linear acceleration), sym E_kl . e_c = K_G(f = -rho e_c x x0) (unit
      angular acceleration), and J''_kl[a, b] -= 2 K_G(f = rho (delta_ab x0 -
      sym(x0_a e_b))) (unit rate product: the centrifugal load).

    Twelve static solves with one factorization of the clamped stiffness, twelve
    assemblies of K_G on the solid's quadrature.

    Parameters
    ----------
    basis : skfem.Basis
        The solid's vector basis, positions from the interface point, frame M [m].
    K : scipy.sparse.csr_matrix, shape (n, n)
        Its stiffness matrix [N/m].
    clamped : ndarray, shape (n_b,)
        The DOFs held at the interface (indices) [-].
    phi : ndarray, shape (n, k)
        The clamped modes over every DOF, mass-normalized, zero on ``clamped``
        [1/sqrt(kg)].
    density_kg_m3 : float
        rho [kg/m^3].
    lame_lambda_pa, lame_mu_pa : float
        Lame's parameters lambda and mu [Pa].

    Returns
    -------
    dict
        ``inertia_derivatives`` (k, 3, 3) [sqrt(kg) m], ``first_moment_hessian``
        (k, k, 3) [1/m], ``coupling_gradient`` (k, k, 3) [-], ``inertia_hessian``
        (k, k, 3, 3) [-], frame M: the fields of :class:`flexsat.config.ModalData`.
    """
    from scipy.sparse.linalg import splu
    from skfem import BilinearForm, LinearForm
    from skfem.helpers import grad

    rho, lam, mu = density_kg_m3, lame_lambda_pa, lame_mu_pa
    k = phi.shape[1]
    eye = np.eye(3)

    @BilinearForm
    def scalar_mass(u, v, w):  # rho u_a v_b: components a, b of the vector fields
        return rho * u[w.a] * v[w.b]

    def unit(a: int) -> np.ndarray:
        return eye[a][:, None, None]

    S = np.zeros((k, k, 3, 3))  # S[k, l, a, b] = sum m Phi_k,a Phi_l,b
    for a in range(3):
        for b in range(3):
            Mab = scalar_mass.assemble(basis, a=a, b=b)
            S[:, :, a, b] = phi.T @ (Mab @ phi)
    # First moments: sum m x0_a Phi_k,b = (x0_a e_b)^T M Phi_k, x0 interpolated exactly.
    x0 = basis.doflocs  # (3, n): each DOF's position
    component = np.empty(basis.N, dtype=int)
    for axis, dofs in enumerate(basis.split_indices()):
        component[dofs] = axis
    M = sum(scalar_mass.assemble(basis, a=a, b=a) for a in range(3))
    first = np.zeros((k, 3, 3))  # first[k, a, b] = sum m x0_a Phi_k,b
    for a in range(3):
        for b in range(3):
            field = np.where(component == b, x0[a], 0.0)
            first[:, a, b] = field @ (M @ phi)
    trace = np.einsum("kaa->k", first)
    J1 = 2.0 * trace[:, None, None] * eye - first - first.transpose(0, 2, 1)

    free = np.setdiff1d(np.arange(basis.N), clamped)
    solve = splu(K[free][:, free].tocsc())

    @LinearForm
    def load(v, w):
        return np.einsum("a...,a...->...", w.f, v)

    @BilinearForm
    def geometric(u, v, w):
        return np.einsum("ij...,mi...,mj...->...", w.sigma, grad(u), grad(v))

    def stiffness_of(body_force) -> np.ndarray:
        """Phi^T K_G(sigma) Phi of the stress of the clamped solid under body_force(x)."""
        x = basis.global_coordinates().value  # (3, elements, points) [m]
        f = load.assemble(basis, f=body_force(x))
        u = np.zeros(basis.N)
        u[free] = solve.solve(f[free])
        g = basis.interpolate(u).grad  # g[m, i] = d u_m / d x_i
        strain = 0.5 * (g + g.transpose(1, 0, 2, 3))
        tr = np.einsum("ii...->...", strain)
        sigma = lam * tr * eye[:, :, None, None] + 2.0 * mu * strain
        return phi.T @ (geometric.assemble(basis, sigma=sigma) @ phi)

    C = np.zeros((k, k, 3))
    E_sym = np.zeros((k, k, 3))
    for c in range(3):
        C[:, :, c] = stiffness_of(lambda x, c=c: -rho * np.broadcast_to(unit(c), x.shape))
        E_sym[:, :, c] = stiffness_of(lambda x, c=c: -rho * np.cross(eye[c], x, axis=0))
    J2 = 2.0 * (
        np.einsum("klaa->kl", S)[:, :, None, None] * eye - 0.5 * (S + S.transpose(0, 1, 3, 2))
    )
    for a in range(3):
        for b in range(a, 3):

            def centrifugal(x, a=a, b=b):
                f = (a == b) * x - 0.5 * (x[a] * unit(b) + x[b] * unit(a))
                return rho * f

            G = stiffness_of(centrifugal)
            J2[:, :, a, b] -= 2.0 * G
            if b != a:
                J2[:, :, b, a] -= 2.0 * G
    levi = np.zeros((3, 3, 3))
    levi[0, 1, 2] = levi[1, 2, 0] = levi[2, 0, 1] = 1.0
    levi[0, 2, 1] = levi[2, 1, 0] = levi[1, 0, 2] = -1.0
    E = np.einsum("cab,lkab->klc", levi, S) + 0.5 * (E_sym + E_sym.transpose(1, 0, 2))
    C = 0.5 * (C + C.transpose(1, 0, 2))
    J2 = 0.5 * (J2 + J2.transpose(1, 0, 2, 3))
    return {"inertia_derivatives": J1.tolist(), "first_moment_hessian": C.tolist(),
            "coupling_gradient": E.tolist(), "inertia_hessian": J2.tolist()}  # fmt: skip
