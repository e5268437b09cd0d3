"""The microvibration jitter recomputed from its definitions, for the study and CLI tests.

Written from docs/pointing.md, 'Microvibration', not from flexsat.linear.jitter's
lines: each term's force or torque is evaluated in the time domain as the wheel
model writes it (F = C Omega^2 (cos x e1 + sin x e2), x = h Omega t + phi, ...) and
projected on e^(i omega t) over one period; the closed loop's response is
C (i omega I - A)^-1 B + D solved with numpy; lines of one frequency add, lines of
different frequencies add in power. Only the closed loop's matrices come from flexsat
(flexsat.linear.jitter.closed_loop, checked against time-domain runs in
tests/linear/test_jitter.py).
"""

from __future__ import annotations

import numpy as np

ARCSEC = 180.0 / np.pi * 3600.0
_SAMPLES = 64  # per period: the projection of a pure sinusoid is exact to round-off


def _fourier(signal, omega: float) -> np.ndarray:
    """U with signal(t) = Re(U e^(i omega t)), from samples over one period (``signal``
    takes the sample times, shape (n,), and gives shape (n, 3) or (n, 1))."""
    t = np.arange(_SAMPLES) * (2.0 * np.pi / omega) / _SAMPLES
    values = signal(t)
    return 2.0 / _SAMPLES * np.sum(values * np.exp(-1j * omega * t)[:, None], axis=0)


def _terms(table: dict) -> list[tuple[str, float, float]]:
    """(kind, h, C) in the table's order: the imbalances (h = 1) first, zeros dropped."""
    terms = [("radial_force", 1.0, table.get("static_imbalance_kg_m", 0.0)),
             ("radial_torque", 1.0, table.get("dynamic_imbalance_kg_m2", 0.0))]  # fmt: skip
    for kind in ("radial_force", "axial_force", "radial_torque"):
        terms += [(kind, h["number"], h["coefficient"]) for h in table.get(kind, [])]
    return [t for t in terms if t[2] > 0.0]


def wheel_torque_lines(axes: np.ndarray, table: dict, speed_rpm: float) -> dict[float, np.ndarray]:
    """Hub torque per line frequency [Hz] -> complex amplitude (3,) [N m], every wheel at
    ``speed_rpm``: the time-domain wheel model projected on each harmonic."""
    omega = speed_rpm * 2.0 * np.pi / 60.0
    n = axes.shape[0]
    terms = _terms(table)
    phases = np.random.default_rng(table.get("seed", 1)).uniform(0.0, 2 * np.pi, (len(terms), n))
    positions = table.get("positions_m")
    positions = np.zeros((n, 3)) if positions is None else np.array(positions, dtype=float)
    vibrating = table.get("wheels") or range(1, n + 1)  # 1-based; phases drawn for all
    lines: dict[float, tuple[float, np.ndarray]] = {}
    for i in (w - 1 for w in vibrating):
        a = axes[i]
        e1 = np.eye(3)[np.argmin(np.abs(a))]  # the hub axis least aligned with a
        e1 = e1 - (e1 @ a) * a
        e1 /= np.linalg.norm(e1)
        e2 = np.cross(a, e1)
        for k, (kind, h, c) in enumerate(terms):
            amp, phi, r = c * omega**2, phases[k, i], positions[i]

            def torque(t, kind=kind, h=h, amp=amp, phi=phi, r=r, a=a, e1=e1, e2=e2):
                x = (h * omega * t + phi)[:, None]
                if kind == "axial_force":
                    return np.cross(r, amp * np.sin(x) * a)
                radial = amp * (np.cos(x) * e1 + np.sin(x) * e2)
                return radial if kind == "radial_torque" else np.cross(r, radial)

            _add(lines, h * omega / (2.0 * np.pi), _fourier(torque, h * omega))
    return {f: u for f, u in lines.values()}


def _add(lines: dict, frequency_hz: float, u) -> None:
    """Add a line to those of the same frequency (to 1e-9 Hz), keyed by its rounding."""
    key = round(frequency_hz, 9)
    f, previous = lines.get(key, (frequency_hz, 0.0))
    lines[key] = (f, previous + u)


def stepper_force_lines(stepper: dict) -> dict[float, complex]:
    """The stepper's ripple T_k sin(2 pi h_k f_s t + phi_k) per frequency [Hz] [N m]."""
    rate = stepper["rate_deg_s"] / stepper["step_angle_deg"]
    harmonics = stepper["harmonics"]
    phases = np.random.default_rng(stepper.get("seed", 1)).uniform(0.0, 2 * np.pi, len(harmonics))
    lines: dict[float, tuple[float, complex]] = {}
    for h, phi in zip(harmonics, phases, strict=True):
        omega = 2.0 * np.pi * h["number"] * rate

        def ripple(t, amp=h["amplitude_nm"], omega=omega, phi=phi):
            return (amp * np.sin(omega * t + phi))[:, None]

        _add(lines, h["number"] * rate, _fourier(ripple, omega)[0])
    return {f: u for f, u in lines.values()}


def response(model, frequency_hz: float, u: np.ndarray) -> np.ndarray:
    """C (i omega I - A)^-1 B u + D u: the closed loop's output line [rad]."""
    s = 2j * np.pi * frequency_hz
    A, B = np.asarray(model.A), np.asarray(model.B)
    x = np.linalg.solve(s * np.eye(A.shape[0]) - A, B @ u)
    return np.asarray(model.C) @ x + np.asarray(model.D) @ u


def rms_arcsec(outputs: list[np.ndarray], gains: list[float] | None = None) -> np.ndarray:
    """sqrt(sum_k |Y_k g_k|^2 / 2) per output [arcsec]: lines of distinct frequencies."""
    gains = [1.0] * len(outputs) if gains is None else gains
    power = sum(0.5 * np.abs(y * g) ** 2 for y, g in zip(outputs, gains, strict=True))
    return np.sqrt(power) * ARCSEC


def rpe_gain(frequency_hz: float, window_s: float) -> float:
    """|1 - sin(pi f dt) / (pi f dt)|: a sinusoid less its centred window mean."""
    x = np.pi * frequency_hz * window_s
    return abs(1.0 - np.sin(x) / x)
