"""Benchmark: flexsat against Basilisk on the thesis's open-loop run.

Scenario (the thesis's open-loop validation, :func:`flexsat.simulate.scenario.thesis_openloop`):
the nominal satellite at rest, body torque (0, 0, 1) N m on the hub for 0 <= t < 10 s,
then free, to 120 s; fixed-step RK4 at dt = 1 ms, hub rate recorded every 10 ms. The
yaw rate then carries a ripple at about 1.23 Hz, the antisymmetric in-plane bending
mode of the panels, strongly coupled with hub yaw (thesis mode 12).

Both engines run in this one process. Run with ``python bench/bench_basilisk.py``
(Basilisk is an optional dependency: ``pip install -e '.[bench]'``); :func:`compare`
returns the numbers as a dict.

The Basilisk model
------------------
Every number is read off the flexsat :class:`~flexsat.Plant` built from the nominal
preset, so both models share one source of truth:

* hub: ``spacecraft.Spacecraft`` with ``Plant.hub_mass`` and ``Plant.hub_J``; its
  centre of mass is the body-frame origin (``r_BcB_B = 0``), as in flexsat;
* each panel: one ``spinningBodyNDOFStateEffector`` holding a chain of three spinning
  bodies hinged at the mount point (``Plant.mount_point``, mount frame from
  ``Plant.R_BM``). The chain spins about Z, then the new Y, then the new X, so its
  three angles are exactly flexsat's ZYX joint rotation angles (rho_z, rho_y, rho_x)
  and the frame of the last body is flexsat's panel frame. The first two bodies are
  massless; the third carries the panel: ``Plant.panel_mass``, ``Plant.panel_J``
  about its centre of mass, centre of mass at ``Plant.com_offset``;
* each hinge gets the stiffness and damping flexsat's inverse tuning computes for
  that rotational joint DOF (``Plant.stiffness``/``Plant.damping``, columns
  eta_rz, eta_ry, eta_rx): the spring-damper torque -k theta - c theta_dot acts on
  the angle, as flexsat's k rho + c rho_dot acts on its generalized coordinate;
* the torque: ``extForceTorque.ExtForceTorque`` with ``extTorquePntB_B`` =
  (0, 0, 1) N m; the simulation runs to 10 s, the torque is set to zero and it
  continues to 120 s. Both engines hold the torque constant over each step, so the
  switch falls on the same step boundary;
* integration: ``svIntegrators.svIntegratorRK4`` on a 1 ms task, no gravity; the hub
  rate ``omega_BN_B`` comes from a 10 ms recorder of the spacecraft state message.

What is not equivalent
----------------------
* flexsat's joints have six DOFs: besides the three rotations, three root
  translations (eta_x, eta_y, eta_z) on stiff springs tuned to 50 Hz. Basilisk's
  N-DOF spinning-body effector has rotational DOFs only, so its panels are rigidly
  held in translation at the hinge: 12 DOFs in Basilisk against flexsat's 18. On
  this run the translations barely move; linearized, removing them shifts the
  yaw-coupled mode by about 2e-5 Hz (both modal frequencies are reported).
* Basilisk propagates the hub attitude as MRPs and its translation in the inertial
  frame, flexsat as ZYX Euler angles and r_N; the compared output, the body rate,
  does not depend on that choice.
* The effectors are not added to the task: the spacecraft integrates their states
  regardless, and their per-step output messages (not needed here) are then not
  written; adding them changes the time by less than the run-to-run scatter.
  ``extForceTorque`` and the recorder are on the task.

Checks
------
The dominant frequency of the yaw rate after the torque ends (10 s to 120 s,
linearly detrended) is the peak of a Hann-windowed periodogram zero-padded to
2**20 points (bins of 1e-4 Hz), searched above 0.1 Hz. Both engines' frequencies
must lie within ``FREQ_TOL_HZ`` (0.01 Hz, about the 1 / 110 s resolution of the
window) of the thesis's 1.23 Hz. The final yaw rates (rigid-body value for 10 N m s
of angular momentum: about 3.22 deg/s) and the largest yaw-rate difference between
the two histories are reported too.

Timing
------
Best of ``repeats`` runs for each engine, flexsat and Basilisk runs interleaved so
that a passing load on the machine hits both alike:

* flexsat: ``run_openloop(plant)``, run once first so that compilation (or loading
  the compiled cache) is not timed. The integration alone (the dataset attribute
  ``wall_time_s``) is the reference of the ratio column; the whole call, which also
  builds the recorded dataset (energies, loads, momentum every 10 ms), is shown too.
* Basilisk: the wall time of the two ``ExecuteSimulation`` calls (0-10 s and
  10-120 s). Building the model and ``InitializeSimulation`` (setup) are timed
  separately and reported below the table. Every repeat builds a fresh simulation.
"""

