"""Reference equations of motion of the flexible satellite, derived symbolically (SymPy).

This module is the human-readable reference formulation of the dynamics: a plain
Euler-Lagrange derivation from the kinetic, potential and dissipation energies
(thesis ch. 2, eqs. 2.28-2.48, generalized to N appendages). It shares no code with
the compiled engine (:mod:`flexsat.dynamics.kernels`), which is checked against it.

Generalized coordinates, ``n = 6 + 6N``::

    q[0:3]          r        hub centre-of-mass position, inertial frame N [m]
    q[3:6]          Theta    hub ZYX Euler angles (phi, theta, psi) [rad]
    q[6+6i:9+6i]    eta_i    root translation of appendage i, mount frame M_i [m]
    q[9+6i:12+6i]   rho_i    root rotation of appendage i, ZYX angles [rad]

Kinematics (``R_NB = Rz(psi) Ry(theta) Rx(phi)`` maps hub-frame components to
inertial ones)::

    v_B     = R_NB^T r_dot                               hub velocity, frame B
    omega_B = S(phi, theta) Theta_dot                    hub rate, frame B (eq. 2.28)
    R_BM    = Rz(gamma_i) Ry(alpha_i)                    mount yaw, then SADM angle
    R_MP    = Rz(rho_z) Ry(rho_y) Rx(rho_x)              panel -> mount
    d_i     = [0, s_i L_i / 2, 0]                        root -> panel CoM, frame P
    r_G     = r_m + R_BM (eta + R_MP d)                  panel CoM in B (eq. 2.29)
    v_G     = v_B + omega_B x r_G + d/dt r_G             panel CoM velocity in B (eq. 2.30)
    omega_P = (R_BM R_MP)^T omega_B + S(rho) rho_dot     panel rate, frame P (eq. 2.31)

with ``S(a, b) = [[1, 0, -sin b], [0, cos a, cos b sin a], [0, -sin a, cos b cos a]]``.
The ``"small_angle"`` variant uses ``rho_dot`` in place of ``S(rho) rho_dot``, which
is eq. 2.31 as the thesis prints it. ``d/dt r_G`` is the exact chain-rule derivative
``(dr_G/dq) q_dot``.

Energies and equations::

    T = 1/2 m_h v_B.v_B + 1/2 omega_B.J_h omega_B
        + sum_i 1/2 m_i v_G.v_G + 1/2 omega_P.J_p omega_P        (eqs. 2.32-2.34)
    U = sum_i 1/2 q_i^T diag(k_i) q_i,  D = sum_i 1/2 q_dot_i^T diag(c_i) q_dot_i
    p = dT/dq_dot,  M = dp/dq_dot,  h = (dp/dq) q_dot - (dT/dq)^T,
    k_el = dU/dq,   C = d^2 D / dq_dot^2
    M q_ddot + h + C q_dot + k_el = Q                             (eqs. 2.37-2.48)

Every physical parameter stays a symbol, so one derivation serves every numeric
configuration with the same number of appendages. :func:`derive` returns the
symbolic model; :func:`reference_model` compiles it to plain Python (common
subexpressions eliminated) for numeric evaluation. A fresh derivation takes about
6 s, 11 s and 20 s for N = 1, 2 and 3, and code generation 1-3 s more, so both the
derived model (pickle) and the generated source are cached on disk, keyed by the
topology, this file's source and the SymPy and Python versions: under
``$FLEXSAT_CACHE_DIR`` or, by default, ``~/.cache/flexsat`` (see :func:`cache_dir`).
Loading a pickle or generated source runs code, so every cache file is signed
(HMAC-SHA256) with a per-user secret key kept apart from the cache
(``~/.config/flexsat/cache-key``, mode 0600): a file planted in the cache folder is
never unpickled or executed, only regenerated. Within one process, results are
memoized per topology.
"""

from __future__ import annotations

import contextlib
import functools
import hashlib
import hmac
import math
import os
import pickle
import secrets
import sys
import tempfile
import textwrap
import warnings
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any, Literal

import numpy as np
import sympy as sp
from numpy.typing import ArrayLike
from sympy.printing.pycode import PythonCodePrinter

if TYPE_CHECKING:
    from flexsat.config import SatelliteConfig

__all__ = [
    "AppendageSymbols",
    "HubSymbols",
    "PanelRates",
    "ReferenceModel",
    "ReferenceParameters",
    "SymbolicModel",
    "cache_dir",
    "derive",
    "euler_rate_matrix",
    "reference_model",
    "rot_x",
    "rot_y",
    "rot_z",
    "rot_zyx",
]

PanelRates = Literal["exact", "small_angle"]
_PANEL_RATES = ("exact", "small_angle")

#: Bump when the layout of the generated source changes.
_CODEGEN_VERSION = 1
_AXES = ("x", "y", "z")
_JOINT_AXES = ("x", "y", "z", "rx", "ry", "rz")


# ---------------------------------------------------------------------------
# Rotations and Euler-rate matrix
# ---------------------------------------------------------------------------


def rot_x(a: sp.Expr) -> sp.Matrix:
    """Rotation by ``a`` about X: child-frame components to parent-frame components."""
    c, s = sp.cos(a), sp.sin(a)
    return sp.Matrix([[1, 0, 0], [0, c, -s], [0, s, c]])


def rot_y(a: sp.Expr) -> sp.Matrix:
    """Rotation by ``a`` about Y: child-frame components to parent-frame components."""
    c, s = sp.cos(a), sp.sin(a)
    return sp.Matrix([[c, 0, s], [0, 1, 0], [-s, 0, c]])


def rot_z(a: sp.Expr) -> sp.Matrix:
    """Rotation by ``a`` about Z: child-frame components to parent-frame components."""
    c, s = sp.cos(a), sp.sin(a)
    return sp.Matrix([[c, -s, 0], [s, c, 0], [0, 0, 1]])


