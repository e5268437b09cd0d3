"""Microvibration jitter in the frequency domain: wheel and SADM harmonics to pointing.

Each disturbance source is a set of harmonic *lines*: a frequency f_k [Hz] and a
complex amplitude U_k (one entry per input of the linear model: body torque [N m],
then the actuated coordinates' forces), the input being u(t) = Re(U_k e^(i 2 pi f_k t)).
The satellite's answer is a line of the same frequency, Y_k = H(i 2 pi f_k) U_k, H the
closed loop of :func:`closed_loop` (the linearized flexible satellite, every flexible
mode included, with the law's static feedback as :func:`~flexsat.linear.frequency.law_gains`
builds it for the margins). Lines of one frequency add coherently (the wheels of a
cluster spinning at one speed); lines of different frequencies are uncorrelated, so
the jitter's mean square is the sum of the lines' ‖Y_k‖^2 / 2, and its power spectral
density is ‖H‖^2 times the disturbance spectrum: H S_u H^H, S_u = sum_k U_k U_k^H / 2
delta(f - f_k) (:func:`jitter_psd` spreads each line over its frequency bin).

A window Δt (the RPE's, ``docs/pointing.md``) removes from each line its mean over the
window centred on each record: a line of frequency f is scaled by 1 - sinc(f Δt).

Wheels (:func:`wheel_lines`): the empirical model of the wheels stage
(:mod:`flexsat.control.stages.wheels`, 'Microvibration'), term k of wheel i at speed
Omega_i [rad/s] gives the line f = h_k Omega_i / (2 pi) with the torque amplitude

    radial force   r_i x C_k Omega_i^2 (e1_i - i e2_i) e^(i phi_ik)
    axial force    r_i x C_k Omega_i^2 (-i a_i) e^(i phi_ik)
    radial torque  C_k Omega_i^2 (e1_i - i e2_i) e^(i phi_ik)

the same phases as the time-domain stage, so the two describe one realisation.

SADM stepper (:func:`stepper_lines`): a stepper driving an array at the rate r
[deg/s] with the step angle s [deg] steps at f_s = r / s; harmonic k of its torque
ripple, amplitude T_k [N m] at h_k f_s, acts as a generalized force on the driven
coordinate (between hub and array, as the SADM drive's own torque does).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Annotated

import numpy as np
from pydantic import Field
from scipy.optimize import minimize_scalar
from scipy.signal import find_peaks

from flexsat.config.models import _Frozen
from flexsat.control.laws import LawConfig
from flexsat.control.stages.wheels import WheelsConfig, radial_basis
from flexsat.dynamics.plant import Plant
from flexsat.errors import ConfigError
from flexsat.linear.frequency import law_gains
from flexsat.linear.linearize import linearize
from flexsat.linear.model import LinearModel

__all__ = [
    "Lines",
    "SpeedSweep",
    "StepperConfig",
    "StepperHarmonic",
    "closed_loop",
    "jitter_psd",
    "jitter_rms",
    "line_response",
    "los_rows",
    "speed_sweep",
    "stepper_lines",
    "wheel_lines",
    "window_gain",
]

_RPM = 2.0 * np.pi / 60.0  # [rad/s per rpm]
_AXES = ("x", "y", "z")


@dataclass(frozen=True)
class Lines:
    """Harmonic disturbance lines on the inputs of a linear model.

    Attributes
    ----------
    frequency_hz : ndarray, shape (n,)
        f_k [Hz].
    amplitude : ndarray, shape (n, n_u), complex
        U_k, one entry per model input (torque [N m], generalized force [N or N m]).
    source : tuple of str
        What each line is (``"wheel 1 radial_force h=1"``).
    """

    frequency_hz: np.ndarray
    amplitude: np.ndarray
    source: tuple[str, ...]

    def __add__(self, other: Lines) -> Lines:
        """Both sources' lines together."""
        return Lines(
            np.concatenate([self.frequency_hz, other.frequency_hz]),
            np.vstack([self.amplitude, other.amplitude]),
            self.source + other.source,
        )


