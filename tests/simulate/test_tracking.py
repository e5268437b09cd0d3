"""Tracked and shaped slews: the laws follow the eigenaxis reference (eq. 4.12), and the
ZVD-shaped slew leaves far less vibration than the thesis's step regulation."""

from __future__ import annotations

import numpy as np
import pytest

from flexsat.control.laws import law_names
from flexsat.control.quaternion import pointing_error, quaternion_product
from flexsat.control.stages.eigenaxis_reference import EigenaxisReferenceConfig
from flexsat.simulate.closedloop import run_slew
from flexsat.simulate.scenario import SlewScenario

DURATION_S = 60.0
MANOEUVRE_S = 37.0  # the step-regulated ASMC slew is inside R1 from 37.0 s (docs/control.md)


def _scenario(reference: dict | None = None, **fields) -> SlewScenario:
    data = {"duration_s": DURATION_S, **fields}
    if reference is not None:
        data["reference"] = reference
    return SlewScenario.model_validate(data)


def residual_elastic_energy(ds, after_s: float) -> float:
    """The largest elastic energy U after ``after_s`` [J]: the residual vibration's level."""
    t = ds["time"].values
    return float(ds["elastic_energy"].values[t >= after_s].max())


def _shaped(nominal_plant, scale: float = 1.0, kind: str = "zvd") -> dict:
    """A polynomial slew whose shaped reference ends at MANOEUVRE_S (equal duration)."""
    shaper = {"kind": kind, "frequency_scale": scale}
    probe = EigenaxisReferenceConfig(profile="polynomial", duration_s=10.0, shaper=shaper)
    length = probe.duration(_scenario(), nominal_plant) - 10.0  # the shaper's own length
    return {"kind": "eigenaxis", "profile": "polynomial", "duration_s": MANOEUVRE_S - length,
            "shaper": shaper}  # fmt: skip


@pytest.fixture(scope="module")
def step_residual(nominal_plant) -> float:
    return residual_elastic_energy(run_slew(nominal_plant, _scenario()).dataset, MANOEUVRE_S)


def test_zvd_shaped_tracking_leaves_ten_times_less_vibration(nominal_plant, step_residual):
    # Acceptance: at equal slew duration (the shaped reference at rest at 37.0 s, when
    # the step-regulated slew enters R1) the ZVD-shaped tracked slew leaves at least
    # 10x less residual elastic energy. Measured: 3.9e-6 J (step) against 1.2e-10 J
    # (ZVD), 3e4x; the margin to 10x absorbs any tuning change.
    ds = run_slew(nominal_plant, _scenario(_shaped(nominal_plant))).dataset
    shaped = residual_elastic_energy(ds, MANOEUVRE_S)
    assert shaped * 10.0 <= step_residual
    # the shaping, not only the smooth profile: the same polynomial unshaped over the
    # same 37 s leaves 1.7e-7 J, more than 10x the shaped slew
    plain = {"kind": "eigenaxis", "profile": "polynomial", "duration_s": MANOEUVRE_S}
    unshaped = residual_elastic_energy(run_slew(nominal_plant, _scenario(plain)).dataset,
                                       MANOEUVRE_S)  # fmt: skip
    assert shaped * 10.0 <= unshaped
    # and the slew is flown: inside R1 (0.05 deg) by the end of the manoeuvre
    assert ds["pointing_error_deg"].values[ds["time"].values >= MANOEUVRE_S].max() < 0.05


@pytest.mark.parametrize("scale", [0.8, 1.2])
def test_shaping_is_robust_to_twenty_percent_frequency_error(nominal_plant, step_residual,
                                                             scale):  # fmt: skip
    # The sensitivity campaign's +-20 % on the joint stiffness moves the frequencies by
    # up to ~+-10 %; a shaper designed 20 % off still leaves >= 10x less than the step
    # (measured: 9e-11 J at 0.8, 4.5e-10 J at 1.2, against 3.9e-6 J).
    ds = run_slew(nominal_plant, _scenario(_shaped(nominal_plant, scale))).dataset
    assert residual_elastic_energy(ds, MANOEUVRE_S) * 10.0 <= step_residual


def tracking_errors_deg(ds, scenario, plant) -> np.ndarray:
    """Angle [deg] between the true attitude and the reference q_d(t) at each record,
    q_d rebuilt from the recorded reference angle about the eigenaxis."""
    packed = scenario.reference.packed(scenario, plant)
    q0, axis = packed[:4], packed[4:7]
    out = []
    for theta, q in zip(ds["reference_angle"].values, ds["quaternion"].values, strict=True):
        q_d = quaternion_product(q0, (np.cos(theta / 2), *(np.sin(theta / 2) * axis)))
        out.append(pointing_error(np.array(q_d), q))
    return np.degrees(out)


@pytest.mark.parametrize("law", law_names())
def test_every_law_tracks_the_reference(nominal_plant, law):
    # Each law flies the tracked 45/45/45 deg slew (trapezoid 2 deg/s, 0.2 deg/s^2,
    # eigenaxis angle 64.76 deg) with the thesis's disturbances at maximum. Measured
    # largest tracking errors: ASMC 0.013, SMC 0.048, ISMC 0.049, STSMC < 1e-4, PD
    # 0.19 deg (PD has no robust term against the 0.85 N m bound); 0.25 deg bounds
    # them all. Tracking excites the panels far less than the step: the peak elastic
    # energy is 10-100x below the same law's step regulation (measured), asserted 3x.
    reference = {"kind": "eigenaxis", "rate_limit_deg_s": 2.0, "acceleration_limit_deg_s2": 0.2}
    tracked = _scenario(reference, controller={"kind": law}, record_dt_s=0.1)
    ds = run_slew(nominal_plant, tracked).dataset
    assert ds.attrs["status"] == "ok"
    assert ds["reference_angle"].values[-1] == pytest.approx(np.radians(64.76), abs=1e-3)
    assert tracking_errors_deg(ds, tracked, nominal_plant).max() < 0.25
    step = run_slew(nominal_plant, _scenario(controller={"kind": law}, record_dt_s=0.1)).dataset
    assert 3.0 * ds["elastic_energy"].values.max() < step["elastic_energy"].values.max()
