"""Time-frequency analysis of recorded signals, and the modal lines to compare it with.

- :func:`spectrogram`: short-time power spectral density of a uniformly sampled
  signal (``scipy.signal.spectrogram`` on the linearly detrended record).
- :func:`coupled_frequencies`: the natural frequencies of the flexible modes that
  drive the hub rotation about one body axis, the lines a hub-rate or
  hub-acceleration spectrogram should show.
"""

from __future__ import annotations

import numpy as np
from scipy import signal

from flexsat.analysis.modal import ModalAnalysis

__all__ = [
    "DEFAULT_OVERLAP",
    "DEFAULT_WINDOW_S",
    "HUB_ROTATION_DOF",
    "coupled_frequencies",
    "spectrogram",
]

DEFAULT_WINDOW_S = 25.0
"""Default segment length [s]: 0.04 Hz bins, enough to separate lines 0.26-1.3 Hz apart."""

DEFAULT_OVERLAP = 0.9
"""Default fraction of a segment shared with the next one (a 2.5 s hop at 25 s)."""

HUB_ROTATION_DOF = {"x": "phi", "y": "theta", "z": "psi"}
"""Hub rotation coordinate (``Mode.hub_dof``) about each body axis."""


def spectrogram(
    values: np.ndarray,
    dt: float,
    window_s: float = DEFAULT_WINDOW_S,
    overlap: float = DEFAULT_OVERLAP,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Short-time power spectral density of a uniformly sampled signal.

    The whole record is linearly detrended (a constant rate or a drift would
    otherwise swamp the low bins), cut into segments of ``window_s`` seconds that
    overlap by ``overlap`` of their length, and each segment, linearly detrended
    again and Hann-windowed, gives one one-sided periodogram
    (``scipy.signal.spectrogram``, density scaling). The frequency resolution is
    ``1 / window_s`` [Hz]; the time resolution is the hop
    ``(1 - overlap) * window_s`` [s]. The defaults (25 s, 90 %) suit a 120 s
    record sampled at 100 Hz: 0.04 Hz bins and a spectrum every 2.5 s, so lines
    between ~0.25 and ~1.3 Hz stand apart. A record shorter than the window is
    analysed as one segment.

    Parameters
    ----------
    values : ndarray, shape (m,)
        The signal, any unit ``u`` (e.g. rad/s^2) [u].
    dt : float
        Sample interval [s].
    window_s : float
        Segment length [s].
    overlap : float
        Overlap of consecutive segments, as a fraction of a segment, in [0, 1) [-].

    Returns
    -------
    freqs_hz : ndarray, shape (n_f,)
        Frequencies of the bins, 0 to the Nyquist frequency ``1 / (2 dt)`` [Hz].
    times_s : ndarray, shape (n_t,)
        Centre of each segment, from the first sample [s].
    power : ndarray, shape (n_f, n_t)
        Power spectral density [u^2/Hz].

    Raises
    ------
    ValueError
        If ``dt`` or ``window_s`` is not positive, ``overlap`` is outside [0, 1),
        ``values`` is not one-dimensional, or it has fewer than 4 samples.
    """
    values = np.asarray(values, dtype=float)
    if values.ndim != 1:
        raise ValueError(f"values must be one-dimensional, got shape {values.shape}")
    if values.size < 4:
        raise ValueError(f"values needs at least 4 samples, got {values.size}")
    if not dt > 0.0:
        raise ValueError(f"dt must be positive, got {dt}")
    if not window_s > 0.0:
        raise ValueError(f"window_s must be positive, got {window_s}")
    if not 0.0 <= overlap < 1.0:
        raise ValueError(f"overlap must be in [0, 1), got {overlap}")
    nperseg = int(np.clip(round(window_s / dt), 4, values.size))
    noverlap = min(round(overlap * nperseg), nperseg - 1)
    freqs, times, power = signal.spectrogram(
        signal.detrend(values, type="linear"),
        fs=1.0 / dt,
        window="hann",
        nperseg=nperseg,
        noverlap=noverlap,
        detrend="linear",
        scaling="density",
        mode="psd",
    )
    return freqs, times, power


def coupled_frequencies(analysis: ModalAnalysis, hub_axis: str) -> np.ndarray:
    """Natural frequencies of the flexible modes that drive the hub about one body axis.

    A mode counts when its ``hub_dof`` (the hub coordinate it drives most, see
    :func:`flexsat.analysis.modal.modal_analysis`) is the hub rotation about
    ``hub_axis``: ``phi`` for x, ``theta`` for y, ``psi`` for z. Modes that mainly
    drive a hub translation (e.g. the symmetric flapping mode, which moves the hub
    along Z but does not turn it) and modes that leave the hub at rest are left out.

    Parameters
    ----------
    analysis : ModalAnalysis
        The modes (:func:`flexsat.analysis.modal_analysis`).
    hub_axis : {"x", "y", "z"}
        Body axis of the hub rotation; the coordinate names ``"phi"``, ``"theta"``,
        ``"psi"`` are accepted too.

    Returns
    -------
    ndarray, shape (k,)
        Frequencies [Hz], ascending; empty if no flexible mode drives that rotation.

    Raises
    ------
    ValueError
        If ``hub_axis`` names no hub rotation.
    """
    key = str(hub_axis).lower()
    dof = HUB_ROTATION_DOF.get(key, key)
    if dof not in HUB_ROTATION_DOF.values():
        raise ValueError(f"hub_axis must be one of x, y, z (or phi, theta, psi), got {hub_axis!r}")
    freqs = [
        m.frequency_hz
        for m in analysis.modes
        if m.kind != "rigid" and m.frequency_hz > 0.0 and m.hub_dof == dof
    ]
    return np.sort(np.asarray(freqs, dtype=float))
