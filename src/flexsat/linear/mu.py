"""Structured singular value (mu) of flexsat's loops under real parametric uncertainty.

The uncertain satellite (:mod:`flexsat.linear.uncertain`) closed by a linear
controller (a static gain on attitude and rate, or a state-space law) leaves the
interconnection ``N(s)`` seen by ``Delta``: the loop is stable for every
``‖Delta‖ <= 1/beta`` iff ``mu_Delta(N(i w)) < beta`` at every frequency (the main
loop theorem), so ``k_max = 1 / max_w mu`` is the factor by which the parameter box
can grow (or must shrink) before the loop can lose stability.

- **Upper bound**: the D-G scalings of Fan, Tits and Doyle ("Robustness in the
  presence of mixed parametric uncertainty and unmodeled dynamics", IEEE TAC 1991),
  ``mu <= sqrt(lambda_max(N_D^H N_D + j (G N_D - N_D^H G)))`` for every diagonal
  ``D > 0`` (N_D = D^1/2 N D^-1/2) and real diagonal G on the real channels; the
  bound is minimized over (log D, G) with scipy's L-BFGS-B and an exact gradient.
  Any D, G give a valid bound, so the optimizer's result is a certificate. With G = 0
  it is the complex (D-scaled, Osborne's) bound.
- **Full-block upper bound** (:func:`mu_upper_bound_lmi`): D_i Hermitian positive
  definite and G_i Hermitian on each repeated scalar block, the LMI
  ``N^H D N + j (G N - N^H G) - beta^2 D <= 0`` (Young 1993) solved by bisection on
  beta with cvxpy; never looser than the diagonal bound, much costlier with many
  channels (docs/linear.md, 'Robust stability: mu'), so :func:`analyze` uses it only
  at the diagonal bound's peak frequencies when asked (``bound="lmi"``).
- **Lower bound**: a real perturbation that destabilizes the loop. For purely real
  blocks the power iteration of Young and Doyle often does not converge (their
  paper says so), so the lower bound is found directly: along a direction of the
  parameter box the smallest scale ``alpha`` at which a closed-loop pole reaches the
  imaginary axis (at ``i w*``) gives ``det(I - N(i w*) alpha Delta) = 0``, so
  ``mu(N(i w*)) >= 1/alpha``. The box's vertices and axes are searched, then the best
  direction is refined (Nelder-Mead); the destabilizing point is the worst-case
  parameter combination.
"""

from __future__ import annotations

import warnings
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from scipy.linalg import eigh
from scipy.optimize import minimize, minimize_scalar

from flexsat.errors import ConfigError
from flexsat.linear.blas_threads import one_blas_thread
from flexsat.linear.uncertain import UncertainModel

__all__ = [
    "LMI_MAX_CHANNELS",
    "LinearController",
    "LmiBisection",
    "LmiStep",
    "MuAnalysis",
    "analyze",
    "closed_loop",
    "lmi_certificate",
    "mu_upper_bound",
    "mu_upper_bound_lmi",
    "stability_boundary",
]

LMI_MAX_CHANNELS = 40
"""Most channels :func:`analyze` gives the LMI bound (30 cost 29 s an SDP, 69 over 30 min)."""
_X_BOUND = 40.0  # |log d| of the D scaling kept below this (no overflow)
_ALPHA_MAX = 4.0  # the destabilizing search looks up to 4x the parameter box
_STABLE_MARGIN = 0.0  # a pole with Re > 0 is unstable


@dataclass(frozen=True)
class LinearController:
    """A linear controller ``x_k' = A x_k + B y``, ``u = C x_k + D y``.

    ``y = [phi, theta, psi, omega_x, omega_y, omega_z]`` [rad, rad/s] about rest,
    ``u`` the body torque [N m] (positive feedback convention: the law as it maps
    measurements to torque).

    Attributes
    ----------
    A, B, C, D : ndarray
        Shapes (n, n), (n, 6), (3, n), (3, 6) [SI]; n = 0 for a static law.
    """

    A: np.ndarray
    B: np.ndarray
    C: np.ndarray
    D: np.ndarray

    @classmethod
    def static(cls, K: np.ndarray) -> LinearController:
        """flexsat's static law ``tau = -K [theta; omega]`` (``law_gains``), K (3, 6)."""
        K = np.asarray(K, dtype=float)
        if K.shape != (3, 6):
            raise ConfigError(f"controller: a static gain is 3 x 6, got {K.shape}")
        return cls(np.zeros((0, 0)), np.zeros((0, 6)), np.zeros((3, 0)), -K)

    @classmethod
    def from_arrays(cls, A, B, C, D) -> LinearController:
        """A user's state-space law; shapes (n, n), (n, 6), (3, n), (3, 6).

        Raises
        ------
        ConfigError
            Naming the matrix whose shape or values do not fit.
        """
        mats = [np.atleast_2d(np.asarray(m, dtype=float)) for m in (A, B, C, D)]
        n = mats[0].shape[0] if mats[0].size else 0
        if mats[0].size == 0:
            mats[0] = np.zeros((0, 0))
            mats[1] = np.zeros((0, 6))
            mats[2] = np.zeros((3, 0))
        shapes = {"A": (n, n), "B": (n, 6), "C": (3, n), "D": (3, 6)}
        for (name, shape), m in zip(shapes.items(), mats, strict=True):
            if m.shape != shape:
                raise ConfigError(f"controller.{name}: expected shape {shape} (6 measurements "
                                  f"phi..omega_z, 3 torques), got {m.shape}")  # fmt: skip
            if not np.all(np.isfinite(m)):
                raise ConfigError(f"controller.{name}: every entry must be a finite number")
        return cls(*mats)


