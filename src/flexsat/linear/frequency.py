"""Frequency-domain views: rigid reference model, modal effective inertia, PD loop margins.

- :func:`rigid_model`: the rigidized satellite (J_tot of the design model) from body
  torque to attitude and rate, to draw beside the flexible model.
- :func:`effective_inertia`: modal effective inertia per flexible mode and body axis,
  the CSI ranking of the modes.
- :func:`pd_loop` and :func:`loop_margins`: the loop gain of the quaternion PD law
  linearized about rest, one axis at a time (that axis's loop broken at the torque
  input, the other two closed), with gain, phase and delay margins.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.optimize import brentq, minimize_scalar

from flexsat.analysis.modal import effective_masses
from flexsat.control.laws import LawConfig, get_law, law_names
from flexsat.control.laws.pd import PDConfig
from flexsat.dynamics.plant import Plant
from flexsat.dynamics.rigid import rigid_inertia
from flexsat.errors import ConfigError
from flexsat.linear.model import LinearModel

__all__ = [
    "Crossover",
    "FlexiblePeak",
    "LoopMargins",
    "effective_inertia",
    "effective_masses",
    "law_gains",
    "loop_margins",
    "pd_gains",
    "pd_loop",
    "rigid_model",
]

_AXES = ("x", "y", "z")
_BESIDE_POLE = 1e-7  # relative offset of the grid points beside each pole frequency
_PEAK_NEAR_MODE = 0.05  # a loop-gain peak belongs to a flexible mode within 5 % of it


def rigid_model(plant: Plant) -> LinearModel:
    """The rigidized satellite about rest: attitude and body rate from body torque.

    ``J_tot theta_ddot = tau`` with J_tot of :func:`flexsat.dynamics.rigid.rigid_inertia`;
    states and outputs ``phi, theta, psi, omega_x, omega_y, omega_z``.

    Parameters
    ----------
    plant : Plant
        The satellite.

    Returns
    -------
    LinearModel
        Inputs body torque [N m], states and outputs [rad, rad/s].
    """
    J_inv = np.linalg.inv(rigid_inertia(plant))
    A = np.zeros((6, 6))
    A[:3, 3:] = np.eye(3)
    B = np.vstack([np.zeros((3, 3)), J_inv])
    names = ("phi", "theta", "psi", "omega_x", "omega_y", "omega_z")
    units = ("rad",) * 3 + ("rad/s",) * 3
    return LinearModel(
        A=A, B=B, C=np.eye(6), D=np.zeros((6, 3)), x0=np.zeros(6), u0=np.zeros(3),
        spin=np.zeros(3), state_names=names, input_names=("tau_x", "tau_y", "tau_z"),
        output_names=names, state_units=units, input_units=("N m",) * 3, output_units=units,
        jacobian="analytic",
    )  # fmt: skip


def effective_inertia(plant: Plant) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Modal effective inertia of the appendage modes about each body axis.

    The appendages' modes with the hub held fixed (hybrid coordinates):
    ``K_ff phi = omega^2 M_ff phi`` with ``phi^T M_ff phi = 1`` on the joint
    coordinates f of M(0) (eq. 3.3 restricted to f). Their participation factors
    on the hub coordinates h are ``L = phi^T M_fh`` and the effective inertia of
    mode k about body axis a is ``J_eff,ka = L_k,a^2`` [kg m^2]. Together with the
    residual inertia ``J_res = M_hh - M_hf M_ff^-1 M_fh`` (the inertia the hub
    shows above every appendage mode) they add up to the locked inertia M(0)_hh.
    A large J_eff at a low frequency means strong control-structure interaction.

    Parameters
    ----------
    plant : Plant
        The satellite.

    Returns
    -------
    frequencies_hz : ndarray, shape (n_flex,)
        Frequencies of the hub-fixed appendage modes, ascending [Hz].
    J_eff : ndarray, shape (n_flex, 3)
        Effective inertia about body X, Y, Z [kg m^2].
    J_residual : ndarray, shape (3,)
        Residual inertia about X, Y, Z [kg m^2].
    """
    frequencies, effective, residual = effective_masses(plant)
    return frequencies, effective[:, 3:], residual[3:]