def rot_zyx(a_x: sp.Expr, a_y: sp.Expr, a_z: sp.Expr) -> sp.Matrix:
    """ZYX Euler rotation ``Rz(a_z) Ry(a_y) Rx(a_x)`` (thesis eq. 2.25)."""
    return rot_z(a_z) * rot_y(a_y) * rot_x(a_x)


def euler_rate_matrix(a_x: sp.Expr, a_y: sp.Expr) -> sp.Matrix:
    """Matrix ``S`` mapping ZYX Euler-angle rates to the body rate (thesis eq. 2.28).

    ``omega = S(a_x, a_y) @ [a_x_dot, a_y_dot, a_z_dot]``, body-frame components.
    """
    return sp.Matrix(
        [
            [1, 0, -sp.sin(a_y)],
            [0, sp.cos(a_x), sp.cos(a_y) * sp.sin(a_x)],
            [0, -sp.sin(a_x), sp.cos(a_y) * sp.cos(a_x)],
        ]
    )


# ---------------------------------------------------------------------------
# Symbols
# ---------------------------------------------------------------------------


def _sym(name: str) -> sp.Symbol:
    return sp.Symbol(name)


@dataclass(frozen=True, eq=False)
class HubSymbols:
    """Parameter symbols of the hub.

    Attributes
    ----------
    mass : Symbol
        Hub mass ``m_h`` [kg].
    inertia : ImmutableMatrix
        Symmetric 3x3 inertia about the hub centre of mass in frame B, built from
        the six symbols ``J_hxx, J_hyy, J_hzz, J_hxy, J_hxz, J_hyz`` [kg m^2].
    """

    mass: sp.Symbol
    inertia: sp.ImmutableMatrix

    def flat(self) -> tuple[sp.Symbol, ...]:
        """Symbols in parameter-vector order: m_h, J_xx, J_yy, J_zz, J_xy, J_xz, J_yz."""
        j = self.inertia
        return (self.mass, j[0, 0], j[1, 1], j[2, 2], j[0, 1], j[0, 2], j[1, 2])


@dataclass(frozen=True, eq=False)
class AppendageSymbols:
    """Parameter symbols of one appendage (index ``i`` is 1-based in the names).

    Attributes
    ----------
    mount_point : ImmutableMatrix
        Root position ``r_m,i`` from the hub centre of mass, frame B (3x1) [m].
    mount_yaw : Symbol
        Mount-frame rotation ``gamma_i`` about Z_B [rad].
    sadm : Symbol
        SADM angle ``alpha_i`` about the yawed Y axis [rad].
    span_sign : Symbol
        ``s_i = +1`` when the plate spans along +Y_P, -1 along -Y_P.
    length : Symbol
        Panel length ``L_i`` [m].
    mass : Symbol
        Panel mass ``m_i`` [kg].
    inertia_diag : tuple of Symbol
        Principal inertia ``(J_ixx, J_iyy, J_izz)`` about the panel CoM, frame P [kg m^2].
    stiffness, damping : tuple of Symbol
        Joint stiffness ``k_i`` and damping ``c_i`` per DOF, order
        ``(x, y, z, rx, ry, rz)``.
    """

    mount_point: sp.ImmutableMatrix
    mount_yaw: sp.Symbol
    sadm: sp.Symbol
    span_sign: sp.Symbol
    length: sp.Symbol
    mass: sp.Symbol
    inertia_diag: tuple[sp.Symbol, sp.Symbol, sp.Symbol]
    stiffness: tuple[sp.Symbol, ...]
    damping: tuple[sp.Symbol, ...]

    def flat(self) -> tuple[sp.Symbol, ...]:
        """Symbols in parameter-vector order (23): r_m (3), gamma, alpha, s, L, m,
        J_p diagonal (3), k (6), c (6)."""
        return (
            *self.mount_point,
            self.mount_yaw,
            self.sadm,
            self.span_sign,
            self.length,
            self.mass,
            *self.inertia_diag,
            *self.stiffness,
            *self.damping,
        )


def _hub_symbols() -> HubSymbols:
    jxx, jyy, jzz, jxy, jxz, jyz = (_sym(f"J_h{a}") for a in ("xx", "yy", "zz", "xy", "xz", "yz"))
    inertia = sp.ImmutableMatrix([[jxx, jxy, jxz], [jxy, jyy, jyz], [jxz, jyz, jzz]])
    return HubSymbols(mass=_sym("m_h"), inertia=inertia)


def _appendage_symbols(i: int) -> AppendageSymbols:
    k = i + 1
    return AppendageSymbols(
        mount_point=sp.ImmutableMatrix([_sym(f"r_m{k}{a}") for a in _AXES]),
        mount_yaw=_sym(f"gamma_{k}"),
        sadm=_sym(f"alpha_{k}"),
        span_sign=_sym(f"s_{k}"),
        length=_sym(f"L_{k}"),
        mass=_sym(f"m_{k}"),
        inertia_diag=tuple(_sym(f"J_{k}{a}{a}") for a in _AXES),
        stiffness=tuple(_sym(f"k_{k}{a}") for a in _JOINT_AXES),
        damping=tuple(_sym(f"c_{k}{a}") for a in _JOINT_AXES),
    )


def _coordinates(n_appendages: int) -> tuple[list[sp.Symbol], list[sp.Symbol]]:
    q = [_sym(f"r_{a}") for a in _AXES] + [_sym(a) for a in ("phi", "theta", "psi")]
    qd = [_sym(f"rdot_{a}") for a in _AXES] + [_sym(f"{a}dot") for a in ("phi", "theta", "psi")]
    for i in range(n_appendages):
        k = i + 1
        q += [_sym(f"eta_{k}{a}") for a in _AXES] + [_sym(f"rho_{k}{a}") for a in _AXES]
        qd += [_sym(f"etadot_{k}{a}") for a in _AXES]
        qd += [_sym(f"rhodot_{k}{a}") for a in _AXES]
    return q, qd


# ---------------------------------------------------------------------------
# Derivation
# ---------------------------------------------------------------------------


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