def closed_loop(model: UncertainModel, controller: LinearController):
    """The interconnection N(s) = C (sI - A)^-1 B + D seen by Delta, loop closed.

    The hub's translation states (nothing reads them about rest) are dropped.

    Parameters
    ----------
    model : UncertainModel
        Its outputs must be attitude then rate (``uncertain_model``'s default).
    controller : LinearController
        The law closing the loop from attitude and rate to body torque.

    Returns
    -------
    tuple of ndarray
        (A, B, C, D) [SI]: shapes (n, n), (n, n_w), (n_w, n), (n_w, n_w).
    """
    if model.output_names[:6] != ("phi", "theta", "psi", "omega_x", "omega_y", "omega_z"):
        raise ConfigError("outputs: the loop reads attitude then rate; build the model with "
                          "outputs=('attitude', 'rate')")  # fmt: skip
    keep = np.setdiff1d(np.arange(model.A.shape[0]), model.translation)
    A, B1, B2 = model.A[np.ix_(keep, keep)], model.B1[keep], model.B2[keep]
    C1, C2 = model.C1[:, keep], model.C2[:6, keep]
    k = controller
    Acl = np.block([[A + B2 @ k.D @ C2, B2 @ k.C], [k.B @ C2, k.A]])
    Bcl = np.vstack([B1, np.zeros((k.A.shape[0], B1.shape[1]))])
    Ccl = np.hstack([C1 + model.D12 @ k.D @ C2, model.D12 @ k.C])
    return Acl, Bcl, Ccl, model.D11.copy()


def _response(loop, w: float) -> np.ndarray:
    A, B, C, D = loop
    return C @ np.linalg.solve(1j * w * np.eye(A.shape[0]) - A, B) + D


def _dg_bound(p: np.ndarray, N: np.ndarray, real: np.ndarray) -> tuple[float, np.ndarray]:
    """lambda_max of the D-G bound's matrix at p = [log D, G], and its gradient."""
    n = N.shape[0]
    x, g = p[:n], p[n:] * real
    e = np.exp(0.5 * x)
    Nd = (e[:, None] * N) / e[None, :]
    H = Nd.conj().T @ Nd + 1j * (g[:, None] * Nd - Nd.conj().T * g[None, :])
    # The largest eigenpair alone (LAPACK's MRRR, zheevr): 2-2.5x faster than the full
    # eigendecomposition at n = 69 (docs/linear.md, 'Robust stability: mu').
    lam, V = eigh(H, subset_by_index=[n - 1, n - 1], driver="evr")
    v = V[:, -1]
    a = Nd @ v
    c = Nd.conj().T @ a
    e_ = Nd.conj().T @ (g * v)
    dx = np.abs(a) ** 2 - np.real(c.conj() * v) - np.imag(g * v.conj() * a - e_.conj() * v)
    dg = -2.0 * np.imag(v.conj() * a) * real
    return float(lam[-1]), np.concatenate([dx, dg])


