"""Benchmark: per-step cost of modal appendages against their modes, and against chains.

Two appendages on the same hub: the uniform beam of the tests (scikit-fem, 32
Hermite elements) reduced by Craig–Bampton to 1, 5, 20 and 50 clamped modes each
(:func:`flexsat.fe.craig_bampton`); chains of 16, 32 and 64 rigid segments of the same
beam; the thesis plate for reference. For each it times, on one core:

* "q̈ µs": one ``accelerations`` call from a compiled loop (best of 5);
* "µs/step": an open-loop RK4 run (the dataset's ``wall_time_s`` over its steps);
* "yaw error": the first coupled yaw frequency against the Euler–Bernoulli frequency
  equation (:func:`flexsat.fe.euler_bernoulli_hub_frequencies`), the accuracy.

Target: a modal appendage cheaper per step than a chain of equal accuracy. The line
fit of the step cost against the modes shows its growth (linear by construction: every
kernel loops once over the modes; below ~20 modes the per-mode increment is smaller
than the timing noise of a shared machine). Run with
``python bench/bench_modal.py``.
"""

from __future__ import annotations

import sys

import numpy as np
from scipy.linalg import eigh

import harness
from bench_scaling import evaluation_us, linear_fit
from flexsat.config import load_config, validate_config
from flexsat.dynamics.plant import Plant
from flexsat.fe import craig_bampton, euler_bernoulli_hub_frequencies, uniform_beam
from flexsat.simulate import OpenLoopScenario, run_openloop

MODES = (1, 5, 20, 50)
SEGMENTS = (16, 32, 64)
LENGTH, RHO_A, EI_X, EI_Z = 4.0, 2.0, 400.0, 50.0  # [m], [kg/m], [N m^2], [N m^2]
GJ, RHO_IP, EA = 80.0, 0.05, 1e5  # [N m^2], [kg m], [N]
HUB = {"mass_kg": 100.0, "inertia_kg_m2": [[40.0, 0, 0], [0, 35.0, 0], [0, 0, 30.0]]}
ROOT = 0.5  # [m]
SCENARIO = OpenLoopScenario.model_validate({
    "duration_s": 2.0, "dt_s": 1e-4, "record_dt_s": 0.01,
    "torque": [{"start_s": 0.0, "end_s": 1.0, "torque_nm": [0.0, 0.0, 1e-3]}],
})  # fmt: skip


def _pair(wing: dict, turned: dict) -> Plant:
    return Plant.from_config(validate_config({"hub": HUB, "appendages": [
        {**wing, "name": "wing_1", "mount_point_m": [0.0, ROOT, 0.0]},
        {**wing, **turned, "name": "wing_2", "mount_point_m": [0.0, -ROOT, 0.0]},
    ]}))  # fmt: skip


def modal_plant(n_modes: int) -> Plant:
    beam = uniform_beam(
        LENGTH,
        32,
        mass_per_length_kg_m=RHO_A,
        bending_stiffness_x_n_m2=EI_X,
        bending_stiffness_z_n_m2=EI_Z,
        axial_stiffness_n=EA,
        torsional_stiffness_n_m2=GJ,
        polar_inertia_per_length_kg_m=RHO_IP,
    )
    data = craig_bampton(beam.M, beam.K, beam.interface_dofs, n_modes,
                         interface_map=beam.interface_map)  # fmt: skip
    return _pair({"model": "modal", "data": data.model_dump()}, {"mount_yaw_deg": 180.0})


def chain_plant(segments: int) -> Plant:
    wing = {"model": "chain", "span_direction": "+y", "segments": segments,
            "length_m": LENGTH, "width_m": 0.01, "thickness_m": 0.001,
            "mass_kg": RHO_A * LENGTH, "joint": {"dofs": ["rz"]},
            "beam": {"EI_in_plane_N_m2": EI_Z}}  # fmt: skip
    return _pair(wing, {"mount_yaw_deg": 180.0})


def yaw_error(plant: Plant, reference: float) -> float:
    """Relative error of the first coupled mode that moves the hub about Z."""
    lam, phi = eigh(plant.stiffness_matrix(), plant.mass_matrix())
    yaw = (np.abs(phi[5]) > 1e-8 * np.abs(phi).max(axis=0)) & (lam > 1e-9)
    return abs(np.sqrt(lam[yaw][0]) / (2 * np.pi) / reference - 1.0)


def _step_us(plant: Plant) -> float:
    run_openloop(plant, SCENARIO)  # warm-up: compile or load the cache
    ds = run_openloop(plant, SCENARIO).dataset
    return 1e6 * float(ds.attrs["wall_time_s"]) / int(ds.attrs["steps"])


def measure() -> list[dict]:
    reference = euler_bernoulli_hub_frequencies(30.0, ROOT, LENGTH, RHO_A, EI_Z, 1)[0]
    rows = []
    cases = [("thesis plates", 6, Plant.from_config(load_config()))]
    cases += [(f"modal, {n} modes", n, modal_plant(n)) for n in MODES]
    cases += [(f"chain, {n} segments", n, chain_plant(n)) for n in SEGMENTS]
    for label, size, plant in cases:
        compiled, _ = evaluation_us(plant)
        error = float("nan") if label.startswith("thesis") else yaw_error(plant, reference)
        rows.append({"case": label, "size": size, "dof": plant.n_dof, "qdd_us": compiled,
                     "step_us": _step_us(plant), "yaw_error": error})  # fmt: skip
    return rows


@harness.register(
    "modal appendages (Craig-Bampton, 1 ... 50 modes) against chains of the same beam: us per "
    "q_ddot and per RK4 step, and the first yaw frequency against Euler-Bernoulli"
)
def main(argv: list[str] | None = None) -> list[dict]:
    rows = measure()
    table = harness.table(
        "Modal appendages: cost per step against modes and chains",
        ("case", "DOF", "q̈ µs", "µs/step", "yaw error"),
        right=(),
    )
    for r in rows:
        table.add_row(
            r["case"],
            str(r["dof"]),
            f"{r['qdd_us']:.2f}",
            f"{r['step_us']:.2f}",
            "-" if np.isnan(r["yaw_error"]) else f"{r['yaw_error']:.1e}",
        )
    console = harness.console()
    console.print(table)
    modal = [r for r in rows if r["case"].startswith("modal")]
    n = np.array([r["size"] for r in modal], dtype=float)
    a, b, r2 = linear_fit(n, np.array([r["step_us"] for r in modal]))
    console.print(f"µs/step = {a:.2f} + {b:.3f} n (n modes per appendage, R² = {r2:.3f})")
    chains = [r for r in rows if r["case"].startswith("chain")]
    best_chain = min(chains, key=lambda r: r["yaw_error"])
    match = next(r for r in modal if r["yaw_error"] <= best_chain["yaw_error"])
    met = match["step_us"] < best_chain["step_us"]
    console.print(
        f"target: a modal appendage as accurate as the best chain ({best_chain['case']}, "
        f"{best_chain['yaw_error']:.1e}) costs less per step: {match['case']} "
        f"{match['step_us']:.1f} µs against {best_chain['step_us']:.1f} µs "
        f"({'met' if met else 'not met'})"
    )
    return rows


if __name__ == "__main__":
    main(sys.argv[1:])
