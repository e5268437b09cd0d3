"""Spectral analysis of recorded signals (scipy.signal)."""

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
    # imported here: scipy.signal costs 0.6 s to import, and every campaign worker
    # reaches this module through the slew metrics without calling it
    from scipy import signal

    values = signal.detrend(np.asarray(values, dtype=float))
    freqs, power = signal.periodogram(values, fs=1.0 / dt, window="hann")
    power[freqs < max(min_hz, freqs[1])] = 0.0
    k = int(np.argmax(power))
    if 0 < k < power.size - 1 and np.all(power[k - 1 : k + 2] > 0):
        a, b, c = np.log(power[k - 1 : k + 2])
        offset = 0.5 * (a - c) / (a - 2 * b + c)
        return float(freqs[k] + offset * (freqs[1] - freqs[0]))
    return float(freqs[k])
