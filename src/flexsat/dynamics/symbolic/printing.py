"""Readable export of a derived model: LaTeX and Unicode text."""

from __future__ import annotations

import textwrap
from collections.abc import Sequence
from typing import Any

import sympy as sp

from flexsat.dynamics.symbolic.rotations import euler_rate_matrix, rotation
from flexsat.dynamics.symbolic.symbols import _AXES

# A derived model (:class:`flexsat.dynamics.symbolic.derivation.SymbolicModel`), read
# by its attributes: derivation calls this module, so this module does not import it.
SymbolicModel = Any

_PRETTY_COLUMNS = 100


def _display_parts(m: SymbolicModel, i: int) -> tuple[sp.Matrix, sp.Matrix]:
    """R_BM and d of appendage ``i``, rebuilt for display."""
    app = m.appendages[i]
    R_BM = rotation("z", app.mount_yaw) * rotation("y", app.sadm)
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
