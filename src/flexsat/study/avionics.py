"""What the thesis could not say: its 45/45/45 ASMC slew with real avionics.

(a) R1, R2 and the windowed metrics (APE, RPE) of the ideal loop beside the loop
with the gyro, the star tracker, the MEKF and the reaction-wheel pyramid; (b) a
sweep over the computational delay (the ``delay`` stage, whole control periods):
the smallest delay at which R1, then R2, is lost, and the one at which the loop
goes unstable, with the figure of the pointing and jitter figures against delay;
(c) the rotating solar arrays are not modelled (``docs/control.md``, 'Not
modelled yet'), and the part says so. Writes ``avionics/avionics.json`` and
``avionics/delay_boundary.png``. The runs are independent: they fly in forked
processes side by side (:func:`flexsat.parallel.forked_map`).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from flexsat.analysis.requirements import slew_metrics
from flexsat.simulate import SlewScenario, run_slew

__all__ = ["AVIONICS", "DELAYS_S", "QUICK_DELAYS_S", "avionics_study", "delayed", "render_avionics"]

AVIONICS = {
    "sensor_stages": [{"kind": "gyro"}, {"kind": "star_tracker"}, {"kind": "mekf"}],
    "actuator": {"kind": "wheels"},
}
"""The realistic chain: the stages' default (documented) settings."""
DELAYS_S = (0.0, 0.01, 0.02, 0.05, 0.1, 0.2, 0.3, 0.5, 0.8)
QUICK_DELAYS_S = (0.05, 0.5)
_KEYS = ("r1_pass", "r2_pass", "r3_pass", "ape_deg", "rpe_deg", "max_rate_error_deg_s",
         "settling_time_s", "final_pointing_error_deg", "status")  # fmt: skip
UNSTABLE_POINTING_DEG = 1.0
"""A delayed run is called unstable when it diverged (stopped) or ends farther than
this from the target (the nominal slew ends within 0.003 deg)."""


def delayed(periods: int) -> dict:
    """Slew scenario fields of the ideal loop with the torque command held back by
    ``periods`` whole control periods (the ``delay`` actuator stage)."""
    return {"actuator_stages": [{"kind": "delay", "periods": periods}]}


def _metrics(plant, fields: dict) -> dict:
    ds = run_slew(plant, SlewScenario.model_validate(fields), progress=False).dataset
    metrics = slew_metrics(ds)
    return {key: metrics[key] for key in _KEYS}


def avionics_study(plant, out: str | Path, quick: bool = False) -> dict:
    """Run (a) and (b) on ``plant``; write the JSON and the figure under ``out``.

    Returns
    -------
    dict
        ``json`` and ``figures``: paths written.
    """
    from flexsat.parallel import forked_map

    out = Path(out)
    control_dt = SlewScenario().control_dt_s
    periods = [round(delay / control_dt) for delay in (QUICK_DELAYS_S if quick else DELAYS_S)]
    runs = [{}, AVIONICS, *(delayed(n) for n in periods)]
    ideal, avionics, *swept = forked_map(lambda fields: _metrics(plant, fields), runs)
    side_by_side = {"ideal": ideal, "avionics": avionics}
    sweep = []
    for n, row in zip(periods, swept, strict=True):
        row["delay_s"] = n * control_dt
        row["unstable"] = row["status"] != "ok" or not (
            row["final_pointing_error_deg"] < UNSTABLE_POINTING_DEG)  # fmt: skip
        sweep.append(row)

    def first(key, value):
        hits = [r["delay_s"] for r in sweep if r[key] == value]
        return hits[0] if hits else None

    payload = {
        "side_by_side": side_by_side,
        "delay_sweep": sweep,
        "r1_lost_at_delay_s": first("r1_pass", False),
        "r2_lost_at_delay_s": first("r2_pass", False),
        "unstable_at_delay_s": first("unstable", True),
        "sadm": "not modelled: the plate model holds its SADM angle fixed",
        "quick": quick,
    }
    from flexsat.study.outputs import write_json

    json_path = write_json(out / "avionics.json", payload)
    figure = _delay_figure(sweep, out / "delay_boundary.png")
    return {"json": json_path, "figures": [figure]}


def _delay_figure(sweep: list[dict], path: Path) -> Path:
    from flexsat.analysis.requirements import Requirements
    from flexsat.plots.style import figure, save_figure

    req = Requirements()
    fig, axes = figure(2, 1, size=(9.0, 6.5))
    delay = np.array([r["delay_s"] for r in sweep])
    for ax, key, band, label in (
        (axes[0, 0], "ape_deg", req.pointing_deg, "APE over the window [deg] (R1)"),
        (axes[1, 0], "max_rate_error_deg_s", req.jitter_deg_s, "max rate error [deg/s] (R2)"),
    ):
        values = np.array([r[key] if r[key] is not None else np.nan for r in sweep], float)
        ax.semilogy(delay, values, "o-")
        ax.axhline(band, color="k", ls="--", lw=1, label="requirement")
        unstable = np.array([r["unstable"] for r in sweep])
        ax.semilogy(delay[unstable], values[unstable], "rx", ms=10, label="unstable")
        ax.set_ylabel(label)
        ax.legend()
    axes[1, 0].set_xlabel("computational delay [s]")
    axes[0, 0].set_title("45/45/45 deg ASMC slew: stability boundary against delay")
    return save_figure(fig, path, dpi=110)


def render_avionics(root: Path, outputs: dict, cell) -> tuple[list, list, str]:
    """Table rows for the report: the side-by-side metrics, the delay sweep, and the
    sentence of the boundaries. ``cell(relative_json, *path)`` makes a traced cell."""
    import json

    rel = outputs["json"]
    data = json.loads((root / rel).read_text())
    side = [[key, cell(rel, "side_by_side", "ideal", key),
             cell(rel, "side_by_side", "avionics", key)] for key in _KEYS]  # fmt: skip
    sweep = [[cell(rel, "delay_sweep", i, "delay_s"), cell(rel, "delay_sweep", i, "r1_pass"),
              cell(rel, "delay_sweep", i, "r2_pass"), cell(rel, "delay_sweep", i, "ape_deg"),
              cell(rel, "delay_sweep", i, "max_rate_error_deg_s"),
              cell(rel, "delay_sweep", i, "unstable")]
             for i in range(len(data["delay_sweep"]))]  # fmt: skip

    def fmt(value):
        return "beyond the sweep" if value is None else f"{value:g} s"

    sentence = (f"R1 is lost at a delay of {fmt(data['r1_lost_at_delay_s'])}, R2 at "
                f"{fmt(data['r2_lost_at_delay_s'])}; the loop is unstable from "
                f"{fmt(data['unstable_at_delay_s'])}. Rotating arrays (SADM): "
                f"{data['sadm']}.")  # fmt: skip
    return side, sweep, sentence
