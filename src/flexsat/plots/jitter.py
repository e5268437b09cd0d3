"""Figures of the microvibration jitter: the Campbell (waterfall) diagram of a speed sweep.

Drawn with the shared style (:mod:`flexsat.plots.style`), no pyplot.

- :func:`plot_campbell`: the wheel harmonics' frequencies against the wheel speed,
  each point coloured by the jitter that harmonic causes, over the closed loop's
  lightly damped modes; below, the RMS jitter against the speed with the worst
  speeds marked.
"""

from __future__ import annotations

import numpy as np
from matplotlib.colors import LogNorm
from matplotlib.figure import Figure

from flexsat.linear.jitter import SpeedSweep
from flexsat.plots import style

__all__ = ["plot_campbell"]

_RAD_TO_ARCSEC = 180.0 / np.pi * 3600.0


def plot_campbell(sweep: SpeedSweep, title: str = "Wheel microvibration") -> Figure:
    """Campbell diagram of a wheel-speed sweep and its RMS jitter.

    Top: each harmonic h is the line f = h Omega / 60 against the speed Omega [rpm],
    its points coloured by that harmonic's response amplitude (the outputs' norm
    [arcsec], log scale); the closed loop's lightly damped modes are horizontal
    lines, so a resonance is where a harmonic crosses one. Bottom: the RMS jitter
    (the outputs together) against the speed, the worst speeds marked.

    Parameters
    ----------
    sweep : SpeedSweep
        From :func:`flexsat.linear.jitter.speed_sweep`.
    title : str
        The figure's title.

    Returns
    -------
    Figure
        The figure.
    """
    # room on the right for the colour bar, which both rows leave (their x axes align)
    fig, axes = style.figure(2, 1, size=(10.0, 8.0), height_ratios=(3, 2), right=0.8, left=0.1)
    top, bottom = axes[0, 0], axes[1, 0]
    speed = sweep.speed_rpm
    amplitude = sweep.line_amplitude * _RAD_TO_ARCSEC
    positive = amplitude[amplitude > 0.0]
    norm = LogNorm(vmin=max(positive.min(), positive.max() * 1e-4), vmax=positive.max())
    f_max = float(sweep.line_hz.max()) * 1.05
    for mode in sweep.modes_hz[sweep.modes_hz <= f_max]:
        top.axhline(mode, color="0.6", linewidth=0.7, linestyle="--")
    for k, h in enumerate(sweep.harmonics):
        top.plot(speed, sweep.line_hz[:, k], color="0.85", linewidth=0.6, zorder=1)
        points = top.scatter(speed, sweep.line_hz[:, k], c=np.maximum(amplitude[:, k], norm.vmin),
                             s=6, cmap="viridis", norm=norm, zorder=2)  # fmt: skip
        top.annotate(f"h = {h:g}", (speed[-1], sweep.line_hz[-1, k]), fontsize=8,
                     xytext=(3, 0), textcoords="offset points", va="center")  # fmt: skip
    top.set_ylim(0.0, f_max)
    top.set_ylabel("frequency [Hz]")
    fig.colorbar(points, cax=top.inset_axes((1.03, 0.0, 0.02, 1.0)),
                 label="harmonic's jitter amplitude [arcsec]")  # fmt: skip
    rms = sweep.total * _RAD_TO_ARCSEC
    bottom.plot(speed, rms, color="tab:blue", linewidth=1.0, label="RMS jitter")
    bottom.plot(sweep.worst_rpm, sweep.worst_rms * _RAD_TO_ARCSEC, "v", color="tab:red",
                label="worst speeds")  # fmt: skip
    for s, r in zip(sweep.worst_rpm, sweep.worst_rms * _RAD_TO_ARCSEC, strict=True):
        bottom.annotate(f"{s:.0f} rpm", (s, r), fontsize=8, xytext=(0, 5),
                        textcoords="offset points", ha="center")  # fmt: skip
    if rms.max() > 10.0 * rms.min():
        bottom.set_yscale("log")
    bottom.set_xlabel("wheel speed [rpm]")
    bottom.set_ylabel("RMS jitter [arcsec]")
    bottom.grid(True, color="0.88", linewidth=0.5)
    bottom.legend(fontsize=8)
    fig.suptitle(f"{title}: Campbell diagram ({', '.join(sweep.outputs)})")
    return fig
