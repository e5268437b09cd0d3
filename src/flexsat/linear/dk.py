"""mu-synthesis of an attitude controller by D-K iteration (dkpy's steps, flexsat's loop).

D-K iteration (Doyle, "Structured uncertainty in control system design", IEEE CDC
1985; Skogestad and Postlethwaite, *Multivariable Feedback Control*, 2nd ed. 2005,
section 8.12) alternates two convex steps on the robust-performance problem
``mu_Delta(F_l(P, K)(i w)) < 1``, ``Delta = diag(Delta_unc, Delta_perf)``:

- **K step**: an H-infinity controller for the scaled plant ``D P D^-1`` (slycot's
  ``sb10ad`` through ``control.hinfsyn``);
- **D step**: mu's complex upper bound of the closed loop on a frequency grid (one
  LMI per frequency), its D scalings fitted by stable minimum-phase transfer
  functions of a fixed order (slycot's ``sb10yd``).

The steps are dkpy's (``HinfSynSlicot``, ``SsvLmiBisection``, ``DScaleFitSlicot``,
Python package ``dkpy``); the loop is flexsat's: it records mu's peak after each K
step and keeps the best controller, stopping when mu does not decrease (dkpy's
own loops run a fixed count and return the last controller, whose mu can rise
when a D fit is poor). dkpy handles complex blocks only (its LMI raises
``NotImplementedError`` on real blocks), so the uncertainty is covered by complex
blocks (``docs/control.md``, "mu-synthesis by D-K iteration").

flexsat's design problem (:func:`synthesize_dk`) is the H-infinity problem of
:mod:`flexsat.linear.hinf` (same weights, same design plant) with a complex input
multiplicative uncertainty ``u_in = (I + r0 Delta_I) u``, ``‖Delta_I‖ <= 1``, whose
radius r0 covers the rigid attitude's torque-to-acceleration gain over the
parameter box's vertices (:func:`inertia_uncertainty`).
"""

from __future__ import annotations

import itertools
from dataclasses import dataclass, field

import numpy as np

from flexsat.control.laws.statespace import DiscreteController
from flexsat.errors import ConfigError
from flexsat.linear.blas_threads import one_blas_thread
from flexsat.linear.hinf import HinfWeights, _as_model, design_plant, generalized_plant
from flexsat.linear.model import LinearModel
from flexsat.linear.reduce import balanced_truncation

__all__ = [
    "DKDesign",
    "DKResult",
    "dk_iterate",
    "inertia_uncertainty",
    "synthesize_dk",
]

_LOW_W = 1e-5  # rad/s: s G_omega(s) there is the rigid attitude's J^-1 to 1e-10 relative
_SSV_TOL = 1e-9  # Clarabel's tolerances for the per-frequency LMI (dkpy's defaults)


def _require_dkpy():
    """Import dkpy (and slycot, cvxpy) or raise one ConfigError naming the extra."""
    try:
        import dkpy
        import slycot  # noqa: F401  (the H-infinity and D-fit solvers)
    except ImportError:
        raise ConfigError(
            "D-K iteration needs dkpy, slycot and cvxpy: pip install 'flexsat[robust]'"
        ) from None
    return dkpy


@dataclass(frozen=True, eq=False)
class DKResult:
    """What a D-K iteration achieved.

    Attributes
    ----------
    controller : control.StateSpace
        The best controller (lowest mu peak), u = K y.
    mu_history : tuple of float
        mu's peak over the grid after each accepted K step (the first is the
        H-infinity controller of the unscaled plant); non-increasing [-].
    mu_omega : ndarray, shape (n_omega,)
        mu's upper bound at each frequency of the grid with ``controller`` [-].
    omega : ndarray, shape (n_omega,)
        The grid [rad/s].
    gammas : tuple of float
        ``hinfsyn``'s gamma of each accepted K step (of the scaled plant) [-].
    stopped : str
        Why the loop stopped.
    """

    controller: object
    mu_history: tuple[float, ...]
    mu_omega: np.ndarray
    omega: np.ndarray
    gammas: tuple[float, ...]
    stopped: str

    @property
    def mu(self) -> float:
        """The final controller's mu peak [-]."""
        return self.mu_history[-1]