@one_blas_thread
def mu_upper_bound(
    N: np.ndarray,
    real: np.ndarray,
    start: tuple[np.ndarray, np.ndarray] | None = None,
    maxiter: int = 200,
) -> tuple[float, np.ndarray, np.ndarray]:
    """Upper bound on mu of N for repeated real (or complex) scalar channels.

    Parameters
    ----------
    N : ndarray, shape (n, n)
        Complex matrix seen by Delta = diag(delta_k) [-] (a repeated scalar is several
        channels with the same delta; diagonal scalings are valid for it).
    real : ndarray of bool, shape (n,)
        True on the channels of a real parameter (they get a G scaling) [-].
    start : tuple of ndarray, optional
        log D and G to start from (a neighbouring frequency's) [-].
    maxiter : int
        L-BFGS-B iterations; fewer give a looser but still valid bound.

    Returns
    -------
    bound : float
        sqrt(lambda_max(N_D^H N_D + j (G N_D - N_D^H G))) at the scalings found [-].
    x : ndarray, shape (n,)
        log of D's diagonal [-].
    g : ndarray, shape (n,)
        G's diagonal (zero on complex channels) [-].
    """
    n = N.shape[0]
    real = np.asarray(real, dtype=bool)
    x0, g0 = (np.zeros(n), np.zeros(n)) if start is None else start

    def fun(p):
        return _dg_bound(p, N, real)

    p0 = np.concatenate([x0, g0])
    bounds = [(-_X_BOUND, _X_BOUND)] * n + [(None, None)] * n
    res = minimize(fun, p0, jac=True, method="L-BFGS-B", bounds=bounds,
                   options={"maxiter": maxiter})  # fmt: skip
    best = res.x if res.fun <= fun(p0)[0] else p0
    lam = fun(best)[0]
    return float(np.sqrt(max(lam, 0.0))), best[:n], best[n:] * real


def _require_cvxpy():
    """Import cvxpy or raise one ConfigError naming the extra that brings it."""
    try:
        import cvxpy
    except ImportError:
        raise ConfigError(
            "the LMI mu bound (full D, G scalings) needs cvxpy: pip install 'flexsat[robust]'"
        ) from None
    return cvxpy


def lmi_certificate(N: np.ndarray, D: np.ndarray, G: np.ndarray) -> float:
    """The mu upper bound that given scalings D, G certify (Fan, Tits and Doyle 1991).

    If ``N^H D N + j (G N - N^H G) <= beta^2 D`` then ``mu(N) <= beta``; the least such
    beta is the largest generalized eigenvalue of the pencil, computed here with
    ``D = L L^H``: ``beta^2 = lambda_max(L^-1 (N^H D N + j (G N - N^H G)) L^-H)``.

    Parameters
    ----------
    N : ndarray, shape (n, n)
        The complex matrix seen by Delta [-].
    D : ndarray, shape (n, n)
        Hermitian positive definite, block diagonal in Delta's structure [-].
    G : ndarray, shape (n, n)
        Hermitian, block diagonal, zero on complex blocks [-].

    Returns
    -------
    float
        The certified bound beta [-] (``inf`` if D is not positive definite).
    """
    D = 0.5 * (D + D.conj().T)
    G = 0.5 * (G + G.conj().T)
    try:
        L = np.linalg.cholesky(D)
    except np.linalg.LinAlgError:
        return float("inf")
    H = N.conj().T @ D @ N + 1j * (G @ N - N.conj().T @ G)
    X = np.linalg.solve(L, np.linalg.solve(L, H.conj().T).conj().T)  # L^-1 H L^-H
    lam = np.linalg.eigvalsh(0.5 * (X + X.conj().T))[-1]
    return float(np.sqrt(max(lam, 0.0)))


@dataclass(frozen=True)
class LmiStep:
    """One beta of :func:`mu_upper_bound_lmi`'s bisection.

    Attributes
    ----------
    beta : float
        The beta tried [-].
    outcome : str
        ``"certified"`` (the exact certificate of the D, G found is at most beta),
        ``"infeasible"`` (the solver's optimal t exceeds its margin: no admissible
        D, G reach beta), ``"resolution"`` (t within the margin of 0 and the
        certificate above beta: beta is the LMI's optimum to the solver's accuracy)
        or ``"undecided"`` (the solver failed, or t is clearly negative, feasible,
        while the certificate does not confirm it).
    t : float
        The SDP's optimal t of the last solve [-] (``nan`` if the solver failed).
    certificate : float
        :func:`lmi_certificate` of its D, G [-] (``inf`` if none).
    solves : int
        Solves tried at this beta (the first, then the retries).
    status : str
        cvxpy's status of the last solve (``"solver_error"`` if it raised); of the SDP
        with ``t >= -1`` when the first was unbounded.
    """

    beta: float
    outcome: str
    t: float
    certificate: float
    solves: int
    status: str = ""


@dataclass(frozen=True)
class LmiBisection:
    """How :func:`mu_upper_bound_lmi`'s bisection ended.

    Attributes
    ----------
    status : str
        ``"converged"`` (the interval is below ``rtol``), ``"resolution"`` (the
        solver's accuracy was reached before ``rtol``), ``"undecided"`` (a beta
        stayed undecided after every retry: the bisection stopped there, with a
        ``RuntimeWarning``), ``"max_steps"`` or ``"trivial"`` (N = 0, no SDP).
    lower : float
        The bisection's lower end [-]: only betas found infeasible raise it, so the
        LMI's least beta is not below it (a bound on the LMI, not on mu).
    upper : float
        The certified bound returned [-].
    steps : tuple of LmiStep
        Every beta tried, in order.
    """

    status: str
    lower: float
    upper: float
    steps: tuple[LmiStep, ...] = ()