def closed_loop(
    plant: Plant,
    law: LawConfig | None = None,
    wheel_momentum_B: Sequence[float] | None = None,
    actuated: Sequence[str] = (),
    actuator_time_constant_s: float | None = None,
) -> LinearModel:
    """The linearized flexible satellite about rest, its attitude loop closed.

    ``tau = -K [theta; omega]`` with K of :func:`~flexsat.linear.frequency.law_gains`
    (the loop the margins break), plus the wheels' gyroscopic torque about rest,
    ``-omega x H_w = H_w x omega``, H_w the cluster's momentum. With a time constant
    tau_m the law's torque reaches the hub through the wheels' motors, a first-order
    lag ``tau_a_dot = (tau_cmd - tau_a) / tau_m`` (the pseudo-inverse allocation of a
    spanning cluster gives the hub the command itself, each motor lagging alike).

    Parameters
    ----------
    plant : Plant
        The satellite (every flexible mode is kept).
    law : LawConfig, optional
        The control law; default the PD law with its default gains.
    wheel_momentum_B : sequence of 3 floats, optional
        H_w = sum a_i h_i, hub frame B [N m s]; default zero.
    actuated : sequence of str
        Appendage coordinates that receive a disturbance force (a SADM's driven
        coordinate), named as for :func:`~flexsat.linear.linearize.linearize`.
    actuator_time_constant_s : float, optional
        tau_m, the wheels' ``motor_time_constant_s`` [s]; default none (the law's torque
        acts at once, as for the margins).

    Returns
    -------
    LinearModel
        Inputs: the disturbance torque on the hub ``tau_x, tau_y, tau_z`` [N m] (added
        to the law's), then ``Q_<coordinate>``; outputs ``phi, theta, psi``, the hub's
        small attitude angles [rad]. With tau_m, three more states ``tau_a_x`` ...
        ``tau_a_z`` [N m].
    """
    model = linearize(plant, outputs=("attitude", "rate"), actuated=actuated)
    K = law_gains(plant, law)
    H = np.zeros(3) if wheel_momentum_B is None else np.asarray(wheel_momentum_B, float)
    skew = np.array([[0.0, -H[2], H[1]], [H[2], 0.0, -H[0]], [-H[1], H[0], 0.0]])
    gyroscopic = np.hstack([np.zeros((3, 3)), skew])  # on [theta; omega]
    B3 = model.B[:, :3]
    A, B, C = model.A + B3 @ (gyroscopic - K) @ model.C, model.B, model.C[:3]
    names, units = model.state_names, model.state_units
    if actuator_time_constant_s is not None:
        if not actuator_time_constant_s > 0.0 or not np.isfinite(actuator_time_constant_s):
            raise ConfigError(
                f"actuator_time_constant_s: must be > 0 s, got {actuator_time_constant_s!r}"
            )
        rate = 1.0 / actuator_time_constant_s
        A = np.block([[model.A + B3 @ gyroscopic @ model.C, B3],
                      [-rate * K @ model.C, -rate * np.eye(3)]])  # fmt: skip
        B = np.vstack([model.B, np.zeros((3, model.B.shape[1]))])
        C = np.hstack([C, np.zeros((3, 3))])
        names = names + tuple(f"tau_a_{a}" for a in _AXES)
        units = units + ("N m",) * 3
    return LinearModel(
        A=A, B=B, C=C, D=model.D[:3], x0=np.zeros(A.shape[0]), u0=model.u0,
        spin=model.spin, state_names=names, input_names=model.input_names,
        output_names=model.output_names[:3], state_units=units,
        input_units=model.input_units, output_units=model.output_units[:3],
        jacobian=model.jacobian,
    )  # fmt: skip