def pd_gains(plant: Plant, pd: PDConfig | None = None) -> np.ndarray:
    """Static gain K, shape (3, 6), of the PD law about rest: tau = -K [theta; omega].

    The law ``tau = w x Jw - J (kp q_v,e + kd w)`` with ``q_v,e ~ theta / 2`` and
    J the rigid design inertia linearizes to ``tau = -J (wn^2 theta + 2 zeta wn w)``
    (the gyroscopic term is quadratic in the rate).

    Parameters
    ----------
    plant : Plant
        The satellite (its rigid design inertia).
    pd : PDConfig, optional
        The PD law's parameters; default the built-in defaults.

    Returns
    -------
    ndarray, shape (3, 6)
        K on [theta; omega] [N m/rad, N m s/rad].
    """
    return law_gains(plant, pd or PDConfig())


def law_gains(plant: Plant, law: LawConfig | None = None) -> np.ndarray:
    """Static gain K, shape (3, 6), of a law linearized about rest: tau = -K [theta; omega].

    Parameters
    ----------
    plant : Plant
        Its rigidized inertia is the law's design model.
    law : LawConfig, optional
        Any registered law's parameters; default: the PD law with its default gains.
        Each law says how it linearizes (``LawConfig.linear_feedback``): the
        sliding-mode laws inside their boundary layer, the SMC with its constant
        Lambda and JK, the ASMC with its steady-state values at the target
        (Lambda = lambda_max, JK = JK_min).

    Raises
    ------
    ConfigError
        For a law without a linear form about rest.
    """
    law = law or PDConfig()
    K = law.linear_feedback(rigid_inertia(plant))
    if K is None:
        linear = [
            name
            for name in law_names()  # the laws that say how they linearize
            if get_law(name).config.linear_feedback is not LawConfig.linear_feedback
        ]
        raise ConfigError(
            f"controller.kind: the {law.kind!r} law has no linear form about rest "
            f"(laws with one: {', '.join(linear)})"
        )
    return np.asarray(K, dtype=float)


def pd_loop(model: LinearModel, K: np.ndarray, axis: str) -> LinearModel:
    """Loop gain L(s) at the torque input of ``axis`` with the other two loops closed.

    Parameters
    ----------
    model : LinearModel
        Must have the outputs ``phi, theta, psi, omega_x, omega_y, omega_z`` and the
        three torque inputs.
    K : ndarray, shape (3, 6)
        Static feedback ``tau = -K [theta; omega]``.
    axis : {"x", "y", "z"}

    Returns
    -------
    LinearModel
        SISO, input ``tau_<axis>``, output ``loop_<axis>``: the negative-feedback
        loop gain (closing the loop is ``u = -y``).
    """
    if axis not in _AXES:
        raise ConfigError(f"axis: unknown axis {axis!r} (allowed: x, y, z)")
    sub = model.select(
        outputs=["phi", "theta", "psi", "omega_x", "omega_y", "omega_z"],
        inputs=["tau_x", "tau_y", "tau_z"],
    )
    a = _AXES.index(axis)
    P = np.eye(3)
    P[a, a] = 0.0  # the other axes stay closed
    A = sub.A - sub.B @ P @ K @ sub.C
    return LinearModel(
        A=A, B=sub.B[:, [a]], C=K[[a]] @ sub.C, D=np.zeros((1, 1)), x0=sub.x0, u0=sub.u0[[a]],
        spin=sub.spin, state_names=sub.state_names, input_names=(f"tau_{axis}",),
        output_names=(f"loop_{axis}",), state_units=sub.state_units, input_units=("N m",),
        output_units=("N m",), jacobian=sub.jacobian,
    )  # fmt: skip


@dataclass(frozen=True)
class Crossover:
    """One gain crossover of a loop gain: ``|L|`` = 1 (0 dB).

    Attributes
    ----------
    frequency_hz : float
        Where ``|L|`` crosses 1 [Hz].
    phase_margin_deg : float
        180 deg + the phase of L there, in (-180, 180] [deg].
    delay_margin_s : float
        The pure delay that brings this crossing onto -180 deg:
        (phase margin mod 360 deg) / (360 deg * frequency) [s].
    """

    frequency_hz: float
    phase_margin_deg: float
    delay_margin_s: float