def _default_solve(problem, solver: str, settings: dict) -> None:
    """cvxpy's ``problem.solve`` with one solver and its settings."""
    problem.solve(solver=solver, **settings)


# The solves tried at one beta: the first with the solver's defaults, then tighter
# tolerances, then the other installed interior-point or first-order solver. Each
# with the t above which its answer means "infeasible", by status: ten times the
# solver's absolute gap tolerance (Clarabel 1e-8, or 5e-5 when it reports
# "optimal_inaccurate"; SCS its eps). t is absolute as the SDP fixes sum tr D_i = n.
_DEFAULT = {
    "CLARABEL": ({}, {"optimal": 1e-7, "optimal_inaccurate": 5e-4}),
    "SCS": ({}, {"optimal": 1e-3}),
}
_TIGHT = {
    "CLARABEL": (
        {"tol_gap_abs": 1e-10, "tol_gap_rel": 1e-10, "tol_feas": 1e-10, "max_iter": 500},
        {"optimal": 1e-9, "optimal_inaccurate": 5e-4},
    ),
    "SCS": ({"eps_abs": 1e-7, "eps_rel": 1e-7, "max_iters": 20_000}, {"optimal": 1e-6}),
}
_OTHER_MARGIN = {"optimal": 1e-6}  # a solver without a row here


def _attempts(cp, solver: str | None) -> list[tuple[str, dict, dict]]:
    """(solver, settings, t margin by status) of each solve tried at one beta."""
    first = (solver or cp.CLARABEL).upper()
    out = [(first, *_DEFAULT.get(first, ({}, _OTHER_MARGIN)))]
    if first in _TIGHT:
        out.append((first, *_TIGHT[first]))
    installed = set(cp.installed_solvers())
    other = next((s for s in _TIGHT if s != first and s in installed), None)
    if other is not None:
        out.append((other, *_TIGHT[other]))
    return out