def los_rows(boresight: Sequence[float]) -> np.ndarray:
    """The small-angle line-of-sight error of a boresight, as rows on the hub's angles.

    The error rotation theta moves b to b + theta x b; the line-of-sight error is
    theta's part perpendicular to b, along u and v = b x u (u the hub axis least
    aligned with b, made perpendicular to it: the axes of
    :func:`flexsat.analysis.pointing.line_of_sight_error`).

    Parameters
    ----------
    boresight : sequence of 3 floats
        b, hub frame B (normalised here) [-].

    Returns
    -------
    ndarray, shape (2, 3)
        [u; v]: eps = rows @ theta [rad per rad].
    """
    b = np.asarray(boresight, dtype=float)
    if b.shape != (3,) or not np.all(np.isfinite(b)) or np.linalg.norm(b) == 0.0:
        raise ConfigError(f"boresight: three finite numbers, not all zero, got {boresight!r}")
    b = b / np.linalg.norm(b)
    u = np.eye(3)[int(np.argmin(np.abs(b)))]
    u = u - (u @ b) * b
    u /= np.linalg.norm(u)
    return np.stack([u, np.cross(b, u)])


def wheel_lines(
    wheels: WheelsConfig, speeds_rpm: float | Sequence[float], n_inputs: int = 3
) -> Lines:
    """The harmonic lines of a wheel cluster's microvibration at constant speeds.

    Parameters
    ----------
    wheels : WheelsConfig
        The cluster, with its ``microvibration`` table (none: no lines).
    speeds_rpm : float or sequence of float
        Each wheel's speed relative to the hub, Omega_i (one for all, or one per
        wheel) [rpm].
    n_inputs : int
        The model's number of inputs (the torque is its first three) [-].

    Returns
    -------
    Lines
        One line per wheel and term, torque on the hub about its reference point.
    """
    axes = wheels.spin_axes()
    n = axes.shape[0]
    speeds = np.broadcast_to(np.asarray(speeds_rpm, dtype=float) * _RPM, (n,))
    vib = wheels.microvibration
    if vib is None or not vib.terms():
        return Lines(np.zeros(0), np.zeros((0, n_inputs), complex), ())
    e1, e2 = radial_basis(axes)
    r = np.zeros((n, 3)) if vib.positions_m is None else np.array(vib.positions_m, float)
    phases = vib.phases(n)
    names = ("radial_force", "axial_force", "radial_torque")
    freqs, amps, source = [], [], []
    on = vib.vibrating(n) & (speeds != 0.0)  # a wheel at rest: no line (C 0^2 = 0)
    for k, (kind, h, c) in enumerate(vib.terms()):
        for i in np.nonzero(on)[0]:
            rotor = np.exp(1j * phases[k, i]) * c * speeds[i] ** 2
            vector = -1j * axes[i] if kind == 1 else e1[i] - 1j * e2[i]
            torque = rotor * (vector if kind == 2 else _cross(r[i], vector))
            row = np.zeros(n_inputs, dtype=complex)
            row[:3] = torque
            freqs.append(h * abs(speeds[i]) / (2.0 * np.pi))
            amps.append(row if speeds[i] >= 0.0 else np.conj(row))  # spinning backwards
            source.append(f"wheel {i + 1} {names[kind]} h={h:g}")
    amplitude = np.array(amps, dtype=complex).reshape(len(freqs), n_inputs)
    return Lines(np.array(freqs, dtype=float), amplitude, tuple(source))


def _cross(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """a x b of two 3-vectors (b may be complex): np.cross's overhead is 30 times this."""
    return np.array([a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2],
                     a[0] * b[1] - a[1] * b[0]])  # fmt: skip


_StepNumber = Annotated[float, Field(gt=0.0, le=1000.0, allow_inf_nan=False)]


class StepperHarmonic(_Frozen):
    """One harmonic of a stepper's torque ripple: T at h times the step rate."""

    number: _StepNumber = Field(description="h, harmonic number of the step rate [-]")
    amplitude_nm: Annotated[float, Field(ge=0.0, le=1e3, allow_inf_nan=False)] = Field(
        description="T, torque amplitude [N m]"
    )


class StepperConfig(_Frozen):
    """A SADM stepper motor's torque ripple on its driven coordinate (module docstring)."""

    coordinate: str = Field(description="the driven coordinate, '<appendage>.<coordinate>'")
    rate_deg_s: Annotated[float, Field(gt=0.0, le=360.0, allow_inf_nan=False)] = Field(
        description="r, the drive's rate [deg/s]"
    )
    step_angle_deg: Annotated[float, Field(gt=0.0, le=90.0, allow_inf_nan=False)] = Field(
        description="s, the output angle of one (micro)step [deg]"
    )
    harmonics: tuple[StepperHarmonic, ...] = Field(
        min_length=1, max_length=64, description="the ripple's harmonics h_k, T_k [-, N m]"
    )
    seed: Annotated[int, Field(ge=0, lt=2**53)] = Field(1, description="phase stream")

    @property
    def step_rate_hz(self) -> float:
        """f_s = r / s [Hz]."""
        return self.rate_deg_s / self.step_angle_deg


