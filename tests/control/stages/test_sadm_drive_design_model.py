"""The solar-array drive's ``design_model``: the law's rigid design inertia at the
drives' initial angles (default) or following the measured angles.

"measured" writes J_design = J_design,0 + sum_j [J_j(beta_j) - J_j(beta_j,0)], J_j a
degree-2 trigonometric polynomial fitted exactly from five samples of the rigid
model (``flexsat.control.stages.sadm_drive`` module docstring).
"""

from __future__ import annotations

import numpy as np
import pytest

from flexsat.analysis.requirements import slew_metrics
from flexsat.config import nominal
from flexsat.control.stages import JOINT_ACTUATORS
from flexsat.control.stages.sadm_drive import SADMDriveConfig
from flexsat.dynamics.appendages.sadm import DRIVE_COORDINATE, with_sadm
from flexsat.dynamics.plant import Plant
from flexsat.dynamics.rigid import design_coordinates, rigid_inertia
from flexsat.errors import ConfigError
from flexsat.simulate.closedloop import (
    _compiled_loop,
    finish_slew,
    prepare_slew,
    slew_design_inertia,
)
from flexsat.simulate.openloop import initial_state
from flexsat.simulate.scenario import SlewScenario

STEP = JOINT_ACTUATORS.get("sadm_drive").step
START_DEG = (-40.0, 20.0)  # the two drives' initial angles (sadm_angle_deg)
_DRIVE = {"coordinates": [DRIVE_COORDINATE], "stiffness_nm_rad": 4.0, "damping_nms_rad": 1.0,
          "rate_deg_s": 0.06}  # fmt: skip


@pytest.fixture(scope="module")
def driven() -> Plant:
    """The nominal satellite, its plates on a drive started at START_DEG."""
    base = nominal()
    plates = [a.model_copy(update={"sadm_angle_deg": s})
              for a, s in zip(base.appendages, START_DEG, strict=True)]  # fmt: skip
    config = base.model_copy(update={"appendages": plates})
    return Plant.from_config(with_sadm(config, 0.1, 2.0))


def _drives(plant: Plant) -> list[int]:
    return [plant.layout.dof_names().index(f"panel_{k}.{DRIVE_COORDINATE}") for k in (1, 2)]


def _direct(plant: Plant, q0: np.ndarray, angles) -> np.ndarray:
    """J_tot of the rigid model recomputed directly with the drives at ``angles`` [rad]."""
    q = design_coordinates(plant, q0)
    q[_drives(plant)] = angles
    return rigid_inertia(plant, q)


def test_the_initial_design_model_freezes_the_drives_where_they_start(driven):
    # A drive has no rest angle: the rigid model holds it at its initial one (here
    # -40 and 20 deg), the elastic joints undeformed. Same arithmetic: exact.
    scenario = SlewScenario()
    q0 = initial_state(driven, scenario)[0]
    assert np.degrees(q0[_drives(driven)]) == pytest.approx(START_DEG, rel=1e-14)
    J0 = slew_design_inertia(driven, scenario)
    assert np.array_equal(J0, _direct(driven, q0, q0[_drives(driven)]))
    assert not np.allclose(J0, rigid_inertia(driven), rtol=1e-6)  # q = 0: not where they start


def test_the_followed_design_inertia_is_the_rigid_model_at_the_measured_angles(driven):
    # 25 random pairs of angles within the joints' +-90 deg: the compiled step's
    # J_design equals J_tot recomputed directly by the rigid model. Tolerance 1e-12
    # of the largest entry (~190 kg m^2): the polynomial is exact, what remains is
    # the round-off of the 5x5 solve (well conditioned: five equally spaced angles)
    # and of summing ~10 terms of up to ~100 kg m^2, ~1e-14 relative.
    scenario = SlewScenario()
    config = SADMDriveConfig(**_DRIVE, design_model="measured")
    params = np.ascontiguousarray(config.packed(scenario, driven))
    q0 = initial_state(driven, scenario)[0]
    J0 = slew_design_inertia(driven, scenario)
    n, drives = driven.n_dof, _drives(driven)
    rng = np.random.default_rng(7)
    state, Q, record = np.zeros(10), np.zeros(n), np.zeros(4)
    for angles in rng.uniform(-np.radians(89.0), np.radians(89.0), size=(25, 2)):
        x = np.zeros(2 * n + 2)
        x[drives] = angles
        J = J0.copy()  # the loop's J_design holds the previous instant's: overwritten
        assert STEP(x, n, 1.0, 1e-3, np.array([1.0, 0, 0, 0]), J, params, state, Q, record) == 0
        direct = _direct(driven, q0, angles)
        scale = np.abs(direct).max()
        assert np.abs(J - direct).max() <= 1e-12 * scale
        assert record[3] == pytest.approx(np.abs(direct - J0).max(), rel=1e-9, abs=1e-12 * scale)
    assert np.array_equal(state[:9], J0.ravel())  # J_design,0 captured at the first call