def _check_topology(n_appendages: int, panel_rates: str) -> None:
    if isinstance(n_appendages, bool) or not isinstance(n_appendages, int | np.integer):
        raise TypeError(f"n_appendages must be an int, got {type(n_appendages).__name__}")
    if n_appendages < 0:
        raise ValueError(f"n_appendages must be >= 0, got {n_appendages}")
    if panel_rates not in _PANEL_RATES:
        raise ValueError(f"panel_rates must be 'exact' or 'small_angle', got {panel_rates!r}")


def derive(
    n_appendages: int, panel_rates: PanelRates = "exact", *, cache: bool = True
) -> SymbolicModel:
    """Derive the equations of motion of a hub carrying ``n_appendages`` appendages.

    Parameters
    ----------
    n_appendages : int
        Number of flexible appendages N (``>= 0``).
    panel_rates : {"exact", "small_angle"}
        Panel angular velocity relative to its mount: ``"exact"`` uses
        ``S(rho) rho_dot``; ``"small_angle"`` uses ``rho_dot`` (eq. 2.31 as the
        thesis prints it). Both agree at ``rho = 0``.
    cache : bool, optional
        Reuse the model derived earlier in this process or stored in the disk
        cache (see :func:`cache_dir`), and store it there. ``False`` always derives
        afresh and touches no file.

    Returns
    -------
    SymbolicModel
        The symbols, kinematics, energies and the terms ``M, h, k_el, C_damp``.

    Notes
    -----
    A fresh derivation takes several seconds (about 6 s for N = 1, 11 s for
    N = 2, 20 s for N = 3); no simplification is attempted. The disk cache
    brings a repeated call in a new process down to a fraction of a second.
    """
    _check_topology(n_appendages, panel_rates)
    n = int(n_appendages)
    if not cache:
        return _derive(n, panel_rates)
    return _derive_cached(n, panel_rates)


@functools.cache
def _derive_cached(n_appendages: int, panel_rates: PanelRates) -> SymbolicModel:
    return _load_model(n_appendages, panel_rates, _cache_subdir())


def _load_model(
    n_appendages: int, panel_rates: PanelRates, directory: Path | None
) -> SymbolicModel:
    """The model from ``directory`` if stored there and valid, else derived and stored."""
    path = _cache_path(directory, "model", n_appendages, panel_rates, ".pickle")
    if path is not None:
        data = _read_signed(path)  # unpickling runs code: only what this user wrote
        try:
            model = pickle.loads(data) if data is not None else None
        except Exception:  # stale or damaged: derive again and overwrite it
            model = None
        if (
            isinstance(model, SymbolicModel)
            and model.n_appendages == n_appendages
            and model.panel_rates == panel_rates
        ):
            return model
    model = _derive(n_appendages, panel_rates)
    if path is not None:
        _write_atomic(path, pickle.dumps(model, protocol=pickle.HIGHEST_PROTOCOL))
    return model


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
        R_BM = rot_z(app.mount_yaw) * rot_y(app.sadm)
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


# ---------------------------------------------------------------------------
# Readable export
# ---------------------------------------------------------------------------

_PRETTY_COLUMNS = 100


def _display_parts(m: SymbolicModel, i: int) -> tuple[sp.Matrix, sp.Matrix]:
    """R_BM and d of appendage ``i``, rebuilt for display."""
    app = m.appendages[i]
    R_BM = rot_z(app.mount_yaw) * rot_y(app.sadm)
    d = sp.Matrix([0, app.span_sign * app.length / 2, 0])
    return R_BM, d


def _stiffness_damping(m: SymbolicModel) -> tuple[list[sp.Expr], list[sp.Expr]]:
    K = sp.hessian(m.U, m.q)
    return [K[j, j] for j in range(m.n_dof)], [m.C_damp[j, j] for j in range(m.n_dof)]


def _tidy(expr: sp.Expr, signs: set[sp.Symbol], angles: Sequence[sp.Symbol]) -> sp.Expr:
    """Cheap cleanup of a small expression for display.

    Uses ``s**(2k) = 1`` for the span signs and, per angle, whichever of
    ``sin**2 = 1 - cos**2`` and ``cos**2 = 1 - sin**2`` (or neither) gives the
    fewest operations after expansion. Polynomial work only, no ``trigsimp``.
    """
    if expr == 0:
        return expr
    expr = sp.expand(expr).replace(
        lambda e: e.is_Pow and e.base in signs and e.exp.is_even, lambda e: sp.S.One
    )
    expr = sp.expand(expr)
    for a in angles:
        if not expr.has(a):
            continue
        with_cos = sp.expand(expr.xreplace({sp.sin(a) ** 2: 1 - sp.cos(a) ** 2}))
        with_sin = sp.expand(expr.xreplace({sp.cos(a) ** 2: 1 - sp.sin(a) ** 2}))
        expr = min((expr, with_cos, with_sin), key=sp.count_ops)
    return sp.factor_terms(expr)


def _mass_entries_at_rest(m: SymbolicModel) -> list[tuple[int, int, sp.Expr]]:
    M0 = m.M_at_rest(simplify=True)
    return [(r, c, M0[r, c]) for r in range(m.n_dof) for c in range(r, m.n_dof) if M0[r, c] != 0]