def stepper_lines(stepper: StepperConfig, model: LinearModel) -> Lines:
    """The lines of a SADM stepper's torque ripple, on its coordinate's input.

    Parameters
    ----------
    stepper : StepperConfig
        The stepper.
    model : LinearModel
        The closed loop, built with ``actuated=[stepper.coordinate]``.

    Returns
    -------
    Lines
        T_k (-i) e^(i phi_k) at h_k f_s on ``Q_<coordinate>``, phases from ``seed``.
    """
    name = f"Q_{stepper.coordinate}"
    if name not in model.input_names:
        raise ConfigError(
            f"coordinate: the model has no input {name!r} (inputs: "
            f"{', '.join(model.input_names)}); build it with actuated=[{stepper.coordinate!r}]"
        )
    column = model.input_names.index(name)
    phases = np.random.default_rng(stepper.seed).uniform(0.0, 2 * np.pi, len(stepper.harmonics))
    amps = np.zeros((len(stepper.harmonics), len(model.input_names)), dtype=complex)
    amps[:, column] = [-1j * h.amplitude_nm * np.exp(1j * phi)
                       for h, phi in zip(stepper.harmonics, phases, strict=True)]  # fmt: skip
    freqs = np.array([h.number * stepper.step_rate_hz for h in stepper.harmonics])
    source = tuple(f"stepper h={h.number:g}" for h in stepper.harmonics)
    return Lines(freqs, amps, source)


def line_response(
    model: LinearModel, lines: Lines, rows: np.ndarray | None = None
) -> tuple[np.ndarray, np.ndarray]:
    """The satellite's answer to the lines, those of one frequency added coherently.

    Parameters
    ----------
    model : LinearModel
        The closed loop (:func:`closed_loop`).
    lines : Lines
        The disturbance.
    rows : ndarray, shape (n_y, n_model_outputs), optional
        A map of the model's outputs (:func:`los_rows` for a line of sight); default
        the outputs themselves [rad per rad].

    Returns
    -------
    frequency_hz : ndarray, shape (n_f,)
        The distinct line frequencies, ascending [Hz].
    Y : ndarray, shape (n_f, n_y), complex
        The output lines [rad].
    """
    freqs, where = np.unique(lines.frequency_hz, return_inverse=True)
    if freqs.size == 0:  # no line (wheels at rest, no table): no jitter
        n_y = model.C.shape[0] if rows is None else np.asarray(rows).shape[0]
        return freqs, np.zeros((0, n_y), dtype=complex)
    U = np.zeros((freqs.size, lines.amplitude.shape[1]), dtype=complex)
    np.add.at(U, where, lines.amplitude)
    G = model.frequency_response(freqs)  # (n_f, n_out, n_u)
    Y = np.einsum("fou,fu->fo", G, U)
    return freqs, (Y if rows is None else Y @ np.asarray(rows).T)


def window_gain(frequency_hz: np.ndarray, window_s: float | None) -> np.ndarray:
    """What of a line is left once each record's window mean is removed: 1 - sinc(f Δt).

    Parameters
    ----------
    frequency_hz : ndarray
        Line frequencies [Hz].
    window_s : float or None
        Δt [s]; None: no window (gain 1).

    Returns
    -------
    ndarray
        The amplitude gain [-], same shape.
    """
    f = np.asarray(frequency_hz, dtype=float)
    if window_s is None:
        return np.ones_like(f)
    if not window_s > 0.0 or not np.isfinite(window_s):
        raise ConfigError(f"window_s: must be a positive number of seconds, got {window_s!r}")
    return np.abs(1.0 - np.sinc(f * window_s))


