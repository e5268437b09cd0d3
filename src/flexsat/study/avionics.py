"""What the thesis could not say: its 45/45/45 ASMC slew with real avionics.

(a) R1, R2 and the windowed metrics (APE, RPE) of the ideal loop beside the loop
with the gyro, the star tracker, the MEKF and the reaction-wheel pyramid; (b) a
sweep over the computational delay (the ``delay`` stage, whole control periods) on
the ideal loop: the smallest delay at which R1, then R2, is lost, and each delay's
stability verdict from its residual-rate envelope
(:func:`flexsat.analysis.requirements.residual_rate_verdict`: stable, limit cycle or
diverges), the sweep refined around the delay margin of the same law's linear loop
(:func:`delay_margin`, which predicts the boundary the sweep confirms), with the
figure of the pointing and jitter figures against delay;
(c) the arrays rotating at a realistic SADM rate during the slew: the plates on a
drive (:func:`flexsat.dynamics.appendages.sadm.with_sadm`), the ideal loop with
the drive holding its angle beside the drive turning at :data:`SADM_RATE_DEG_S`
(``docs/control.md``, "Solar-array drive (SADM)"). Writes
``avionics/avionics.json``, ``avionics/delay_boundary.png`` and the avionics
run's ``avionics/mekf.png`` and ``avionics/wheels.png`` (the estimation error
inside its covariance; the wheels' momentum and limit). The runs of (a)
and (b) and the two of (c) are independent: they fly in forked processes side by
side (:func:`flexsat.parallel.forked_map`).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from flexsat.analysis.requirements import Requirements, residual_rate_verdict, slew_metrics
from flexsat.config.models import SatelliteConfig
from flexsat.dynamics.plant import Plant
from flexsat.simulate import SlewScenario, run_slew

__all__ = [
    "AVIONICS",
    "AVIONICS_FIGURES",
    "DELAYS_S",
    "NO_DRIVE",
    "QUICK_DELAYS_S",
    "SADM_DRIVE",
    "SADM_RATE_DEG_S",
    "avionics_study",
    "bracket_delays",
    "delay_margin",
    "delayed",
    "render_avionics",
    "sadm_plant",
    "sadm_runs",
    "sadm_study",
]

AVIONICS = {
    "sensor_stages": [{"kind": "gyro"}, {"kind": "star_tracker"}, {"kind": "mekf"}],
    "actuator": {"kind": "wheels"},
}
"""The realistic chain: the stages' default (documented) settings."""
AVIONICS_FIGURES = ("mekf", "wheels")
"""Stage figures of the avionics run in the report (:mod:`flexsat.plots.stages`)."""
DELAYS_S = (0.0, 0.01, 0.02, 0.05, 0.1, 0.15, 0.2, 0.3, 0.5, 0.8)
"""The sweep's delays [s], besides those around the linear margin (:func:`bracket_delays`)."""
QUICK_DELAYS_S = (0.05, 0.1, 0.2, 0.5)
"""The quick study's [s]."""
MARGIN_FACTORS = (0.9, 1.0, 1.02, 1.04, 1.1)
"""Delays added around the linear loop's delay margin m, as multiples of m (1.0: the
control periods just below and just above it) [-]."""
QUICK_MARGIN_FACTORS = (1.0, 1.04, 1.1)
"""The quick study's [-]."""
_KEYS = ("r1_pass", "r2_pass", "r3_pass", "ape_deg", "rpe_deg", "max_rate_error_deg_s",
         "settling_time_s", "final_pointing_error_deg", "status")  # fmt: skip
SADM_RATE_DEG_S = 0.06
"""The sun-tracking rate of an array in low Earth orbit: one turn per orbit of about
100 min (360 deg / 6000 s) [deg/s]."""
SADM_DRIVE = {"rotor_inertia_kg_m2": 0.1, "rotor_mass_kg": 2.0, "frequency_hz": 2.0,
              "damping_ratio": 0.7}  # fmt: skip