from __future__ import annotations

import sys
from dataclasses import dataclass
from types import SimpleNamespace

import numpy as np
import scipy.linalg
from rich.table import Table
from scipy import signal

import harness
from flexpanels import import_basilisk
from flexsat import Plant
from flexsat.analysis.modal import modal_analysis
from flexsat.config import nominal
from flexsat.simulate import run_openloop
from flexsat.simulate.scenario import OpenLoopScenario, thesis_openloop

INSTALL_HINT = "Basilisk not installed: pip install -e '.[bench]'"

FREQ_REF_HZ = 1.23  # the thesis's yaw-coupled mode (mode 12)
FREQ_TOL_HZ = 0.01  # about 1 / (110 s), the resolution of the analysed window
FREQ_MIN_HZ = 0.1  # the peak search starts here, above what the detrend leaves
NFFT = 2**20  # zero-padding of the periodogram: bins of 1e-4 Hz at 100 Hz sampling

# flexsat joint DOF column of each spinning body in a panel's chain, hub outwards:
# about Z (eta_rz), then the new Y (eta_ry), then the new X (eta_rx): ZYX angles.
_CHAIN = ((2, 5), (1, 4), (0, 3))  # (spin axis index, column of Plant.stiffness)


# -- scenario and signal analysis ----------------------------------------------------------


def _torque_pulse(scenario: OpenLoopScenario) -> tuple[np.ndarray, float]:
    """The scenario's single torque segment from t = 0: torque [N m] and end time [s]."""
    (segment,) = scenario.torque
    if segment.start_s != 0.0 or segment.end_s is None or scenario.solver != "rk4":
        raise ValueError("the comparison needs one RK4 torque pulse starting at t = 0")
    return np.array(segment.torque_nm, dtype=float), float(segment.end_s)


def yaw_mode_frequency(t: np.ndarray, yaw_rate: np.ndarray, t_start: float) -> float:
    """Dominant oscillation frequency of the yaw rate from ``t_start`` on [Hz].

    Parameters
    ----------
    t : ndarray, shape (n,)
        Uniform sample times [s].
    yaw_rate : ndarray, shape (n,)
        Hub yaw rate [any unit].
    t_start : float
        Start of the analysed window [s] (the end of the torque).

    Returns
    -------
    float
        Peak of the Hann-windowed, zero-padded periodogram of the linearly
        detrended signal, above ``FREQ_MIN_HZ``.
    """
    keep = t >= t_start - 1e-9
    x = signal.detrend(np.asarray(yaw_rate, dtype=float)[keep])
    fs = 1.0 / float(np.mean(np.diff(t[keep])))
    f, power = signal.periodogram(x, fs=fs, window="hann", nfft=NFFT, detrend=False)
    band = f >= FREQ_MIN_HZ
    return float(f[band][np.argmax(power[band])])


def modal_yaw_frequencies(plant: Plant) -> tuple[float, float]:
    """Linearized yaw-coupled mode frequency of flexsat's model, with and without the
    joint translations [Hz].

    The first is flexsat's modal analysis (the lowest flexible mode driving hub yaw
    most); the second solves K phi = omega^2 M(0) phi on the hub and rotational joint
    DOFs only, the DOF set of the Basilisk model, and takes the mode nearest the first.
    """
    modes = modal_analysis(plant).modes
    full = min(
        m.frequency_hz
        for m in modes
        if m.hub_dof == "psi" and m.kind not in ("rigid", "translation")
    )
    keep = [j for j in range(plant.n_dof) if j < 6 or (j - 6) % 6 >= 3]
    sub = np.ix_(keep, keep)
    eig = scipy.linalg.eigh(
        plant.stiffness_matrix()[sub], plant.mass_matrix()[sub], eigvals_only=True
    )
    freqs = np.sqrt(np.clip(eig, 0.0, None)) / (2.0 * np.pi)
    return float(full), float(freqs[np.argmin(np.abs(freqs - full))])


# -- flexsat -------------------------------------------------------------------------------


def run_flexsat(plant: Plant, scenario: OpenLoopScenario) -> dict:
    """One timed ``run_openloop`` call: integration and whole-call wall times, hub rate."""
    timed = harness.stopwatch(lambda: run_openloop(plant, scenario, progress=False))
    whole, result = timed.wall_s, timed.value
    result.raise_for_status()
    ds = result.dataset
    return {
        "wall_time_s": float(ds.attrs["wall_time_s"]),
        "whole_call_s": whole,
        "steps": int(ds.attrs["steps"]),
        "t": ds["time"].values,
        "omega": ds["omega"].values,
    }


