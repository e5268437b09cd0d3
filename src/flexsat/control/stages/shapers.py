"""Input shapers: impulse sequences that cancel the residual vibration of chosen modes.

A shaper is a sequence of impulses (amplitudes A_i summing to 1, times t_i >= 0); a
command convolved with it excites a mode of frequency f and damping ratio zeta with
no residual vibration (ZV), with also zero sensitivity to f (ZVD), or with at most
a tolerated fraction V of the unshaped vibration over a band of f (EI). Multi-mode
shapers are the convolution of one shaper per mode. Singhose, Seering and Singer,
"Residual vibration reduction using vector diagrams to generate shaped inputs"
(1994), and Singer and Seering, "Preshaping command inputs to reduce system
vibration" (1990), give the sequences; ``docs/control.md``, "Reference trajectories
and input shaping", states the choices.
"""

from __future__ import annotations

from collections.abc import Sequence
from math import exp, pi, sqrt

import numpy as np

__all__ = ["SHAPERS", "convolve", "residual_vibration", "shaper", "shaper_for_modes"]


def _zv(K: float, half: float) -> tuple[list[float], list[float]]:
    return [1.0, K], [0.0, half]


def _zvd(K: float, half: float) -> tuple[list[float], list[float]]:
    return [1.0, 2.0 * K, K * K], [0.0, half, 2.0 * half]


def _ei(K: float, half: float, tolerance: float = 0.05) -> tuple[list[float], list[float]]:
    # Extra-insensitive shaper: residual V at the design frequency, zero at two
    # frequencies either side (Singhose et al. 1994, the undamped form with the
    # damped half period and the damping decay K applied to the middle impulse).
    amplitudes = [(1.0 + tolerance) / 4.0, (1.0 - tolerance) / 2.0 * K,
                  (1.0 + tolerance) / 4.0 * K * K]  # fmt: skip
    return amplitudes, [0.0, half, 2.0 * half]


SHAPERS = {"zv": _zv, "zvd": _zvd, "ei": _ei}
"""The shaper of each kind: (K, damped half period [s]) -> (amplitudes, times)."""


def shaper(kind: str, frequency_hz: float, damping_ratio: float) -> tuple[np.ndarray, np.ndarray]:
    """Impulse amplitudes (sum 1) and times [s] of one mode's shaper.

    Parameters
    ----------
    kind : {"zv", "zvd", "ei"}
        The shaper (:data:`SHAPERS`).
    frequency_hz : float
        Natural frequency f of the mode [Hz], > 0.
    damping_ratio : float
        zeta of the mode, 0 <= zeta < 1 [-].

    Returns
    -------
    amplitudes : ndarray, shape (k,)
        Impulse amplitudes, sum 1 [-].
    times : ndarray, shape (k,)
        Impulse times, the first at 0 [s].
    """
    zeta = float(damping_ratio)
    wd = 2.0 * pi * frequency_hz * sqrt(1.0 - zeta * zeta)  # damped frequency [rad/s]
    K = exp(-zeta * pi / sqrt(1.0 - zeta * zeta))
    amplitudes, times = SHAPERS[kind](K, pi / wd)
    A = np.array(amplitudes)
    return A / A.sum(), np.array(times)


def convolve(
    first: tuple[np.ndarray, np.ndarray], second: tuple[np.ndarray, np.ndarray]
) -> tuple[np.ndarray, np.ndarray]:
    """The shaper whose impulses are every pair's product at the sum of their times.

    Parameters
    ----------
    first, second : tuple of ndarray
        Each shaper's (amplitudes [-], times [s]).

    Returns
    -------
    amplitudes : ndarray
        The products, in time order [-].
    times : ndarray
        The sums of the times, sorted [s].
    """
    A = np.multiply.outer(first[0], second[0]).ravel()
    t = np.add.outer(first[1], second[1]).ravel()
    order = np.argsort(t, kind="stable")
    return A[order], t[order]


def shaper_for_modes(
    kind: str, frequencies_hz: Sequence[float], damping_ratios: Sequence[float]
) -> tuple[np.ndarray, np.ndarray]:
    """One shaper per mode, convolved (multi-mode shaping).

    Parameters
    ----------
    kind : {"zv", "zvd", "ei"}
        The shaper of every mode.
    frequencies_hz : sequence of float
        The modes' natural frequencies [Hz].
    damping_ratios : sequence of float
        Their damping ratios [-].

    Returns
    -------
    amplitudes : ndarray
        Impulse amplitudes, sum 1 [-].
    times : ndarray
        Impulse times [s].
    """
    out = (np.ones(1), np.zeros(1))
    for f, zeta in zip(frequencies_hz, damping_ratios, strict=True):
        out = convolve(out, shaper(kind, f, zeta))
    return out


def residual_vibration(
    amplitudes: np.ndarray, times: np.ndarray, frequency_hz: float, damping_ratio: float
) -> float:
    """Residual vibration of a damped mode after the impulses, relative to one impulse.

    V = exp(-zeta w t_N) ‖sum A_i exp(zeta w t_i) exp(j w_d t_i)‖ (Singer and Seering
    1990), 0 for a perfect shaper, 1 for no shaping.

    Parameters
    ----------
    amplitudes : ndarray, shape (k,)
        Impulse amplitudes [-].
    times : ndarray, shape (k,)
        Impulse times, ascending [s].
    frequency_hz : float
        The mode's natural frequency [Hz].
    damping_ratio : float
        Its damping ratio [-].

    Returns
    -------
    float
        V [-].
    """
    w = 2.0 * pi * frequency_hz
    zeta = damping_ratio
    wd = w * sqrt(1.0 - zeta * zeta)
    t_end = times[-1]
    phasors = amplitudes * np.exp(zeta * w * (times - t_end)) * np.exp(1j * wd * times)
    return float(abs(phasors.sum()))
