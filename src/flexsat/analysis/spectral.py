"""Spectral analysis of recorded signals: the strongest line of a periodogram.

Written with NumPy's FFT rather than :mod:`scipy.signal`, the slowest import of
``flexsat openloop``, which reports this line (docs/performance.md, 'Start-up'). The periodogram is
scipy's ``periodogram(detrend(x), fs, window="hann")`` written out; the tests hold the
two together to round-off.
"""

from __future__ import annotations

import numpy as np

__all__ = ["dominant_frequency"]


def dominant_frequency(values: np.ndarray, dt: float, min_hz: float = 0.0) -> float:
    """Frequency of the strongest spectral line of a uniformly sampled signal [Hz].

    The signal is linearly detrended and Hann-windowed; the peak of the one-sided
    periodogram above ``min_hz`` is refined by parabolic interpolation of the log
    power (accuracy well below one frequency bin for a clean line).

    Parameters
    ----------
    values : ndarray, shape (m,)
        The signal, any unit [u].
    dt : float
        Sample interval [s].
    min_hz : float
        Ignore lines below this frequency (drift) [Hz].
    """
    values = _detrend_linear(np.asarray(values, dtype=float))
    freqs, power = _periodogram_hann(values, 1.0 / dt)
    power[freqs < max(min_hz, freqs[1])] = 0.0
    k = int(np.argmax(power))
    if 0 < k < power.size - 1 and np.all(power[k - 1 : k + 2] > 0):
        a, b, c = np.log(power[k - 1 : k + 2])
        offset = 0.5 * (a - c) / (a - 2 * b + c)
        return float(freqs[k] + offset * (freqs[1] - freqs[0]))
    return float(freqs[k])


def _detrend_linear(values: np.ndarray) -> np.ndarray:
    """The signal minus its least-squares straight line (``scipy.signal.detrend``)."""
    n = values.size
    basis = np.ones((n, 2))
    basis[:, 0] = np.arange(1, n + 1) / n  # scaled as scipy scales it
    coefficients, *_ = np.linalg.lstsq(basis, values, rcond=None)
    return values - basis @ coefficients


def _periodogram_hann(values: np.ndarray, fs: float) -> tuple[np.ndarray, np.ndarray]:
    """One-sided power spectral density, periodic Hann window, mean removed [u²/Hz].

    As ``scipy.signal.periodogram(values, fs, window="hann")``: the window is the
    periodic ("DFT-even") Hann window of ``scipy.signal.get_window``, the density is
    ‖X_k‖² / (fs Σ w²), doubled on every bin but the zero and (even length) Nyquist
    ones.
    """
    n = values.size
    window = 0.5 - 0.5 * np.cos(2.0 * np.pi * np.arange(n) / n)
    spectrum = np.fft.rfft((values - values.mean()) * window)
    power = (spectrum.real**2 + spectrum.imag**2) / (fs * np.sum(window**2))
    power[1 : None if n % 2 else -1] *= 2.0
    return np.fft.rfftfreq(n, 1.0 / fs), power