# -- Basilisk ------------------------------------------------------------------------------


@dataclass
class BasiliskModel:
    """A built Basilisk simulation; holds every SWIG object so none is collected early."""

    sim: object
    torque: object
    recorder: object
    keep_alive: list


def _column(v) -> list[list[float]]:
    return [[float(x)] for x in np.asarray(v, dtype=float).ravel()]


def _matrix(m) -> list[list[float]]:
    return np.asarray(m, dtype=float).tolist()


def build_basilisk(bsk: SimpleNamespace, plant: Plant, scenario: OpenLoopScenario) -> BasiliskModel:
    """The Basilisk equivalent of ``plant`` under ``scenario`` (see the module docstring).

    Not initialized; the external torque is set to the pulse's value.
    """
    torque, _ = _torque_pulse(scenario)
    sbn = bsk.spinningBodyNDOFStateEffector
    sim = bsk.SimulationBaseClass.SimBaseClass()
    process = sim.CreateNewProcess("dynamicsProcess")
    process.addTask(sim.CreateNewTask("dynamicsTask", bsk.macros.sec2nano(scenario.dt_s)))

    sc = bsk.spacecraft.Spacecraft()
    sc.ModelTag = "flexsat-nominal"
    sc.hub.mHub = float(plant.hub_mass)
    sc.hub.r_BcB_B = _column(np.zeros(3))  # flexsat's hub frame B is centred on the hub CoM
    sc.hub.IHubPntBc_B = _matrix(plant.hub_J)
    keep_alive: list = [sc]

    zero3, zero33 = np.zeros(3), np.zeros((3, 3))
    stiffness, damping = plant.stiffness.reshape(-1, 6), plant.damping.reshape(-1, 6)
    for i, app in enumerate(plant.config.appendages):
        row, plate = plant.params[i], plant.models[i]
        panel = plate.describe(app, row)
        J_panel = np.array(panel["centroidal_inertia_kg_m2"])
        chain = sbn.SpinningBodyNDOFStateEffector()
        chain.ModelTag = app.name
        for k, (axis, dof) in enumerate(_CHAIN):
            first, last = k == 0, k == len(_CHAIN) - 1
            body = sbn.SpinningBody()
            body.setMass(float(panel["mass_kg"]) if last else 0.0)
            body.setISPntSc_S(_matrix(J_panel if last else zero33))
            body.setR_ScS_S(_column(plate.com_offset(row) if last else zero3))
            # The first hinge sits at the mount point; its zero-angle frame is the mount
            # frame M ([S0 B] = R_BM^T). The others share its hinge point and frame.
            body.setR_SP_P(_column(plate.mount_point(row) if first else zero3))
            body.setDCM_S0P(_matrix(plate.mount_rotation(row).T if first else np.eye(3)))
            body.setSHat_S(_column(np.eye(3)[axis]))
            body.setK(float(stiffness[i, dof]))
            body.setC(float(damping[i, dof]))
            chain.addSpinningBody(body)
            keep_alive.append(body)
        chain.setNameOfThetaState(f"{app.name}Theta")
        chain.setNameOfThetaDotState(f"{app.name}ThetaDot")
        sc.addStateEffector(chain)
        keep_alive.append(chain)

    ext = bsk.extForceTorque.ExtForceTorque()
    ext.ModelTag = "hubTorque"
    ext.extTorquePntB_B = _column(torque)
    sc.addDynamicEffector(ext)

    integrator = bsk.svIntegrators.svIntegratorRK4(sc)
    sc.setIntegrator(integrator)
    keep_alive.append(integrator)

    recorder = sc.scStateOutMsg.recorder(bsk.macros.sec2nano(scenario.record_dt_s))
    sim.AddModelToTask("dynamicsTask", ext)
    sim.AddModelToTask("dynamicsTask", sc)
    sim.AddModelToTask("dynamicsTask", recorder)
    return BasiliskModel(sim=sim, torque=ext, recorder=recorder, keep_alive=keep_alive)


