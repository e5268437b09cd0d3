"""Reduced-order models: modal truncation and balanced truncation.

Both keep the marginal part of the model exactly (the rigid-body modes at rest; the
rigid modes seen from a spinning frame about a spin) and reduce only the
asymptotically stable flexible part, which is first split off with an ordered real
Schur form and a Sylvester equation (an exact block diagonalization).

- **Modal truncation** keeps the flexible modes of lowest natural frequency. The
  error is the discarded subsystem itself; its H-infinity norm is reported, as the
  peak over a frequency grid that includes every discarded mode's frequency.
- **Balanced truncation** (square-root method: Gramians from ``scipy.linalg``'s
  Lyapunov solver, factors from a symmetric eigendecomposition, one SVD). It needs
  the joints' damping (undamped flexible modes have no Gramians). The a-priori
  bound ``||G - G_r||_inf <= 2 sum(discarded Hankel singular values)`` is reported.
  python-control's ``balred`` needs slycot; this needs scipy only.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np
from scipy.linalg import schur, solve_continuous_lyapunov, solve_sylvester

from flexsat.errors import ConfigError
from flexsat.linear.model import LinearModel

__all__ = ["ReducedModel", "balanced_truncation", "modal_truncation"]

_MARGINAL_REL = 1e-6  # |Re lambda| below this times max|lambda|: a marginal (rigid) pole
_GRID_POINTS = 2000


@dataclass(frozen=True, eq=False)
class ReducedModel:
    """A reduced model and what its reduction discarded.

    Attributes
    ----------
    model : LinearModel
        The reduced model; states ``z1 ... zr`` (the first ``n_marginal`` span the
        marginal modes), same inputs and outputs as the full model.
    method : str
        ``"modal"`` or ``"balanced"``.
    n_marginal : int
        States of the marginal (rigid) part kept exactly.
    hankel_singular_values : ndarray or None
        Of the stable part, descending (balanced truncation only) [units of the model's gain].
    error_bound : float
        Balanced: 2 x the sum of the discarded Hankel singular values (a bound on
        the H-infinity error). Modal: the H-infinity norm of the discarded part
        estimated on a frequency grid (the error itself, not a bound) [units of the model's gain].
    """

    model: LinearModel
    method: str
    n_marginal: int
    hankel_singular_values: np.ndarray | None
    error_bound: float


def _split_marginal(full: LinearModel):
    """(A1, B1, C1), (A2, B2, C2): marginal and stable parts, exactly decoupled."""
    lam = np.linalg.eigvals(full.A)
    tol = _MARGINAL_REL * max(1.0, float(np.max(np.abs(lam))))
    return _decouple(full.A, full.B, full.C, lambda re, im: np.abs(re) <= tol)


def _decouple(A, B, C, first):
    """Order the real Schur form with ``first`` eigenvalues leading; decouple the blocks."""
    T, U, k = schur(A, output="real", sort=first)
    B_s, C_s = U.T @ B, C @ U
    if 0 < k < A.shape[0]:
        # [[I, X], [0, I]]^-1 T [[I, X], [0, I]] is block diagonal when T11 X - X T22 = -T12.
        X = solve_sylvester(T[:k, :k], -T[k:, k:], -T[:k, k:])
        B_s = np.vstack([B_s[:k] - X @ B_s[k:], B_s[k:]])
        C_s = np.hstack([C_s[:, :k], C_s[:, :k] @ X + C_s[:, k:]])
    return (T[:k, :k], B_s[:k], C_s[:, :k]), (T[k:, k:], B_s[k:], C_s[:, k:])


def _check_order(full: LinearModel, order: int, n_marginal: int) -> None:
    if n_marginal == full.n_states:
        raise ConfigError(
            "the model has no asymptotically stable part to reduce (undamped modes): give "
            "the appendages a damping_ratio > 0"
        )
    if not n_marginal <= order < full.n_states:
        raise ConfigError(
            f"order: must be between {n_marginal} (the marginal rigid-body states) and "
            f"{full.n_states - 1} (the full model has {full.n_states} states), got {order}"
        )


def _assemble(full, parts, method, n_marginal, hsv, bound) -> ReducedModel:
    A = np.zeros((sum(p[0].shape[0] for p in parts),) * 2)
    i = 0
    for Ap, _, _ in parts:
        m = Ap.shape[0]
        A[i : i + m, i : i + m] = Ap
        i += m
    r = A.shape[0]
    model = replace(
        full,
        A=A,
        B=np.vstack([p[1] for p in parts]),
        C=np.hstack([p[2] for p in parts]),
        x0=np.zeros(r),
        state_names=tuple(f"z{k + 1}" for k in range(r)),
        state_units=("-",) * r,
    )
    return ReducedModel(model, method, n_marginal, hsv, float(bound))


def _hinf_estimate(A, B, C, extra_rad_s: np.ndarray) -> float:
    if A.shape[0] == 0:
        return 0.0
    lam = np.abs(np.linalg.eigvals(A))
    w = np.unique(
        np.concatenate([np.geomspace(1e-3, 10 * lam.max(), _GRID_POINTS), lam, extra_rad_s])
    )
    eye = np.eye(A.shape[0])
    return max(float(np.linalg.norm(C @ np.linalg.solve(1j * wk * eye - A, B), 2)) for wk in w)


def modal_truncation(full: LinearModel, order: int) -> ReducedModel:
    """Keep the marginal part and the lowest-frequency flexible modes, ``order`` states.

    Parameters
    ----------
    full : LinearModel
        The model to reduce.
    order : int
        States of the reduced model, marginal part included.

    Returns
    -------
    ReducedModel

    Raises
    ------
    ConfigError
        If ``order`` is below the marginal states or not smaller than the model, or
        would split a complex-conjugate pair.
    """
    marginal, stable = _split_marginal(full)
    n_marginal = marginal[0].shape[0]
    _check_order(full, order, n_marginal)
    A2, B2, C2 = stable
    keep = order - n_marginal
    mags = np.sort(np.abs(np.linalg.eigvals(A2)))
    if 0 < keep < mags.size and np.isclose(mags[keep - 1], mags[keep], rtol=1e-9, atol=0.0):
        raise ConfigError(
            f"order: {order} would split a complex-conjugate pair; use {order - 1} or {order + 1}"
        )
    cut = 0.0 if keep == 0 else 0.5 * (mags[keep - 1] + mags[keep])
    kept, dropped = _decouple(A2, B2, C2, lambda re, im: np.hypot(re, im) < cut)
    err = _hinf_estimate(*dropped, np.abs(np.linalg.eigvals(dropped[0])))
    parts = [marginal, kept] if keep else [marginal]
    return _assemble(full, parts, "modal", n_marginal, None, err)


def balanced_truncation(full: LinearModel, order: int) -> ReducedModel:
    """Square-root balanced truncation of the stable part to ``order`` states in all.

    Parameters
    ----------
    full : LinearModel
        The model to reduce.
    order : int
        States of the reduced model, marginal part included.

    Returns
    -------
    ReducedModel

    Raises
    ------
    ConfigError
        If ``order`` is out of range, or the flexible part is not asymptotically
        stable (no joint damping).
    """
    marginal, stable = _split_marginal(full)
    n_marginal = marginal[0].shape[0]
    _check_order(full, order, n_marginal)
    A2, B2, C2 = stable
    if A2.shape[0] and np.max(np.linalg.eigvals(A2).real) >= 0.0:
        raise ConfigError(
            "balanced truncation needs asymptotically stable flexible modes: give the "
            "appendages a damping_ratio > 0 (or use modal truncation)"
        )
    P = solve_continuous_lyapunov(A2, -B2 @ B2.T)  # A P + P A^T + B B^T = 0
    Q = solve_continuous_lyapunov(A2.T, -C2.T @ C2)
    Lp, Lq = _psd_factor(P), _psd_factor(Q)
    U, hsv, Vt = np.linalg.svd(Lq.T @ Lp)
    keep = order - n_marginal
    s = 1.0 / np.sqrt(hsv[:keep])
    T = Lp @ Vt[:keep].T * s  # x_stable = T z
    Ti = (s[:, None] * U[:, :keep].T) @ Lq.T
    kept = (Ti @ A2 @ T, Ti @ B2, C2 @ T)
    bound = 2.0 * hsv[keep:].sum()
    parts = [marginal, kept] if keep else [marginal]
    return _assemble(full, parts, "balanced", n_marginal, hsv, bound)


def _psd_factor(P: np.ndarray) -> np.ndarray:
    """L with L L^T = P for a symmetric positive semi-definite P (round-off clipped)."""
    w, V = np.linalg.eigh(0.5 * (P + P.T))
    return V * np.sqrt(np.clip(w, 0.0, None))