@one_blas_thread
def mu_upper_bound_lmi(
    N: np.ndarray,
    blocks: np.ndarray,
    real: np.ndarray,
    beta0: float | None = None,
    rtol: float = 1e-3,
    max_steps: int = 30,
    solver: str | None = None,
    details: bool = False,
    solve: Callable[[Any, str, dict], None] | None = None,
) -> tuple[float, np.ndarray, np.ndarray] | tuple[float, np.ndarray, np.ndarray, LmiBisection]:
    """mu upper bound with full D and G blocks for repeated scalar blocks (an LMI).

    For ``Delta = diag(delta_i I_{r_i})`` the scalings commuting with Delta are
    ``D = diag(D_i)``, D_i Hermitian positive definite r_i x r_i, and on the real
    blocks ``G = diag(G_i)``, G_i Hermitian (zero on complex ones); then
    ``mu(N) <= beta`` whenever ``N^H D N + j (G N - N^H G) - beta^2 D <= 0`` (Fan, Tits
    and Doyle 1991; Young, "Robustness analysis with real parametric and dynamic
    uncertainty", PhD thesis, Caltech 1993). The least beta is a generalized
    eigenvalue problem, solved by bisection on beta: at each beta the SDP ``min t``
    s.t. ``N^H D N + j (G N - N^H G) - beta^2 D <= t I``, ``sum tr D_i = n``,
    ``D_i >= 1e-6 I`` (cvxpy), posed on ``S N S^-1`` with S the diagonal bound's
    ``D^1/2`` (:func:`mu_upper_bound`; a similarity commuting with Delta, so its
    scalings map back as ``S D S``, ``S G S``; the SDP is far better conditioned).

    Each beta ends one of three ways. **Certified**: :func:`lmi_certificate` of the
    D, G found (exact, whatever the solver's accuracy) is at most beta; the upper
    end drops to it. **Infeasible**: the solver's optimal t exceeds its margin (ten
    times its gap tolerance for the status it reports); beta is the new lower end.
    **Undecided**: the solver failed, or t says feasible while the certificate does
    not confirm it; the solve is retried with tighter tolerances, then with the
    other installed solver (Clarabel, SCS), and the lower end never moves on such
    evidence. A beta still undecided after the retries stops the bisection with a
    ``RuntimeWarning``: the bound returned is the best certified one, valid but
    perhaps not the LMI's optimum. A t within the margin of 0 (retried with
    tighter tolerances only) ends it without a warning: the solver's resolution
    is reached. A t unbounded below (G alone makes the LMI negative: beta is
    feasible with room to spare) is solved again with ``t >= -1`` for its D, G.
    The upper end starts at the diagonal bound, which is always valid.

    Parameters
    ----------
    N : ndarray, shape (n, n)
        Complex matrix seen by Delta [-].
    blocks : ndarray of int, shape (n,)
        The block (parameter) of each channel; channels of one block share delta [-].
    real : ndarray of bool, shape (n_blocks,)
        True for a real parameter (it gets a G block) [-].
    beta0 : float, optional
        The first beta tried (a neighbouring frequency's bound) [-]; default half the
        diagonal D-G bound (:func:`mu_upper_bound`).
    rtol : float
        Stop when the bisection's interval is below this, relative to its upper end
        [-].
    max_steps : int
        At most this many betas (each one SDP, more when retried).
    solver : str, optional
        cvxpy's solver name for the first solve at each beta; default Clarabel
        (interior point).
    details : bool
        Also return how the bisection ended (:class:`LmiBisection`).
    solve : callable, optional
        ``solve(problem, solver, settings)`` solves the cvxpy problem in place;
        default ``problem.solve(solver=solver, **settings)``. Lets a caller wrap the
        solver (to log, or to test the bisection against an inaccurate solve).

    Returns
    -------
    bound : float
        The certified bound [-]: never above ``beta0`` nor the diagonal bound.
    D, G : ndarray, shape (n, n)
        The certifying scalings (``lmi_certificate(N, D, G) == bound``) [-].
    bisection : LmiBisection
        Only with ``details=True``: its status, ends and steps.

    Raises
    ------
    ConfigError
        cvxpy missing (the ``robust`` extra).
    """
    cp = _require_cvxpy()
    solve = solve or _default_solve
    attempts = _attempts(cp, solver)
    n = N.shape[0]
    blocks = np.asarray(blocks, dtype=int)
    real = np.asarray(real, dtype=bool)
    real_ch = real[blocks]
    b_diag, x, g = mu_upper_bound(N, real_ch)
    best = (b_diag, np.diag(np.exp(x)).astype(complex), np.diag(g).astype(complex))
    beta = b_diag if beta0 is None else min(float(beta0), b_diag)

    def done(status, lo, steps):
        if status == "undecided":
            warnings.warn(
                "mu_upper_bound_lmi: the solver failed or stayed inaccurate at beta = "
                f"{steps[-1].beta:.6g} after {steps[-1].solves} solves; the bound "
                f"{best[0]:.6g} is certified but the LMI's optimum lies in "
                f"[{lo:.6g}, {best[0]:.6g}]",
                RuntimeWarning,
                stacklevel=4,  # the caller of the one-BLAS-thread wrapper
            )
        if details:
            return (*best, LmiBisection(status, lo, best[0], tuple(steps)))
        return best

    if beta <= 0.0:
        return done("trivial", 0.0, [])
    s = np.exp(0.5 * x)  # S = D^1/2 of the diagonal bound
    Ns = (s[:, None] * N) / s[None, :]
    terms_h, terms_d, Ds, Gs = [], [], [], []
    for i in np.unique(blocks):
        idx = np.flatnonzero(blocks == i)
        r = idx.size
        E = np.zeros((r, n))
        E[np.arange(r), idx] = 1.0
        Ni = Ns[idx]
        Di = cp.Variable((r, r), hermitian=True)
        Ds.append((idx, Di))
        terms_h.append(Ni.conj().T @ Di @ Ni)
        terms_d.append(E.T @ Di @ E)
        if real[i]:
            Gi = cp.Variable((r, r), hermitian=True)
            Gs.append((idx, Gi))
            terms_h.append(1j * (E.T @ Gi @ Ni - Ni.conj().T @ Gi @ E))
    beta2 = cp.Parameter(nonneg=True)
    t = cp.Variable()
    lmi = sum(terms_h[1:], terms_h[0]) - beta2 * sum(terms_d[1:], terms_d[0])
    cons = [lmi << t * np.eye(n), sum(cp.real(cp.trace(Di)) for _, Di in Ds) == n]
    cons += [Di >> 1e-6 * np.eye(Di.shape[0]) for _, Di in Ds]
    problem = cp.Problem(cp.Minimize(t), cons)
    # t unbounded below (G can make the LMI as negative as it likes: beta is feasible
    # with room to spare) leaves no D, G; the same SDP with t >= -1 returns some.
    bounded = cp.Problem(cp.Minimize(t), [*cons, t >= -1.0])

    def scalings():
        """The D, G of the last solve, mapped back to N: S D S, S G S."""
        D = np.zeros((n, n), complex)
        G = np.zeros((n, n), complex)
        for idx, Di in Ds:
            D[np.ix_(idx, idx)] = Di.value
        for idx, Gi in Gs:
            G[np.ix_(idx, idx)] = Gi.value
        return s[:, None] * D * s[None, :], s[:, None] * G * s[None, :]

    lo, hi = 0.0, beta
    beta = 0.5 * hi if beta0 is None else beta  # a given beta0 is tried first
    steps: list[LmiStep] = []
    for _ in range(max_steps):
        beta2.value = beta**2
        outcome, t_val, cert, solves, tol = "undecided", float("nan"), float("inf"), 0, np.inf
        status = "not_solved"
        for name, settings, margin in attempts:
            if outcome == "resolution" and margin["optimal"] >= tol:
                continue  # a solver no finer than the last cannot resolve t near 0
            solves += 1
            try:
                with warnings.catch_warnings():  # an inaccurate solve still gives D, G
                    warnings.simplefilter("ignore")
                    solve(problem, name, settings)
                    status = problem.status
                    if status == "unbounded":
                        solve(bounded, name, settings)
                        status = bounded.status
            except cp.SolverError:
                status = "solver_error"
            if status not in ("optimal", "optimal_inaccurate") or t.value is None:
                continue
            t_val = float(t.value)
            D, G = scalings()
            cert = lmi_certificate(N, D, G)  # exact, whatever the solver's accuracy
            if cert < best[0]:
                best = (cert, D, G)
            tol = margin.get(status, np.inf)
            if cert <= beta:
                outcome = "certified"
            elif t_val > tol:
                outcome = "infeasible"
            else:  # t within the margin of 0, or feasible while the certificate is not
                outcome = "resolution" if t_val >= -tol else "undecided"
                continue  # retry
            break
        steps.append(LmiStep(beta, outcome, t_val, cert, solves, status))
        hi = min(hi, best[0])
        if outcome == "infeasible":
            lo = beta
        elif outcome in ("undecided", "resolution"):
            return done(outcome, lo, steps)
        if hi - lo <= rtol * hi:
            return done("converged", lo, steps)
        beta = 0.5 * (lo + hi)
    return done("max_steps", lo, steps)