def run_basilisk(bsk: SimpleNamespace, plant: Plant, scenario: OpenLoopScenario) -> dict:
    """Build, initialize and run the Basilisk model; setup and execution timed apart."""
    _, t_off = _torque_pulse(scenario)

    def build() -> BasiliskModel:
        model = build_basilisk(bsk, plant, scenario)
        model.sim.InitializeSimulation()
        return model

    def fly() -> None:
        model.sim.ConfigureStopTime(bsk.macros.sec2nano(t_off))
        model.sim.ExecuteSimulation()
        model.torque.extTorquePntB_B = _column(np.zeros(3))
        model.sim.ConfigureStopTime(bsk.macros.sec2nano(scenario.duration_s))
        model.sim.ExecuteSimulation()

    built = harness.stopwatch(build)
    model = built.value
    return {
        "execute_s": harness.stopwatch(fly).wall_s,
        "setup_s": built.wall_s,
        "steps": round(scenario.duration_s / scenario.dt_s),
        "t": np.asarray(model.recorder.times(), dtype=float) * 1e-9,
        "omega": np.array(model.recorder.omega_BN_B, dtype=float),
    }


# -- the comparison ------------------------------------------------------------------------


def _summary(run: dict, t_off: float) -> dict:
    yaw = run["omega"][:, 2]
    return {
        "yaw_mode_hz": yaw_mode_frequency(run["t"], yaw, t_off),
        "final_yaw_rate_deg_s": float(np.degrees(yaw[-1])),
        "n_records": int(yaw.size),
    }


def compare(repeats: int = 3) -> dict:
    """Run both engines on the thesis's open-loop scenario and compare them.

    Parameters
    ----------
    repeats : int
        Timed runs of each engine; the best (shortest) wall time is kept.

    Returns
    -------
    dict
        ``flexsat`` and ``basilisk`` (wall times, microseconds per step, DOFs, yaw-mode
        frequency, final yaw rate), the linearized modal frequencies, the frequency
        check, the largest yaw-rate difference and the timing ratios.

    Raises
    ------
    ImportError
        If Basilisk is not installed.
    """
    if repeats < 1:
        raise ValueError(f"repeats must be >= 1, got {repeats}")
    bsk = import_basilisk()
    plant = Plant.from_config(nominal())
    scenario = thesis_openloop()
    _, t_off = _torque_pulse(scenario)

    run_flexsat(plant, scenario)  # compile (or load the compiled cache) first
    runs = harness.interleave(
        {
            "flexsat": lambda: run_flexsat(plant, scenario),
            "basilisk": lambda: run_basilisk(bsk, plant, scenario),
        },
        repeats,
    )
    flex_runs, bsk_runs = runs["flexsat"], runs["basilisk"]

    flex_last, bsk_last = flex_runs[-1], bsk_runs[-1]
    if flex_last["t"].shape != bsk_last["t"].shape or not np.allclose(
        flex_last["t"], bsk_last["t"], atol=1e-9
    ):
        raise RuntimeError("the two engines recorded different time grids")

    flex_wall = min(r["wall_time_s"] for r in flex_runs)
    flex_whole = min(r["whole_call_s"] for r in flex_runs)
    bsk_exec = min(r["execute_s"] for r in bsk_runs)
    bsk_setup = min(r["setup_s"] for r in bsk_runs)
    steps = flex_last["steps"]
    flexsat = {
        "engine": "flexsat",
        "dof": plant.n_dof,
        "wall_time_s": flex_wall,
        "whole_call_s": flex_whole,
        "us_per_step": 1e6 * flex_wall / steps,
        "us_per_step_whole_call": 1e6 * flex_whole / steps,
        "steps": steps,
        "walls_s": [r["wall_time_s"] for r in flex_runs],
        "whole_calls_s": [r["whole_call_s"] for r in flex_runs],
        **_summary(flex_last, t_off),
    }
    basilisk = {
        "engine": f"Basilisk {bsk.version}",
        "dof": 6 + len(_CHAIN) * plant.n_appendages,
        "execute_s": bsk_exec,
        "setup_s": bsk_setup,
        "us_per_step": 1e6 * bsk_exec / bsk_last["steps"],
        "steps": bsk_last["steps"],
        "executes_s": [r["execute_s"] for r in bsk_runs],
        "setups_s": [r["setup_s"] for r in bsk_runs],
        **_summary(bsk_last, t_off),
    }
    modal_full, modal_rot = modal_yaw_frequencies(plant)
    f_flex, f_bsk = flexsat["yaw_mode_hz"], basilisk["yaw_mode_hz"]
    yaw_diff = np.degrees(np.abs(flex_last["omega"][:, 2] - bsk_last["omega"][:, 2]))
    return {
        "scenario": {
            "duration_s": scenario.duration_s,
            "dt_s": scenario.dt_s,
            "record_dt_s": scenario.record_dt_s,
            "torque_off_s": t_off,
            "repeats": repeats,
            "panels": plant.n_appendages,
        },
        "flexsat": flexsat,
        "basilisk": basilisk,
        "modal_yaw_hz": modal_full,
        "modal_yaw_hz_rotations_only": modal_rot,
        "reference_hz": FREQ_REF_HZ,
        "tolerance_hz": FREQ_TOL_HZ,
        "frequencies_agree": bool(
            abs(f_flex - FREQ_REF_HZ) <= FREQ_TOL_HZ and abs(f_bsk - FREQ_REF_HZ) <= FREQ_TOL_HZ
        ),
        "frequency_difference_hz": f_bsk - f_flex,
        "max_yaw_rate_difference_deg_s": float(yaw_diff.max()),
        "ratio_basilisk_vs_flexsat": bsk_exec / flex_wall,
        "ratio_basilisk_vs_flexsat_whole_call": bsk_exec / flex_whole,
    }


