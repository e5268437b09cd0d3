"""Euler-Lagrange derivation of the equations of motion from T, U and D (SymPy)."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal

import sympy as sp

from flexsat.dynamics.symbolic.printing import _equations_latex, _equations_pretty, _tidy
from flexsat.dynamics.symbolic.rotations import euler_rate_matrix, rot_zyx, rotation
from flexsat.dynamics.symbolic.symbols import (
    AppendageSymbols,
    HubSymbols,
    PanelRates,
    _appendage_symbols,
    _coordinates,
    _hub_symbols,
)

__all__ = ["SymbolicModel"]


@dataclass(frozen=True, eq=False)
class SymbolicModel:
    """Symbolic equations of motion ``M q_ddot + h + C q_dot + k_el = Q``.

    Attributes
    ----------
    n_appendages : int
        Number of appendages N.
    panel_rates : {"exact", "small_angle"}
        Panel angular-velocity variant (eq. 2.31), see :func:`derive`.
    q, qd : ImmutableMatrix
        Generalized coordinates and rates, ``(6 + 6N) x 1``.
    hub : HubSymbols
        Hub parameter symbols.
    appendages : tuple of AppendageSymbols
        Parameter symbols of each appendage.
    v_B, omega_B : ImmutableMatrix
        Hub velocity and angular velocity in frame B (3x1).
    r_G, v_G, omega_P : tuple of ImmutableMatrix
        Per appendage: panel CoM position and velocity in frame B, panel angular
        velocity in panel frame P (3x1 each).
    T_bodies : tuple of Expr
        Kinetic energy of the hub, then of each panel; ``T = sum(T_bodies)``.
    T, U, D : Expr
        Kinetic energy, elastic potential energy and Rayleigh dissipation function.
    M : ImmutableMatrix
        Mass matrix ``dp/dq_dot``, ``n x n``.
    h : ImmutableMatrix
        Coriolis and centrifugal terms ``(dp/dq) q_dot - (dT/dq)^T``, ``n x 1``.
    k_el : ImmutableMatrix
        Elastic forces ``dU/dq``, ``n x 1``.
    C_damp : ImmutableMatrix
        Damping matrix ``d^2 D / dq_dot^2``, ``n x n``.
    """

    n_appendages: int
    panel_rates: PanelRates
    q: sp.ImmutableMatrix
    qd: sp.ImmutableMatrix
    hub: HubSymbols
    appendages: tuple[AppendageSymbols, ...]
    v_B: sp.ImmutableMatrix
    omega_B: sp.ImmutableMatrix
    r_G: tuple[sp.ImmutableMatrix, ...]
    v_G: tuple[sp.ImmutableMatrix, ...]
    omega_P: tuple[sp.ImmutableMatrix, ...]
    T_bodies: tuple[sp.Expr, ...]
    T: sp.Expr
    U: sp.Expr
    D: sp.Expr
    M: sp.ImmutableMatrix
    h: sp.ImmutableMatrix
    k_el: sp.ImmutableMatrix
    C_damp: sp.ImmutableMatrix

    @property
    def n_dof(self) -> int:
        """Number of generalized coordinates, ``6 + 6N``."""
        return 6 + 6 * self.n_appendages

    @property
    def parameters(self) -> tuple[sp.Symbol, ...]:
        """All parameter symbols in the order of :meth:`ReferenceParameters.vector`."""
        out = self.hub.flat()
        for app in self.appendages:
            out += app.flat()
        return out

    def M_at_rest(self, simplify: bool = False) -> sp.ImmutableMatrix:
        """Mass matrix at ``q = 0``, symbolic in the parameters.

        Parameters
        ----------
        simplify : bool, optional
            Tidy each entry for display: expand, use ``s_i**2 = 1`` for the span
            signs and ``sin**2 + cos**2 = 1`` for the mount angles (cheap: the
            entries are small at ``q = 0``).
        """
        zero = dict.fromkeys(self.q, sp.S.Zero)
        M0 = self.M.xreplace(zero)
        if simplify:
            signs = {app.span_sign for app in self.appendages}
            angles = [a for app in self.appendages for a in (app.mount_yaw, app.sadm)]
            M0 = M0.applyfunc(lambda e: _tidy(e, signs, angles))
        return sp.ImmutableMatrix(M0)

    def equations_text(self, format: Literal["latex", "pretty"] = "latex") -> str:
        """Readable export of the model.

        Lists the generalized coordinates, the kinematics, the energies ``T`` (per
        body, in full), ``U`` and ``D``, the equation of motion with the
        definitions of its terms, ``K``, ``C`` and the non-zero entries of the mass
        matrix at ``q = 0`` (upper triangle; ``M`` is symmetric).

        Parameters
        ----------
        format : {"latex", "pretty"}
            ``"latex"``: LaTeX source (``align*`` blocks, needs ``amsmath``) to
            paste into a document. ``"pretty"``: Unicode text for a terminal.

        Returns
        -------
        str
        """
        if format == "latex":
            return _equations_latex(self)
        if format == "pretty":
            return _equations_pretty(self)
        raise ValueError(f"format must be 'latex' or 'pretty', got {format!r}")


def _derive(n_appendages: int, panel_rates: PanelRates) -> SymbolicModel:
    q_list, qd_list = _coordinates(n_appendages)
    q = sp.Matrix(q_list)
    qd = sp.Matrix(qd_list)
    hub = _hub_symbols()
    apps = tuple(_appendage_symbols(i) for i in range(n_appendages))
    half = sp.Rational(1, 2)

    # Hub: velocity and angular velocity in B (eq. 2.28), kinetic energy (eq. 2.32).
    phi, theta, psi = q[3], q[4], q[5]
    R_NB = rot_zyx(phi, theta, psi)
    v_B = R_NB.T * qd[0:3, 0]
    omega_B = euler_rate_matrix(phi, theta) * qd[3:6, 0]
    T_hub = half * hub.mass * v_B.dot(v_B) + half * omega_B.dot(hub.inertia * omega_B)
    T_bodies = [T_hub]

    U = sp.S.Zero
    D = sp.S.Zero
    r_Gs, v_Gs, omega_Ps = [], [], []
    for i, app in enumerate(apps):
        o = 6 + 6 * i
        eta, rho = q[o : o + 3, 0], q[o + 3 : o + 6, 0]
        rho_dot = qd[o + 3 : o + 6, 0]
        R_BM = rotation("z", app.mount_yaw) * rotation("y", app.sadm)
        R_MP = rot_zyx(rho[0], rho[1], rho[2])
        d = sp.Matrix([0, app.span_sign * app.length / 2, 0])
        # Panel CoM position in B (eq. 2.29) and its exact time derivative (chain rule).
        r_G = app.mount_point + R_BM * (eta + R_MP * d)
        r_G_dot = r_G.jacobian(q) * qd
        v_G = v_B + omega_B.cross(r_G) + r_G_dot  # eq. 2.30
        if panel_rates == "exact":
            omega_rel = euler_rate_matrix(rho[0], rho[1]) * rho_dot
        else:
            omega_rel = rho_dot
        omega_P = (R_BM * R_MP).T * omega_B + omega_rel  # eq. 2.31
        J_p = sp.diag(*app.inertia_diag)
        T_i = half * app.mass * v_G.dot(v_G) + half * omega_P.dot(J_p * omega_P)  # eqs. 2.33-2.34
        T_bodies.append(T_i)
        for j in range(6):
            U += half * app.stiffness[j] * q[o + j] ** 2  # eq. 2.35
            D += half * app.damping[j] * qd[o + j] ** 2  # eq. 2.36
        r_Gs.append(sp.ImmutableMatrix(r_G))
        v_Gs.append(sp.ImmutableMatrix(v_G))
        omega_Ps.append(sp.ImmutableMatrix(omega_P))

    T = sp.Add(*T_bodies)
    # Euler-Lagrange (eqs. 2.37-2.48).
    dT_dqd = sp.Matrix([T]).jacobian(qd)
    p = dT_dqd.T  # generalized momenta
    M = p.jacobian(qd)  # eq. 2.39
    h = p.jacobian(q) * qd - sp.Matrix([T]).jacobian(q).T  # eqs. 2.43-2.44
    k_el = sp.Matrix([U]).jacobian(q).T
    C_damp = sp.hessian(D, qd)

    return SymbolicModel(
        n_appendages=n_appendages,
        panel_rates=panel_rates,
        q=sp.ImmutableMatrix(q),
        qd=sp.ImmutableMatrix(qd),
        hub=hub,
        appendages=apps,
        v_B=sp.ImmutableMatrix(v_B),
        omega_B=sp.ImmutableMatrix(omega_B),
        r_G=tuple(r_Gs),
        v_G=tuple(v_Gs),
        omega_P=tuple(omega_Ps),
        T_bodies=tuple(T_bodies),
        T=T,
        U=U,
        D=D,
        M=sp.ImmutableMatrix(M),
        h=sp.ImmutableMatrix(h),
        k_el=sp.ImmutableMatrix(k_el),
        C_damp=sp.ImmutableMatrix(C_damp),
    )