def _poles_max_real(model: UncertainModel, loop, delta: np.ndarray) -> tuple[float, float]:
    """(max Re, ‖Im‖ of that pole) of the closed loop at the parameter point delta."""
    A, B, C, D = loop
    Dl = model.delta_matrix(delta)
    X = np.linalg.solve(np.eye(D.shape[0]) - Dl @ D, Dl)
    lam = np.linalg.eigvals(A + B @ X @ C)
    k = int(np.argmax(lam.real))
    return float(lam[k].real), float(abs(lam[k].imag))


@one_blas_thread
def stability_boundary(
    model: UncertainModel, loop, direction: np.ndarray, alpha_max: float = _ALPHA_MAX
) -> tuple[float, float]:
    """Smallest scale alpha at which the loop at ``alpha * direction`` is unstable.

    Parameters
    ----------
    model : UncertainModel
        The satellite's LFT the loop was built from.
    loop : tuple
        :func:`closed_loop`'s (A, B, C, D).
    direction : ndarray, shape (n_parameters,)
        [-] A point of the box's boundary (max ‖delta_i‖ = 1).
    alpha_max : float
        Search up to this scale [-].

    Returns
    -------
    alpha : float
        The scale at which a pole crosses into Re > 0 (``inf`` if none up to
        ``alpha_max``), to 1e-6 [-].
    frequency : float
        That pole's ‖Im‖ at the crossing [rad/s].
    """
    grid = np.linspace(0.0, alpha_max, 41)[1:]
    prev = 0.0
    for a in grid:
        if _poles_max_real(model, loop, a * direction)[0] > _STABLE_MARGIN:
            lo, hi = prev, a
            while hi - lo > 1e-6:
                mid = 0.5 * (lo + hi)
                if _poles_max_real(model, loop, mid * direction)[0] > _STABLE_MARGIN:
                    hi = mid
                else:
                    lo = mid
            return hi, _poles_max_real(model, loop, hi * direction)[1]
        prev = a
    return float("inf"), float("nan")