"""The drive: rotor inertia as seen at the array (a geared motor's, N^2 J_motor) and
mass; its loop's natural frequency, stiff against the array's modes (0.25-0.8 Hz)
as a geared drive is, and damping ratio."""
_SADM_KEYS = ("array_angle_deg", "peak_drive_torque_nm", "peak_tracking_error_deg",
              "attitude_difference_deg")  # fmt: skip
NO_DRIVE = ("not applicable: the satellite has no thesis plate to put on a drive (the drive "
            "is built for plates; a chain or modal appendage keeps its mount fixed)")  # fmt: skip
"""What (c) reports for a satellite without plates."""
_VERDICT_KEYS = ("verdict", "envelope_first_deg_s", "envelope_last_deg_s", "envelope_ratio",
                 "span_s")  # fmt: skip


def delay_margin(plant) -> dict | None:
    """The delay margin of the sweep's law linearized about rest, the smallest over the axes.

    The loop of the report's frequency section (:func:`flexsat.study.linear.write_margins`
    with the slew scenario's law, the ASMC by default): the law inside its boundary
    layer closed around the flexible plant, broken at one axis's torque with the
    other two closed.

    Parameters
    ----------
    plant : Plant
        The satellite.

    Returns
    -------
    dict or None
        ``law``, ``axis`` (the axis with the smallest margin), ``margin_s`` [s] and
        ``crossover_hz`` [Hz] (the gain crossover it is taken at); None when no axis
        has a finite delay margin.
    """
    from flexsat.study.linear import write_margins

    summary = write_margins(plant, SlewScenario())
    finite = {axis: m for axis, m in summary["axes"].items()
              if m.get("delay_margin_s") is not None
              and np.isfinite(m["delay_margin_s"])}  # fmt: skip
    if not finite:
        return None
    axis = min(finite, key=lambda a: finite[a]["delay_margin_s"])
    return {"law": summary["law"], "axis": axis, "margin_s": finite[axis]["delay_margin_s"],
            "crossover_hz": finite[axis]["delay_crossover_hz"]}  # fmt: skip


def bracket_delays(margin_s: float | None, control_dt_s: float,
                   factors: tuple[float, ...] = MARGIN_FACTORS) -> list[int]:  # fmt: skip
    """Delays around a delay margin, in whole control periods.

    Parameters
    ----------
    margin_s : float or None
        The linear loop's delay margin [s]; None: no delay.
    control_dt_s : float
        The control period [s].
    factors : tuple of float
        Multiples of the margin [-]; 1.0 gives the periods just below and just above it.

    Returns
    -------
    list of int
        Control periods [-], increasing, each at least 1.
    """
    if margin_s is None:
        return []
    periods = set()
    for factor in factors:
        exact = factor * margin_s / control_dt_s
        if factor == 1.0:
            periods |= {int(np.floor(exact)), int(np.ceil(exact))}
        else:
            periods.add(round(exact))
    return sorted(p for p in periods if p >= 1)


def delayed(periods: int) -> dict:
    """Slew scenario fields of the ideal loop with the torque command held back by
    whole control periods (the ``delay`` actuator stage).

    Parameters
    ----------
    periods : int
        Control periods of delay [-].

    Returns
    -------
    dict
        The scenario fields [-].
    """
    return {"actuator_stages": [{"kind": "delay", "periods": periods}]}


def _run(plant, fields: dict, duration_s: float | None):
    if duration_s is not None:
        fields = {**fields, "duration_s": duration_s}
    return run_slew(plant, SlewScenario.model_validate(fields), progress=False).dataset


