"""The microvibration jitter of a slew's wheels (and a SADM stepper): sweep, figure, summary."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from flexsat.dynamics.plant import Plant
from flexsat.errors import ConfigError

__all__ = [
    "DEFAULT_MICROVIBRATION",
    "REPORT_WINDOW_S",
    "budget_contributors",
    "jitter_scenario",
    "write_jitter",
]

_ARCSEC = 180.0 / np.pi * 3600.0
_SWEEP_POINTS = 400

DEFAULT_MICROVIBRATION = {
    "static_imbalance_kg_m": 1e-5,
    "dynamic_imbalance_kg_m2": 2e-6,
    "radial_force": [{"number": 2.0, "coefficient": 1e-6}],
    "axial_force": [{"number": 1.0, "coefficient": 2e-6}],
    "positions_m": [[0.3, 0.3, -0.5], [-0.3, 0.3, -0.5], [-0.3, -0.3, -0.5], [0.3, -0.3, -0.5]],
    "seed": 1,
}
"""An illustrative table of a small wheel (U_s = 0.1 g cm, U_d = 0.02 g cm^2, one radial
and one axial harmonic), the four pyramid wheels 0.5 m below the hub's reference point:
what the study sweeps when its scenario gives none. Not a datasheet's values."""


REPORT_WINDOW_S = 1.0
"""The RPE window of the study's pointing-budget section [s] (the budget's example's)."""


def jitter_scenario(speed_rpm: float = 2000.0):
    """The thesis slew flown on the pyramid wheels with :data:`DEFAULT_MICROVIBRATION`.

    Parameters
    ----------
    speed_rpm : float
        The wheels' initial speed [rpm].

    Returns
    -------
    SlewScenario
    """
    from flexsat.simulate.scenario import SlewScenario

    wheels = {"kind": "wheels", "initial_speed_rpm": speed_rpm,
              "microvibration": DEFAULT_MICROVIBRATION}  # fmt: skip
    return SlewScenario.model_validate({"actuator": wheels})