@dataclass(frozen=True)
class FlexiblePeak:
    """The resonance of one flexible mode in a loop gain, and how it is stabilized.

    A mode is *gain-stabilized* when its peak loop gain stays below 0 dB: the loop
    is stable whatever the phase of the mode, and a gain margin protects it. A mode
    whose peak rises above 0 dB is *phase-stabilized*: it adds two gain crossovers,
    and the loop stays stable only because the phase at them keeps away from
    -180 deg (their phase and delay margins are in :attr:`LoopMargins.crossovers`).

    Attributes
    ----------
    mode_hz : float
        Natural frequency of the satellite's flexible mode (free model) [Hz].
    peak_hz : float
        Where ``|L|`` peaks [Hz].
    peak_gain_db : float
        20 log10 max ``|L|`` near the mode [dB]; inf for an undamped mode.
    stabilized : str
        ``"gain"`` (peak below 0 dB) or ``"phase"`` (at or above 0 dB).
    """

    mode_hz: float
    peak_hz: float
    peak_gain_db: float
    stabilized: str


@dataclass(frozen=True)
class LoopMargins:
    """Stability margins of a SISO loop gain (negative feedback).

    ``gain_margin`` [-] (inf when the phase never crosses -180 deg above the lowest
    frequency); ``phase_margin_deg`` and ``delay_margin_s`` are the smallest over all
    gain crossovers (a flexible peak above 0 dB adds crossovers); the frequencies
    are those of the limiting crossing [Hz]; ``crossovers_hz`` lists them all, and
    ``crossovers`` each with its own phase and delay margins; ``flexible_peaks`` the
    flexible modes that show as a peak of ``|L|``, each gain- or phase-stabilized.

    Attributes
    ----------
    gain_margin : float
        Gain margin [-].
    phase_crossover_hz : float
        Frequency where the phase crosses -180 deg [Hz].
    phase_margin_deg : float
        Smallest phase margin over the gain crossovers [deg].
    gain_crossover_hz : float
        The gain crossover that sets it [Hz].
    delay_margin_s : float
        Smallest delay margin over the gain crossovers [s].
    delay_crossover_hz : float
        The gain crossover that sets it [Hz].
    crossovers_hz : tuple of float
        Every gain crossover, ascending [Hz].
    crossovers : tuple of Crossover
        Every gain crossover with its phase and delay margins, ascending.
    flexible_peaks : tuple of FlexiblePeak
        Every peak of ``|L|`` at a flexible mode of the satellite, ascending.
    """

    gain_margin: float
    phase_crossover_hz: float
    phase_margin_deg: float
    gain_crossover_hz: float
    delay_margin_s: float
    delay_crossover_hz: float
    crossovers_hz: tuple[float, ...]
    crossovers: tuple[Crossover, ...] = ()
    flexible_peaks: tuple[FlexiblePeak, ...] = ()

    def to_dict(self) -> dict:
        """The margins as JSON-ready values; crossovers and peaks as lists of dicts."""
        out = {k: getattr(self, k) for k in self.__dataclass_fields__}
        out["crossovers"] = [vars(c).copy() for c in self.crossovers]
        out["flexible_peaks"] = [vars(p).copy() for p in self.flexible_peaks]
        return out