def _equations_latex(m: SymbolicModel) -> str:
    L = sp.latex
    a_x, a_y = sp.symbols("a_x a_y")
    rows: list[str] = []

    def block(title: str, lines: Sequence[str]) -> None:
        rows.append(rf"\paragraph{{{title}}}")
        rows.append(r"\begin{align*}")
        rows.append(" \\\\\n".join(lines))
        rows.append(r"\end{align*}")

    def tup(symbols: Sequence[sp.Expr]) -> str:
        return r"\left(" + ",\\ ".join(L(s) for s in symbols) + r"\right)"

    def vec(symbols: Sequence[sp.Expr]) -> str:
        return tup(symbols) + "^{T}"

    rows.append(
        f"% flexsat reference equations of motion: {m.n_appendages} appendage(s), "
        f"panel rates '{m.panel_rates}'."
    )
    rows.append("% LaTeX with amsmath; very long lines may need breqn or manual breaks.")
    block(
        "Generalized coordinates",
        [rf"q &= {vec(list(m.q))}", rf"\dot{{q}} &= {vec(list(m.qd))}"],
    )
    kin = [
        r"R_{NB} &= R_z(\psi)\, R_y(\theta)\, R_x(\phi)",
        rf"S(a_x, a_y) &= {L(euler_rate_matrix(a_x, a_y))}",
        rf"v_B &= R_{{NB}}^{{T}} \dot{{r}} = {L(m.v_B)}",
        rf"\omega_B &= S(\phi, \theta)\, \dot{{\Theta}} = {L(m.omega_B)}",
        rf"J_h &= {L(m.hub.inertia)}",
    ]
    block("Hub kinematics", kin)
    for i, app in enumerate(m.appendages):
        k = i + 1
        R_BM, d = _display_parts(m, i)
        o = 6 + 6 * i
        rho = [L(s) for s in m.q[o + 3 : o + 6]]
        if m.panel_rates == "exact":
            rel = rf"S({rho[0]}, {rho[1]})\, \dot{{\rho}}_{{{k}}}"
        else:
            rel = rf"\dot{{\rho}}_{{{k}}}"
        lines = [
            rf"R_{{BM,{k}}} &= R_z({L(app.mount_yaw)})\, R_y({L(app.sadm)}) = {L(R_BM)}",
            rf"R_{{MP,{k}}} &= R_z({rho[2]})\, R_y({rho[1]})\, R_x({rho[0]})",
            rf"d_{{{k}}} &= {L(d)}, \qquad r_{{m,{k}}} = {L(app.mount_point)}",
            rf"r_{{G,{k}}} &= r_{{m,{k}}} + R_{{BM,{k}}} "
            rf"\left(\eta_{{{k}}} + R_{{MP,{k}}} d_{{{k}}}\right)",
            rf"v_{{G,{k}}} &= v_B + \omega_B \times r_{{G,{k}}} + \dot{{r}}_{{G,{k}}}, "
            rf"\qquad \dot{{r}}_{{G,{k}}} = \frac{{\partial r_{{G,{k}}}}}{{\partial q}} \dot{{q}}",
            rf"\omega_{{P,{k}}} &= \left(R_{{BM,{k}}} R_{{MP,{k}}}\right)^{{T}} \omega_B + {rel}",
            rf"J_{{p,{k}}} &= \operatorname{{diag}}{tup(app.inertia_diag)}",
        ]
        for axis, expr in zip(_AXES, m.v_G[i], strict=True):
            lines.append(rf"v_{{G,{k},{axis}}} &= {L(expr)}")
        for axis, expr in zip(_AXES, m.omega_P[i], strict=True):
            lines.append(rf"\omega_{{P,{k},{axis}}} &= {L(expr)}")
        block(f"Appendage {k} kinematics", lines)
    energies = [
        r"T &= T_h + \sum_{i} T_i",
        r"T_h &= \tfrac{1}{2} m_h v_B^{T} v_B + \tfrac{1}{2} \omega_B^{T} J_h \omega_B"
        rf" = {L(m.T_bodies[0])}",
    ]
    for i in range(m.n_appendages):
        k = i + 1
        energies.append(
            rf"T_{{{k}}} &= \tfrac{{1}}{{2}} m_{{{k}}} v_{{G,{k}}}^{{T}} v_{{G,{k}}} "
            rf"+ \tfrac{{1}}{{2}} \omega_{{P,{k}}}^{{T}} J_{{p,{k}}} \omega_{{P,{k}}} "
            rf"= {L(m.T_bodies[k])}"
        )
    energies += [rf"U &= {L(m.U)}", rf"D &= {L(m.D)}"]
    block("Energies", energies)
    stiff, damp = _stiffness_damping(m)
    block(
        "Equations of motion",
        [
            r"M(q)\, \ddot{q} + h(q, \dot{q}) + C \dot{q} + k_{el}(q) &= Q",
            r"p &= \left(\frac{\partial T}{\partial \dot{q}}\right)^{T}, \qquad "
            r"M = \frac{\partial p}{\partial \dot{q}}, \qquad "
            r"h = \frac{\partial p}{\partial q} \dot{q} - \left(\frac{\partial T}{\partial q}"
            r"\right)^{T} = \dot{M} \dot{q} - \left(\frac{\partial T}{\partial q}\right)^{T}",
            r"k_{el} &= \left(\frac{\partial U}{\partial q}\right)^{T} = K q, \qquad "
            r"C = \frac{\partial^2 D}{\partial \dot{q}^2}",
            rf"K &= \operatorname{{diag}}{tup(stiff)}",
            rf"C &= \operatorname{{diag}}{tup(damp)}",
        ],
    )
    names = [L(s) for s in m.q]
    block(
        r"Mass matrix at $q = 0$ (non-zero entries of the upper triangle; $M$ is symmetric)",
        [rf"M_{{{names[r]},\, {names[c]}}} &= {L(e)}" for r, c, e in _mass_entries_at_rest(m)],
    )
    return "\n".join(rows) + "\n"


