"""Benchmark: microseconds per evaluation of M(q), h(q, q_dot) and q_ddot.

Run with ``make bench`` (or ``python bench/bench_dynamics.py``). Prints a table for
the nominal two-panel satellite and for eight appendages, plus the numba compile
time (fresh cache) and the cached start-up time, each measured in a new process.
"""

from __future__ import annotations

import copy
import os
import subprocess
import sys
import tempfile
import tomllib

import numpy as np

import harness
from flexsat.config import preset_path, validate_config
from flexsat.dynamics import kernels
from flexsat.dynamics.packed import only
from flexsat.dynamics.plant import Plant


def _config(n_appendages: int):
    """Nominal hub with ``n_appendages`` nominal panels spread evenly around hub Z."""
    data = tomllib.loads(preset_path("nominal").read_text())
    if n_appendages == 2:
        return validate_config(data)
    base = data["appendages"][0]
    apps = []
    for k in range(n_appendages):
        yaw = 360.0 * k / n_appendages
        app = copy.deepcopy(base)
        app.update(
            name=f"panel_{k + 1}",
            mount_yaw_deg=yaw,
            mount_point_m=[-0.8 * np.sin(np.radians(yaw)), 0.8 * np.cos(np.radians(yaw)), 0.0],
        )
        apps.append(app)
    data["appendages"] = apps
    return validate_config(data)


def measure(n_appendages: int) -> dict[str, float]:
    plant = Plant.from_config(_config(n_appendages))
    rng = np.random.default_rng(0)
    q = rng.normal(scale=0.1, size=plant.n_dof)
    qd = rng.normal(scale=0.1, size=plant.n_dof)
    Q = rng.normal(size=plant.n_dof)
    M = np.empty((plant.n_dof, plant.n_dof))
    h = np.empty(plant.n_dof)
    qdd = np.empty(plant.n_dof)
    # Each evaluation gets the plant with only its own kernels, as Plant's methods do.
    views = {
        k: only(plant.packed, *v)
        for k, v in (
            ("M", ("mass_matrix",)),
            ("h", ("bias_forces",)),
            ("qdd", ("pass1", "pass2", "mass_matrix")),
        )
    }
    return {
        "M(q)": harness.per_call_us(lambda: kernels.mass_matrix(q, views["M"], M)),
        "h(q, qd)": harness.per_call_us(lambda: kernels.bias_forces(q, qd, views["h"], h)),
        "q_ddot": harness.per_call_us(lambda: kernels.accelerations(q, qd, Q, views["qdd"], qdd)),
        "q_ddot via M, h + np.linalg.solve": harness.per_call_us(
            lambda: np.linalg.solve(
                plant.mass_matrix(q),
                Q - plant.bias_forces(q, qd) - plant.damping_forces(qd) - plant.elastic_forces(q),
            )
        ),
    }


_STARTUP = """
import time
t0 = time.perf_counter()
import numpy as np
from flexsat.config import nominal
from flexsat.dynamics.plant import Plant
from flexsat.dynamics import kernels
plant = Plant.from_config(nominal())
q = np.zeros(plant.n_dof); out = np.empty(plant.n_dof)
kernels.accelerations(q, q, q, plant.packed, out)
kernels.bias_forces(q, q, plant.packed, out)
print(time.perf_counter() - t0)
"""


def startup_seconds(cache_dir: str) -> float:
    env = dict(os.environ, NUMBA_CACHE_DIR=cache_dir)
    result = subprocess.run(
        [sys.executable, "-c", _STARTUP], env=env, capture_output=True, text=True, check=True
    )
    return float(result.stdout.strip())


@harness.register(
    "us per evaluation of M(q), h(q, q_dot), q_ddot, and q_ddot through M, h and "
    "np.linalg.solve, for 2 and 8 appendages; kernel compile and cached load"
)
def main(argv: list[str] | None = None) -> dict:
    """Print the table and the start-up times; return them (us per call, s)."""
    del argv  # no options
    console = harness.console()
    sizes = (2, 8)
    results = {n: measure(n) for n in sizes}
    table = harness.table("flexsat dynamics kernels: microseconds per evaluation (one core)",
                          ("evaluation", *(f"{n} appendages ({6 + 6 * n} DOF), us"
                                           for n in sizes)))  # fmt: skip
    for name in results[sizes[0]]:
        table.add_row(name, *(f"{results[n][name]:.2f}" for n in sizes))
    console.print(table)
    with tempfile.TemporaryDirectory() as cache:
        cold = startup_seconds(cache)
        warm = startup_seconds(cache)
    console.print(f"import + plant + first calls, empty numba cache (compiles): {cold:.2f} s")
    console.print(f"import + plant + first calls, numba cache filled:           {warm:.2f} s")
    return {"per_call_us": results, "startup_cold_s": cold, "startup_cached_s": warm}


if __name__ == "__main__":
    main()