def sadm_study(plant, duration_s: float | None = None) -> dict:
    """(c): the ideal slew with the plates on a drive, holding beside turning.

    Parameters
    ----------
    plant : Plant
        The satellite; its plates go on the drive :data:`SADM_DRIVE`.
    duration_s : float, optional
        Run length [s]; default the scenario's.

    Returns
    -------
    dict
        ``rate_deg_s``, the drive settings, the slew metrics ``holding`` and
        ``turning``, and of the turning run the array angle reached
        ``array_angle_deg``, the peak drive torque ``peak_drive_torque_nm``, the
        peak tracking error ``peak_tracking_error_deg`` and the largest attitude
        difference from the holding run ``attitude_difference_deg``; for a satellite
        without plates, ``rate_deg_s`` and ``not_applicable`` (:data:`NO_DRIVE`).
    """
    driven, runs = _sadm_runs(plant)
    return _sadm_summary(*(_sadm_run(driven, fields, duration_s) for fields in runs))


def sadm_plant(config: SatelliteConfig) -> Plant:
    """The satellite of (c): its plates on the drive :data:`SADM_DRIVE`.

    Parameters
    ----------
    config : SatelliteConfig
        The satellite.

    Returns
    -------
    Plant
        The same satellite with each plate on a drive (two-segment chains).
    """
    from flexsat.dynamics.appendages.sadm import with_sadm

    drive = SADM_DRIVE
    return Plant.from_config(
        with_sadm(config, drive["rotor_inertia_kg_m2"], drive["rotor_mass_kg"])
    )


def sadm_runs(config: SatelliteConfig) -> list[dict]:
    """The slew scenario fields of (c)'s runs on :func:`sadm_plant`, holding then turning.

    Parameters
    ----------
    config : SatelliteConfig
        The satellite (its plates size the drive's loop).

    Returns
    -------
    list of dict
        The fields of the holding run (rate 0) and of the turning run
        (:data:`SADM_RATE_DEG_S`), or none for a satellite without plates [-].
    """
    from flexsat.dynamics.appendages.plate_config import PlateConfig
    from flexsat.dynamics.appendages.sadm import DRIVE_COORDINATE

    drive = SADM_DRIVE
    plates = [a for a in config.appendages if isinstance(a, PlateConfig)]
    if not plates:
        return []
    inertia = drive["rotor_inertia_kg_m2"] + max(a.centroidal_inertia()[1, 1] for a in plates)
    omega_n = 2.0 * np.pi * drive["frequency_hz"]
    runs = []
    for rate in (0.0, SADM_RATE_DEG_S):
        joint = {"kind": "sadm_drive", "coordinates": [DRIVE_COORDINATE], "rate_deg_s": rate,
                 "stiffness_nm_rad": inertia * omega_n**2,
                 "damping_nms_rad": 2.0 * drive["damping_ratio"] * omega_n * inertia}  # fmt: skip
        runs.append({"joint_actuator": joint})
    return runs


def _sadm_runs(plant) -> tuple[Plant | None, list[dict]]:
    """The driven satellite and the scenario fields of (c)'s runs, holding then turning
    (none, and no satellite, without plates)."""
    runs = sadm_runs(plant.config)
    return (sadm_plant(plant.config) if runs else None), runs


def _sadm_run(driven, fields: dict, duration_s: float | None) -> dict:
    """One run of (c), reduced to what its summary reads (small enough to return from a
    forked process): metrics, attitude history, final drive angle, drive peaks."""
    from flexsat.dynamics.appendages.sadm import DRIVE_COORDINATE

    ds = _run(driven, fields, duration_s)
    metrics = slew_metrics(ds)
    first = next(d for d in ds["dof"].values if d.endswith(f".{DRIVE_COORDINATE}"))  # plate 1's
    return {
        "metrics": {key: metrics[key] for key in _KEYS},
        "quaternion": ds["quaternion"].values,
        "array_angle_deg": float(np.degrees(ds["q"].sel(dof=first).values[-1])),
        "peak_drive_torque_nm": float(ds["sadm_torque"].max()),
        "peak_tracking_error_deg": float(np.degrees(ds["sadm_tracking_error"].max())),
    }