def _equations_pretty(m: SymbolicModel) -> str:
    def pp(expr: Any) -> str:
        return sp.pretty(expr, use_unicode=True, wrap_line=True, num_columns=_PRETTY_COLUMNS)

    def eq(lhs: str, expr: Any) -> str:
        body = sp.pretty(expr, use_unicode=True, wrap_line=False)
        lines = body.splitlines()
        if len(lines) == 1 and len(lhs) + len(body) + 5 <= _PRETTY_COLUMNS:
            return f"  {lhs} = {body}"
        if max(len(line) for line in lines) + 6 <= _PRETTY_COLUMNS:
            return f"  {lhs} =\n" + "\n".join("      " + line for line in lines)
        if isinstance(expr, sp.MatrixBase) and expr.shape[1] == 1:
            labels = _AXES if expr.shape[0] == 3 else range(expr.shape[0])
            return "\n".join(eq(f"{lhs}  [{k}]", e) for k, e in zip(labels, expr, strict=True))
        # Too wide for a 2-D layout: linear form, wrapped at the operators.
        text = textwrap.fill(
            sp.sstr(expr),
            width=_PRETTY_COLUMNS,
            initial_indent="      ",
            subsequent_indent="        ",
            break_long_words=False,
        )
        return f"  {lhs} =\n{text}"

    def names(symbols: Sequence[sp.Expr]) -> str:
        return ", ".join(pp(s) for s in symbols)

    a_x, a_y = sp.symbols("a_x a_y")
    out: list[str] = [
        f"flexsat reference equations of motion: {m.n_appendages} appendage(s), "
        f"panel rates '{m.panel_rates}'",
        "",
        f"Generalized coordinates (n = {m.n_dof})",
        f"  q = ({names(list(m.q))})",
        f"  q̇ = ({names(list(m.qd))})",
        "",
        "Hub kinematics",
        "  R_NB = Rz(ψ) Ry(θ) Rx(φ)          (body -> inertial)",
        eq("S(a_x, a_y)", euler_rate_matrix(a_x, a_y)),
        eq("v_B = R_NBᵀ ṙ", m.v_B),
        eq("ω_B = S(φ, θ) Θ̇", m.omega_B),
        eq("J_h", m.hub.inertia),
    ]
    for i, app in enumerate(m.appendages):
        k = i + 1
        R_BM, d = _display_parts(m, i)
        o = 6 + 6 * i
        rho = [pp(s) for s in m.q[o + 3 : o + 6]]
        rel = f"S({rho[0]}, {rho[1]}) ρ̇_{k}" if m.panel_rates == "exact" else f"ρ̇_{k}"
        out += [
            "",
            f"Appendage {k} kinematics",
            eq(f"R_BM,{k} = Rz({pp(app.mount_yaw)}) Ry({pp(app.sadm)})", R_BM),
            f"  R_MP,{k} = Rz({rho[2]}) Ry({rho[1]}) Rx({rho[0]})    (panel -> mount)",
            eq(f"d_{k}", d),
            eq(f"r_m,{k}", app.mount_point),
            f"  r_G,{k} = r_m,{k} + R_BM,{k} (η_{k} + R_MP,{k} d_{k})",
            f"  v_G,{k} = v_B + ω_B × r_G,{k} + ṙ_G,{k},    ṙ_G,{k} = (∂r_G,{k}/∂q) q̇",
            f"  ω_P,{k} = (R_BM,{k} R_MP,{k})ᵀ ω_B + {rel}",
            f"  J_p,{k} = diag({names(app.inertia_diag)})",
        ]
        out += [eq(f"v_G,{k},{a}", e) for a, e in zip(_AXES, m.v_G[i], strict=True)]
        out += [eq(f"ω_P,{k},{a}", e) for a, e in zip(_AXES, m.omega_P[i], strict=True)]
    out += [
        "",
        "Energies",
        "  T = T_h + Σ_i T_i",
        eq("T_h = ½ m_h v_Bᵀ v_B + ½ ω_Bᵀ J_h ω_B", m.T_bodies[0]),
    ]
    for i in range(m.n_appendages):
        k = i + 1
        out.append(
            eq(f"T_{k} = ½ m_{k} v_G,{k}ᵀ v_G,{k} + ½ ω_P,{k}ᵀ J_p,{k} ω_P,{k}", m.T_bodies[k])
        )
    out += [eq("U", m.U), eq("D", m.D)]
    stiff, damp = _stiffness_damping(m)
    out += [
        "",
        "Equations of motion",
        "  M(q) q̈ + h(q, q̇) + C q̇ + k_el(q) = Q",
        "  p = (∂T/∂q̇)ᵀ,  M = ∂p/∂q̇,  h = (∂p/∂q) q̇ - (∂T/∂q)ᵀ = Ṁ q̇ - (∂T/∂q)ᵀ",
        "  k_el = (∂U/∂q)ᵀ = K q,  C = ∂²D/∂q̇²",
        f"  K = diag({names(stiff)})",
        f"  C = diag({names(damp)})",
        "",
        "Mass matrix at q = 0 (non-zero entries of the upper triangle; M is symmetric)",
    ]
    q_names = [pp(s) for s in m.q]
    out += [eq(f"M[{q_names[r]}, {q_names[c]}]", e) for r, c, e in _mass_entries_at_rest(m)]
    return "\n".join(out) + "\n"


# ---------------------------------------------------------------------------
# Disk cache
# ---------------------------------------------------------------------------


def cache_dir() -> Path:
    """Directory of the on-disk cache: ``$FLEXSAT_CACHE_DIR``, else ``~/.cache/flexsat``.

    Derived models and generated numeric code live in its ``symbolic/``
    subdirectory. Files are named by topology (number of appendages, panel-rate
    variant) and a hash of this module's source, the SymPy version and the
    Python version, so a stale file is never used; it is safe to delete the
    directory at any time. The directory is read once per process and topology.
    """
    env = os.environ.get("FLEXSAT_CACHE_DIR")
    return Path(env).expanduser() if env else Path.home() / ".cache" / "flexsat"


def _cache_subdir() -> Path:
    return cache_dir() / "symbolic"


@functools.cache
def _fingerprint() -> str | None:
    """Hash of this module's source and the tool versions; ``None`` disables the cache."""
    try:
        source = Path(__file__).read_bytes()
    except OSError:
        return None
    digest = hashlib.sha256(source)
    digest.update(
        f"|sympy {sp.__version__}|python {sys.version_info[0]}.{sys.version_info[1]}"
        f"|codegen {_CODEGEN_VERSION}".encode()
    )
    return digest.hexdigest()[:20]


