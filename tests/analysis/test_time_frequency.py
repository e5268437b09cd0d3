"""Spectrogram of recorded signals and the coupled modal lines to overlay on it."""

from __future__ import annotations

import numpy as np
import pytest

from flexsat.analysis.modal import modal_analysis
from flexsat.analysis.time_frequency import coupled_frequencies, spectrogram

DT = 0.01  # 100 Hz
DURATION = 120.0
LINES_HZ = (0.52, 1.23)


def _two_sines(ramp: float = 0.0) -> np.ndarray:
    t = np.arange(round(DURATION / DT)) * DT
    x = np.sin(2 * np.pi * LINES_HZ[0] * t) + 0.7 * np.sin(2 * np.pi * LINES_HZ[1] * t + 0.3)
    return x + ramp * (t + 5.0)


def _two_strongest_peaks(freqs: np.ndarray, spectrum: np.ndarray) -> list[float]:
    inner = (spectrum[1:-1] > spectrum[:-2]) & (spectrum[1:-1] >= spectrum[2:])
    peaks = np.nonzero(inner)[0] + 1
    strongest = peaks[np.argsort(spectrum[peaks])[::-1][:2]]
    return sorted(freqs[strongest].tolist())


@pytest.mark.parametrize("ramp", [0.0, 0.05])
def test_strongest_bins_at_the_two_lines(ramp: float) -> None:
    freqs, times, power = spectrogram(_two_sines(ramp), DT)
    df = freqs[1] - freqs[0]
    assert df <= 0.1  # fine enough to separate 0.52 and 1.23 Hz by many bins
    assert power.shape == (freqs.size, times.size)
    assert times.size >= 5
    assert 0.0 < times[0] < times[-1] < DURATION
    assert freqs[-1] == pytest.approx(0.5 / DT)
    assert np.all(power >= 0.0)
    # Every time slice, and the average, peaks at the two lines (a ramp is detrended).
    for spectrum in (power.mean(axis=1), power[:, 0], power[:, -1]):
        found = _two_strongest_peaks(freqs, spectrum)
        for got, want in zip(found, LINES_HZ, strict=True):
            assert abs(got - want) <= df
    assert np.argmax(power.mean(axis=1)) == np.argmin(np.abs(freqs - LINES_HZ[0]))


def test_window_sets_the_resolution() -> None:
    freqs, times, _ = spectrogram(_two_sines(), DT, window_s=20.0, overlap=0.5)
    assert freqs[1] - freqs[0] == pytest.approx(1.0 / 20.0)
    assert times[1] - times[0] == pytest.approx(10.0)


def test_short_record_is_one_segment() -> None:
    freqs, times, power = spectrogram(_two_sines()[:500], DT)  # 5 s < the default window
    assert times.size == 1
    assert power.shape == (freqs.size, 1)


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"dt": 0.0}, "dt"),
        ({"window_s": -1.0}, "window_s"),
        ({"overlap": 1.0}, "overlap"),
        ({"values": np.zeros((10, 2))}, "one-dimensional"),
        ({"values": np.zeros(3)}, "at least 4"),
    ],
)
def test_bad_arguments(kwargs: dict, match: str) -> None:
    args = {"values": _two_sines(), "dt": DT} | kwargs
    with pytest.raises(ValueError, match=match):
        spectrogram(**args)


@pytest.fixture(scope="module")
def nominal_analysis(nominal_plant):
    return modal_analysis(nominal_plant)


def test_coupled_yaw_frequencies(nominal_analysis) -> None:
    yaw = coupled_frequencies(nominal_analysis, "z")
    # The antisymmetric in-plane mode turns the hub about Z ...
    assert np.any(np.abs(yaw - 1.231) < 2e-3)
    # ... the symmetric flapping mode (0.258 Hz) moves the hub along Z, not about it.
    assert not np.any(np.abs(yaw - 0.258) < 0.02)
    assert np.all(np.diff(yaw) >= 0.0)
    assert np.all(yaw > 0.0)
    np.testing.assert_array_equal(coupled_frequencies(nominal_analysis, "psi"), yaw)


def test_coupled_frequencies_per_axis(nominal_analysis) -> None:
    roll = coupled_frequencies(nominal_analysis, "x")
    pitch = coupled_frequencies(nominal_analysis, "y")
    assert np.any(np.abs(roll - 0.521) < 2e-3)  # antisymmetric flapping rolls the hub
    assert np.any(np.abs(pitch - 0.824) < 2e-3)  # symmetric torsion pitches it
    every = {m.frequency_hz for m in nominal_analysis.modes if m.hub_dof in ("phi", "theta", "psi")}
    assert set(roll) | set(pitch) | set(coupled_frequencies(nominal_analysis, "z")) == every


def test_coupled_frequencies_rejects_unknown_axis(nominal_analysis) -> None:
    with pytest.raises(ValueError, match="hub_axis"):
        coupled_frequencies(nominal_analysis, "w")


def test_the_package_name_is_the_function_after_the_module_is_imported():
    # the module's name differs from its function's, so importing the module does not
    # rebind flexsat.analysis.spectrogram to it
    import flexsat.analysis
    import flexsat.analysis.time_frequency as module

    assert flexsat.analysis.spectrogram is module.spectrogram
    assert callable(flexsat.analysis.spectrogram)