def write_jitter(
    plant: Plant, scenario, out: Path | None = None, *,
    speeds_rpm: np.ndarray | None = None, window_s: float | None = None,
    boresight: list[float] | None = None, stepper=None,
) -> dict:  # fmt: skip
    """The wheels' jitter at their speed, the speed sweep and its Campbell diagram.

    Parameters
    ----------
    plant : Plant
        The satellite.
    scenario : SlewScenario
        Its ``[actuator]`` is the wheel cluster with its ``microvibration`` table; its
        law closes the loop (:func:`flexsat.linear.jitter.closed_loop`), its wheels'
        ``initial_speed_rpm`` is the speed the jitter is given at.
    out : Path, optional
        Folder for ``jitter.json``, ``campbell.png`` and ``contributors.toml`` (the
        lines as the budget's periodic contributors, :func:`budget_contributors`).
    speeds_rpm : ndarray, optional
        Speeds to sweep [rpm]; default 400 from 1 % of the wheels' limit to it.
    window_s : float, optional
        The RPE's window Δt [s]: adds the windowed jitter.
    boresight : list of 3 floats, optional
        A payload boresight, hub frame B: the sweep is taken on its line of sight.
    stepper : StepperConfig, optional
        A SADM stepper: its lines' jitter is added (:func:`flexsat.linear.jitter.stepper_lines`).

    Returns
    -------
    dict
        JSON-ready summary: ``speed_rpm``, ``rms_arcsec`` per output (and
        ``rpe_rms_arcsec`` with a window), ``lines`` (each distinct frequency with its
        response), ``worst`` speeds, the ``sweep``'s range, the closed loop's
        ``modes_hz``, the ``stepper``'s and ``files``; ``wheels``: what the loop and
        the lines were built from (spin axes, momentum H_w [N m s], motor time constant
        [s], the microvibration table).

    Raises
    ------
    ConfigError
        A scenario without wheels or without a microvibration table.
    """
    from flexsat.linear.jitter import (
        closed_loop,
        line_response,
        los_rows,
        speed_sweep,
        stepper_lines,
        wheel_lines,
        window_gain,
    )

    wheels = scenario.actuator
    if wheels.kind != "wheels" or wheels.microvibration is None:
        raise ConfigError(
            'actuator.microvibration: the jitter needs [actuator] kind = "wheels" with an '
            "[actuator.microvibration] table (docs/pointing.md, 'Microvibration')"
        )
    speed = float(wheels.initial_speed_rpm)
    axes = wheels.spin_axes()
    h0 = wheels.spin_inertia_kg_m2 * speed * np.pi / 30.0
    actuated = [] if stepper is None else [stepper.coordinate]
    model = closed_loop(plant, scenario.controller, axes.sum(axis=0) * h0, actuated,
                        wheels.motor_time_constant_s)  # fmt: skip
    names = ["x", "y", "z"]
    rows = np.eye(3)
    if boresight is not None:
        rows = np.vstack([rows, los_rows(boresight)])
        names += ["los_u", "los_v"]
    lines = wheel_lines(wheels, speed, model.B.shape[1])
    if stepper is not None:
        lines = lines + stepper_lines(stepper, model)
    freqs, Y = line_response(model, lines, rows)
    built = {"axes": axes.tolist(), "momentum_B_nms": (axes.sum(axis=0) * h0).tolist(),
             "motor_time_constant_s": wheels.motor_time_constant_s,
             "microvibration": wheels.microvibration.model_dump(mode="json")}  # fmt: skip
    summary = {
        "law": scenario.controller.kind, "speed_rpm": speed, "outputs": names, "wheels": built,
        "rms_arcsec": _rms(Y, np.ones(freqs.size), names),
        "lines": [{"frequency_hz": float(f), "amplitude_arcsec": _per(np.abs(y), names)}
                  for f, y in zip(freqs, Y, strict=True)],
    }  # fmt: skip
    if window_s is not None:
        summary["window_s"] = float(window_s)
        summary["rpe_rms_arcsec"] = _rms(Y, window_gain(freqs, window_s), names)
    if stepper is not None:
        own = stepper_lines(stepper, model)
        f_s, Y_s = line_response(model, own, rows)
        summary["stepper"] = {"step_rate_hz": stepper.step_rate_hz,
                              "rms_arcsec": _rms(Y_s, np.ones(f_s.size), names)}  # fmt: skip
    if speeds_rpm is None:
        top = wheels.max_speed_rpm
        speeds_rpm = np.linspace(0.01 * top, top, _SWEEP_POINTS)
    sweep_rows = None if boresight is None else rows[3:]
    sweep = speed_sweep(model, wheels, speeds_rpm, sweep_rows, window_s,
                        outputs=names[3:] if boresight is not None else names)  # fmt: skip
    summary["worst"] = [{"speed_rpm": float(s), "rms_arcsec": float(r * _ARCSEC)}
                        for s, r in zip(sweep.worst_rpm, sweep.worst_rms, strict=True)]  # fmt: skip
    summary["modes_hz"] = [float(m) for m in sweep.modes_hz]
    summary["sweep"] = {"low_rpm": float(np.min(speeds_rpm)), "high_rpm": float(np.max(speeds_rpm)),
                        "count": int(np.size(speeds_rpm))}  # fmt: skip
    if out is not None:
        from flexsat.files import write_text
        from flexsat.plots.jitter import plot_campbell
        from flexsat.plots.style import save_figure
        from flexsat.study.outputs import prepare_output_dir, write_json

        folder = prepare_output_dir(out)
        figure = save_figure(plot_campbell(sweep), folder / "campbell.png", dpi=110)
        toml = write_text(folder / "contributors.toml", budget_contributors(summary))
        summary["files"] = [str(figure), str(folder / "jitter.json"), str(toml)]
        write_json(folder / "jitter.json", summary)
    return summary


def budget_contributors(summary: dict) -> str:
    """The jitter's lines as periodic contributors of a pointing budget, TOML text.

    One ``[[pointing.contributors]]`` table per line: ``kind = "periodic"``, its
    amplitude per hub axis and its period 1/f (docs/pointing.md, 'Contributors'). Each
    axis's sinusoids add in the budget as σ = A/√2 each, so its statistical sum's σ is
    the RMS jitter of the line response, and its RPE's the windowed jitter.

    Parameters
    ----------
    summary : dict
        :func:`write_jitter`'s summary.

    Returns
    -------
    str
        TOML to append to a requirement file (``flexsat budget --requirements``).
    """
    head = (f"# the microvibration lines at {summary['speed_rpm']:g} rpm "
            f"({summary['law']} loop): periodic contributors, amplitudes [deg]\n")  # fmt: skip
    blocks = []
    for k, line in enumerate(summary["lines"], start=1):
        amplitude = [line["amplitude_arcsec"][a] / 3600.0 for a in ("x", "y", "z")]
        blocks.append(
            "[[pointing.contributors]]\n"
            f'name = "microvibration line {k} ({line["frequency_hz"]:.6g} Hz)"\n'
            'kind = "periodic"\n'
            f"amplitude_deg = [{', '.join(repr(float(a)) for a in amplitude)}]\n"
            f"period_s = {1.0 / line['frequency_hz']!r}\n"
        )
    return head + "\n".join(blocks)


def _per(values: np.ndarray, names: list[str]) -> dict:
    return {n: float(v * _ARCSEC) for n, v in zip(names, values, strict=True)}


def _rms(Y: np.ndarray, gain: np.ndarray, names: list[str]) -> dict:
    """sqrt(sum_k |Y_k|^2 g_k^2 / 2) per output [arcsec]."""
    return _per(np.sqrt(0.5 * np.sum(np.abs(Y * gain[:, None]) ** 2, axis=0)), names)