def _sadm_summary(holding: dict | None = None, turning: dict | None = None) -> dict:
    """:func:`sadm_study`'s payload from its two runs (:func:`_sadm_run`); without
    them (no plates), what (c) reports instead."""
    if holding is None:
        return {"rate_deg_s": SADM_RATE_DEG_S, "not_applicable": NO_DRIVE}
    overlap = np.abs(np.sum(turning["quaternion"] * holding["quaternion"], axis=1))
    difference = 2.0 * np.arccos(np.minimum(1.0, overlap))  # angle between the attitudes
    return {
        "rate_deg_s": SADM_RATE_DEG_S, "drive": SADM_DRIVE,
        "holding": holding["metrics"], "turning": turning["metrics"],
        **{key: turning[key] for key in ("array_angle_deg", "peak_drive_torque_nm",
                                         "peak_tracking_error_deg")},
        "attitude_difference_deg": float(np.degrees(difference.max())),
    }  # fmt: skip


def avionics_study(plant, out: str | Path, quick: bool = False,
                   duration_s: float | None = None) -> dict:  # fmt: skip
    """Run (a), (b) and (c) on ``plant``; write the JSON and the figure under ``out``.

    Parameters
    ----------
    plant : Plant
        The satellite.
    out : str or Path
        The part's folder.
    quick : bool
        The short version: :data:`QUICK_DELAYS_S` and :data:`QUICK_MARGIN_FACTORS`
        (eight delayed runs on the nominal satellite instead of sixteen), each still
        the full run.
    duration_s : float, optional
        Shortens every run [s] (default: the scenario's, the thesis's 120 s); the
        windowed requirements then read a shorter record, and the delay verdicts the
        run's last quarter (:func:`~flexsat.analysis.requirements.residual_rate_verdict`).

    Returns
    -------
    dict
        ``json`` and ``figures``: paths written. The JSON's ``delay_sweep`` rows hold
        each delay's metrics, ``verdict`` (``"stable"``, ``"limit cycle"`` or
        ``"diverges"``), the residual-rate envelopes [deg/s] and their ratio [-];
        ``linear_delay_margin`` is :func:`delay_margin`'s, and
        ``stable_up_to_delay_s``, ``unstable_at_delay_s`` [s] bracket the boundary.
    """
    from flexsat.parallel import forked_map

    out = Path(out)
    control_dt = SlewScenario().control_dt_s
    margin = delay_margin(plant)
    around = bracket_delays(margin and margin["margin_s"], control_dt,
                            QUICK_MARGIN_FACTORS if quick else MARGIN_FACTORS)  # fmt: skip
    swept_s = QUICK_DELAYS_S if quick else DELAYS_S
    periods = sorted({round(delay / control_dt) for delay in swept_s} | set(around))
    driven, drive_runs = _sadm_runs(plant)
    # (how, fields): the items are pickled to the forks, the satellites are not (the
    # forks inherit them); the avionics run also draws its stages' figures
    runs = [("metrics", {}), ("figures", AVIONICS)]
    runs += [("delay", delayed(n)) for n in periods] + [("drive", f) for f in drive_runs]

    def fly(run: tuple) -> tuple[dict, list[Path]]:
        how, fields = run
        if how == "drive":
            return _sadm_run(driven, fields, duration_s), []
        ds = _run(plant, fields, duration_s)
        metrics = slew_metrics(ds)
        figures = _stage_figures(ds, out) if how == "figures" else []
        kept = {key: metrics[key] for key in _KEYS}
        if how == "delay":
            verdict = residual_rate_verdict(
                ds["time"].values, ds["rate_error_deg_s"].values,
                metrics["observation_window_s"], Requirements().jitter_deg_s,
                stopped=metrics["status"] != "ok")  # fmt: skip
            kept.update({key: verdict[key] for key in _VERDICT_KEYS})
        return kept, figures

    flown = forked_map(fly, runs)
    (ideal, _), (avionics, stage_figures), *rest = flown
    swept = [metrics for metrics, _ in rest[: len(periods)]]
    driven_runs = [metrics for metrics, _ in rest[len(periods) :]]
    side_by_side = {"ideal": ideal, "avionics": avionics}
    sweep = []
    for n, row in zip(periods, swept, strict=True):
        row["delay_s"] = n * control_dt
        row["unstable"] = row["verdict"] != "stable"
        sweep.append(row)

    def first(key, value):
        hits = [r["delay_s"] for r in sweep if r[key] == value]
        return hits[0] if hits else None

    unstable_at = first("unstable", True)
    stable = [r["delay_s"] for r in sweep if unstable_at is None or r["delay_s"] < unstable_at]
    payload = {
        "side_by_side": side_by_side,
        "delay_sweep": sweep,
        "r1_lost_at_delay_s": first("r1_pass", False),
        "r2_lost_at_delay_s": first("r2_pass", False),
        "unstable_at_delay_s": unstable_at,
        "stable_up_to_delay_s": max(stable) if stable else None,
        "limit_cycle_at_delay_s": first("verdict", "limit cycle"),
        "diverges_at_delay_s": first("verdict", "diverges"),
        "linear_delay_margin": margin,
        "run_duration_s": duration_s if duration_s is not None else SlewScenario().duration_s,
        "sadm": _sadm_summary(*driven_runs),
        "quick": quick,
    }
    from flexsat.study.outputs import write_json

    json_path = write_json(out / "avionics.json", payload)
    figure = _delay_figure(sweep, margin, out / "delay_boundary.png")
    return {"json": json_path, "figures": [figure, *stage_figures]}