def loop_margins(
    loop: LinearModel, f_min_hz: float = 1e-4, f_max_hz: float = 200.0,
    modes_hz: np.ndarray | None = None,
) -> LoopMargins:  # fmt: skip
    """Gain, phase and delay margins of a SISO loop gain, from its exact response.

    Crossings are bracketed on a log grid of 5000 points, to which the frequency of
    every pole of the loop is added with a point just below and just above it (so
    the two crossings beside a sharp or undamped peak are always bracketed), and are
    refined with Brent's method on the exact response (no fitting); phase crossings
    likewise. The peaks of ``|L|`` are the grid's local maxima refined by a bounded
    scalar search between their neighbouring grid points; one within 5 % of a
    flexible mode's frequency is that mode's peak (:class:`FlexiblePeak`).

    Parameters
    ----------
    loop : LinearModel
        SISO loop gain L(s) (one input, one output) [-].
    f_min_hz, f_max_hz : float
        Frequency band searched [Hz].
    modes_hz : ndarray, optional
        Natural frequencies of the satellite's flexible modes [Hz]; default: those of
        the loop's own lightly damped poles (damping ratio below 0.3).

    Returns
    -------
    LoopMargins
    """
    if loop.B.shape[1] != 1 or loop.C.shape[0] != 1:
        raise ConfigError("loop_margins needs a single-input single-output loop gain")

    def L(f):
        return loop.frequency_response(f)[0, 0, 0]

    lam = np.linalg.eigvals(loop.A)
    f_poles = np.abs(lam[lam.imag > 0]) / (2 * np.pi)
    f_poles = f_poles[(f_poles > f_min_hz) & (f_poles < f_max_hz)]
    f = np.unique(
        np.concatenate([
            np.geomspace(f_min_hz, f_max_hz, 5000),
            f_poles * (1 - _BESIDE_POLE), f_poles * (1 + _BESIDE_POLE),
        ])
    )  # fmt: skip
    G = loop.frequency_response(f)[:, 0, 0]
    log_mag = np.log(np.abs(G))
    cross = [
        brentq(lambda x: np.log(abs(L(x))), f[k], f[k + 1], xtol=1e-14)
        for k in np.nonzero(np.sign(log_mag[:-1]) != np.sign(log_mag[1:]))[0]
    ]
    pm, dm, f_pm, f_dm = np.inf, np.inf, np.nan, np.nan
    crossovers = []
    for fc in cross:
        margin = np.angle(-L(fc))  # phase above -180 deg, in (-pi, pi]
        delay = (margin % (2 * np.pi)) / (2 * np.pi * fc)  # phase a delay can eat first
        crossovers.append(Crossover(float(fc), float(np.degrees(margin)), float(delay)))
        if abs(np.degrees(margin)) < abs(pm):
            pm, f_pm = float(np.degrees(margin)), fc
        if delay < dm:
            dm, f_dm = float(delay), fc
    imag = G.imag
    gm, f_gm = np.inf, np.nan
    for k in np.nonzero((np.sign(imag[:-1]) != np.sign(imag[1:])) & (G.real[:-1] < 0))[0]:
        fp = brentq(lambda x: L(x).imag, f[k], f[k + 1], xtol=1e-14)
        mag = abs(L(fp))
        if mag == 0.0:  # a phase jump at an undamped zero, not a crossing of -180 deg
            continue
        g = 1.0 / mag
        if abs(np.log(g)) < abs(np.log(gm)):
            gm, f_gm = float(g), fp
    if modes_hz is None:
        light = lam[(lam.imag > 0) & (-lam.real < 0.3 * np.abs(lam))]
        modes_hz = np.abs(light) / (2 * np.pi)
    peaks = _flexible_peaks(L, lam, f, np.abs(G), np.asarray(modes_hz, dtype=float))
    return LoopMargins(gm, f_gm, pm, f_pm, dm, f_dm, tuple(float(c) for c in cross),
                       tuple(crossovers), peaks)  # fmt: skip


def _flexible_peaks(L, lam: np.ndarray, f: np.ndarray, mag: np.ndarray,
                    modes_hz: np.ndarray) -> tuple[FlexiblePeak, ...]:  # fmt: skip
    """The local maxima of ``|L|`` on the grid, refined, each named by its flexible mode."""
    if modes_hz.size == 0:
        return ()
    undamped = np.abs(lam[(lam.imag > 0) & (-lam.real <= 1e-9 * np.abs(lam))]) / (2 * np.pi)
    peaks: dict[int, FlexiblePeak] = {}
    for k in np.nonzero((mag[1:-1] > mag[:-2]) & (mag[1:-1] >= mag[2:]))[0] + 1:
        if np.any(np.abs(undamped / f[k] - 1) < 10 * _BESIDE_POLE):
            f_peak, gain = f[k], np.inf  # an undamped mode: |L| has no finite peak
        else:
            best = minimize_scalar(lambda x: -abs(L(np.exp(x))), method="bounded",
                                   bounds=(np.log(f[k - 1]), np.log(f[k + 1])),
                                   options={"xatol": 1e-12})  # fmt: skip
            f_peak, gain = float(np.exp(best.x)), float(-best.fun)
            if gain < mag[k]:  # never below the grid point that found it
                f_peak, gain = f[k], mag[k]
        m = int(np.argmin(np.abs(np.log(modes_hz / f_peak))))
        if abs(modes_hz[m] / f_peak - 1) > _PEAK_NEAR_MODE:
            continue  # a closed rigid loop's bump, not a flexible mode
        db = 20 * np.log10(gain)
        if m not in peaks or db > peaks[m].peak_gain_db:
            peaks[m] = FlexiblePeak(float(modes_hz[m]), float(f_peak), float(db),
                                    "gain" if db < 0.0 else "phase")  # fmt: skip
    return tuple(peaks[m] for m in sorted(peaks))
