"""Benchmark: the modal appendage's cost per step with its large-motion terms on and off.

Two appendages on one hub: the uniform beam of bench_modal.py (scikit-fem, 32 Hermite
elements) reduced by Craig–Bampton to 6, 24 and 96 clamped modes each, once with the
large-motion invariants (:attr:`flexsat.fe.BeamModel.large_motion`: the geometric
stiffness, the modes' gyroscopic coupling and second-order inertia) and once without
(the first-order model). For each it times one ``accelerations`` call of the whole
plant from a compiled loop (best of 5), which is what an RK4 step costs four times.

Target: at 24 modes the terms cost at most 1.5 times the first-order step. The
large-motion sums run over every pair of modes (n^2 per step, where the first-order
model is linear in n): two matrix-vector products (BLAS) of the invariants' packed
15 n x n matrix (J'' by its six distinct entries), its 12 n rows J'', C, E with eta and
its 9 n rows C, E, E^T with eta_dot, 21 n^2 multiply-adds (27 n^2 before J'' was
stored symmetric and the rows E^T stopped meeting eta), against a first-order step
of some hundred per mode. The table's last column is the growth,
the fit of the extra cost against n^2 states it; the target is not met at 24 modes
(the n^2 products alone are several first-order steps there). Run with
``python bench/bench_modal_large_motion.py`` (``--quick``: 6 and 24 modes).
"""

from __future__ import annotations

import sys

import numpy as np

import harness
from bench_modal import HUB, LENGTH, RHO_A, ROOT
from bench_scaling import _evaluate
from flexsat.config import validate_config
from flexsat.dynamics.plant import Plant
from flexsat.fe import craig_bampton, uniform_beam

MODES = (6, 24, 96)
QUICK = (6, 24)
CALLS = 400_000  # accelerations calls per timing, divided by n^2 / 36 (>= 50)
TARGET_RATIO = 1.5  # at 24 modes


def plant(n_modes: int, large_motion: bool) -> Plant:
    """Two Craig–Bampton beams of ``n_modes`` modes each, with or without the terms."""
    beam = uniform_beam(LENGTH, 32, mass_per_length_kg_m=RHO_A,
                        bending_stiffness_x_n_m2=400.0, bending_stiffness_z_n_m2=50.0,
                        axial_stiffness_n=1e5, torsional_stiffness_n_m2=80.0,
                        polar_inertia_per_length_kg_m=0.05)  # fmt: skip
    data = craig_bampton(beam.M, beam.K, beam.interface_dofs, n_modes,
                         interface_map=beam.interface_map,
                         large_motion=beam.large_motion if large_motion else None)  # fmt: skip
    wing = {"model": "modal", "data": data.model_dump()}
    return Plant.from_config(validate_config({"hub": HUB, "appendages": [
        {**wing, "name": "wing_1", "mount_point_m": [0.0, ROOT, 0.0]},
        {**wing, "name": "wing_2", "mount_point_m": [0.0, -ROOT, 0.0], "mount_yaw_deg": 180.0},
    ]}))  # fmt: skip


def call_us(p: Plant, n_modes: int) -> float:
    """One ``accelerations`` call from a compiled loop [us], best of 5."""
    rng = np.random.default_rng(0)
    q, qd = rng.normal(scale=0.1, size=(2, p.n_dof))
    Q = rng.normal(size=p.n_dof)
    qdd = np.empty(p.n_dof)
    calls = max(50, int(CALLS * 36 / n_modes**2))
    _evaluate(q, qd, Q, p.packed, qdd, 10)  # compile or load the cache
    return 1e6 * harness.best_of(lambda: _evaluate(q, qd, Q, p.packed, qdd, calls), 5)[0] / calls


def measure(modes=MODES) -> list[dict]:
    rows = []
    for n in modes:
        off, on = call_us(plant(n, False), n), call_us(plant(n, True), n)
        rows.append({"modes": n, "off_us": off, "on_us": on, "ratio": on / off})
    return rows


def _ratio_at_24(rows: list[dict]) -> float | None:
    return next((r["ratio"] for r in rows if r["modes"] == 24), None)


@harness.register(
    "modal appendage (Craig-Bampton beams, 6/24/96 modes): us per q_ddot with the "
    "large-motion terms against the first-order model",
    targets=[
        harness.Target(
            "large-motion terms at 24 modes", TARGET_RATIO, "x", _ratio_at_24, shown="{:.2f}x"
        )
    ],
    quick_argv=("--quick",),
)
def main(argv: list[str] | None = None) -> list[dict]:
    rows = measure(QUICK if argv and "--quick" in argv else MODES)
    table = harness.table(
        "Modal appendage: large-motion terms against the first-order model",
        ("modes per appendage", "first order µs", "large motion µs", "ratio"),
        right=(),
    )
    for r in rows:
        table.add_row(str(r["modes"]), f"{r['off_us']:.2f}", f"{r['on_us']:.2f}",
                      f"{r['ratio']:.2f}")  # fmt: skip
    console = harness.console()
    console.print(table)
    n = np.array([r["modes"] for r in rows], dtype=float)
    extra = np.array([r["on_us"] - r["off_us"] for r in rows])
    slope = float(np.linalg.lstsq((n**2)[:, None], extra, rcond=None)[0][0])
    console.print(f"extra µs per call ≈ {1e3 * slope:.2f} ns × n² (n modes per appendage, "
                  "two appendages)")  # fmt: skip
    ratio = _ratio_at_24(rows)
    if ratio is not None:
        console.print(f"target: at most {TARGET_RATIO}x at 24 modes: {ratio:.2f}x "
                      f"({'met' if ratio <= TARGET_RATIO else 'not met'})")  # fmt: skip
    return rows


if __name__ == "__main__":
    main(sys.argv[1:])