def _augment(D, n_y: int):
    """diag(D(s), I_{n}) as a ``control.StateSpace``: the scaling passes y (or u) through."""
    import control

    D = control.ss(D)
    m = D.ninputs
    B = np.hstack([D.B, np.zeros((D.nstates, n_y))])
    C = np.vstack([D.C, np.zeros((n_y, D.nstates))])
    Dd = np.block([[D.D, np.zeros((D.noutputs, n_y))], [np.zeros((n_y, m)), np.eye(n_y)]])
    return control.ss(D.A, B, C, Dd)


@one_blas_thread
def dk_iterate(
    P,
    n_y: int,
    n_u: int,
    omega: np.ndarray,
    blocks: list,
    n_iterations: int = 4,
    fit_order: int = 4,
) -> DKResult:
    """D-K iteration on a generalized plant, keeping the best controller.

    Parameters
    ----------
    P : control.StateSpace
        Generalized plant: inputs ``[w_Delta, w_perf, u]``, outputs
        ``[z_Delta, z_perf, y]`` (continuous time).
    n_y, n_u : int
        Measurements and controls (the last outputs and inputs of P).
    omega : ndarray
        Frequency grid of the D step [rad/s].
    blocks : list of dkpy.UncertaintyBlock
        Block structure of Delta (``dkpy.ComplexFullBlock`` ...), the performance
        block last.
    n_iterations : int
        At most this many D-K steps after the first H-infinity design.
    fit_order : int
        Order of each D scaling's transfer-function fit.

    Returns
    -------
    DKResult

    Raises
    ------
    ConfigError
        dkpy missing, or the first H-infinity synthesis or mu computation failed.
    """
    dkpy = _require_dkpy()
    import control

    omega = np.asarray(omega, dtype=float)
    hinf = dkpy.HinfSynSlicot()
    ssv = dkpy.SsvLmiBisection(n_jobs=None)  # one process: the frequencies one by one
    fit = dkpy.DScaleFitSlicot()

    def mu_of(K):
        N = P.lft(K)
        mu_w, D_l, D_r, info = ssv.compute_ssv(N(1j * omega), blocks)
        if mu_w is None or any(m is None for m in np.atleast_1d(mu_w)):
            return None, None, None
        return np.asarray(mu_w, dtype=float), D_l, D_r

    K, _, gamma, _ = hinf.synthesize(P, n_y, n_u)
    if K is None:
        raise ConfigError("D-K iteration: the first H-infinity synthesis has no solution")
    mu_w, D_l, D_r = mu_of(K)
    if mu_w is None:
        raise ConfigError("D-K iteration: mu of the first controller could not be computed")
    history, gammas = [float(np.max(mu_w))], [float(gamma)]
    best = (K, mu_w)
    stopped = f"{n_iterations} iterations done"
    for _ in range(n_iterations):
        D_fit, D_fit_inv = fit.fit(omega, D_l, D_r, fit_order, blocks)
        Ps = _augment(D_fit, n_y) * P * _augment(D_fit_inv, n_u)
        Ps = control.minreal(control.ss(Ps), verbose=False)
        K_new, _, gamma, _ = hinf.synthesize(Ps, n_y, n_u)
        if K_new is None:
            stopped = "the scaled plant's H-infinity synthesis failed"
            break
        mu_new, D_l_new, D_r_new = mu_of(K_new)
        if mu_new is None or np.max(mu_new) >= history[-1]:
            stopped = "mu did not decrease"
            break
        history.append(float(np.max(mu_new)))
        gammas.append(float(gamma))
        best = (K_new, mu_new)
        D_l, D_r = D_l_new, D_r_new
    return DKResult(best[0], tuple(history), best[1], omega, tuple(gammas), stopped)


