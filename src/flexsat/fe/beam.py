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

from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp

from flexsat.errors import ConfigError

__all__ = ["BeamModel", "euler_bernoulli_hub_frequencies", "uniform_beam"]


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
    """

    M: sp.csr_matrix
    K: sp.csr_matrix
    interface_dofs: np.ndarray
    interface_map: np.ndarray
    tip_dofs: np.ndarray
    tip_position_m: tuple[float, float, float]


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
    return BeamModel(M, K, dofs, T, tip_dofs, (0.0, float(length_m), 0.0))


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
