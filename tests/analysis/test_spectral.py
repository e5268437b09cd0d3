"""The strongest spectral line (:func:`flexsat.analysis.spectral.dominant_frequency`).

Its periodogram is written with NumPy's FFT; the reference is scipy's own
``periodogram(detrend(x), fs, window="hann")``, which it replaces (docs/performance.md,
'Start-up'), and a sine of known frequency.
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy import signal

from flexsat.analysis import spectral

SEED = 20261207  # fixed, printed below: the noise of the reference signals


def _signal(n: int, dt: float, rng: np.random.Generator) -> np.ndarray:
    t = np.arange(n) * dt
    line = np.sin(2 * np.pi * 1.23 * t + 0.4) + 0.2 * np.sin(2 * np.pi * 7.1 * t)
    return line + 0.3 * t + 0.05 * rng.normal(size=n)  # a ramp and some noise


@pytest.mark.parametrize("n", [64, 65, 1001, 4096, 12000])  # even and odd lengths
def test_the_periodogram_is_scipys(n: int) -> None:
    print(f"seed {SEED}")
    rng = np.random.default_rng(SEED)
    dt = 0.01  # [s]
    x = _signal(n, dt, rng)
    detrended = spectral._detrend_linear(x)
    reference = signal.detrend(x)
    # Round-off: the same least-squares line, computed the same way (float64).
    assert np.max(np.abs(detrended - reference)) <= 1e-12 * np.max(np.abs(x))
    freqs, power = spectral._periodogram_hann(detrended, 1.0 / dt)
    ref_freqs, ref_power = signal.periodogram(reference, fs=1.0 / dt, window="hann")
    np.testing.assert_array_equal(freqs, ref_freqs)
    # Round-off of two FFTs of the same data: 1e-12 of the peak is ~1e4 ulps of margin.
    assert np.max(np.abs(power - ref_power)) <= 1e-12 * ref_power.max()


def test_a_sine_is_found_within_a_small_fraction_of_a_bin() -> None:
    dt, n = 0.01, 6000  # 100 Hz for 60 s: bins of 1/60 Hz
    t = np.arange(n) * dt
    f_true = 1.2313  # [Hz] the thesis's yaw ripple (thesis fig. 3.14), off the bin grid
    found = spectral.dominant_frequency(np.sin(2 * np.pi * f_true * t) + 0.5 * t, dt, 0.05)
    # Parabolic interpolation of the log power is exact for a Gaussian peak; on the Hann
    # main lobe its bias is at most 0.016 bin (a line swept across one bin in 40 steps
    # at this length): 0.05 bin leaves three times that.
    assert found == pytest.approx(f_true, abs=0.05 / (n * dt))


def test_the_line_below_min_hz_is_ignored() -> None:
    dt, n = 0.01, 6000
    t = np.arange(n) * dt
    x = 3.0 * np.sin(2 * np.pi * 0.03 * t) + np.sin(2 * np.pi * 2.0 * t)  # drift + line
    assert spectral.dominant_frequency(x, dt, 0.5) == pytest.approx(2.0, abs=0.05 / (n * dt))