def inertia_uncertainty(lft, n_vertices_max: int = 256) -> float:
    """r0: the input multiplicative uncertainty that covers the box's rigid gains.

    The rigid attitude's gain from torque to angular acceleration, ``J^-1``, taken as
    ``s G_omega(s)`` at s = i 1e-5 rad/s, at each vertex of the parameter box
    (``J_v^-1``) against the box's centre (``J_0^-1``): ``G_v = G_0 (I + E_v)``,
    ``E_v = J_0 J_v^-1 - I``, and r0 = max over the vertices of ``sigma_max(E_v)``.

    Parameters
    ----------
    lft : UncertainModel
        The satellite's LFT (:func:`flexsat.linear.uncertain.uncertain_model`).
    n_vertices_max : int
        Refuse boxes with more vertices than this.

    Returns
    -------
    float
        r0 [-].
    """
    n_p = len(lft.parameters)
    if 2**n_p > n_vertices_max:
        raise ConfigError(f"parameters: at most {int(np.log2(n_vertices_max))} for the "
                          f"vertex search, got {n_p}")  # fmt: skip

    def gain(delta):
        m = lft.evaluate(delta)
        keep = np.setdiff1d(np.arange(m.A.shape[0]), lft.translation)
        A, B, C = m.A[np.ix_(keep, keep)], m.B[keep], m.C[3:6, keep]
        s = 1j * _LOW_W
        return np.real(s * C @ np.linalg.solve(s * np.eye(A.shape[0]) - A, B))

    J0 = np.linalg.inv(gain(np.zeros(n_p)))
    r0 = 0.0
    for v in itertools.product((-1.0, 1.0), repeat=n_p):
        E = J0 @ gain(np.array(v)) - np.eye(3)
        r0 = max(r0, float(np.linalg.norm(E, 2)))
    return r0


@dataclass(frozen=True, eq=False)
class DKDesign:
    """A D-K design for the statespace law.

    Attributes
    ----------
    result : DKResult
        The iteration.
    r0 : float
        The input multiplicative uncertainty's radius [-].
    reduced : control.StateSpace
        The controller after balanced truncation.
    reduction_bound : float
        2 x the sum of the discarded Hankel singular values [N m per unit input].
    discrete : DiscreteController
        ``reduced`` discretized at the control period (Tustin).
    weights : HinfWeights
        The weights.
    """

    result: DKResult
    r0: float
    reduced: object
    reduction_bound: float
    discrete: DiscreteController
    weights: HinfWeights = field(default_factory=HinfWeights)


@one_blas_thread
def synthesize_dk(
    model: LinearModel,
    lft,
    control_dt_s: float,
    order: int = 6,
    n_modes: int = 0,
    weights: HinfWeights | None = None,
    omega: np.ndarray | None = None,
    n_iterations: int = 3,
    fit_order: int = 2,
) -> DKDesign:
    """mu-synthesis of an attitude controller, reduced and discretized like the H-infinity one.

    Parameters
    ----------
    model : LinearModel
        The satellite about rest (:func:`flexsat.linear.linearize`).
    lft : UncertainModel
        The satellite's LFT over the parameter box (r0 from its vertices).
    control_dt_s : float
        The control period [s].
    order : int
        States of the reduced controller.
    n_modes : int
        Flexible modes in the design plant.
    weights : HinfWeights, optional
        Default :class:`HinfWeights`.
    omega : ndarray, optional
        The D step's grid [rad/s]; default 30 log-spaced points over 1e-3 ... 1e2.
    n_iterations, fit_order : int
        As in :func:`dk_iterate`.

    Returns
    -------
    DKDesign

    Raises
    ------
    ConfigError
        dkpy missing, a failed synthesis, or ``order`` out of range.
    """
    dkpy = _require_dkpy()
    import control

    weights = weights or HinfWeights()
    r0 = inertia_uncertainty(lft)
    plant = design_plant(model, n_modes)
    P = control.ss(generalized_plant(plant, weights, input_uncertainty=r0))
    blocks = [dkpy.ComplexFullBlock(3, 3), dkpy.ComplexFullBlock(9, 9)]
    omega = np.logspace(-3, 2, 30) if omega is None else np.asarray(omega, dtype=float)
    result = dk_iterate(P, 6, 3, omega, blocks, n_iterations, fit_order)
    K = control.ss(result.controller)
    if not 1 <= order <= K.nstates:
        raise ConfigError(f"order: between 1 and {K.nstates} (the full controller), got {order}")
    if order < K.nstates:
        red = balanced_truncation(_as_model(K), order)
        Kr = control.ss(red.model.A, red.model.B, red.model.C, red.model.D)
        bound = red.error_bound
    else:
        Kr, bound = K, 0.0
    Kd = control.c2d(Kr, control_dt_s, method="tustin")
    discrete = DiscreteController(np.asarray(Kd.A), np.asarray(Kd.B), np.asarray(Kd.C),
                                  np.asarray(Kd.D), float(control_dt_s))  # fmt: skip
    return DKDesign(result, r0, Kr, float(bound), discrete, weights)