@dataclass(frozen=True)
class MuAnalysis:
    """mu of one loop against its parameter box, over frequency.

    Attributes
    ----------
    frequencies_hz : ndarray, shape (n_f,)
        The grid, refined near the peaks [Hz].
    upper : ndarray, shape (n_f,)
        The D-G upper bound at each frequency [-].
    peak_upper : float
        max over the grid of ``upper`` (refined by a bounded search at the peak) [-].
    peak_frequency_hz : float
        Where [Hz].
    lower : float
        The lower bound 1/alpha from the destabilizing perturbation [-] (0 if none
        within the search's ``alpha_max``).
    lower_frequency_hz : float
        The frequency of the pole that crosses the axis there [Hz].
    k_max : tuple of float
        (1/peak_upper, 1/lower): the stability margin lies between [-]; the loop is
        stable over k x the box for every k < k_max[0].
    worst_delta : ndarray, shape (n_parameters,)
        The destabilizing perturbation, normalized (max ‖delta‖ = alpha) [-].
    worst_factors : dict
        Each parameter's factor on its nominal value there [-].
    nominal_stable : bool
        Whether the loop at Delta = 0 (the box's centre) is stable.
    bound : str
        ``"diagonal"`` (D, G diagonal) or ``"lmi"`` (full D, G blocks at the
        frequencies ``lmi_frequencies_hz``, the diagonal bound elsewhere).
    lmi_frequencies_hz : ndarray
        Where the LMI bound was computed [Hz].
    """

    frequencies_hz: np.ndarray
    upper: np.ndarray
    peak_upper: float
    peak_frequency_hz: float
    lower: float
    lower_frequency_hz: float
    k_max: tuple[float, float]
    worst_delta: np.ndarray
    worst_factors: dict = field(default_factory=dict)
    nominal_stable: bool = True
    bound: str = "diagonal"
    lmi_frequencies_hz: np.ndarray = field(default_factory=lambda: np.zeros(0))

    def to_dict(self) -> dict:
        """Plain data for JSON."""
        return {
            "frequencies_hz": self.frequencies_hz.tolist(),
            "mu_upper": self.upper.tolist(),
            "peak_upper": self.peak_upper,
            "peak_frequency_hz": self.peak_frequency_hz,
            "lower": self.lower,
            "lower_frequency_hz": self.lower_frequency_hz,
            "k_max_lower": self.k_max[0],
            "k_max_upper": self.k_max[1],
            "worst_delta": self.worst_delta.tolist(),
            "worst_factors": self.worst_factors,
            "nominal_stable": self.nominal_stable,
            "bound": self.bound,
            "lmi_frequencies_hz": self.lmi_frequencies_hz.tolist(),
        }


def _search_worst(model: UncertainModel, loop, seed_directions: Sequence[np.ndarray]):
    """The destabilizing direction with the smallest alpha: candidates, then Nelder-Mead."""
    best = (float("inf"), float("nan"), None)
    for d in seed_directions:
        a, w = stability_boundary(model, loop, d)
        if a < best[0]:
            best = (a, w, d)
    if best[2] is None:
        return best

    def alpha_of(p):
        d = np.clip(p, -1.0, 1.0)
        m = np.max(np.abs(d))
        if m < 1e-6:
            return _ALPHA_MAX
        a, _ = stability_boundary(model, loop, d / m, alpha_max=min(_ALPHA_MAX, 1.5 * best[0]))
        return min(a, _ALPHA_MAX)

    res = minimize(alpha_of, best[2], method="Nelder-Mead",
                   options={"maxfev": 60, "xatol": 1e-3, "fatol": 1e-5})  # fmt: skip
    if res.fun < best[0]:
        d = np.clip(res.x, -1.0, 1.0)
        d = d / np.max(np.abs(d))
        a, w = stability_boundary(model, loop, d)
        if a < best[0]:
            best = (a, w, d)
    return best


