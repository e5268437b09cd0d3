"""flexsat's chain model against Basilisk on its hinged flexible-panel scenario.

``tests/data/basilisk_flexpanels_N<N>.npz`` hold the hub attitude and rate of
Basilisk's three engines (``nHingedRigidBodyStateEffector``,
``spinningBodyNDOFStateEffector``, MuJoCo) and the hinge angles, over the 8 s window
of Basilisk's flexible-panel dynamics-engine comparison (1 s for N = 32), made by
``bench/basilisk_flexpanels.py`` (Basilisk 2.12.1); the scenario is stated once in
``bench/flexpanels.py``. The test needs no Basilisk.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from bench import flexpanels as fp
from scipy.spatial.transform import Rotation

from flexsat.config import validate_config
from flexsat.dynamics.plant import Plant
from flexsat.simulate import OpenLoopScenario, run_openloop

DATA = Path(__file__).resolve().parents[2] / "data"

# Both are fixed-step RK4 at the same dt on the same equations of motion, but on
# different attitude coordinates (Basilisk MRPs or MuJoCo's quaternion, flexsat ZYX
# Euler angles from a switching frame), so their truncation errors differ, as dt^4:
# measured 5.5e-12 rad (attitude), 2.5e-12 rad/s (rate), 1.7e-13 rad (hinges) at
# N = 1 (dt = 10 ms); 8.0e-13, 3.1e-13, 1.9e-14 at N = 2 (dt = 6.08 ms: the ratio
# 6.9 is (10 / 6.08)^4 = 7.3); round-off, 1e-15 to 1e-14, from N = 4 (dt <= 2.2 ms)
# on, the same against each of the three engines. Bounds: 10 times the N = 1 figures.
TOL_ATTITUDE_RAD = 6e-11
TOL_RATE_RAD_S = 3e-11
TOL_HINGE_RAD = 2e-12


def _flexsat(n: int, data) -> dict:
    dt = float(data["dt"])
    t = data["time"]
    every = round((t[1] - t[0]) / dt)
    scenario = fp.flexsat_scenario(n, duration_s=float(t[-1]), record_every=every)
    plant = Plant.from_config(validate_config(fp.flexsat_config(n)))
    ds = run_openloop(plant, OpenLoopScenario.model_validate(scenario)).dataset
    np.testing.assert_allclose(ds["time"].values, t, rtol=0, atol=1e-9)
    q = ds["quaternion"].values
    return {
        "attitude": Rotation.from_quat(np.column_stack([q[:, 1:], q[:, 0]])),
        "omega": ds["omega"].values,
        "theta": fp.hinge_angles(ds),
    }


@pytest.mark.parametrize("n", fp.SEGMENT_COUNTS)
def test_chains_agree_with_every_basilisk_engine(n):
    data = np.load(DATA / f"basilisk_flexpanels_N{n}.npz")
    ours = _flexsat(n, data)
    engines = [k.removeprefix("sigma_") for k in data.files if k.startswith("sigma_")]
    assert {"nHinged", "spinningBodyNDOF"} <= set(engines)
    worst = {}
    for engine in engines:
        theirs = fp.mrp_rotation(data[f"sigma_{engine}"])
        worst[engine] = (
            float((theirs.inv() * ours["attitude"]).magnitude().max()),
            float(np.abs(data[f"omega_{engine}"] - ours["omega"]).max()),
        )
    hinge = float(np.abs(data["theta"] - ours["theta"]).max())
    print(f"N = {n}: attitude, rate per engine {worst}; hinge angles {hinge:.2e} rad")
    for attitude, rate in worst.values():
        assert attitude <= TOL_ATTITUDE_RAD
        assert rate <= TOL_RATE_RAD_S
    assert hinge <= TOL_HINGE_RAD
    # a comparison with motion in it: the root hinges start at 8 deg and swing
    np.testing.assert_allclose(data["theta"][0, :, 0], np.radians(8.0), rtol=1e-15)
    assert np.ptp(data["theta"][:, :, 0], axis=0).min() > np.radians(8.0)
