"""Exact panel angular velocity (flexsat) against the thesis's small-angle eq. 2.31, in time.

The thesis writes the panel rate as R^T omega + rho_dot; flexsat uses the exact
R^T omega + S(rho) rho_dot (docs/model.md). On the thesis's open-loop run (pure yaw)
the two are the same model: rho_x = rho_y = 0 there, so S(rho) = I exactly. This
test measures the difference where it exists, on a three-axis torque pulse, by
integrating the SymPy small-angle model with the same RK4 (1 ms, zero-order hold).
"""

from __future__ import annotations

import numpy as np
import pytest

from flexsat.dynamics.symbolic import ReferenceParameters, reference_model
from flexsat.simulate import OpenLoopScenario, run_openloop

DURATION_S = 12.0  # the 10 s pulse and 2 s of free ringing
TORQUE = (0.5, 0.5, 1.0)  # [N m], body frame


def _small_angle_run(plant, dt=1e-3, record_every=10):
    params = ReferenceParameters.from_config(
        plant.config, plant.stiffness.reshape(-1, 6), plant.damping.reshape(-1, 6)
    )
    model = reference_model(plant.n_appendages, "small_angle")

    def accelerations(q, qd, torque):
        terms = model.evaluate(params, q, qd)
        Q = plant.generalized_forces(q, torque)
        return np.linalg.solve(terms["M"], Q - terms["h"] - terms["C"] @ qd - terms["k_el"])

    q, qd = plant.zeros(), plant.zeros()
    records = [q.copy()]
    for k in range(round(DURATION_S / dt)):
        torque = TORQUE if k * dt < 10.0 else (0.0, 0.0, 0.0)
        a1 = accelerations(q, qd, torque)
        v2 = qd + 0.5 * dt * a1
        a2 = accelerations(q + 0.5 * dt * qd, v2, torque)
        v3 = qd + 0.5 * dt * a2
        a3 = accelerations(q + 0.5 * dt * v2, v3, torque)
        v4 = qd + dt * a3
        a4 = accelerations(q + dt * v3, v4, torque)
        q = q + dt / 6 * (qd + 2 * v2 + 2 * v3 + v4)
        qd = qd + dt / 6 * (a1 + 2 * a2 + 2 * a3 + a4)
        if (k + 1) % record_every == 0:
            records.append(q.copy())
    return np.array(records)


def test_hub_attitude_is_insensitive_to_the_panel_rate_model(nominal_plant):
    scenario = OpenLoopScenario.model_validate(
        {"duration_s": DURATION_S, "torque": [{"start_s": 0.0, "end_s": 10.0, "torque_nm": TORQUE}]}
    )
    exact = run_openloop(nominal_plant, scenario).dataset["q"].values
    small = _small_angle_run(nominal_plant)
    attitude_diff = np.degrees(np.abs(exact[:, 3:6] - small[:, 3:6]).max())
    slew = np.degrees(np.abs(exact[-1, 3:6]).max())
    # Measured: 1.4e-3 deg after a ~50 deg three-axis slew (3e-5 of it), well
    # below the 0.05 deg pointing requirement R1; bound 5e-3 deg.
    assert slew > 40.0
    assert attitude_diff < 5e-3
    # The torsion root rotation (smallest inertia, J_yy = 1.27 kg m^2) is where the
    # small-angle form departs: measured 0.02 deg of a 0.05 deg peak. Recorded here
    # so a change in either model shows up; flexsat keeps the exact form.
    torsion = [np.degrees(np.abs(r[:, [10, 16]]).max()) for r in (exact, small)]
    torsion_diff = np.degrees(np.abs(exact[:, [10, 16]] - small[:, [10, 16]]).max())
    assert torsion_diff == pytest.approx(0.02, rel=0.3)
    assert torsion[0] == pytest.approx(0.053, rel=0.1)