def _stage_figures(ds, out: Path) -> list[Path]:
    """The figures of the stages of the avionics run that show what the ideal loop
    cannot: the estimation error inside its covariance, and the wheels
    (:mod:`flexsat.plots.stages`)."""
    from flexsat.plots.stages import plot_stage
    from flexsat.plots.style import save_figure

    return [save_figure(plot_stage(ds, name), out / f"{name}.png", dpi=110)
            for name in AVIONICS_FIGURES]  # fmt: skip


def _delay_figure(sweep: list[dict], margin: dict | None, path: Path) -> Path:
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
        for verdict, marker in (("limit cycle", "rs"), ("diverges", "rx")):
            hit = np.array([r["verdict"] == verdict for r in sweep])
            if hit.any():
                ax.semilogy(delay[hit], values[hit], marker, ms=9, mfc="none", label=verdict)
        if margin is not None:
            ax.axvline(margin["margin_s"], color="tab:purple", ls=":", lw=1.2,
                       label=f"linear delay margin ({margin['axis']})")  # fmt: skip
        ax.set_ylabel(label)
        ax.legend()
    axes[1, 0].set_xscale("symlog", linthresh=0.01)  # 0 s and the margin's neighbours apart
    ticks = [d for d in (0.0, 0.01, 0.02, 0.05, 0.1, 0.2, 0.5, 1.0)
             if delay.min() * 0.8 <= d <= delay.max() * 1.2]  # fmt: skip
    axes[1, 0].set_xticks(ticks, [f"{d:g}" for d in ticks])
    axes[1, 0].set_xlim(0.8 * delay.min() if delay.min() > 0.0 else -0.002, 1.1 * delay.max())
    axes[1, 0].set_xlabel("computational delay [s]")
    axes[0, 0].set_title("45/45/45 deg ASMC slew: stability boundary against delay")
    return save_figure(fig, path, dpi=110)


_SWEEP_KEYS = ("delay_s", "r1_pass", "r2_pass", "ape_deg", "max_rate_error_deg_s", "verdict",
               "envelope_last_deg_s", "envelope_ratio")  # fmt: skip
SWEEP_HEADER = ("delay [s]", "R1", "R2", "APE [deg]", "max rate error [deg/s]",
                "stability (residual-rate envelope)",
                "envelope, window's 2nd half [deg/s]", "2nd half / 1st half [-]")  # fmt: skip
"""The report's delay-sweep table: its columns, one per key of a sweep row."""


