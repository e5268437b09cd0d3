"""Figures of the linear analysis: Bode, singular values, poles and zeros, loop gains.

Drawn with the shared style (:mod:`flexsat.plots.style`), no pyplot.

- :func:`plot_bode`: body torque to body rate (or attitude) per axis, the flexible
  model beside the rigidized one.
- :func:`plot_singular_values`: singular values of torque to rate, flexible and rigid.
- :func:`plot_pole_zero`: poles of the model and zeros of each axis's torque to rate.
- :func:`plot_effective_inertia`: modal effective inertia per mode and axis.
- :func:`plot_loops`: PD loop gain per axis with its margins, the flexible peaks
  marked; :func:`plot_nichols`: the same loops in the Nichols plane.
- :func:`plot_loop_family`: the loop gains of a campaign's cases, one curve per case.
- :func:`write_linear_figures`: all of them into a folder.
- :class:`FrequencyResponses`: the responses the figures draw, each model's computed
  once and shared by the figures of a set.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
from matplotlib.figure import Figure

from flexsat.linear.frequency import LoopMargins
from flexsat.linear.model import LinearModel
from flexsat.plots import style

__all__ = [
    "FIGURES",
    "FrequencyResponses",
    "frequency_grid_hz",
    "phase_deg",
    "plot_bode",
    "plot_effective_inertia",
    "plot_loop_family",
    "plot_loops",
    "plot_nichols",
    "plot_pole_zero",
    "plot_singular_values",
    "write_linear_figures",
]

FIGURES = (
    "bode_rate", "bode_attitude", "singular_values", "pole_zero", "effective_inertia",
    "loop_gain", "nichols",
)  # fmt: skip


def frequency_grid_hz(n: int = 3000) -> np.ndarray:
    """The frequency grid of every figure: 1 mHz to 200 Hz, log-spaced [Hz].

    Parameters
    ----------
    n : int
        Number of frequencies.

    Returns
    -------
    ndarray, shape (n,)
        The frequencies [Hz].
    """
    return np.geomspace(1e-3, 200.0, n)


def phase_deg(response: np.ndarray) -> np.ndarray:
    """The phase every figure draws: unwrapped along frequency, one branch from the start.

    The phase is continuous over the grid (``numpy.unwrap``, no jump above 180 deg
    between neighbouring frequencies), and the whole curve is shifted by a multiple
    of 360 deg so that its lowest-frequency value lies in (-270, 90] deg: a double
    integrator (torque to attitude, the loop gains) starts at -180 deg, a single one
    (torque to rate) at -90 deg, whichever side of the branch cut the first complex
    value's round-off falls.

    Parameters
    ----------
    response : ndarray, shape (n_f,) or (n_f, ...)
        Complex response, frequency along the first axis [output unit / input unit].

    Returns
    -------
    ndarray
        Phase [deg], the shape of ``response``.
    """
    phase = np.degrees(np.unwrap(np.angle(response), axis=0))
    turns = np.ceil((phase[:1] + 270.0) / 360.0) - 1.0  # start in (-270, 90] deg
    return phase - 360.0 * turns


class FrequencyResponses:
    """Frequency responses on :func:`frequency_grid_hz`, each model's computed once.

    A response costs one linear solve of the model's states per frequency (about
    0.06 s of CPU for the 36 states of the reference satellite), whatever inputs and
    outputs are kept. The Bode diagrams and the singular values draw the same two
    models, the loop gain and the Nichols plot the same loops: computing each
    model's whole response once, before the figures are drawn by forked processes,
    replaces thirteen responses of 36-state models (the flexible model and the
    loops) by four.
    """

    def __init__(self) -> None:
        self.frequencies_hz = frequency_grid_hz()
        """The frequency grid [Hz]."""
        self._full: dict[LinearModel, np.ndarray] = {}  # models compare by identity

    def __call__(
        self, model: LinearModel, outputs: list[str] | None = None,
        inputs: list[str] | None = None,
    ) -> np.ndarray:  # fmt: skip
        """G(i 2 pi f) of ``model`` on :attr:`frequencies_hz`, the named signals only.

        Parameters
        ----------
        model : LinearModel
            The model; its whole response is computed on the first call.
        outputs, inputs : list of str, optional
            Output and input names, in the order wanted; default all.

        Returns
        -------
        ndarray, shape (n_f, n_outputs, n_inputs)
            The response [SI output unit per SI input unit].
        """
        if model not in self._full:
            self._full[model] = model.frequency_response(self.frequencies_hz)
        rows = [model.output_names.index(n) for n in outputs or model.output_names]
        cols = [model.input_names.index(n) for n in inputs or model.input_names]
        return self._full[model][:, rows][:, :, cols]


def plot_bode(
    flexible: LinearModel, rigid: LinearModel, output: str = "rate", *,
    responses: FrequencyResponses | None = None,
) -> Figure:  # fmt: skip
    """Bode diagrams tau_a -> omega_a (``output="rate"``) or -> attitude, a = x, y, z.

    Parameters
    ----------
    flexible : LinearModel
        The flexible satellite's model.
    rigid : LinearModel
        The rigid reference model.
    output : {"rate", "attitude"}
        The output of the response.
    responses : FrequencyResponses, optional
        Responses shared with other figures; default computed here.

    Returns
    -------
    Figure
        The figure.
    """
    outs = {"rate": ["omega_x", "omega_y", "omega_z"], "attitude": ["phi", "theta", "psi"]}
    unit = {"rate": "rad/s / N m", "attitude": "rad / N m"}[output]
    responses = FrequencyResponses() if responses is None else responses
    f = responses.frequencies_hz
    torque = [f"tau_{axis}" for axis in style.AXES]
    diagonal = {model: np.diagonal(responses(model, outs[output], torque), axis1=1, axis2=2)
                for model in (flexible, rigid)}  # fmt: skip
    fig, axes = style.figure(2, 3, size=(14.0, 7.0), height_ratios=(2, 1))
    for a, (axis, out) in enumerate(zip(style.AXES, outs[output], strict=True)):
        for model, label, ls in ((flexible, "flexible", "-"), (rigid, "rigid", "--")):
            G = diagonal[model][:, a]
            colour = style.AXIS_COLOURS[a] if ls == "-" else "0.4"
            axes[0, a].loglog(f, np.abs(G), ls, color=colour, label=label)
            axes[1, a].semilogx(f, phase_deg(G), ls, color=colour, label=label)
        axes[0, a].set_title(f"tau_{axis} -> {out}")
        axes[0, a].set_ylabel(f"|G| [{unit}]")
        axes[1, a].set_ylabel("phase [deg]")
        axes[1, a].set_xlabel("frequency [Hz]")
        axes[0, a].legend(loc="lower left", fontsize=8)
    for ax in axes.ravel():
        ax.grid(True, which="both", color="0.88", linewidth=0.5)
    fig.suptitle(f"Body torque to body {output}: flexible model and rigidized satellite")
    return fig


def plot_singular_values(
    flexible: LinearModel, rigid: LinearModel, *, responses: FrequencyResponses | None = None
) -> Figure:
    """Singular values of the 3 x 3 torque -> rate response, flexible and rigid.

    Parameters
    ----------
    flexible : LinearModel
        The flexible satellite's model.
    rigid : LinearModel
        The rigid reference model.
    responses : FrequencyResponses, optional
        Responses shared with other figures; default computed here.

    Returns
    -------
    Figure
        The figure.
    """
    responses = FrequencyResponses() if responses is None else responses
    f = responses.frequencies_hz
    rate, torque = ["omega_x", "omega_y", "omega_z"], ["tau_x", "tau_y", "tau_z"]
    fig, axes = style.figure(1, 1, size=(9.0, 5.5))
    ax = axes[0, 0]
    for model, label, ls in ((flexible, "flexible", "-"), (rigid, "rigid", "--")):
        G = responses(model, rate, torque)
        sv = np.linalg.svd(G, compute_uv=False)
        for k in range(sv.shape[1]):
            ax.loglog(f, sv[:, k], ls, color=style.AXIS_COLOURS[k], label=f"{label} σ{k + 1}")
    ax.set_xlabel("frequency [Hz]")
    ax.set_ylabel("singular value [rad/s / N m]")
    ax.grid(True, which="both", color="0.88", linewidth=0.5)
    ax.legend(fontsize=8, ncol=2)
    fig.suptitle("Singular values, body torque to body rate")
    return fig


def plot_pole_zero(flexible: LinearModel) -> Figure:
    """Poles of the model and the zeros of tau_a -> omega_a per axis (s-plane, [rad/s]).

    Parameters
    ----------
    flexible : LinearModel
        The flexible satellite's model.

    Returns
    -------
    Figure
        The figure.
    """
    fig, axes = style.figure(1, 1, size=(9.0, 6.0))
    ax = axes[0, 0]
    poles = flexible.poles()
    ax.plot(poles.real, poles.imag, "x", color="k", label="poles")
    for a, axis in enumerate(style.AXES):
        siso = flexible.select(outputs=[f"omega_{axis}"], inputs=[f"tau_{axis}"])
        z = np.asarray(siso.to_statespace().zeros())
        z = z[np.isfinite(z) & (np.abs(z) < 10 * np.abs(poles).max())]
        ax.plot(z.real, z.imag, "o", mfc="none", color=style.AXIS_COLOURS[a],
                label=f"zeros tau_{axis} -> omega_{axis}")  # fmt: skip
    ax.set_yscale("symlog", linthresh=1.0)
    ax.set_xscale("symlog", linthresh=1e-3)
    ax.set_xlabel("Re s [1/s]")
    ax.set_ylabel("Im s [rad/s]")
    ax.grid(True, color="0.88", linewidth=0.5)
    ax.legend(fontsize=8)
    fig.suptitle("Pole-zero map: alternating poles and zeros of each collocated axis")
    return fig


def plot_effective_inertia(frequencies_hz: np.ndarray, J_eff: np.ndarray) -> Figure:
    """Bars of the modal effective inertia per appendage mode and body axis [kg m^2].

    Parameters
    ----------
    frequencies_hz : ndarray, shape (n,)
        The appendage modes' frequencies [Hz].
    J_eff : ndarray, shape (n, 3)
        Their effective inertia about each body axis [kg m^2].

    Returns
    -------
    Figure
        The figure.
    """
    fig, axes = style.figure(1, 1, size=(10.0, 5.5))
    ax = axes[0, 0]
    keep = J_eff.max(axis=1) > 1e-6 * J_eff.max()
    k = np.arange(int(keep.sum()))
    for a, axis in enumerate(style.AXES):
        ax.bar(k + (a - 1) * 0.27, J_eff[keep, a], width=0.27, color=style.AXIS_COLOURS[a],
               label=f"about {axis}")  # fmt: skip
    ax.set_xticks(k, [f"{fk:.3g} Hz" for fk in frequencies_hz[keep]], rotation=45)
    ax.set_yscale("log")
    ax.set_ylabel("effective inertia J_eff [kg m²]")
    ax.grid(True, axis="y", color="0.88", linewidth=0.5)
    ax.legend(fontsize=8)
    fig.suptitle("Modal effective inertia of the hub-fixed appendage modes (CSI ranking)")
    return fig


def plot_loops(
    loops: dict[str, LinearModel], margins: dict[str, LoopMargins], modes_hz: np.ndarray,
    *, responses: FrequencyResponses | None = None,
) -> Figure:  # fmt: skip
    """Loop gain per axis: Bode with 0 dB, -180 deg, crossovers and flexible modes marked.

    Every gain crossover is a dot on 0 dB labelled with its phase margin, and the
    phase there a dot on the phase plot; the crossover that sets the delay margin is
    ringed in red. Each flexible mode's peak is a triangle labelled with its peak
    loop gain and ``G`` (gain-stabilized, below 0 dB) or ``P`` (phase-stabilized).

    Parameters
    ----------
    loops : dict of str to LinearModel
        The loop gain of each axis, by axis name.
    margins : dict of str to LoopMargins
        Their margins, by axis name.
    modes_hz : ndarray
        The flexible modes marked [Hz].
    responses : FrequencyResponses, optional
        Responses shared with other figures; default computed here.

    Returns
    -------
    Figure
        The figure.
    """
    responses = FrequencyResponses() if responses is None else responses
    f = responses.frequencies_hz
    fig, axes = style.figure(2, 3, size=(14.0, 7.0), height_ratios=(2, 1))
    for a, axis in enumerate(style.AXES):
        L = responses(loops[axis])[:, 0, 0]
        m = margins[axis]
        colour = style.AXIS_COLOURS[a]
        phase = phase_deg(L)
        axes[0, a].loglog(f, np.abs(L), color=colour)
        axes[1, a].semilogx(f, phase, color=colour)
        axes[0, a].axhline(1.0, color="0.3", linewidth=0.8)
        axes[1, a].axhline(-180.0, color="0.3", linewidth=0.8)
        for fm in modes_hz:
            for ax in axes[:, a]:
                ax.axvline(fm, color="0.75", linewidth=0.6, linestyle=":")
        for k, c in enumerate(m.crossovers):  # labels stepped down: close crossovers
            axes[0, a].plot(c.frequency_hz, 1.0, "o", color="k", ms=4)
            axes[0, a].annotate(f"PM {c.phase_margin_deg:.0f}°", (c.frequency_hz, 1.0),
                                textcoords="offset points", xytext=(3, -11 - 10 * k),
                                fontsize=7)  # fmt: skip
            # The crossing's exact phase, PM - 180 deg, on the branch the curve is drawn on.
            near = np.interp(np.log(c.frequency_hz), np.log(f), phase)
            at = c.phase_margin_deg - 180.0
            at += 360.0 * np.round((near - at) / 360.0)
            axes[1, a].plot(c.frequency_hz, at, "o", color="k", ms=4)
            if c.frequency_hz == m.delay_crossover_hz:
                for ax, y in ((axes[0, a], 1.0), (axes[1, a], at)):
                    ax.plot(c.frequency_hz, y, "o", mfc="none", mec="tab:red", ms=10, mew=1.5)
        for p in m.flexible_peaks:
            gain = 10 ** (p.peak_gain_db / 20) if np.isfinite(p.peak_gain_db) else np.abs(L).max()
            axes[0, a].plot(p.peak_hz, gain, "v", color="k", ms=5)
            axes[0, a].annotate(f"{p.peak_gain_db:+.1f} dB {p.stabilized[0].upper()}",
                                (p.peak_hz, gain), textcoords="offset points", xytext=(4, 2),
                                fontsize=7)  # fmt: skip
        axes[0, a].set_title(
            f"axis {axis}: PM {m.phase_margin_deg:.1f} deg, GM {_db(m.gain_margin)}, "
            f"DM {m.delay_margin_s:.3g} s at {m.delay_crossover_hz:.3g} Hz (red)",
            fontsize=9,
        )
        axes[0, a].set_ylabel("|L| [-]")
        axes[1, a].set_ylabel("phase [deg]")
        axes[1, a].set_xlabel("frequency [Hz] (dotted: flexible modes)")
    for ax in axes.ravel():
        ax.grid(True, which="both", color="0.88", linewidth=0.5)
    fig.suptitle("Loop gain per axis (loop broken at that torque, others closed); "
                 "flexible peaks: G gain-, P phase-stabilized")  # fmt: skip
    return fig


def plot_nichols(
    loops: dict[str, LinearModel], *, responses: FrequencyResponses | None = None
) -> Figure:
    """Nichols plot of the loop gains: open-loop phase [deg] against gain [dB].

    Parameters
    ----------
    loops : dict of str to LinearModel
        The loop gain of each axis, by axis name.
    responses : FrequencyResponses, optional
        Responses shared with other figures; default computed here.

    Returns
    -------
    Figure
        The figure.
    """
    responses = FrequencyResponses() if responses is None else responses
    fig, axes = style.figure(1, 1, size=(9.0, 6.5))
    ax = axes[0, 0]
    for a, axis in enumerate(style.AXES):
        L = responses(loops[axis])[:, 0, 0]
        ax.plot(phase_deg(L), 20 * np.log10(np.abs(L)),
                color=style.AXIS_COLOURS[a], label=f"axis {axis}")  # fmt: skip
    ax.plot(-180.0, 0.0, "+", color="k", ms=12, mew=2)
    ax.set_xlabel("open-loop phase [deg]")
    ax.set_ylabel("open-loop gain [dB]")
    ax.grid(True, color="0.88", linewidth=0.5)
    ax.legend(fontsize=8)
    fig.suptitle("Nichols plot of the PD loop gains (critical point at -180 deg, 0 dB)")
    return fig


def plot_loop_family(
    loops: dict[str, dict[str, LinearModel]], margins: dict[str, dict[str, dict]]
) -> Figure:
    """Loop-gain magnitude per axis, one curve per case; the legend gives its delay margin.

    Parameters
    ----------
    loops : dict of str to dict of str to LinearModel
        Per case id, the loop gain of each axis.
    margins : dict of str to dict of str to dict
        Per case id, the margins of each axis (delay margin [s]).

    Returns
    -------
    Figure
        The figure.
    """
    f = frequency_grid_hz()
    fig, axes = style.figure(1, 3, size=(15.0, 5.5))
    for a, axis in enumerate(style.AXES):
        ax = axes[0, a]
        for case, case_loops in loops.items():
            L = case_loops[axis].frequency_response(f)[:, 0, 0]
            dm = margins[case][axis]["delay_margin_s"]
            ax.loglog(f, np.abs(L), linewidth=0.8, label=f"{style.literal(case)}: DM {dm:.3g} s")
        ax.axhline(1.0, color="0.3", linewidth=0.8)
        ax.set_title(f"axis {axis}")
        ax.set_xlabel("frequency [Hz]")
        ax.set_ylabel("|L| [-]")
        ax.grid(True, which="both", color="0.88", linewidth=0.5)
        if len(loops) <= 12:
            ax.legend(fontsize=6)
    fig.suptitle("PD loop gain over the campaign's cases (one curve per case)")
    return fig


def _db(gain: float) -> str:
    return "inf" if np.isinf(gain) else f"{20 * np.log10(gain):.1f} dB"


def write_linear_figures(
    out_dir: str | Path,
    flexible: LinearModel,
    rigid: LinearModel,
    effective: tuple[np.ndarray, np.ndarray],
    loops: dict[str, LinearModel] | None = None,
    margins: dict[str, LoopMargins] | None = None,
    *,
    dpi: int = 110,
) -> list[Path]:
    """Write the figures of :data:`FIGURES` (the loop figures only with ``loops``).

    Parameters
    ----------
    out_dir : str or Path
        Where the files go; created if missing.
    flexible : LinearModel
        The flexible satellite's model.
    rigid : LinearModel
        The rigid reference model.
    effective : tuple of ndarray
        Frequencies [Hz] and effective inertias [kg m^2] of the appendage modes.
    loops : dict of str to LinearModel, optional
        The loop gain of each axis.
    margins : dict of str to LoopMargins, optional
        Their margins.
    dpi : int
        Resolution [dots per inch].

    Returns
    -------
    list of Path
        The files written.
    """
    modes_hz = effective[0]
    responses = FrequencyResponses()
    for model in (flexible, rigid, *(loops or {}).values()):
        responses(model)  # here, so the drawing processes inherit them
    draw = {
        "bode_rate": lambda: plot_bode(flexible, rigid, "rate", responses=responses),
        "bode_attitude": lambda: plot_bode(flexible, rigid, "attitude", responses=responses),
        "singular_values": lambda: plot_singular_values(flexible, rigid, responses=responses),
        "pole_zero": lambda: plot_pole_zero(flexible),
        "effective_inertia": lambda: plot_effective_inertia(*effective),
        "loop_gain": lambda: plot_loops(loops, margins, modes_hz, responses=responses),
        "nichols": lambda: plot_nichols(loops, responses=responses),
    }
    names = [n for n in FIGURES if loops is not None or n not in ("loop_gain", "nichols")]
    return style.write_figures(out_dir, names, lambda n: draw[n](), dpi=dpi)
