"""The plain-Python controller example runs and flies the slew."""

from __future__ import annotations

import importlib.util
from pathlib import Path

EXAMPLE = Path(__file__).resolve().parents[2] / "examples" / "python_controller.py"


def _load():
    spec = importlib.util.spec_from_file_location("python_controller", EXAMPLE)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_python_pid_flies_the_slew():
    # 120 s at 10 ms control: the PID's integral removes the PD's standing error
    # under the constant disturbances; R1 and R3 hold.
    metrics = _load().run(duration_s=120.0)
    assert metrics["controller"] == "python"
    assert metrics["r3_pass"]
    assert metrics["final_pointing_error_deg"] < 0.05


def test_python_controller_matches_compiled_pd(nominal_plant):
    # The same PD law written in Python and run through the Python path gives the
    # compiled PD's trajectory (both sample at 10 ms): equal to round-off.
    import numpy as np

    from flexsat.control.quaternion import quaternion_error
    from flexsat.simulate import SlewScenario, design_inertia, run_slew

    scenario = SlewScenario.model_validate(
        {"duration_s": 5.0, "control_dt_s": 0.01, "controller": {"kind": "pd"}}
    )
    kp, kd = scenario.controller.gains(scenario.actuator)[2:4]
    J = design_inertia()
    q_d = tuple(_load().target_quaternion(scenario.target_euler_deg))

    def pd(t, q, omega):
        e = np.array(quaternion_error(q_d, tuple(q)))
        return np.cross(omega, J @ omega) - J @ (kp * e[1:] + kd * omega)

    compiled = run_slew(nominal_plant, scenario).dataset
    python = run_slew(nominal_plant, scenario, controller=pd).dataset
    np.testing.assert_allclose(python["q"].values, compiled["q"].values, rtol=0, atol=1e-12)
    np.testing.assert_allclose(
        python["pointing_error_deg"].values, compiled["pointing_error_deg"].values, atol=1e-9
    )
