"""Reference histories of the hinged flexible-panel scenario from every Basilisk engine.

Runs the scenario of :mod:`bench.flexpanels` (Basilisk's flexible-panel
dynamics-engine comparison) over its 8 s accuracy window for N = 1 ... 32 segments
per array with ``nHingedRigidBodyStateEffector``, ``spinningBodyNDOFStateEffector``
and, if the installed wheel ships it, the MuJoCo back end, and stores per N, decimated
to about ``ROWS`` records (N = 32 over the first ``WINDOW_N32_S`` only: its 84 000
steps of 0.1 ms take spinningBodyNDOF about 40 min on a loaded two-core machine)::

    tests/data/basilisk_flexpanels_N<N>.npz
        time (m,) [s]; dt [s]; bsk_version
        sigma_<engine> (m, 3)  hub MRP sigma_BN
        omega_<engine> (m, 3)  hub rate omega_BN_B [rad/s]
        theta (m, 2, N)        hinge angles [rad] (spinningBodyNDOF; array +x, then -x)

``tests/dynamics/appendages/test_chain_basilisk.py`` holds flexsat against them without
Basilisk. Run ``python bench/basilisk_flexpanels.py [N ...]`` (``pip install -e
'.[bench]'``); it prints the cross-engine agreement.
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))

from bench import flexpanels as fp

DATA = Path(__file__).resolve().parents[1] / "tests" / "data"
ROWS = 200  # records kept per history: a few hundred kB for the six files
WINDOW_N32_S = 1.0


def window(n: int) -> float:
    """The compared window for N segments per array [s]."""
    return WINDOW_N32_S if n >= 32 else fp.WINDOW_S


def principal_angles(sigma_a: np.ndarray, sigma_b: np.ndarray) -> np.ndarray:
    """Principal angle between two MRP histories (m, 3) [rad]."""
    return (fp.mrp_rotation(sigma_a).inv() * fp.mrp_rotation(sigma_b)).magnitude()


def reference(bsk, n: int) -> dict:
    """Run every engine over the window; the decimated histories as arrays."""
    dt = fp.time_step(n)
    out: dict = {"dt": np.array(dt), "bsk_version": np.array(bsk.version)}
    for name, build in fp.engines(bsk).items():
        model = build(bsk, n, dt, True)
        model.sim.ConfigureStopTime(bsk.macros.sec2nano(window(n)))
        model.sim.ExecuteSimulation()
        t = np.asarray(model.recorder.times(), dtype=float) * 1e-9
        every = max(1, t.size // ROWS)
        rows = slice(0, None, every)
        out["time"] = t[rows]
        out[f"sigma_{name}"] = np.array(model.recorder.sigma_BN)[rows]
        out[f"omega_{name}"] = np.array(model.recorder.omega_BN_B)[rows]
        if model.hinges:
            theta = np.array([[np.asarray(r.theta) for r in arr] for arr in model.hinges])
            out["theta"] = np.moveaxis(theta, 2, 0)[rows]  # (m, 2, N)
    return out


def main(counts: tuple[int, ...] = fp.SEGMENT_COUNTS) -> None:
    bsk = fp.import_basilisk()
    names = list(fp.engines(bsk))
    print(f"Basilisk {bsk.version}: engines {', '.join(names)}")
    for n in counts:
        data = reference(bsk, n)
        path = DATA / f"basilisk_flexpanels_N{n}.npz"
        np.savez_compressed(path, **data)
        first = data[f"sigma_{names[0]}"]
        spread = {k: float(principal_angles(first, data[f"sigma_{k}"]).max()) for k in names[1:]}
        print(f"N = {n:2d}  dt = {float(data['dt']):.6g} s  max attitude difference vs "
              f"{names[0]}: " + ", ".join(f"{k} {v:.2e} rad" for k, v in spread.items())
              + f"  ({path.stat().st_size / 1e3:.0f} kB)")  # fmt: skip


if __name__ == "__main__":
    main(tuple(int(a) for a in sys.argv[1:]) or fp.SEGMENT_COUNTS)
