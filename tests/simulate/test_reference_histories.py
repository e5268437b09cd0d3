"""The thesis's open-loop run and 45/45/45 deg slew against histories stored before refactoring.

``tests/data/reference_*.npz`` hold every 10th record (0.1 s) of ``run_openloop`` and
``run_slew`` with their defaults on the nominal plant, as flexsat 0.1.0 computed them
before the engine, the laws and the loop became pluggable. Any change to the code
paths that fly the thesis must reproduce them: same model, same arithmetic up to
the order of floating-point operations.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from flexsat.simulate import run_openloop
from flexsat.simulate.closedloop import run_slew

DATA = Path(__file__).resolve().parents[1] / "data"

# Relative to each variable's largest magnitude over the run. 1e-10 allows a
# reordering of floating-point operations (round-off ~1e-16 per step, grown by the
# damped dynamics over 120 000 steps) and nothing that changes the model.
RTOL = 1e-10


def _largest_difference(stored: np.lib.npyio.NpzFile, ds) -> dict[str, float]:
    rows = slice(None, None, 10)
    np.testing.assert_array_equal(ds["time"].values[rows], stored["time"])
    out = {}
    for name in stored.files:
        if name == "time":
            continue
        new = ds[name].values[rows]
        ref = stored[name]
        assert new.shape == ref.shape, name
        scale = np.max(np.abs(ref))
        out[name] = float(np.max(np.abs(new - ref)) / scale) if scale > 0 else 0.0
    return out


@pytest.mark.parametrize(
    ("kind", "run"),
    [("openloop", run_openloop), ("slew", run_slew)],
)
def test_thesis_runs_reproduce_stored_histories(nominal_plant, kind, run):
    stored = np.load(DATA / f"reference_{kind}.npz")
    differences = _largest_difference(stored, run(nominal_plant).dataset)
    worst = max(differences, key=differences.get)
    print(f"{kind}: largest relative difference {differences[worst]:.3e} ({worst})")
    assert differences[worst] <= RTOL, differences
