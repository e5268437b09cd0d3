"""A uniform beam as a finite-element model (scikit-fem), clamped-free reference structure.

The beam spans [0, L] along Y_M from the interface. Four fields on one
:class:`skfem.MeshLine`, each with its own basis: axial displacement u_y and twist
phi_y (linear Lagrange elements), bending deflections w_x and w_z (cubic Hermite
elements: Euler–Bernoulli, no shear deformation, no rotary inertia of the section,
as in the analytic solution it is compared with). The node at s = 0 is the interface;
its six DOFs map to [tx, ty, tz, rx, ry, rz] through u_y, phi_y, w_x, w_z and the
slopes: r_x = +dw_z/ds and r_z = -dw_x/ds (a rotation about X takes Y into Z, about
Z takes X into -Y).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp

from flexsat.errors import ConfigError

__all__ = [
    "BeamModel",
    "beam_invariants",
    "euler_bernoulli_hub_frequencies",
    "rotating_cantilever_frequencies",
    "uniform_beam",
]


@dataclass(frozen=True)
class BeamModel:
    """FE matrices of a free-free beam and where its interface and tip live.

    Attributes
    ----------
    M, K : scipy.sparse.csr_matrix, shape (n, n)
        Mass and stiffness matrices, the arguments of :func:`flexsat.fe.craig_bampton`
        [kg, kg m^2; N/m, N m/rad by DOF kind].
    interface_dofs : ndarray, shape (6,)
        The interface node's DOFs (indices into the matrices) [-].
    interface_map : ndarray, shape (6, 6)
        T_b, boundary displacement per unit interface motion [-].
    tip_dofs : ndarray, shape (3,)
        The tip's translation DOFs x, y, z (indices) [-].
    tip_position_m : tuple of float
        The tip's place from the interface, frame M [m].
    large_motion : callable or None
        ``large_motion(phi)``: the large-motion invariants of modes ``phi`` (n, k)
        (:func:`beam_invariants`), the ``large_motion`` argument of
        :func:`flexsat.fe.craig_bampton`.
    """

    M: sp.csr_matrix
    K: sp.csr_matrix
    interface_dofs: np.ndarray
    interface_map: np.ndarray
    tip_dofs: np.ndarray
    tip_position_m: tuple[float, float, float]
    large_motion: Callable[[np.ndarray], dict] | None = None


def uniform_beam(length_m: float, n_elements: int, *, mass_per_length_kg_m: float,
                 bending_stiffness_x_n_m2: float, bending_stiffness_z_n_m2: float,
                 axial_stiffness_n: float, torsional_stiffness_n_m2: float,
                 polar_inertia_per_length_kg_m: float) -> BeamModel:  # fmt: skip
    """Assemble a uniform Euler–Bernoulli beam with scikit-fem.

    Parameters
    ----------
    length_m : float
        L [m].
    n_elements : int
        Elements along the span.
    mass_per_length_kg_m : float
        rho A [kg/m].
    bending_stiffness_x_n_m2, bending_stiffness_z_n_m2 : float
        EI_x, bending about X_M (deflection w_z, out of the X-Y plane), and EI_z,
        bending about Z_M (deflection w_x, in the X-Y plane) [N m^2].
    axial_stiffness_n : float
        EA [N].
    torsional_stiffness_n_m2 : float
        GJ [N m^2].
    polar_inertia_per_length_kg_m : float
        rho I_p, twist inertia per length [kg m].

    Returns
    -------
    BeamModel
    """
    try:
        from skfem import Basis, BilinearForm, ElementLineHermite, ElementLineP1, MeshLine
        from skfem.helpers import dd, ddot, dot, grad
    except ImportError:  # pragma: no cover - the fe extra is not installed
        raise ConfigError("uniform_beam needs scikit-fem: pip install 'flexsat[fe]'") from None
    if n_elements < 1:
        raise ConfigError(f"n_elements: must be >= 1, got {n_elements}")
    mesh = MeshLine(np.linspace(0.0, length_m, n_elements + 1))

    @BilinearForm
    def mass(u, v, w):
        return u * v

    @BilinearForm
    def stretch(u, v, w):
        return dot(grad(u), grad(v))

    @BilinearForm
    def bend(u, v, w):
        return ddot(dd(u), dd(v))

    lagrange, hermite = Basis(mesh, ElementLineP1()), Basis(mesh, ElementLineHermite())
    m_l, m_h = mass.assemble(lagrange), mass.assemble(hermite)
    k_l, k_h = stretch.assemble(lagrange), bend.assemble(hermite)
    # Fields in order u_y, phi_y, w_x, w_z.
    M = sp.block_diag(
        [
            mass_per_length_kg_m * m_l,
            polar_inertia_per_length_kg_m * m_l,
            mass_per_length_kg_m * m_h,
            mass_per_length_kg_m * m_h,
        ]
    ).tocsr()
    K = sp.block_diag(
        [
            axial_stiffness_n * k_l,
            torsional_stiffness_n_m2 * k_l,
            bending_stiffness_z_n_m2 * k_h,
            bending_stiffness_x_n_m2 * k_h,
        ]
    ).tocsr()
    # w_x bends about Z (stiffness EI_z), w_z about X (EI_x).
    n_l, n_h = lagrange.N, hermite.N
    offsets = (0, n_l, 2 * n_l, 2 * n_l + n_h)
    value, slope = hermite.nodal_dofs[0], hermite.nodal_dofs[1]
    root, tip = 0, n_elements
    dofs = np.array([
        offsets[2] + value[root],  # tx: w_x
        offsets[0] + lagrange.nodal_dofs[0][root],  # ty: u_y
        offsets[3] + value[root],  # tz: w_z
        offsets[3] + slope[root],  # rx = +dw_z/ds
        offsets[1] + lagrange.nodal_dofs[0][root],  # ry: phi_y
        offsets[2] + slope[root],  # rz = -dw_x/ds
    ])  # fmt: skip
    T = np.eye(6)
    T[5, 5] = -1.0
    tip_dofs = np.array([offsets[2] + value[tip], offsets[0] + lagrange.nodal_dofs[0][tip],
                         offsets[3] + value[tip]])  # fmt: skip
    fields = {"x": (offsets[2], n_h), "y": (offsets[0], n_l), "z": (offsets[3], n_h)}

    def large_motion(phi: np.ndarray) -> dict:
        return beam_invariants(mesh, fields, phi, length_m, mass_per_length_kg_m)

    return BeamModel(M, K, dofs, T, tip_dofs, (0.0, float(length_m), 0.0), large_motion)


def beam_invariants(mesh, fields: dict, phi: np.ndarray, length_m: float,
                    mass_per_length_kg_m: float) -> dict:  # fmt: skip
    """The large-motion invariants of a straight beam along Y_M's modes (frame M).

    With Phi_k(s) = (w_x, u_y, w_z) the translation field of mode k along the span s
    and the foreshortening of bending u_2,kl(s) = -int_0^s (w_k' . w_l') ds' (the
    second-order displacement, along Y), sums over the beam's mass rho A ds:

    - J'_k = sum m (2 x0.Phi_k I - x0 Phi_k^T - Phi_k x0^T), x0 = s e_y;
    - C_kl = sum m u_2,kl e_y = -rho A int (L - s) w_k'.w_l' ds e_y: the geometric
      stiffness of the tension a unit axial acceleration puts in the beam;
    - E_kl = sum m Phi_l x Phi_k (x0 x e_y u_2 = 0 on the axis);
    - J''_kl = 2 sum m (Phi_k.Phi_l I - sym(Phi_k Phi_l^T)) (the modes' second-order
      inertia) - rho A int (L^2 - s^2) w_k'.w_l' ds diag(1, 0, 1) (the geometric
      stiffness of the centrifugal tension).

    Exact Gauss quadrature (order 6) of the cubic and linear shape functions. The
    twist's polar inertia is left out of the second-order terms (its first-order
    coupling is in the participation factors).

    Parameters
    ----------
    mesh : skfem.MeshLine
        The beam's mesh, s in [0, L] [m].
    fields : dict
        ``"x"``, ``"y"``, ``"z"`` -> (offset, size) of w_x, u_y, w_z in the DOFs [-].
    phi : ndarray, shape (n, k)
        The modes over every DOF, mass-normalized [1/sqrt(kg) by DOF unit].
    length_m : float
        L [m].
    mass_per_length_kg_m : float
        rho A [kg/m].

    Returns
    -------
    dict
        ``inertia_derivatives`` (k, 3, 3) [sqrt(kg) m], ``first_moment_hessian``
        (k, k, 3) [1/m], ``coupling_gradient`` (k, k, 3) [-], ``inertia_hessian``
        (k, k, 3, 3) [-], frame M: the fields of :class:`flexsat.config.ModalData`.
    """
    from skfem import Basis, BilinearForm, ElementLineHermite, ElementLineP1, LinearForm
    from skfem.helpers import grad

    bases = {"x": Basis(mesh, ElementLineHermite(), intorder=6),
             "y": Basis(mesh, ElementLineP1(), intorder=6)}  # fmt: skip
    bases["z"] = bases["x"]
    rho_a, L = mass_per_length_kg_m, length_m

    @BilinearForm
    def mass(u, v, w):
        return rho_a * u * v

    @BilinearForm
    def tension_axial(u, v, w):  # the tension of a unit axial load, per rho A
        return (L - w.x[0]) * grad(u)[0] * grad(v)[0]

    @BilinearForm
    def tension_spin(u, v, w):  # twice the tension of a unit spin, per rho A
        return (L**2 - w.x[0] ** 2) * grad(u)[0] * grad(v)[0]

    @LinearForm
    def moment(v, w):
        return rho_a * w.x[0] * v

    k = phi.shape[1]
    shapes = {a: phi[o : o + size] for a, (o, size) in fields.items()}
    axes = "xyz"
    S = np.zeros((k, k, 3, 3))  # S[k, l, a, b] = sum m Phi_k,a Phi_l,b
    for i, a in enumerate(axes):
        for j, b in enumerate(axes):
            S[:, :, i, j] = shapes[a].T @ (mass.assemble(bases[b], bases[a]) @ shapes[b])
    first = np.stack([moment.assemble(bases[a]) @ shapes[a] for a in axes], axis=1)  # (k, 3)
    J1 = np.zeros((k, 3, 3))
    J1 += 2.0 * first[:, 1, None, None] * np.eye(3)
    J1[:, 1, :] -= first
    J1[:, :, 1] -= first
    bend_axial = sum(shapes[a].T @ tension_axial.assemble(bases[a]) @ shapes[a] for a in "xz")
    bend_spin = sum(shapes[a].T @ tension_spin.assemble(bases[a]) @ shapes[a] for a in "xz")
    C = np.zeros((k, k, 3))
    C[:, :, 1] = -rho_a * bend_axial
    levi = np.zeros((3, 3, 3))
    levi[0, 1, 2] = levi[1, 2, 0] = levi[2, 0, 1] = 1.0
    levi[0, 2, 1] = levi[2, 1, 0] = levi[1, 0, 2] = -1.0
    E = np.einsum("cab,lkab->klc", levi, S)  # E_kl = sum m Phi_l x Phi_k
    sym = 0.5 * (S + S.transpose(0, 1, 3, 2))
    trace = np.einsum("klaa->kl", S)
    J2 = 2.0 * (trace[:, :, None, None] * np.eye(3) - sym)
    J2 -= rho_a * bend_spin[:, :, None, None] * np.diag([1.0, 0.0, 1.0])
    J2 = 0.5 * (J2 + J2.transpose(1, 0, 2, 3))
    return {"inertia_derivatives": J1.tolist(), "first_moment_hessian": C.tolist(),
            "coupling_gradient": E.tolist(), "inertia_hessian": J2.tolist()}  # fmt: skip


def euler_bernoulli_hub_frequencies(hub_inertia_kg_m2: float, root_radius_m: float,
                                    length_m: float, mass_per_length_kg_m: float,
                                    bending_stiffness_n_m2: float, count: int,
                                    max_hz: float = 30.0) -> np.ndarray:  # fmt: skip
    """Analytic antisymmetric in-plane frequencies of a hub carrying two cantilevers.

    A rigid hub (inertia J about Z) with two identical uniform Euler–Bernoulli beams
    clamped at radius R on opposite sides. Y(s) = a cosh + b sinh + c cos + d sin
    (beta s), the absolute transverse displacement, beta^4 = rho A omega^2 / EI, with
    Y(0) = R Theta, Y'(0) = Theta, Y''(L) = Y'''(L) = 0 and the angular momentum
    J Theta + 2 rho A int_0^L (R + s) Y ds = 0: a 5 x 5 determinant whose roots (bracketed
    on a grid, refined by Brent's method to 1e-14) are the frequencies.

    Parameters
    ----------
    hub_inertia_kg_m2 : float
        J, the hub's inertia about Z [kg m^2].
    root_radius_m : float
        R, the clamp radius [m].
    length_m : float
        L, each beam's length [m].
    mass_per_length_kg_m : float
        rho A [kg/m].
    bending_stiffness_n_m2 : float
        EI of the in-plane bending [N m^2].
    count : int
        How many frequencies.
    max_hz : float
        Upper end of the search [Hz].

    Returns
    -------
    ndarray, shape (count,)
        The lowest ``count`` frequencies below ``max_hz`` [Hz].
    """
    from scipy.optimize import brentq

    J, R, L, rho_a, ei = (hub_inertia_kg_m2, root_radius_m, length_m, mass_per_length_kg_m,
                          bending_stiffness_n_m2)  # fmt: skip
    s, w = np.polynomial.legendre.leggauss(80)  # exact for the smooth integrand to 1e-16
    s, w = 0.5 * L * (s + 1.0), 0.5 * L * w

    def det(omega: float) -> float:
        beta = (rho_a * omega**2 / ei) ** 0.25
        x = beta * L
        basis = np.array([np.cosh(beta * s), np.sinh(beta * s), np.cos(beta * s),
                          np.sin(beta * s)])  # fmt: skip
        moment = 2.0 * rho_a * basis @ ((R + s) * w)
        A = np.array([
            [1.0, 0.0, 1.0, 0.0, -R],
            [0.0, beta, 0.0, beta, -1.0],
            [np.cosh(x), np.sinh(x), -np.cos(x), -np.sin(x), 0.0],
            [np.sinh(x), np.cosh(x), np.sin(x), -np.cos(x), 0.0],
            [*moment, J],
        ])  # fmt: skip
        return float(np.linalg.det(A) / np.cosh(x) ** 2)

    grid = 2.0 * np.pi * np.linspace(0.01, max_hz, 6000)
    values = [det(o) for o in grid]
    roots = [brentq(det, a, b, xtol=1e-14, rtol=1e-14)
             for a, b, fa, fb in zip(grid[:-1], grid[1:], values[:-1], values[1:], strict=True)
             if fa * fb < 0.0]  # fmt: skip
    return np.array(roots[:count]) / (2.0 * np.pi)


def rotating_cantilever_frequencies(spin_bar: float, offset_ratio: float = 0.0,
                                    count: int = 1) -> np.ndarray:  # fmt: skip
    """Flapwise frequencies of a uniform cantilever spinning about an axis at its root.

    EI w'''' - (N w')' + rho A w_tt = 0 with the centrifugal tension
    N(s) = rho A Omega^2 (R (L - s) + (L^2 - s^2) / 2), the root at radius R from the
    spin axis (docs/model.md, 'Large motion'), solved by Galerkin on the 12 lowest
    clamped-free modes (written with exponentials so that no cosh - sinh cancels),
    200-point Gauss quadrature: converged to 1e-8 for the first mode, and reproducing
    the published table of Wright et al. (1982). Dimensionless: L = 1,
    Omega_bar = Omega sqrt(rho A L^4 / EI). Southwell's coefficient is
    K = (omega_bar^2 - omega_bar_0^2) / Omega_bar^2 (1.193 as Omega -> 0, R = 0). The
    in-plane frequencies in the rotating frame are the flapwise ones less Omega^2.

    Parameters
    ----------
    spin_bar : float
        Omega sqrt(rho A L^4 / EI), the dimensionless spin rate [-].
    offset_ratio : float
        R / L, the root's distance from the spin axis over the length [-].
    count : int
        How many frequencies [-].

    Returns
    -------
    ndarray, shape (count,)
        omega / sqrt(EI / (rho A L^4)), lowest first [-].
    """
    from scipy.linalg import eigh
    from scipy.optimize import brentq

    b = np.array([brentq(lambda x: np.cos(x) * np.cosh(x) + 1.0, (k + 0.5) * np.pi - 0.6,
                         (k + 0.5) * np.pi + 0.6) for k in range(12)])  # fmt: skip
    s, w = np.polynomial.legendre.leggauss(200)
    s, w = 0.5 * (s + 1.0), 0.5 * w
    sig = (np.cosh(b) + np.cos(b)) / (np.sinh(b) + np.sin(b))
    one_minus_sig = (np.sin(b) - np.cos(b) - np.exp(-b)) / (np.sinh(b) + np.sin(b))
    x = np.outer(s, b)
    grow, decay = 0.5 * np.exp(x) * one_minus_sig, 0.5 * np.exp(-x) * (1.0 + sig)
    phi = grow + decay - np.cos(x) + sig * np.sin(x)
    slope = b * (grow - decay + np.sin(x) + sig * np.cos(x))
    M = phi.T @ (w[:, None] * phi)
    tension = offset_ratio * (1.0 - s) + 0.5 * (1.0 - s**2)
    G = slope.T @ ((w * tension)[:, None] * slope)
    return np.sqrt(eigh(np.diag(b**4) @ M + spin_bar**2 * G, M, eigvals_only=True)[:count])