def test_measured_needs_rotations_each_of_its_own_appendage(driven):
    bad = [
        (["eta_x_1"], "'measured' follows rotation angles only"),
        (["panel_1.eta_ry_0", "panel_1.eta_ry_1"], "one driven coordinate per appendage"),
    ]
    for coordinates, fragment in bad:
        config = SADMDriveConfig(**{**_DRIVE, "coordinates": coordinates}, design_model="measured")
        with pytest.raises(ConfigError, match=f"joint_actuator.design_model: .*{fragment}"):
            config.packed(SlewScenario(), driven)


def _slew(plant: Plant, design_model: str):
    """The thesis slew while both arrays turn 90 deg (to_target at 1.5 deg/s): the drive
    loop at 0.5 Hz, critically damped on rotor + array."""
    inertia = 0.1 + nominal().appendages[0].centroidal_inertia()[1, 1]
    omega_n = 2.0 * np.pi * 0.5
    drive = {**_DRIVE, "kind": "sadm_drive", "profile": "to_target", "target_deg": 50.0,
             "rate_deg_s": 1.5, "stiffness_nm_rad": inertia * omega_n**2,
             "damping_nms_rad": 2.0 * omega_n * inertia, "design_model": design_model}  # fmt: skip
    scenario = SlewScenario.model_validate({"duration_s": 120.0, "joint_actuator": drive})
    run = prepare_slew(plant, scenario)
    status, done, rows = _compiled_loop(run, None, None)
    return run, finish_slew(run, status, done, rows, 0.0).dataset


@pytest.fixture(scope="module")
def slews(driven):
    return {model: _slew(driven, model) for model in ("initial", "measured")}


def test_a_measured_slew_flies_the_rigid_model_at_the_recorded_angles(driven, slews):
    run, ds = slews["measured"]
    assert ds.attrs["status"] == "ok"
    q0 = initial_state(driven, run.scenario)[0]
    drives = [f"panel_{k}.{DRIVE_COORDINATE}" for k in (1, 2)]
    angles = np.column_stack([ds["q"].sel(dof=d).values for d in drives])
    # the first array turned from -40 to 50 deg: 90 deg
    assert np.degrees(angles[-1]) == pytest.approx([50.0, 50.0], abs=1e-3)
    J0 = np.array(ds.attrs["design_inertia"]).reshape(3, 3)
    assert np.array_equal(J0, slew_design_inertia(driven, run.scenario))  # the run's initial
    # Recorded change = max |J_tot(recorded angles) - J0| (control and record at the
    # same instants); 1e-12 of J_tot's largest entry, as the polynomial test.
    changes = ds["design_inertia_change"].values
    scale = np.abs(J0).max()
    for row in range(0, len(changes), 50):
        expected = np.abs(_direct(driven, q0, angles[row]) - J0).max()
        assert abs(changes[row] - expected) <= 1e-12 * scale
    assert changes[-1] > 0.1  # kg m^2: the arrays turned about their span, W^2 m / 12 ~ 1.3
    # The loop's J_design at the end is the rigid model at the final angles.
    final = _direct(driven, q0, run.x[[driven.layout.dof_names().index(d) for d in drives]])
    assert np.abs(run.data.J_design - final).max() <= 1e-12 * scale
    assert np.all(slews["initial"][1]["design_inertia_change"].values == 0.0)


def test_initial_and_measured_pointing(slews):
    # Both settle; printed for the record (the arrays turn about their span axis: the
    # design inertia moves by ~1 % of its entries, the pointing barely).
    metrics = {model: slew_metrics(ds) for model, (_, ds) in slews.items()}
    for model, (_, ds) in slews.items():
        error = ds["pointing_error_deg"].values
        print(model, f"final {error[-1]:.6g} deg, max over the last 20 s "
              f"{error[ds['time'].values >= 100.0].max():.6g} deg", {
                  k: metrics[model][k] for k in sorted(metrics[model])
                  if isinstance(metrics[model][k], float)})  # fmt: skip
        assert error[-1] < 0.1
