"""The environment's record: what the loop's loads were, at the recorded state."""

from __future__ import annotations

import tomllib

import numpy as np
import pytest

from flexsat.config import preset_path, validate_config
from flexsat.dynamics.plant import Plant
from flexsat.environment.loads import environment_loads, ephemeris_row
from flexsat.simulate.closedloop import run_slew
from flexsat.simulate.scenario import SlewScenario
from flexsat.simulate.stage_chain import loop_layout, slew_environment


@pytest.fixture(scope="module")
def orbit_run():
    """20 s of the orbit-nadir template on four wheels with every load model and the
    magnetorquers; the panels' root translations locked (a 50 ms step)."""
    data = tomllib.loads(preset_path("nominal").read_text())
    for app in data["appendages"]:
        app["locked_dofs"] = ["eta_x", "eta_y", "eta_z"]
    plant = Plant.from_config(validate_config(data))
    table = tomllib.loads(preset_path("orbit-nadir").read_text())
    table.update(duration_s=20.0, dt_s=0.05, control_dt_s=0.05, record_dt_s=1.0)
    table["actuator"] = {"kind": "wheels", "motor_time_constant_s": 0.1, "t_max_nm": 0.1}
    table["environment"]["models"]["magnetic"] = {"residual_dipole_a_m2": [0.1, 0.0, 0.0]}
    table["environment"]["magnetorquers"] = {"dipole_max_a_m2": 20.0, "gain_1_s": 2e-3}
    scenario = SlewScenario.model_validate(table)
    result = run_slew(plant, scenario)
    assert result.dataset.attrs["status"] == "ok"
    return plant, scenario, result.dataset


def test_the_recorded_torque_and_dipole_are_the_loads_at_the_recorded_state(orbit_run) -> None:
    """At every record (each an evaluation instant: 1 s is ten 0.1 s periods) the
    environment's kernels, given the recorded time, attitude and wheel momentum, give
    the recorded torque and dipole to round-off (1e-12 relative: the same arithmetic
    on the same inputs, the attitude rebuilt from the recorded quaternion)."""
    from scipy.spatial.transform import Rotation

    plant, scenario, ds = orbit_run
    layout = loop_layout(plant, scenario)
    env = slew_environment(scenario, plant, layout)
    columns = {channel.name: cols for channel, cols in layout.channels()}
    held = np.zeros(layout.record_size)
    torque = ds["environment_torque_B"].values
    dipole = ds["magnetorquer_dipole_B"].values
    assert np.abs(torque).max() > 1e-7  # the loads act (gravity gradient, SRP, field)
    assert np.abs(dipole).max() > 1e-3  # the rods dump the wheels' momentum
    assert np.abs(dipole).max() <= 20.0  # within the rods' limit
    for k, t in enumerate(ds["time"].values):
        if k == 0:
            continue  # t = 0: the record precedes the first evaluation
        ephemeris_row(env.ephemeris, t, env.row)
        q0, q1, q2, q3 = ds["quaternion"].values[k]
        env.C_BN[:] = Rotation.from_quat([q1, q2, q3, q0]).as_matrix().T
        held[columns["wheel_momentum_B"]] = ds["wheel_momentum_B"].values[k]
        assert environment_loads(env, held) == 0
        scale = np.abs(torque[k]).max()
        assert np.allclose(held[columns["environment_torque_B"]], torque[k],
                           rtol=1e-9, atol=1e-9 * scale)  # fmt: skip
        assert np.allclose(held[columns["magnetorquer_dipole_B"]], dipole[k],
                           rtol=1e-9, atol=1e-9 * np.abs(dipole[k]).max())  # fmt: skip


def test_a_run_without_environment_records_none(orbit_run) -> None:
    plant, scenario, _ = orbit_run
    bare = scenario.model_copy(update={"environment": None})
    names = [channel.name for channel, _ in loop_layout(plant, bare).channels()]
    assert "environment_torque_B" not in names and "magnetorquer_dipole_B" not in names
    without_rods = scenario.environment.model_copy(update={"magnetorquers": None})
    plain = scenario.model_copy(update={"environment": without_rods})
    names = [channel.name for channel, _ in loop_layout(plant, plain).channels()]
    assert "environment_torque_B" in names and "magnetorquer_dipole_B" not in names
