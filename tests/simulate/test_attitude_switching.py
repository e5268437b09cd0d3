"""Runs through hub pitch +-90 deg: no error, no loss of accuracy, conservation.

The hub's ZYX Euler angles are integrated relative to a switching reference frame
(docs/model.md, 'Attitude parametrization'). The strongest check is an independent
formulation of the same motion: the plant has no gravity and every load is a body
torque, so a run seen from an inertial frame rotated by a constant R_0 is the same
motion. Starting at roll 90 deg turns a pitch-axis tumble (through the pole, re-based
every 60 deg) into a yaw-axis one (pitch near 0, never re-based); the two must agree.
"""

from __future__ import annotations

import numpy as np
import pytest
from bench import flexpanels as fp
from scipy.spatial.transform import Rotation

from flexsat.config import validate_config
from flexsat.dynamics.plant import Plant
from flexsat.simulate import OpenLoopScenario, run_openloop
from flexsat.simulate.closedloop import run_slew
from flexsat.simulate.scenario import SlewScenario

# A pitch-axis spin with small transverse body torques (the tracker's example).
_TUMBLE = {
    "duration_s": 60.0,
    "initial": {"rate_deg_s": [0.0, 6.0, 0.0]},
    "torque": [{"start_s": 0.0, "torque_nm": [0.01, 0.0, 0.01]}],
}
_ROLL_90 = Rotation.from_euler("x", 90.0, degrees=True)  # R_0: N' = R_0 N


def _tumble(plant, solver="rk4", roll_deg=0.0):
    settings = {**_TUMBLE, "solver": solver}
    settings["initial"] = {**_TUMBLE["initial"], "attitude_deg": [roll_deg, 0.0, 0.0]}
    return run_openloop(plant, OpenLoopScenario.model_validate(settings)).dataset


@pytest.fixture(scope="module")
def through_the_pole(nominal_plant):
    return _tumble(nominal_plant)


@pytest.fixture(scope="module")
def away_from_the_pole(nominal_plant):
    return _tumble(nominal_plant, roll_deg=90.0)


def _attitudes(ds) -> Rotation:
    q = ds["quaternion"].values
    return Rotation.from_quat(np.column_stack([q[:, 1:], q[:, 0]]))


def test_the_tumble_passes_the_pole(through_the_pole, away_from_the_pole):
    pitch = np.abs(through_the_pole["euler_deg"].values[:, 1])
    assert pitch.max() > 89.5  # at 15 s and 45 s, within the transverse drift
    assert np.abs(away_from_the_pole["euler_deg"].values[:, 1]).max() < 30.0


@pytest.mark.parametrize("solver", ["rk4", "dop853"])
def test_the_energy_balance_stays_at_round_off(nominal_plant, through_the_pole, solver):
    # Switching keeps the balance error at 3.3e-14 J (RK4) and 3.7e-15 J (DOP853) over
    # 120 s (measured: the 0.3 J of energy to a few ulp per step, summed); without it
    # this run reaches 1.6e-10 J and 3.0e-12 J as the steps cross 1/cos(pitch) ~ 1e4.
    # 1e-12 J: 30 times the RK4 figure, 160 times below the unswitched one.
    ds = through_the_pole if solver == "rk4" else _tumble(nominal_plant, solver)
    assert ds.attrs["status"] == "ok"
    assert np.abs(ds["energy_balance_error"].values).max() <= 1e-12