def _cache_path(
    directory: Path | None, kind: str, n_appendages: int, panel_rates: str, suffix: str
) -> Path | None:
    key = _fingerprint()
    if directory is None or key is None:
        return None
    return directory / f"{kind}-n{n_appendages}-{panel_rates}-{key}{suffix}"


_SIGNATURE = b"flexsat-hmac-sha256:"


def _key_path() -> Path:
    """This user's secret cache key: kept apart from the cache, in the config folder."""
    config = os.environ.get("XDG_CONFIG_HOME") or Path.home() / ".config"
    return Path(config) / "flexsat" / "cache-key"


def _cache_key() -> bytes | None:
    """The cache key (created on first use, mode 0600); None if it cannot be trusted.

    Cache files are signed with it (HMAC-SHA256), so a file planted in the cache
    folder by anyone who cannot read this key is never unpickled or executed.
    """
    path = _key_path()
    try:
        if not path.exists():
            path.parent.mkdir(parents=True, exist_ok=True)
            fd = os.open(path, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o600)
            with os.fdopen(fd, "wb") as f:
                f.write(secrets.token_bytes(32))
        info = path.stat()
        if info.st_uid != os.getuid() or info.st_mode & 0o077:
            return None  # not this user's, or readable by others
        key = path.read_bytes()
    except OSError:
        return None
    return key if len(key) >= 32 else None


def _read_signed(path: Path) -> bytes | None:
    """The payload of a cache file whose signature checks with this user's key, else None."""
    key = _cache_key()
    try:
        data = path.read_bytes()
    except OSError:
        return None
    header, _, payload = data.partition(b"\n")
    if key is None or not header.startswith(_SIGNATURE):
        return None
    expected = hmac.new(key, payload, hashlib.sha256).hexdigest().encode()
    return payload if hmac.compare_digest(header[len(_SIGNATURE) :], expected) else None


def _write_atomic(path: Path, data: bytes) -> None:
    """Write ``data``, signed, to ``path`` via a temporary file and ``os.replace``.

    Readers in other processes see either no file or a complete one. Failure to
    write (read-only or full disk, no usable key) only costs the cache, with a warning.
    """
    key = _cache_key()
    if key is None:
        warnings.warn(
            f"flexsat: no usable cache key ({_key_path()}); the symbolic cache is off",
            RuntimeWarning,
            stacklevel=3,
        )
        return
    signature = hmac.new(key, data, hashlib.sha256).hexdigest().encode()
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.", suffix=".tmp")
        try:
            with os.fdopen(fd, "wb") as f:
                f.write(_SIGNATURE + signature + b"\n" + data)
            os.replace(tmp, path)
        except BaseException:
            with contextlib.suppress(OSError):
                os.unlink(tmp)
            raise
    except OSError as exc:
        warnings.warn(
            f"flexsat: cannot write the symbolic cache file {path}: {exc}",
            RuntimeWarning,
            stacklevel=3,
        )


# ---------------------------------------------------------------------------
# Code generation
# ---------------------------------------------------------------------------


class _CodePrinter(PythonCodePrinter):
    """Python printer that names the model symbols ``q_j``, ``qd_j`` and ``p_j``."""

    def __init__(self, names: dict[sp.Symbol, str]) -> None:
        super().__init__({"fully_qualified_modules": False})
        self._names = names

    def _print_Symbol(self, expr: sp.Symbol) -> str:
        name = self._names.get(expr)
        return name if name is not None else super()._print_Symbol(expr)


def _function_source(
    printer: _CodePrinter,
    name: str,
    args: Sequence[tuple[str, Sequence[sp.Symbol]]],
    exprs: Sequence[sp.Expr],
    doc: str,
) -> str:
    lines = [f"def {name}({', '.join(a for a, _ in args)}):", f'    """{doc}"""']
    for arg, symbols in args:
        if symbols:
            lines.append(f"    ({', '.join(printer._names[s] for s in symbols)},) = {arg}")
    used = set().union(*(e.free_symbols for e in exprs)) if exprs else set()
    temporaries = sp.numbered_symbols("x", exclude=used)
    replacements, reduced = sp.cse(list(exprs), symbols=temporaries, order="none")
    for sym, expr in replacements:
        lines.append(f"    {sym} = {printer.doprint(expr)}")
    lines.append("    return (")
    lines += [f"        {printer.doprint(e)}," for e in reduced]
    lines.append("    )")
    return "\n".join(lines)


def _generate_source(model: SymbolicModel) -> str:
    """Python source of the numeric functions of ``model`` (plain ``math``, no numpy)."""
    names: dict[sp.Symbol, str] = {}
    for prefix, symbols in (("q", model.q), ("qd", model.qd), ("p", model.parameters)):
        names.update({s: f"{prefix}_{j}" for j, s in enumerate(symbols)})
    printer = _CodePrinter(names)
    q, qd, p = list(model.q), list(model.qd), list(model.parameters)
    functions = [
        _function_source(
            printer,
            "dynamics",
            [("q", q), ("qd", qd), ("p", p)],
            [*model.M, *model.h, *model.k_el, *model.C_damp],
            "M (row-major), h, k_el and C (row-major) as one flat tuple.",
        ),
        _function_source(
            printer,
            "kinetic_energy",
            [("q", q), ("qd", qd), ("p", p)],
            [model.T],
            "Kinetic energy T, as a 1-tuple.",
        ),
        _function_source(
            printer,
            "potential_energy",
            [("q", q), ("p", p)],
            [model.U],
            "Elastic potential energy U, as a 1-tuple.",
        ),
    ]
    imports = [
        f"from {module} import {', '.join(sorted(items))}"
        for module, items in sorted(printer.module_imports.items())
    ]
    header = [
        "# flexsat reference dynamics, generated by flexsat.dynamics.symbolic: do not edit.",
        f"# key: {_fingerprint()}",
        f"# n_appendages: {model.n_appendages}, panel_rates: {model.panel_rates}",
        f"# q order: {', '.join(str(s) for s in q)}",
        f"# p order: {', '.join(str(s) for s in p)}",
    ]
    return "\n".join([*header, *imports, "", "", "\n\n\n".join(functions), ""])


