"""Figures of the robustness analysis: the structured singular value against frequency.

Drawn with the shared style (:mod:`flexsat.plots.style`), no pyplot.
"""

from __future__ import annotations

import numpy as np
from matplotlib.figure import Figure

from flexsat.linear.mu import MuAnalysis
from flexsat.plots import style

__all__ = ["plot_mu"]


def plot_mu(analysis: MuAnalysis, title: str = "") -> Figure:
    """mu's upper bound over frequency, its peak and the lower bound at its frequency.

    Parameters
    ----------
    analysis : MuAnalysis
        :func:`flexsat.linear.mu.analyze`'s result.
    title : str
        Added to the figure's title (the config's name, the law).

    Returns
    -------
    Figure
        One axis: mu against frequency [Hz], log-log, with mu = 1 drawn.
    """
    a = analysis
    fig, axes = style.figure(1, 1, size=(10.0, 5.5))
    ax = axes[0, 0]
    ax.loglog(a.frequencies_hz, style.positive(a.upper), color=style.AXIS_COLOURS[0],
              label="upper bound (D-G scalings)")  # fmt: skip
    ax.plot([a.peak_frequency_hz], [a.peak_upper], "o", color=style.AXIS_COLOURS[0],
            label=f"peak {a.peak_upper:.3g} at {a.peak_frequency_hz:.3g} Hz")  # fmt: skip
    if a.lower > 0 and np.isfinite(a.lower_frequency_hz):
        ax.plot([a.lower_frequency_hz], [a.lower], "s", color=style.AXIS_COLOURS[2],
                label=f"lower bound {a.lower:.3g} at {a.lower_frequency_hz:.3g} Hz")  # fmt: skip
    ax.axhline(1.0, color="0.3", linewidth=0.8)
    ax.set_xlabel("frequency [Hz]")
    ax.set_ylabel("mu [-]")
    ax.grid(True, which="both", color="0.88", linewidth=0.5)
    ax.legend(fontsize=8)
    k_lo, k_hi = a.k_max
    fig.suptitle(style.literal(f"Structured singular value {title}".strip())
                 + f"   k_max in [{k_lo:.3g}, {k_hi:.3g}]")  # fmt: skip
    return fig
