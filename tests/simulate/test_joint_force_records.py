"""The records of a slew with a joint actuator carry its forces (docs/model.md, 'Conventions').

The plant steps under the joint actuator's generalized forces Q, held between control
instants; the derived records (omega_dot, tau_flex) must be those of the same forces.
The checks replay the actuator's own compiled step on the recorded states (every
record is a control instant), so the forces they use do not come from the records:
at every record the hub's Euler equation

    J_hub omega_dot + omega x J_hub omega = tau_applied + tau_flex

holds with omega_dot the plant's (q_ddot under the hub torque and the replayed Q),
the recorded omega_dot is that one, and the recorded ``joint_force`` is the replayed Q.
"""

from __future__ import annotations

import numpy as np
import pytest

from flexsat.campaigns.definition import load_campaign, resolve_cases
from flexsat.compiled.linalg3 import euler_rate_bias, euler_rate_matrix
from flexsat.config import nominal
from flexsat.config.models import SatelliteConfig
from flexsat.control.quaternion import target_quaternion
from flexsat.control.stages import JOINT_ACTUATORS
from flexsat.dynamics.appendages.sadm import DRIVE_COORDINATE, with_sadm
from flexsat.dynamics.plant import Plant
from flexsat.simulate import run_slew
from flexsat.simulate.scenario import SlewScenario

_SHORT = {"duration_s": 2.0, "record_dt_s": 1e-3, "control_dt_s": 1e-3}
"""2 s at 1 ms, a record at every control instant (the replay needs each one)."""


def _replay(plant: Plant, scenario: SlewScenario, ds) -> np.ndarray:
    """The joint actuator's Q at each record, from its compiled step on the recorded
    states (its state and Q carried from instant to instant, as the loop does),
    shape (m, n_dof) [N, N m]."""
    n = plant.n_dof
    spec = JOINT_ACTUATORS.get(scenario.joint_actuator.kind)
    params = np.ascontiguousarray(scenario.joint_actuator.packed(scenario, plant), dtype=float)
    state, Q = np.zeros(spec.state_size), np.zeros(n)
    record = np.zeros(len(spec.records))
    q_d = target_quaternion(scenario.target_euler_deg)
    J = np.array(ds.attrs["design_inertia"]).reshape(3, 3)
    out = np.empty((ds.sizes["time"], n))
    q, qd = ds["q"].values, ds["qd"].values
    for k, t in enumerate(ds["time"].values):
        x = np.concatenate([q[k], qd[k], [0.0, 0.0]])
        assert spec.step(x, n, t, scenario.control_dt_s, q_d, J, params, state, Q, record) == 0
        out[k] = Q
    return out


def _errors(plant: Plant, ds, Q_joint: np.ndarray) -> tuple[float, float]:
    """Largest Euler-equation residual and omega_dot error, each over the peak of
    J_hub omega_dot + omega x J_hub omega, with omega_dot the plant's under Q_joint."""
    J = plant.hub_J
    q, qd = ds["q"].values, ds["qd"].values
    tau = ds["tau_applied"].values
    euler = np.empty_like(tau)
    omega_dot = np.empty_like(tau)
    for k in range(q.shape[0]):
        Q = plant.generalized_forces(q[k], tau[k])
        Q[6:] += Q_joint[k, 6:]
        qdd = plant.accelerations(q[k], qd[k], Q)
        S = np.array(euler_rate_matrix(q[k, 3], q[k, 4]))
        omega = S @ qd[k, 3:6]
        omega_dot[k] = S @ qdd[3:6] + np.array(euler_rate_bias(*q[k, 3:5], *qd[k, 3:6]))
        euler[k] = J @ omega_dot[k] + np.cross(omega, J @ omega)
    peak = np.abs(euler).max()
    residual = np.abs(euler - tau - ds["tau_flex"].values).max() / peak
    return residual, np.abs(ds["omega_dot"].values - omega_dot).max() / np.abs(omega_dot).max()


def _check(plant: Plant, scenario: SlewScenario) -> None:
    ds = run_slew(plant, scenario, progress=False).dataset
    Q = _replay(plant, scenario, ds)
    assert np.abs(Q).max() > 0.0
    # The plant stepped under exactly these forces: the same compiled step on the same
    # states, so the recorded ones are equal bit for bit.
    assert np.array_equal(ds["joint_force"].values, Q)
    residual, rate = _errors(plant, ds, Q)
    print(
        f"peak |Q| {np.abs(Q).max():.3g}: Euler residual {residual:.1e}, omega_dot error "
        f"{rate:.1e} of the peak"
    )
    # Both sides come from one state's q_ddot (the hub solve against the joints'
    # wrench): round-off, 1e-10 of the peak leaves four orders of margin.
    assert residual <= 1e-10
    assert rate <= 1e-10


def test_a_driven_array_s_motor_torque_reacts_in_the_records():
    # The thesis plates on drives (0.1 kg m^2 rotors) turned 1 deg at 0.5 deg/s during
    # the 45/45/45 ASMC slew; the PD drive loop of test_sadm_drive, motor torques up
    # to 0.085 N m. The records take the drive's Q, so tau_flex carries the motor's
    # reaction and omega_dot its effect: Euler residual 8.7e-15 of the peak, omega_dot
    # 3.4e-16 (measured); records without Q miss by 9.5e-2 and 6.7e-2.
    plant = Plant.from_config(with_sadm(nominal(), 0.1, 2.0))
    drive = {"kind": "sadm_drive", "coordinates": [DRIVE_COORDINATE], "profile": "to_target",
             "target_deg": 1.0, "rate_deg_s": 0.5, "stiffness_nm_rad": 4.0,
             "damping_nms_rad": 1.0}  # fmt: skip
    _check(plant, SlewScenario.model_validate({**_SHORT, "joint_actuator": drive}))


@pytest.mark.parametrize("locked", [[], ["eta_x", "eta_y", "eta_z"]])
def test_root_dampers_torques_react_in_the_records(locked):
    # Hybrid damping (tests/simulate/test_hybrid_damping.py) on the thesis plates'
    # root rotations, the first deployment-shock case (deformed panels, the dampers at
    # their 0.1 N m authority). The records take its Q, so tau_flex carries the
    # dampers' torques: Euler residual 3.8e-16 of the peak, omega_dot 2.1e-16
    # (measured); records without Q miss by 1.4e-2 both. With the root translations locked
    # tau_flex adds the dampers' torques to the constraint forces.
    case = resolve_cases(load_campaign("deployment-shock"), nominal())[0]
    config = SatelliteConfig.model_validate(case.plant).model_dump(mode="json")
    for appendage in config["appendages"]:
        appendage["locked_dofs"] = locked
    plant = Plant.from_config(SatelliteConfig.model_validate(config))
    damping = {"kind": "rate_feedback", "coordinates": ["eta_rx", "eta_ry", "eta_rz"],
               "gain": 10.0, "limit": 0.1, "bandwidth_hz": 20.0}  # fmt: skip
    scenario = {**case.scenario, **_SHORT, "joint_actuator": damping}
    _check(plant, SlewScenario.model_validate(scenario))