# ---------------------------------------------------------------------------
# Numeric reference model
# ---------------------------------------------------------------------------


def _as_array(value: ArrayLike, shape: tuple[int, ...], name: str) -> np.ndarray:
    arr = np.array(value, dtype=float)
    if arr.shape != shape:
        raise ValueError(f"{name} must have shape {shape}, got {arr.shape}")
    if not np.all(np.isfinite(arr)):
        raise ValueError(f"{name} must be finite")
    arr.flags.writeable = False
    return arr


@dataclass(frozen=True, eq=False)
class ReferenceParameters:
    """Numeric parameters of the reference model (SI units, radians).

    Attributes
    ----------
    hub_mass : float
        Hub mass [kg].
    hub_inertia : ndarray, shape (3, 3)
        Symmetric hub inertia about its centre of mass, frame B [kg m^2].
    mount_point : ndarray, shape (N, 3)
        Appendage root positions from the hub centre of mass, frame B [m].
    mount_yaw : ndarray, shape (N,)
        Mount-frame rotations about Z_B [rad].
    sadm : ndarray, shape (N,)
        SADM angles [rad].
    span_sign : ndarray, shape (N,)
        +1 (span along +Y_P) or -1 (along -Y_P).
    length : ndarray, shape (N,)
        Panel lengths [m].
    mass : ndarray, shape (N,)
        Panel masses [kg].
    inertia_diag : ndarray, shape (N, 3)
        Principal panel inertias about the panel centre of mass, frame P [kg m^2].
    stiffness : ndarray, shape (N, 6)
        Joint stiffness per DOF (x, y, z, rx, ry, rz) [N/m, N m/rad].
    damping : ndarray, shape (N, 6)
        Joint damping per DOF [N s/m, N m s/rad].
    """

    hub_mass: float
    hub_inertia: np.ndarray
    mount_point: np.ndarray
    mount_yaw: np.ndarray
    sadm: np.ndarray
    span_sign: np.ndarray
    length: np.ndarray
    mass: np.ndarray
    inertia_diag: np.ndarray
    stiffness: np.ndarray
    damping: np.ndarray

    def __post_init__(self) -> None:
        hub_mass = float(self.hub_mass)
        if not math.isfinite(hub_mass):
            raise ValueError("hub_mass must be finite")
        object.__setattr__(self, "hub_mass", hub_mass)
        hub_inertia = _as_array(self.hub_inertia, (3, 3), "hub_inertia")
        if not np.allclose(
            hub_inertia,
            hub_inertia.T,
            rtol=0.0,
            atol=1e-12 * max(1.0, float(np.abs(hub_inertia).max())),
        ):
            raise ValueError("hub_inertia must be symmetric")
        object.__setattr__(self, "hub_inertia", hub_inertia)
        n = np.shape(self.mount_point)[0] if np.ndim(self.mount_point) == 2 else -1
        if n < 0:
            raise ValueError(
                f"mount_point must have shape (N, 3), got {np.shape(self.mount_point)}"
            )
        shapes = {
            "mount_point": (n, 3),
            "mount_yaw": (n,),
            "sadm": (n,),
            "span_sign": (n,),
            "length": (n,),
            "mass": (n,),
            "inertia_diag": (n, 3),
            "stiffness": (n, 6),
            "damping": (n, 6),
        }
        for name, shape in shapes.items():
            object.__setattr__(self, name, _as_array(getattr(self, name), shape, name))

    @property
    def n_appendages(self) -> int:
        """Number of appendages N."""
        return int(self.mount_point.shape[0])

    @classmethod
    def from_config(
        cls, config: SatelliteConfig, stiffness: ArrayLike, damping: ArrayLike
    ) -> ReferenceParameters:
        """Parameters of a validated configuration.

        Parameters
        ----------
        config : flexsat.config.SatelliteConfig
            The satellite. Angles are converted from degrees to radians.
        stiffness, damping : array_like, shape (N, 6), (6,) or scalar
            Joint stiffness and damping per appendage and DOF (x, y, z, rx, ry,
            rz), broadcast to (N, 6). The mass matrix does not depend on them.

        Returns
        -------
        ReferenceParameters
        """
        apps = config.appendages
        n = len(apps)
        return cls(
            hub_mass=config.hub.mass_kg,
            hub_inertia=config.hub.inertia(),
            mount_point=[a.mount_point_m for a in apps],
            mount_yaw=np.radians([a.mount_yaw_deg for a in apps]),
            sadm=np.radians([a.sadm_angle_deg for a in apps]),
            span_sign=[a.span_sign() for a in apps],
            length=[a.length_m for a in apps],
            mass=[a.mass for a in apps],
            inertia_diag=[np.diag(a.centroidal_inertia()) for a in apps],
            stiffness=np.broadcast_to(np.asarray(stiffness, dtype=float), (n, 6)),
            damping=np.broadcast_to(np.asarray(damping, dtype=float), (n, 6)),
        )

    def vector(self) -> np.ndarray:
        """Flat parameter vector in the order of :attr:`SymbolicModel.parameters`.

        Hub (7): mass, J_xx, J_yy, J_zz, J_xy, J_xz, J_yz; then per appendage (23):
        mount point (3), yaw, SADM angle, span sign, length, mass, inertia
        diagonal (3), stiffness (6), damping (6).
        """
        j = self.hub_inertia
        parts = [np.array([self.hub_mass, j[0, 0], j[1, 1], j[2, 2], j[0, 1], j[0, 2], j[1, 2]])]
        for i in range(self.n_appendages):
            parts.append(
                np.concatenate(
                    [
                        self.mount_point[i],
                        [self.mount_yaw[i], self.sadm[i], self.span_sign[i]],
                        [self.length[i], self.mass[i]],
                        self.inertia_diag[i],
                        self.stiffness[i],
                        self.damping[i],
                    ]
                )
            )
        return np.concatenate(parts)