def _boundaries(data: dict, fmt) -> str:
    """The sentence of the sweep: the linear margin's prediction, the sweep's verdicts
    around it, and where R1 and R2 are lost."""
    margin = data.get("linear_delay_margin")
    if margin is None:
        text = "The linear loop has no finite delay margin to predict the boundary. "
    else:
        text = (f"Prediction: the {margin['law'].upper()} law linearized about rest around the "
                f"flexible plant, the loop broken at one axis's torque (the frequency "
                f"section's loop), has its smallest delay margin on axis {margin['axis']}: "
                f"{margin['margin_s']:.3g} s (at {margin['crossover_hz']:.3g} Hz). ")  # fmt: skip
    text += (f"Time domain ({data['run_duration_s']:g} s runs of the ideal loop, every axis "
             f"delayed, each judged on its residual-rate envelope over the observation "
             "window): ")  # fmt: skip
    phrases = (("stable_up_to_delay_s", "stable up to {:g} s", "no delay stable"),
               ("limit_cycle_at_delay_s", "a limit cycle from {:g} s", "no limit cycle"),
               ("diverges_at_delay_s", "diverging from {:g} s", "no run diverging"))  # fmt: skip
    text += ", ".join(none if data[key] is None else found.format(data[key])
                      for key, found, none in phrases)  # fmt: skip
    stable, unstable = data["stable_up_to_delay_s"], data["unstable_at_delay_s"]
    if margin is not None and stable is not None and unstable is not None:
        m = margin["margin_s"]
        text += f"; the boundary lies between {stable:g} and {unstable:g} s, "
        if stable <= m < unstable:
            text += "which holds the linear margin: the sweep confirms the prediction"
        else:
            off = max(abs(stable / m - 1.0), abs(unstable / m - 1.0))
            text += (f"{'above' if stable > m else 'below'} the linear margin, which "
                     f"predicts it to within {off:.1%}")  # fmt: skip
    return (text + f". R1 is lost at a delay of {fmt(data['r1_lost_at_delay_s'])}, R2 at "
            f"{fmt(data['r2_lost_at_delay_s'])}. ")  # fmt: skip


def render_avionics(root: Path, outputs: dict, cell) -> tuple[list, list, list, str]:
    """Table rows for the report: the side-by-side metrics, the delay sweep, the arrays
    holding and turning (SADM), and the sentence of the boundaries.

    Parameters
    ----------
    root : Path
        The study folder.
    outputs : dict
        The avionics part's outputs (manifest).
    cell : callable
        ``cell(relative_json, *path)`` makes a traced table cell.

    Returns
    -------
    metrics, sweep, sadm : list
        The table rows (``sadm`` empty when the satellite has no plate to drive).
    boundaries : str
        The sentence.
    """
    import json

    rel = outputs["json"]
    data = json.loads((root / rel).read_text())
    side = [[key, cell(rel, "side_by_side", "ideal", key),
             cell(rel, "side_by_side", "avionics", key)] for key in _KEYS]  # fmt: skip
    sweep = [[cell(rel, "delay_sweep", i, key) for key in _SWEEP_KEYS]
             for i in range(len(data["delay_sweep"]))]  # fmt: skip
    driven = "not_applicable" not in data["sadm"]
    sadm = []
    if driven:
        sadm = [[key, cell(rel, "sadm", "holding", key), cell(rel, "sadm", "turning", key)]
                for key in _KEYS]  # fmt: skip
        sadm += [[key, "", cell(rel, "sadm", key)] for key in _SADM_KEYS]

    def fmt(value):
        return "beyond the sweep" if value is None else f"{value:g} s"

    sentence = _boundaries(data, fmt)
    if driven:
        sentence += (f"Arrays turning at {data['sadm']['rate_deg_s']:g} deg/s (SADM, one "
                     f"turn per low-orbit revolution) move the attitude by at most "
                     f"{data['sadm']['attitude_difference_deg']:.2g} deg from the arrays "
                     f"held.")  # fmt: skip
    else:
        sentence += f"Arrays turning (SADM): {data['sadm']['not_applicable']}."
    return side, sweep, sadm, sentence