@one_blas_thread
def analyze(
    model: UncertainModel,
    controller: LinearController,
    frequencies_hz: np.ndarray | None = None,
    refine: bool = True,
    maxiter: int = 200,
    add_modes: bool = True,
    bound: str = "diagonal",
    lmi_points: int = 3,
) -> MuAnalysis:
    """Robust stability of a loop: mu bounds, k_max and the worst parameter point.

    Parameters
    ----------
    model : UncertainModel
        The satellite's LFT (outputs attitude, rate).
    controller : LinearController
        The law (``LinearController.static(law_gains(...))`` for flexsat's laws).
    frequencies_hz : ndarray, optional
        The grid [Hz]; default 200 log-spaced points over 1e-3 ... 200 Hz.
    refine : bool
        Refine the upper bound's peak with a bounded scalar search.
    maxiter : int
        L-BFGS-B iterations of the D-G scalings per frequency (:func:`mu_upper_bound`).
    add_modes : bool
        Add the closed loop's modal frequencies at the box's centre (within the
        grid's span) to the grid.
    bound : str
        ``"diagonal"``: the D-G bound with diagonal scalings everywhere (fast);
        ``"lmi"``: then the full-block LMI bound (:func:`mu_upper_bound_lmi`) at the
        grid's highest frequencies, in decreasing order of the diagonal bound, until
        the next diagonal value is below the largest LMI value (the peak is then
        settled) or ``lmi_points`` are done; at most :data:`LMI_MAX_CHANNELS`
        channels.
    lmi_points : int
        At most this many LMI frequencies (each costs an SDP bisection).

    Returns
    -------
    MuAnalysis
    """
    if bound not in ("diagonal", "lmi"):
        raise ConfigError(f"bound: 'diagonal' or 'lmi', got {bound!r}")
    if bound == "lmi":
        _require_cvxpy()
        if model.n_channels > LMI_MAX_CHANNELS:
            raise ConfigError(
                f"bound: the LMI bound takes at most {LMI_MAX_CHANNELS} channels, this model "
                f"has {model.n_channels} (one SDP would take tens of minutes and GBs: "
                "docs/linear.md, 'Robust stability: mu'); use the diagonal bound or fewer "
                "parameters"
            )
    loop = closed_loop(model, controller)
    poles = np.linalg.eigvals(loop[0])
    nominal_stable = bool(np.max(poles.real) < 0.0)
    if frequencies_hz is None:
        frequencies_hz = np.logspace(-3, np.log10(200.0), 200)
    frequencies_hz = np.asarray(frequencies_hz, dtype=float)
    if add_modes:  # the closed loop's modes at the box's centre, within the grid's span
        modal = np.abs(poles.imag[poles.imag > 0]) / (2 * np.pi)
        lo, hi = np.min(frequencies_hz), np.max(frequencies_hz)
        frequencies_hz = np.unique(np.r_[frequencies_hz, modal[(modal >= lo) & (modal <= hi)]])
    f = np.sort(np.asarray(frequencies_hz, dtype=float))
    real = np.ones(model.n_channels, dtype=bool)
    upper = np.empty(f.size)
    starts = []
    start = None
    for i, fi in enumerate(f):
        upper[i], x, g = mu_upper_bound(_response(loop, 2 * np.pi * fi), real, start, maxiter)
        start = (x, g)
        starts.append(start)
    k = int(np.argmax(upper))
    peak, f_peak = float(upper[k]), float(f[k])
    if refine and 0 < k < f.size - 1:
        res = minimize_scalar(
            lambda lf: -mu_upper_bound(_response(loop, 2 * np.pi * 10**lf), real,
                                       starts[k], maxiter)[0],
            bounds=(np.log10(f[k - 1]), np.log10(f[k + 1])), method="bounded",
            options={"xatol": 1e-4, "maxiter": 12},
        )  # fmt: skip
        if -res.fun > peak:
            peak, f_peak = float(-res.fun), float(10**res.x)
            j = int(np.searchsorted(f, f_peak))
            f, upper = np.insert(f, j, f_peak), np.insert(upper, j, peak)
    lmi_f: list[float] = []
    if bound == "lmi":
        upper = upper.copy()
        real_blocks = np.ones(len(model.parameters), dtype=bool)
        settled = 0.0  # the largest LMI value so far
        for k in np.argsort(upper)[::-1][:lmi_points]:
            if upper[k] <= settled:
                break
            b = mu_upper_bound_lmi(_response(loop, 2 * np.pi * f[k]), model.channel_parameter,
                                   real_blocks, beta0=None)[0]  # fmt: skip
            upper[k] = min(upper[k], b)
            settled = max(settled, upper[k])
            lmi_f.append(float(f[k]))
        k = int(np.argmax(upper))
        peak, f_peak = float(upper[k]), float(f[k])
    n_p = len(model.parameters)
    vertices = np.array(np.meshgrid(*[[-1.0, 1.0]] * n_p)).reshape(n_p, -1).T
    axes = np.vstack([np.eye(n_p), -np.eye(n_p)])
    alpha, w_cross, d = _search_worst(model, loop, list(vertices) + list(axes))
    lower = 0.0 if not np.isfinite(alpha) else 1.0 / alpha
    worst = np.zeros(n_p) if d is None else alpha * d
    factors = {p.name: float(p.centre + p.half_range * v)
               for p, v in zip(model.parameters, worst, strict=True)}  # fmt: skip
    return MuAnalysis(
        frequencies_hz=f, upper=upper, peak_upper=peak, peak_frequency_hz=f_peak,
        lower=lower, lower_frequency_hz=float(w_cross / (2 * np.pi)) if lower else float("nan"),
        k_max=(1.0 / peak if peak > 0 else float("inf"), alpha), worst_delta=worst,
        worst_factors=factors, nominal_stable=nominal_stable, bound=bound,
        lmi_frequencies_hz=np.array(sorted(lmi_f)),
    )  # fmt: skip
