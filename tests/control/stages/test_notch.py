"""The notch and roll-off filter stage: its response against the continuous design,
its placement from the modal analysis, and a slew flown through it."""

from __future__ import annotations

import numpy as np
import pytest
from scipy import signal

from flexsat.analysis.modal import modal_analysis
from flexsat.control.stages.notch import Notch, NotchConfig, notch_for_modes
from flexsat.simulate import SlewScenario, run_slew

DT = 1e-3  # control period [s]


def _response(config: NotchConfig, f_hz: np.ndarray) -> np.ndarray:
    H = np.ones(f_hz.size, dtype=complex)
    for b0, b1, b2, a1, a2 in config.sections(DT):
        H *= signal.freqz([b0, b1, b2], [1.0, a1, a2], worN=f_hz, fs=1.0 / DT)[1]
    return H


def test_notch_depth_dc_gain_and_rolloff_match_the_continuous_design():
    config = NotchConfig(notches=(Notch(frequency_hz=0.5, depth_db=20.0, damping=0.3),),
                         rolloff_hz=20.0)  # fmt: skip
    f = np.array([1e-4, 0.5, 20.0])
    H = _response(config, f)
    # Prewarped Tustin: each section exact at its own centre, the others warped
    # there by (w T / 2)^2 / 3 relative in frequency: 1e-6 at 0.5 Hz, 1.3e-3 at 20 Hz
    # (where the notch's response is flat, so its magnitude moves far less). At
    # 1e-4 Hz the gain is 1 to (f / f_c)^2 ~ 4e-8.
    w = 2 * np.pi * f
    notch = ((1j * w) ** 2 + 2 * 0.03 * np.pi * (1j * w) + np.pi**2) / (
        (1j * w) ** 2 + 2 * 0.3 * np.pi * (1j * w) + np.pi**2)  # fmt: skip
    wc = 2 * np.pi * 20.0
    rolloff = wc**2 / ((1j * w) ** 2 + np.sqrt(2) * wc * (1j * w) + wc**2)
    np.testing.assert_allclose(abs(H[0]), 1.0, rtol=1e-6)
    np.testing.assert_allclose(abs(H[1]), abs(notch[1] * rolloff[1]), rtol=1e-6)
    assert 20 * np.log10(abs(H[1])) == pytest.approx(-20.0, abs=1e-5)
    np.testing.assert_allclose(abs(H[2]), abs(notch[2] * rolloff[2]), rtol=1e-3)


def test_notches_sit_on_the_coupled_modes_that_move_the_hub(nominal_plant):
    config = notch_for_modes(nominal_plant, modes=2)
    analysis = modal_analysis(nominal_plant)
    coupled = sorted({round(m.frequency_hz, 9) for m in analysis.modes
                      if m.frequency_hz > 0 and m.hub_dof is not None})  # fmt: skip
    assert [n.frequency_hz for n in config.notches] == pytest.approx(coupled[:2], rel=1e-9)


def test_a_slew_flies_through_the_filter(nominal_plant):
    notch = notch_for_modes(nominal_plant, modes=1, rolloff_hz=5.0)
    scenario = SlewScenario.model_validate({
        "duration_s": 60.0, "controller": {"kind": "pd"},
        "actuator_stages": [notch.model_dump()],
    })  # fmt: skip
    ds = run_slew(nominal_plant, scenario).dataset
    assert ds.attrs["status"] == "ok"
    assert ds.attrs["actuator"] == "notch > static"
    # The PD's 0.3 rad/s bandwidth sits far below the notch: it still converges.
    assert ds["pointing_error_deg"].values[-1] < 0.1 * ds["pointing_error_deg"].values[0]


def test_the_notch_records_its_output_the_filter_of_the_command(nominal_plant):
    # Recorded at every control instant (record_dt_s = control_dt_s = 1 ms), the stage's
    # output is scipy's direct-form filter of the law's command through the same
    # sections from rest, to rounding (1e-12 N m against commands of ~1 N m).
    notch = notch_for_modes(nominal_plant, modes=2, rolloff_hz=5.0)
    scenario = SlewScenario.model_validate({
        "duration_s": 2.0, "record_dt_s": DT, "controller": {"kind": "pd"},
        "actuator_stages": [notch.model_dump()],
    })  # fmt: skip
    ds = run_slew(nominal_plant, scenario).dataset
    output = ds["notch_output"]
    assert output.attrs["units"] == "N m" and output.dims == ("time", "axis")
    sos = np.array([[b0, b1, b2, 1.0, a1, a2] for b0, b1, b2, a1, a2 in notch.sections(DT)])
    expected = signal.sosfilt(sos, ds["tau_cmd"].values, axis=0)
    assert np.abs(expected).max() > 0.1  # the slew's command is not trivial
    np.testing.assert_allclose(output.values, expected, rtol=0.0, atol=1e-12)