def test_through_the_pole_equals_the_same_motion_away_from_it(through_the_pole, away_from_the_pole):
    # Same motion, inertial frames 90 deg apart: R_N'B = R_0 R_NB, same body rates,
    # same panels, same energies. Both are RK4 at 1 ms on different Euler charts, so
    # their truncation errors differ, by (omega dt)^4 ~ 1e-16 per step on the hub
    # rotation. Measured: 1.1e-13 rad on the attitude; 2e-14 (rate), 3e-14 (energy),
    # 4e-14 (momentum), 5e-13 (root rotations, tips) relative to each quantity's
    # largest value; the stiff root translations eta (4 nm at most) and the joint
    # torque they carry differ by 1.3e-10 and 2.9e-11, the chart-dependent part of
    # RK4's truncation of their ~100 Hz modes (omega dt ~ 0.6). Bounds: 10 times
    # each. The unswitched scheme loses 1.6e-10 J (5e-10 of the energy) at the pole.
    a, b = through_the_pole, away_from_the_pole
    mismatch = (_ROLL_90 * _attitudes(a)).inv() * _attitudes(b)
    assert mismatch.magnitude().max() <= 1e-12
    bounds = {"omega": 1e-12, "total_energy": 1e-12, "rho": 1e-11, "tip_displacement": 1e-11,
              "tau_flex": 1e-9, "eta": 1e-9}  # fmt: skip
    for name, bound in bounds.items():
        ref = a[name].values
        np.testing.assert_allclose(b[name].values, ref, rtol=0, atol=bound * np.abs(ref).max(),
                                   err_msg=name)  # fmt: skip
    H_rotated = _ROLL_90.apply(a["angular_momentum"].values)
    np.testing.assert_allclose(b["angular_momentum"].values, H_rotated, rtol=0,
                               atol=1e-12 * np.abs(H_rotated).max())  # fmt: skip


# -- conservation: 120 s of tumbling through +-90 deg -----------------------------------

# A pitch tumble over both poles. The hub's x axis passes over a pole when
# it is normal to the angular momentum H and H is horizontal: the roll rate -0.18 deg/s
# cancels the body-x component of H that the panels' deflections and rates carry
# (H_B = (0, 4.623, 0.058) N m s), and the roll -0.72 deg turns H_B onto N's y axis.
_FREE_TUMBLE = {
    "duration_s": 120.0, "dt_s": 1e-4, "record_dt_s": 0.01, "torque": [],
    "initial": {
        "attitude_deg": [-0.72, 0.0, 0.0],
        "rate_deg_s": [-0.18, 6.0, 0.03],
        "appendages": [
            {"name": "panel_1", "rho_deg": [0.5, -0.3, 0.8]},
            {"name": "panel_2", "rho_deg": [-0.2, 0.4, 0.1], "rho_rate_deg_s": [0.5, 0, 0]},
        ],
    },
}  # fmt: skip


def test_conservation_through_the_pole(nominal_plant):
    # zeta = 0, no torque: total momentum within 1e-10 and energy within 1e-8 of their
    # initial values. Measured 1.1e-13 and 6.6e-9 at dt = 1e-4 s: the momentum is a
    # linear invariant (round-off only); the energy drift is the RK4 truncation of the
    # ~100 Hz joint modes, (omega dt)^6 / 144 per step, as without a pole.
    undamped = nominal_plant.with_joints(nominal_plant.stiffness, np.zeros((2, 6)))
    ds = run_openloop(undamped, OpenLoopScenario.model_validate(_FREE_TUMBLE)).dataset
    # Over +90 deg and -90 deg: measured within 0.18 deg of +90 at 15 s and 0.26 deg of
    # -90 at 45 s (a record every 0.06 deg of pitch; the later passes miss by more, as
    # the panels' nutation moves H_B), roll and yaw turning by 180 deg across each;
    # re-based at each 60 deg of pitch.
    pitch = ds["euler_deg"].values[:, 1]
    assert pitch.max() > 89.5
    assert pitch.min() < -89.5
    energy = ds["total_energy"].values
    H = ds["angular_momentum"].values
    assert np.abs(energy - energy[0]).max() / energy[0] <= 1e-8
    assert np.abs(H - H[0]).max() / np.linalg.norm(H[0]) <= 1e-10


def test_the_damped_energy_balance_closes_through_the_pole(nominal_plant):
    # With the thesis's damping the dissipated energy (0.05 J of 0.30 J here) is
    # integrated with the motion; the balance closes to 7e-13 J measured, round-off
    # of the 0.3 J summed over 1.2 million steps; bound 1e-11 J.
    ds = run_openloop(nominal_plant, OpenLoopScenario.model_validate(_FREE_TUMBLE)).dataset
    assert ds["dissipated_energy"].values[-1] > 0.01
    assert np.abs(ds["energy_balance_error"].values).max() <= 1e-11


