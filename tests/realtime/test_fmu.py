"""The plant as an FMU: built by pythonfmu, stepped by fmpy, against the native open-loop run."""

from __future__ import annotations

import json

import numpy as np
import pytest

from flexsat.config import nominal
from flexsat.dynamics.plant import Plant
from flexsat.realtime.fmu import MODEL_NAME, OpenLoopStepper, export_fmu
from flexsat.simulate import run_openloop
from flexsat.simulate.scenario import OpenLoopScenario
from tests.cli.harness import flexsat

fmpy = pytest.importorskip("fmpy")
from fmpy import extract, read_model_description  # noqa: E402
from fmpy.fmi2 import FMU2Slave  # noqa: E402
from fmpy.validation import validate_fmu  # noqa: E402

STEP_S = 0.01  # communication step: ten RK4 steps of 1 ms
# Two seconds from a tilted, turning start: a torque on all three axes, free, a pitch
# pulse, free. The switches fall half an RK4 step before a communication point, so
# that the native run's torque changes at the very step where the FMU's input does,
# whatever the last bit of t.
SCENARIO = OpenLoopScenario(
    duration_s=2.0, dt_s=1e-3, record_dt_s=STEP_S,
    initial={"attitude_deg": (5.0, -3.0, 10.0), "rate_deg_s": (0.2, 0.0, -0.5)},
    torque=[{"start_s": 0.0, "end_s": 0.4995, "torque_nm": (0.3, -0.2, 1.0)},
            {"start_s": 0.9995, "end_s": 1.4995, "torque_nm": (0.0, 0.5, 0.0)}],
)  # fmt: skip


@pytest.fixture(scope="module")
def plant_fmu(tmp_path_factory):
    return export_fmu(nominal(), tmp_path_factory.mktemp("fmu") / "plant.fmu")


def _instance(path, name="plant"):
    description = read_model_description(str(path))
    slave = FMU2Slave(guid=description.guid, unzipDirectory=extract(str(path)),
                      modelIdentifier=description.coSimulation.modelIdentifier,
                      instanceName=name)  # fmt: skip
    refs = {v.name: v.valueReference for v in description.modelVariables}
    slave.instantiate()
    slave.setupExperiment(startTime=0.0)
    slave.enterInitializationMode()
    return slave, refs


def test_the_model_description_is_valid_fmi_2_with_named_variables_and_units(plant_fmu):
    assert validate_fmu(str(plant_fmu)) == []  # fmpy's checks of the description
    description = read_model_description(str(plant_fmu))
    assert description.fmiVersion == "2.0" and description.coSimulation is not None
    assert description.modelExchange is None
    assert description.coSimulation.modelIdentifier == MODEL_NAME
    variables = {v.name: v for v in description.modelVariables}
    kinds = {name: (v.causality, v.unit) for name, v in variables.items()}
    assert kinds["tau_z"] == ("input", "N.m")
    assert kinds["dt"] == ("parameter", "s") and float(variables["dt"].start) == 1e-3
    assert kinds["initial_pitch"] == ("parameter", "deg")
    assert kinds["initial_rate_x"] == ("parameter", "deg/s")
    assert kinds["q0"] == ("output", "1") and kinds["omega_y"] == ("output", "rad/s")
    assert kinds["yaw"] == ("output", "rad")
    assert kinds["tip.panel_1.z"] == ("output", "m") and kinds["tip.panel_2.x"] == ("output", "m")
    # 3 inputs, 7 parameters, 4 + 3 + 3 + 2 x 3 outputs: nothing else
    assert len(variables) == 3 + 7 + 16
    deg = next(u for u in description.unitDefinitions if u.name == "deg")
    assert deg.baseUnit.rad == 1 and deg.baseUnit.factor == pytest.approx(np.pi / 180, rel=1e-15)


