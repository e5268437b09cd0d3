"""The Campbell diagram (flexsat.plots.jitter) draws the sweep it is given."""

from __future__ import annotations

import numpy as np

from flexsat.control.laws.pd import PDConfig
from flexsat.control.stages.wheels import WheelsConfig
from flexsat.linear.jitter import closed_loop, speed_sweep
from flexsat.plots.jitter import plot_campbell

ARCSEC = 180.0 / np.pi * 3600.0


def test_campbell_draws_each_harmonic_its_modes_and_the_worst_speeds(nominal_plant):
    wheels = WheelsConfig.model_validate({"microvibration": {
        "static_imbalance_kg_m": 2e-5, "dynamic_imbalance_kg_m2": 1e-5,
        "radial_force": [{"number": 2.0, "coefficient": 5e-6}],
        "positions_m": [[0.5, 0.5, 0.2], [-0.5, 0.5, 0.2], [-0.5, -0.5, 0.2], [0.5, -0.5, 0.2]],
    }})  # fmt: skip
    sweep = speed_sweep(closed_loop(nominal_plant, PDConfig()), wheels,
                        np.linspace(100.0, 3000.0, 60))  # fmt: skip
    fig = plot_campbell(sweep)
    top, bottom = fig.axes[0], fig.axes[1]
    scatters = top.collections
    assert len(scatters) == sweep.harmonics.size == 2
    for k, points in enumerate(scatters):
        # each point sits on f = h Omega / 60 and is coloured by that line's amplitude
        on_line = sweep.speed_rpm * sweep.harmonics[k] / 60.0
        np.testing.assert_allclose(points.get_offsets()[:, 1], on_line, rtol=1e-12)
        colour = np.maximum(sweep.line_amplitude[:, k] * ARCSEC, points.norm.vmin)
        np.testing.assert_allclose(points.get_array(), colour, rtol=1e-12)
    shown = [m for m in sweep.modes_hz if m <= sweep.line_hz.max() * 1.05]
    assert len(top.get_lines()) == len(shown) + sweep.harmonics.size
    worst = next(line for line in bottom.get_lines() if line.get_label() == "worst speeds")
    np.testing.assert_allclose(worst.get_xdata(), sweep.worst_rpm)
    np.testing.assert_allclose(worst.get_ydata(), sweep.worst_rms * ARCSEC)