class ReferenceModel:
    """Numeric evaluation of the symbolic equations of motion.

    Obtain one with :func:`reference_model`. The functions are generated Python
    (``math`` only) from :func:`derive` with common subexpressions eliminated;
    intended for verification, not speed (about a millisecond per call).

    Attributes
    ----------
    n_appendages : int
    panel_rates : {"exact", "small_angle"}
    n_dof : int
        ``6 + 6 * n_appendages``.
    source : str
        The generated Python source.
    path : Path or None
        The cache file the source was read from or written to, if any.
    """

    def __init__(
        self,
        n_appendages: int,
        panel_rates: PanelRates,
        source: str,
        path: Path | None = None,
    ) -> None:
        namespace: dict[str, Any] = {"__name__": f"flexsat_reference_n{n_appendages}"}
        exec(compile(source, str(path) if path else "<flexsat reference>", "exec"), namespace)
        self.n_appendages = n_appendages
        self.panel_rates = panel_rates
        self.n_dof = 6 + 6 * n_appendages
        self.source = source
        self.path = path
        self._dynamics: Callable[..., tuple[float, ...]] = namespace["dynamics"]
        self._kinetic: Callable[..., tuple[float]] = namespace["kinetic_energy"]
        self._potential: Callable[..., tuple[float]] = namespace["potential_energy"]

    def __repr__(self) -> str:
        return f"ReferenceModel(n_appendages={self.n_appendages}, panel_rates={self.panel_rates!r})"

    def _inputs(self, params: ReferenceParameters, *states: ArrayLike) -> tuple[list[float], ...]:
        if not isinstance(params, ReferenceParameters):
            raise TypeError(f"params must be ReferenceParameters, got {type(params).__name__}")
        if params.n_appendages != self.n_appendages:
            raise ValueError(
                f"params describe {params.n_appendages} appendage(s), the model {self.n_appendages}"
            )
        out = []
        for k, state in enumerate(states):
            arr = np.asarray(state, dtype=float)
            if arr.shape != (self.n_dof,):
                name = ("q", "qd")[k]
                raise ValueError(f"{name} must have shape ({self.n_dof},), got {arr.shape}")
            out.append(arr.tolist())
        return (*out, params.vector().tolist())

    def evaluate(
        self, params: ReferenceParameters, q: ArrayLike, qd: ArrayLike
    ) -> dict[str, np.ndarray]:
        """Terms of ``M q_ddot + h + C q_dot + k_el = Q`` at one state.

        Parameters
        ----------
        params : ReferenceParameters
            Numeric parameters with ``n_appendages`` appendages.
        q, qd : array_like, shape (n_dof,)
            Generalized coordinates and rates.

        Returns
        -------
        dict of str to ndarray
            ``"M"`` (n_dof, n_dof), ``"h"`` (n_dof,), ``"k_el"`` (n_dof,) and
            ``"C"`` (n_dof, n_dof).
        """
        q_, qd_, p_ = self._inputs(params, q, qd)
        flat = np.array(self._dynamics(q_, qd_, p_), dtype=float)
        n = self.n_dof
        nn = n * n
        return {
            "M": flat[:nn].reshape(n, n),
            "h": flat[nn : nn + n],
            "k_el": flat[nn + n : nn + 2 * n],
            "C": flat[nn + 2 * n :].reshape(n, n),
        }

    def kinetic_energy(self, params: ReferenceParameters, q: ArrayLike, qd: ArrayLike) -> float:
        """Kinetic energy ``T`` evaluated directly from the body velocities [J]."""
        q_, qd_, p_ = self._inputs(params, q, qd)
        return float(self._kinetic(q_, qd_, p_)[0])

    def potential_energy(self, params: ReferenceParameters, q: ArrayLike) -> float:
        """Elastic potential energy ``U`` [J]."""
        q_, p_ = self._inputs(params, q)
        return float(self._potential(q_, p_)[0])


def reference_model(
    n_appendages: int, panel_rates: PanelRates = "exact", *, cache: bool = True
) -> ReferenceModel:
    """Numeric reference model for ``n_appendages`` appendages.

    Parameters
    ----------
    n_appendages : int
        Number of appendages N.
    panel_rates : {"exact", "small_angle"}
        Panel angular-velocity variant, see :func:`derive`.
    cache : bool, optional
        Reuse the model built earlier in this process or the generated source in
        the disk cache (:func:`cache_dir`), and store it there. ``False`` derives
        and generates afresh and touches no file.

    Returns
    -------
    ReferenceModel

    Notes
    -----
    A cold build derives the model (see :func:`derive`) and generates code (about
    1 s more); with a warm disk cache it takes well under a second.
    """
    _check_topology(n_appendages, panel_rates)
    n = int(n_appendages)
    if not cache:
        return ReferenceModel(n, panel_rates, _generate_source(derive(n, panel_rates, cache=False)))
    return _reference_model_cached(n, panel_rates)


@functools.cache
def _reference_model_cached(n_appendages: int, panel_rates: PanelRates) -> ReferenceModel:
    return _load_reference(n_appendages, panel_rates, _cache_subdir())


def _load_reference(
    n_appendages: int, panel_rates: PanelRates, directory: Path | None
) -> ReferenceModel:
    """The model from the source in ``directory`` if valid, else generated and stored."""
    path = _cache_path(directory, "reference", n_appendages, panel_rates, ".py")
    if path is not None:
        data = _read_signed(path)  # the source is executed: only what this user wrote
        try:
            source = data.decode("utf-8") if data is not None else ""
        except UnicodeDecodeError:
            pass
        else:
            if f"# key: {_fingerprint()}\n" in source:
                try:
                    return ReferenceModel(n_appendages, panel_rates, source, path)
                except Exception:  # a damaged file: generate again and overwrite it
                    pass
    source = _generate_source(derive(n_appendages, panel_rates))
    if path is not None:
        _write_atomic(path, source.encode("utf-8"))
    return ReferenceModel(n_appendages, panel_rates, source, path)