def _table(out: dict) -> Table:
    flex, bsk, sc = out["flexsat"], out["basilisk"], out["scenario"]
    per = 120.0 / sc["duration_s"]
    n = sc["panels"]
    rows = [
        ("flexsat", f"RK4 integration (compiled); hub + {n} panels on 6-DOF joints", flex["dof"],
         flex["wall_time_s"], flex["us_per_step"], flex),
        ("flexsat", "whole run_openloop call (incl. building the dataset)", flex["dof"],
         flex["whole_call_s"], flex["us_per_step_whole_call"], flex),
        (bsk["engine"], f"ExecuteSimulation; hub + {n} spinningBodyNDOF panels, 3 rot. DOFs",
         bsk["dof"], bsk["execute_s"], bsk["us_per_step"], bsk),
    ]  # fmt: skip
    table = harness.table(
        f"Open loop, thesis scenario: 1 N m yaw torque for {sc['torque_off_s']:g} s, free "
        f"to {sc['duration_s']:g} s, RK4 dt {1e3 * sc['dt_s']:g} ms (best of {sc['repeats']})",
        ("engine", "model", "DOF", "wall s per 120 s", "µs per step", "yaw-mode frequency Hz",
         "final yaw rate deg/s", "ratio vs flexsat"), left=2, no_wrap=True,
        caption="ratio: wall time / flexsat RK4 integration wall time",
    )  # fmt: skip
    for engine, model, dof, wall, us, run in rows:
        table.add_row(
            engine,
            model,
            str(dof),
            f"{wall * per:.3f}",
            f"{us:.2f}",
            f"{run['yaw_mode_hz']:.5f}",
            f"{run['final_yaw_rate_deg_s']:.6f}",
            f"{wall / flex['wall_time_s']:.2f}x",
        )
    return table


@harness.register(
    "the open-loop run against Basilisk (optional dependency; skipped with a line when absent)",
    optional=True,
)
def main() -> int:
    """Print the comparison table; 0 on success, 1 if the frequencies disagree."""
    console = harness.console(200)
    try:
        import_basilisk()
    except ImportError:
        print(INSTALL_HINT)
        return 0
    out = compare()
    flex, bsk = out["flexsat"], out["basilisk"]
    console.print(_table(out))
    console.print(
        f"Basilisk setup (build + InitializeSimulation), not in the table: "
        f"{bsk['setup_s']:.3f} s. Basilisk ExecuteSimulation is "
        f"{out['ratio_basilisk_vs_flexsat']:.1f}x flexsat's integration and "
        f"{out['ratio_basilisk_vs_flexsat_whole_call']:.1f}x its whole call."
    )
    verdict = "agree" if out["frequencies_agree"] else "DISAGREE"
    console.print(
        f"Yaw-mode frequency (10-120 s, detrended): flexsat {flex['yaw_mode_hz']:.5f} Hz, "
        f"Basilisk {bsk['yaw_mode_hz']:.5f} Hz: both within {out['tolerance_hz']:g} Hz of "
        f"{out['reference_hz']:g} Hz: {verdict}. Linearized: {out['modal_yaw_hz']:.5f} Hz "
        f"(flexsat, 18 DOF), {out['modal_yaw_hz_rotations_only']:.5f} Hz (rotational joint "
        f"DOFs only, as Basilisk)."
    )
    console.print(
        f"Largest yaw-rate difference between the two histories: "
        f"{out['max_yaw_rate_difference_deg_s']:.2e} deg/s."
    )
    console.print(f"Machine: {harness.machine()}.")
    return 0 if out["frequencies_agree"] else 1


if __name__ == "__main__":
    sys.exit(main())