def jitter_rms(
    model: LinearModel, lines: Lines, rows: np.ndarray | None = None,
    window_s: float | None = None,
) -> np.ndarray:  # fmt: skip
    """RMS jitter per output: sqrt(sum_k ‖Y_k‖^2 / 2), windowed by 1 - sinc(f Δt).

    Parameters
    ----------
    model : LinearModel
        The closed loop (:func:`closed_loop`).
    lines : Lines
        The disturbance.
    rows : ndarray, shape (n_y, n_model_outputs), optional
        Output map, as for :func:`line_response` [rad per rad].
    window_s : float, optional
        The RPE's window Δt [s]; default none (the whole error's RMS).

    Returns
    -------
    ndarray, shape (n_y,)
        RMS per output [rad].
    """
    freqs, Y = line_response(model, lines, rows)
    gain = window_gain(freqs, window_s)[:, None]
    return np.sqrt(0.5 * np.sum(np.abs(Y * gain) ** 2, axis=0))


def jitter_psd(
    model: LinearModel, lines: Lines, frequency_hz: np.ndarray,
    rows: np.ndarray | None = None,
) -> np.ndarray:  # fmt: skip
    """One-sided PSD of the jitter on a uniform grid: each line's power over its bin.

    Each line's power ‖Y_k‖^2 / 2 (H at the line's own frequency: exact however coarse
    the grid) is divided by the bin width, in the bin whose centre is nearest; so
    sum(PSD) df is the mean square of :func:`jitter_rms`.

    Parameters
    ----------
    model : LinearModel
        The closed loop (:func:`closed_loop`).
    lines : Lines
        The disturbance.
    frequency_hz : ndarray, shape (n_f,)
        Bin centres, uniformly spaced, ascending [Hz].
    rows : ndarray, shape (n_y, n_model_outputs), optional
        Output map, as for :func:`line_response` [rad per rad].

    Returns
    -------
    ndarray, shape (n_f, n_y)
        PSD [rad^2/Hz]; lines outside the grid are left out.
    """
    f = np.asarray(frequency_hz, dtype=float)
    df = np.diff(f)
    if f.size < 2 or np.any(df <= 0.0) or not np.allclose(df, df[0], rtol=1e-9):
        raise ConfigError("frequency_hz: a uniform ascending grid of at least two bins")
    freqs, Y = line_response(model, lines, rows)
    psd = np.zeros((f.size, Y.shape[1]))
    k = np.rint((freqs - f[0]) / df[0]).astype(int)
    inside = (k >= 0) & (k < f.size)
    np.add.at(psd, k[inside], 0.5 * np.abs(Y[inside]) ** 2 / df[0])
    return psd


@dataclass(frozen=True)
class SpeedSweep:
    """The jitter of a wheel cluster over a range of common wheel speeds.

    Attributes
    ----------
    speed_rpm : ndarray, shape (n_s,)
        The speeds swept, ascending [rpm].
    rms : ndarray, shape (n_s, n_y)
        RMS jitter per output at each speed [rad].
    total : ndarray, shape (n_s,)
        sqrt of the sum of the outputs' mean squares [rad].
    line_hz : ndarray, shape (n_s, n_lines)
        Each harmonic's frequency at each speed [Hz].
    line_amplitude : ndarray, shape (n_s, n_lines)
        Each harmonic's own response amplitude, the outputs' norm [rad].
    harmonics : ndarray, shape (n_lines,)
        h of each line [-].
    modes_hz : ndarray
        The closed loop's lightly damped modes (damping ratio < 0.3) [Hz].
    worst_rpm : ndarray
        The speeds of the largest local maxima of ``total``, worst first [rpm].
    worst_rms : ndarray
        ``total`` there [rad].
    outputs : tuple of str
        Name of each output.
    """

    speed_rpm: np.ndarray
    rms: np.ndarray
    total: np.ndarray
    line_hz: np.ndarray
    line_amplitude: np.ndarray
    harmonics: np.ndarray
    modes_hz: np.ndarray
    worst_rpm: np.ndarray
    worst_rms: np.ndarray
    outputs: tuple[str, ...]