# -- closed loop ------------------------------------------------------------------------


def _slew(plant, target_deg, initial_deg=(0.0, 0.0, 0.0)):
    scenario = SlewScenario(target_euler_deg=target_deg, initial={"attitude_deg": initial_deg})
    return run_slew(plant, scenario).dataset


@pytest.mark.parametrize("target_deg", [(0.0, 120.0, 0.0), (30.0, 90.0, 10.0)])
def test_a_slew_through_the_pole_reaches_its_target(nominal_plant, target_deg):
    # The law's q_d and the sensor stay relative to N: a slew through (or onto) pitch
    # 90 deg ends where the same slew seen from an inertial frame rotated by roll 90
    # deg ends, which never comes near the pole. Both settle to the thesis slew's
    # steady pointing error (disturbances at their maximum: 2.3e-3 deg).
    through = _slew(nominal_plant, target_deg)
    target_away = _ROLL_90 * Rotation.from_euler("ZYX", target_deg[::-1], degrees=True)
    away = _slew(nominal_plant, tuple(target_away.as_euler("ZYX", degrees=True)[::-1]),
                 initial_deg=(90.0, 0.0, 0.0))  # fmt: skip
    assert through.attrs["status"] == "ok"
    assert np.abs(through["euler_deg"].values[:, 1]).max() > 89.9
    assert np.abs(away["euler_deg"].values[:, 1]).max() < 60.0  # never re-based
    error = through["pointing_error_deg"].values
    assert error[-1] < 5e-3
    # Same motion in two frames: the pointing-error histories agree to 1e-8 deg
    # (round-off of the two target quaternions, 1e-16, grown by the loop over 120 s).
    np.testing.assert_allclose(error, away["pointing_error_deg"].values, rtol=0, atol=1e-8)


# -- chains ----------------------------------------------------------------------------


def _chain_tumble(damped: bool, dt_s: float):
    """Basilisk's hinged-panel satellite (4 segments per array) spinning 6 deg/s in
    pitch: the arrays' offset makes it tumble, through pitch 90 deg at about 15 s."""
    config = fp.flexsat_config(4)
    if not damped:
        for array in config["appendages"]:
            for seg in array["segment_list"]:
                seg["joint"]["damping"] = {"ry": 0.0}
    scenario = OpenLoopScenario.model_validate({
        "duration_s": 30.0, "dt_s": dt_s, "record_dt_s": 0.05, "torque": [],
        "initial": {"rate_deg_s": [0.0, 6.0, 0.0]},
    })  # fmt: skip
    return run_openloop(Plant.from_config(validate_config(config)), scenario).dataset


def test_chains_conserve_through_the_pole():
    # c = 0, no torque, dt = 0.5 ms: energy 1.9e-9 and momentum 1.7e-11 of their initial
    # values measured (RK4 truncation of the 600 N m/rad hinge modes; the momentum is
    # not linear in Euler-angle coordinates, so RK4 does not keep it exactly). Bounds:
    # the 1e-8 and 1e-10.
    ds = _chain_tumble(damped=False, dt_s=5e-4)
    assert np.abs(ds["euler_deg"].values[:, 1]).max() > 89.5
    energy, H = ds["total_energy"].values, ds["angular_momentum"].values
    assert np.abs(energy - energy[0]).max() / energy[0] <= 1e-8
    assert np.abs(H - H[0]).max() / np.linalg.norm(H[0]) <= 1e-10


def test_chains_damped_energy_balance_is_truncation_only():
    # With c = 5 N m s/rad the dampers take 9.2 J of 16 J; the balance error is RK4's
    # truncation alone: it falls by 2^4 = 16 when dt halves (measured 15.4; within
    # 15 %), so it closes to round-off as dt -> 0 (2.0e-9 J at 0.5 ms).
    coarse, fine = (np.abs(_chain_tumble(True, dt)["energy_balance_error"].values).max()
                    for dt in (1e-3, 5e-4))  # fmt: skip
    assert coarse / fine == pytest.approx(16.0, rel=0.15)
    assert fine <= 1e-8
