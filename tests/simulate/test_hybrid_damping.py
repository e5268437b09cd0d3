"""Hybrid active damping solves the thesis's deployment shock (sec. 5.3): with root
actuators on the panels' joint rotations closed by joint-rate feedback beside the
ASMC, R2 holds over the 90-120 s observation window in all 32 cases."""

from __future__ import annotations

import numpy as np
import pytest

from flexsat.analysis.requirements import slew_metrics
from flexsat.campaigns.definition import load_campaign, resolve_cases
from flexsat.config import nominal
from flexsat.config.models import SatelliteConfig
from flexsat.dynamics.plant import Plant
from flexsat.simulate.closedloop import run_slew
from flexsat.simulate.scenario import SlewScenario

# The stated authority (docs/control.md, "Hybrid active damping"): 0.1 N m per root
# rotation, 5 % of the hub's 2 N m wheel torque and 1 % of the elastic root torque of
# the shock's 1 deg deflection on the stiffest axis (462 N m/rad x 0.0175 rad = 8 N m);
# 20 Hz bandwidth, 25x the highest coupled mode shaped (0.8 Hz torsion); gain
# 10 N m s/rad, about 7-150x the joints' own damping.
DAMPING = {"kind": "rate_feedback", "coordinates": ["eta_rx", "eta_ry", "eta_rz"],
           "gain": 10.0, "limit": 0.1, "bandwidth_hz": 20.0}  # fmt: skip
STRAIN_GAUGES = {**DAMPING, "kind": "strain_feedback", "noise_rad": 1e-6,
                 "sensor_bandwidth_hz": 50.0, "seed": 7}  # fmt: skip
"""The same loop on the strain rate of noisy root gauges (docs/control.md, 'Strain
sensing'): 1 microradian of noise through a 50 Hz sensor filter."""
HUB_ONLY_FAILING = ("w++++deform3", "w++-+deform4", "w+-++deform3", "w-+++deform2")
"""Cases where the hub-only ASMC fails R2 over the window (19 of the 32 do, measured)."""


@pytest.fixture(scope="module")
def cases():
    return resolve_cases(load_campaign("deployment-shock"), nominal())


def _fly(case, joint_actuator=None):
    scenario = dict(case.scenario)
    if joint_actuator is not None:
        scenario["joint_actuator"] = joint_actuator
    plant = Plant.from_config(SatelliteConfig.model_validate(case.plant))
    return run_slew(plant, SlewScenario.model_validate(scenario), progress=False).dataset


def _after(ds, name, t0):
    values = ds[name].values
    if values.ndim == 3:  # tip displacement: largest magnitude over the appendages
        values = np.linalg.norm(values, axis=-1).max(axis=1)
    return float(values[ds["time"].values >= t0].max())


def test_hub_only_asmc_fails_r2_after_the_shock(cases):
    by_id = {c.case_id: c for c in cases}
    for case_id in HUB_ONLY_FAILING:
        ds = _fly(by_id[case_id])
        assert not slew_metrics(ds)["r2_pass"], case_id
        # the panels still ring at the window: U > 1e-4 J, tips > 5 mm (measured
        # 1e-3 - 5e-3 J and 1.4-2.4 cm)
        assert _after(ds, "elastic_energy", 90.0) > 1e-4
        assert _after(ds, "tip_displacement", 90.0) > 5e-3


@pytest.mark.parametrize("actuator", [DAMPING, STRAIN_GAUGES], ids=lambda a: a["kind"])
def test_hybrid_damping_meets_r2_in_all_32_cases(cases, actuator):
    # Acceptance: R2 (1e-3 deg/s) over the whole 90-120 s window in every case, R1 and
    # R3 kept, within the authority. Measured: inside R2 from 42-45 s, residual elastic
    # energy at the window 3e-12 - 2e-11 J and tips below 1.2e-6 m (hub-only: 1e-3 J
    # and centimetres); bounds 1e-9 J and 1e-4 m leave two orders of margin. The same
    # with the rates estimated from noisy strain gauges (inside R2 from 42.24-44.99 s).
    assert len(cases) == 32
    for case in cases:
        ds = _fly(case, actuator)
        metrics = slew_metrics(ds)
        assert metrics["r1_pass"] and metrics["r2_pass"] and metrics["r3_pass"], case.case_id
        assert metrics["r2_settling_time_s"] < 60.0
        assert _after(ds, "elastic_energy", 90.0) < 1e-9
        assert _after(ds, "tip_displacement", 90.0) < 1e-4
        assert ds["joint_actuator_effort"].values.max() <= actuator["limit"] * (1 + 1e-12)


def test_hub_law_near_the_target_plus_damping(cases):
    # The thesis's last-phase option: the damping loop engages only within 1 deg of
    # the reference. It meets R2 too (measured inside R2 from 42.3 s, U at 90 s 1e-9 J).
    ds = _fly(cases[2], {**DAMPING, "engage_below_deg": 1.0})
    assert slew_metrics(ds)["r2_pass"]
    t = ds["time"].values
    effort = ds["joint_actuator_effort"].values
    far = ds["pointing_error_deg"].values > 1.5  # far from the target: the loop is off
    assert far.any() and np.all(effort[far & (t > 0.1)] < 1e-6)