def test_the_fmu_stepped_by_fmpy_reproduces_the_native_open_loop_run(plant_fmu):
    native = run_openloop(Plant.from_config(nominal()), SCENARIO).dataset
    slave, refs = _instance(plant_fmu)
    names = ("initial_roll", "initial_pitch", "initial_yaw")
    slave.setReal([refs[n] for n in names], list(SCENARIO.initial.attitude_deg))
    rates = ("initial_rate_x", "initial_rate_y", "initial_rate_z")
    slave.setReal([refs[n] for n in rates], list(SCENARIO.initial.rate_deg_s))
    slave.exitInitializationMode()
    quaternion = ["q0", "q1", "q2", "q3"]
    omega = ["omega_x", "omega_y", "omega_z"]
    tips = [f"tip.panel_{k}.{a}" for k in (1, 2) for a in "xyz"]
    got = {"quaternion": [], "omega": [], "euler": [], "tip": []}

    def read():
        for key, names in (("quaternion", quaternion), ("omega", omega),
                           ("euler", ["roll", "pitch", "yaw"]), ("tip", tips)):  # fmt: skip
            got[key].append(slave.getReal([refs[n] for n in names]))

    read()
    torque = native["tau_cmd"].values  # the torque held from each record
    for k in range(SCENARIO.n_steps // SCENARIO.record_every):
        slave.setReal([refs["tau_x"], refs["tau_y"], refs["tau_z"]], list(torque[k]))
        slave.doStep(currentCommunicationPoint=k * STEP_S, communicationStepSize=STEP_S)
        read()
    slave.terminate()
    slave.freeInstance()
    expected = {
        "quaternion": native["quaternion"].values,
        "omega": native["omega"].values,
        "euler": np.radians(native["euler_deg"].values),
        "tip": native["tip_displacement"].values.reshape(-1, 6),
    }
    # The same compiled RK4 step on the same float64 torque (the input is the native
    # run's held torque, carried bit for bit through fmi2SetReal), the same re-basing:
    # the states are equal. The outputs are derived by the same build_dataset on one
    # record instead of all of them, where a vectorised sin or cos may round its last
    # bit differently: 4 ulp of each quantity's scale (quaternion 1, rates 1e-2 rad/s,
    # angles 0.2 rad, tips 1e-3 m) bounds round-off; a one-step shift of the torque
    # switch moves the rates by 1e-5 rad/s, the tips by 1e-6 m.
    scale = {"quaternion": 1.0, "omega": 1e-2, "euler": 0.2, "tip": 1e-3}
    for key, values in expected.items():
        error = np.abs(np.array(got[key]) - values).max()
        print(f"{key}: largest difference {error:.3g}")
        assert error <= 4 * np.finfo(float).eps * scale[key], key
    assert np.abs(expected["tip"]).max() > 1e-4  # the panels did bend
    assert np.abs(expected["omega"][-1] - expected["omega"][0]).max() > 1e-3  # and turn


def test_a_step_not_a_multiple_of_dt_is_an_error_and_the_stepper_says_why(plant_fmu):
    slave, refs = _instance(plant_fmu, "odd")
    slave.exitInitializationMode()
    with pytest.raises(Exception, match="fmi2DoStep"):
        slave.doStep(currentCommunicationPoint=0.0, communicationStepSize=0.0015)
    slave.freeInstance()
    stepper = OpenLoopStepper(Plant.from_config(nominal()), 1e-3)
    with pytest.raises(ValueError, match=r"step size 0.0015 s: must be a whole multiple of dt"):
        stepper.step(np.zeros(3), 0.0015)


def test_fmu_export_command_writes_the_fmu(tmp_path, capsys):
    target = tmp_path / "out" / "plant.fmu"
    outcome = flexsat(["fmu", "export", "-o", str(target), "--dt", "0.002", "--json"], capsys)
    assert outcome.code == 0, outcome.stderr
    summary = json.loads(outcome.stdout)
    assert summary["inputs"] == 3 and summary["parameters"] == 7 and summary["outputs"] == 16
    description = read_model_description(str(target))
    dt = next(v for v in description.modelVariables if v.name == "dt")
    assert float(dt.start) == 0.002
