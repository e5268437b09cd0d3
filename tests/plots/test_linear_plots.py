"""Frequency-domain figures (flexsat.plots.linear): the responses they share."""

from __future__ import annotations

import numpy as np
import pytest

from flexsat.linear.model import LinearModel
from flexsat.plots.linear import FrequencyResponses, frequency_grid_hz


def _two_axis_model() -> LinearModel:
    """Two decoupled damped oscillators, torque to rate and angle, 2 inputs, 4 outputs."""
    A = np.array([[0.0, 1.0, 0.0, 0.0], [-4.0, -0.1, 0.0, 0.0],
                  [0.0, 0.0, 0.0, 1.0], [0.0, 0.0, -9.0, -0.2]])  # fmt: skip
    B = np.array([[0.0, 0.0], [1.0, 0.0], [0.0, 0.0], [0.0, 2.0]])
    return LinearModel(
        A=A, B=B, C=np.eye(4), D=np.zeros((4, 2)), x0=np.zeros(4), u0=np.zeros(2),
        spin=np.zeros(3), state_names=("phi", "omega_x", "theta", "omega_y"),
        input_names=("tau_x", "tau_y"), output_names=("phi", "omega_x", "theta", "omega_y"),
        state_units=("rad", "rad/s", "rad", "rad/s"), input_units=("N m", "N m"),
        output_units=("rad", "rad/s", "rad", "rad/s"), jacobian="analytic",
    )  # fmt: skip


def test_shared_responses_are_those_of_the_selected_model():
    model = _two_axis_model()
    responses = FrequencyResponses()
    outputs, inputs = ["omega_y", "phi"], ["tau_y", "tau_x"]
    expected = model.select(outputs=outputs, inputs=inputs).frequency_response(frequency_grid_hz())
    np.testing.assert_allclose(responses(model, outputs, inputs), expected, rtol=1e-12)
    assert responses(model).shape == (frequency_grid_hz().size, 4, 2)


def _lines(ax, label: str | None = None):
    return [line for line in ax.get_lines() if label is None or line.get_label() == label]


def test_bode_phase_is_one_continuous_branch_for_the_flexible_and_rigid_models():
    from flexsat.config import nominal
    from flexsat.dynamics.plant import Plant
    from flexsat.linear import linearize
    from flexsat.linear.frequency import rigid_model
    from flexsat.plots.linear import plot_bode

    plant = Plant.from_config(nominal())
    flexible, rigid = linearize(plant, outputs=["attitude", "rate"]), rigid_model(plant)
    bounds = {"attitude": (-180.0, 0.0), "rate": (-90.0, 90.0)}
    for output, (low, high) in bounds.items():
        fig = plot_bode(flexible, rigid, output)
        phase_axes = fig.axes[3:6]  # the second row: phase per axis x, y, z
        for ax in phase_axes:
            (flex,), (rig,) = _lines(ax, "flexible"), _lines(ax, "rigid")
            f, p_flex, p_rig = flex.get_xdata(), flex.get_ydata(), rig.get_ydata()
            # The rigid model is a pure integrator chain: exactly -180 deg (attitude) or
            # -90 deg (rate) at every frequency, round-off only.
            np.testing.assert_allclose(p_rig, low if output == "attitude" else -90.0, atol=1e-9)
            # The flexible model starts on the same branch: at 1 mHz, (f / f_1)^2 ~ 2e-5
            # below the first mode, its phase is the rigid one within 0.01 deg.
            assert f[0] == 1e-3 and abs(p_flex[0] - p_rig[0]) < 1e-2
            # Continuous: no jump of 180 deg or more between neighbouring frequencies.
            assert np.abs(np.diff(p_flex)).max() < 180.0
            # Torque and attitude (rate) at the hub are collocated, so the rate response
            # is positive real: its phase stays in [-90, 90] deg, the attitude's in
            # [-180, 0]; the modes' phase swings never leave the band (1e-6 deg: round-off).
            assert p_flex.min() >= low - 1e-6 and p_flex.max() <= high + 1e-6


def test_loop_figure_marks_every_crossover_the_delay_limit_and_the_flexible_peaks():
    from flexsat.config import nominal
    from flexsat.dynamics.plant import Plant
    from flexsat.linear import linearize
    from flexsat.linear.frequency import loop_margins, pd_gains, pd_loop
    from flexsat.plots.linear import plot_loops

    plant = Plant.from_config(nominal())
    model = linearize(plant, outputs=["attitude", "rate"])
    K = pd_gains(plant)
    loops = {axis: pd_loop(model, K, axis) for axis in "xyz"}
    poles = model.poles()
    modes_hz = np.abs(poles[poles.imag > 1e-9]) / (2 * np.pi)
    margins = {axis: loop_margins(loop, modes_hz=modes_hz) for axis, loop in loops.items()}
    fig = plot_loops(loops, margins, np.array([]))
    for a, axis in enumerate("xyz"):
        gain_ax, phase_ax = fig.axes[a], fig.axes[3 + a]
        m = margins[axis]
        marks = [line for line in _lines(gain_ax) if line.get_marker() == "o"]
        dots = [(line.get_xdata()[0], line.get_ydata()[0]) for line in marks
                if line.get_markerfacecolor() != "none"]  # fmt: skip
        assert sorted(x for x, _ in dots) == sorted(c.frequency_hz for c in m.crossovers)
        assert all(y == 1.0 for _, y in dots)
        rings = [line.get_xdata()[0] for line in marks if line.get_markerfacecolor() == "none"]
        assert rings == [m.delay_crossover_hz]
        peaks = [line.get_xdata()[0] for line in _lines(gain_ax) if line.get_marker() == "v"]
        assert peaks == [p.peak_hz for p in m.flexible_peaks]
        labels = [t.get_text() for t in gain_ax.texts]
        for p in m.flexible_peaks:
            assert f"{p.peak_gain_db:+.1f} dB {p.stabilized[0].upper()}" in labels
        # The PD loop at 1 mHz is its rigid part (k_p + k_d s) / s^2, phase
        # -180 deg + atan(2 zeta w / w_n) = -177.84 deg for w_n = 0.3 rad/s, zeta = 0.9
        # (the panels: (f / f_1)^2 ~ 2e-5, 0.01 deg); continuous from there.
        curve = phase_ax.get_lines()[0].get_ydata()
        rigid = -180.0 + np.degrees(np.arctan(2 * 0.9 * 2 * np.pi * 1e-3 / 0.3))
        assert curve[0] == pytest.approx(rigid, abs=1e-2)
        assert np.abs(np.diff(curve)).max() < 180.0
