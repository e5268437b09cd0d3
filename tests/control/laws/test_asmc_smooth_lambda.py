"""The ASMC's smoother Lambda adaptation against eq. 4.27 on the thesis's 45/45/45 slew:
chattering, control energy and settling side by side (docs/control.md,
"A smoother Lambda adaptation")."""

from __future__ import annotations

import numpy as np
import pytest

from flexsat.analysis.requirements import slew_metrics
from flexsat.simulate.closedloop import run_slew
from flexsat.simulate.scenario import SlewScenario


def _figures(ds) -> dict[str, float]:
    t, tau, lam = ds["time"].values, ds["tau_cmd"].values, ds["lambda_act"].values
    power = np.abs((tau * ds["omega"].values).sum(axis=1))
    m = slew_metrics(ds)
    return {
        "torque_variation": float(np.abs(np.diff(tau, axis=0)).sum()),  # chattering [N m]
        "lambda_variation": float(np.abs(np.diff(lam)).sum()),
        "lambda_net": float(lam[-1] - lam[0]),
        "lambda_rate_max": float(np.abs(np.diff(lam) / np.diff(t)).max()),
        "energy": float(np.trapezoid(power, t)),  # int |tau . omega| dt [J]
        "r1": m["settling_time_s"], "r2": m["r2_settling_time_s"],
        "passed": m["r1_pass"] and m["r2_pass"] and m["r3_pass"],
    }  # fmt: skip


@pytest.fixture(scope="module")
def both(nominal_plant):
    out = {}
    for mode in ("thesis", "smooth"):
        scenario = SlewScenario.model_validate({"controller": {"lambda_adaptation": mode}})
        out[mode] = _figures(run_slew(nominal_plant, scenario).dataset)
    return out


def test_smooth_lambda_is_monotone_and_slower_to_change(both):
    thesis, smooth = both["thesis"], both["smooth"]
    # eq. 4.27 with the budget cap moves Lambda back and forth (total variation 5.93
    # rad/s for a net change of 4.8, peak rate 2.1 rad/s^2, measured); the smoothstep
    # through the 2 s filter rises from lambda_min to lambda_max with back-and-forth of
    # 3e-7 rad/s in all (measured; bound 1e-5, against 1.1 rad/s for eq. 4.27) at less
    # than half the peak rate (0.97 rad/s^2 measured).
    assert thesis["lambda_variation"] > 1.2 * thesis["lambda_net"]
    assert smooth["lambda_variation"] == pytest.approx(smooth["lambda_net"], abs=1e-5)
    assert smooth["lambda_net"] == pytest.approx(5.0 - 0.2, abs=1e-4)
    assert smooth["lambda_rate_max"] < 0.6 * thesis["lambda_rate_max"]


def test_smooth_lambda_chatters_less_for_less_energy_and_the_same_settling(both):
    thesis, smooth = both["thesis"], both["smooth"]
    # Measured: torque variation 19.2 -> 14.5 N m (-24 %), control energy 0.552 ->
    # 0.529 J (-4 %), R1 from 37.0 -> 38.4 s, R2 from 45.5 -> 44.4 s. Asserted with
    # margins: less variation by 15 %, less energy, settling within 2 s.
    assert thesis["passed"] and smooth["passed"]
    assert smooth["torque_variation"] < 0.85 * thesis["torque_variation"]
    assert smooth["energy"] < thesis["energy"]
    assert abs(smooth["r1"] - thesis["r1"]) < 2.0 and smooth["r2"] < thesis["r2"] + 2.0
