"""Frequency-domain figures (flexsat.plots.linear): the responses they share."""

from __future__ import annotations

import numpy as np

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