def speed_sweep(
    model: LinearModel, wheels: WheelsConfig, speeds_rpm: np.ndarray,
    rows: np.ndarray | None = None, window_s: float | None = None, n_worst: int = 3,
    outputs: Sequence[str] | None = None,
) -> SpeedSweep:  # fmt: skip
    """Jitter against the wheels' common speed, and the worst speeds.

    Every speed at which a harmonic crosses a lightly damped mode of the closed loop
    (h Omega = 2 pi f_mode) is added to the grid, so no resonance falls between two
    grid points; each local maximum of the total is then refined by a bounded scalar
    search between its neighbouring grid points (the ends of the range count as
    maxima when the total rises towards them).

    Parameters
    ----------
    model : LinearModel
        The closed loop (:func:`closed_loop`).
    wheels : WheelsConfig
        The cluster, with its microvibration.
    speeds_rpm : ndarray
        Speeds to sweep [rpm], every wheel at the same speed (> 0).
    rows : ndarray, optional
        Output map, as for :func:`line_response` [rad per rad].
    window_s : float, optional
        RPE window [s].
    n_worst : int
        How many worst speeds to report.
    outputs : sequence of str, optional
        Names of the mapped outputs; default the model's.

    Returns
    -------
    SpeedSweep
    """
    speeds = np.asarray(speeds_rpm, dtype=float)
    if speeds.size < 2 or np.any(speeds <= 0.0) or not np.all(np.isfinite(speeds)):
        raise ConfigError("speeds_rpm: at least two finite wheel speeds, each > 0 rpm")
    vib = wheels.microvibration
    if vib is None or not vib.terms():
        raise ConfigError("microvibration: the wheels have no imbalance or harmonic to sweep")
    harmonics = np.array(sorted({h for _, h, _ in vib.terms()}))
    lam = np.linalg.eigvals(model.A)
    light = lam[(lam.imag > 0) & (-lam.real < 0.3 * np.abs(lam))]
    modes_hz = np.sort(np.abs(light) / (2 * np.pi))
    crossing = (modes_hz[:, None] / harmonics[None, :]).ravel() * 60.0
    lo, hi = speeds.min(), speeds.max()
    grid = np.unique(np.concatenate([speeds, crossing[(crossing > lo) & (crossing < hi)]]))
    line_hz = np.outer(grid / 60.0, harmonics)
    amplitude = np.empty_like(line_hz)
    rms = []

    def at(speed: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        lines = wheel_lines(wheels, speed, model.B.shape[1])
        freqs, Y = line_response(model, lines, rows)
        gain = window_gain(freqs, window_s)[:, None]
        return np.sqrt(0.5 * np.sum(np.abs(Y * gain) ** 2, axis=0)), freqs, Y

    for s, speed in enumerate(grid):
        row, freqs, Y = at(speed)
        rms.append(row)
        amplitude[s] = np.interp(line_hz[s], freqs, np.linalg.norm(Y, axis=1))
    rms = np.array(rms)
    total = np.sqrt(np.sum(rms**2, axis=1))
    # an end of the range is a maximum when the total rises towards it
    peaks = find_peaks(np.concatenate([total[1:2], total, total[-2:-1]]))[0] - 1
    worst_rpm, worst_rms = grid[peaks], total[peaks]
    for j, k in enumerate(peaks):  # refined between the neighbouring grid points
        if 0 < k < grid.size - 1:
            best = minimize_scalar(lambda v: -np.linalg.norm(at(v)[0]), method="bounded",
                                   bounds=(grid[k - 1], grid[k + 1]),
                                   options={"xatol": 1e-9 * grid[k]})  # fmt: skip
            if -best.fun > worst_rms[j]:
                worst_rpm[j], worst_rms[j] = best.x, -best.fun
    order = np.argsort(worst_rms)[::-1][:n_worst]
    if outputs is not None:
        names = tuple(outputs)
    elif rows is None:
        names = model.output_names
    else:
        names = tuple(f"out_{i}" for i in range(len(rows)))
    return SpeedSweep(grid, rms, total, line_hz, amplitude, harmonics, modes_hz,
                      worst_rpm[order], worst_rms[order], names)  # fmt: skip
