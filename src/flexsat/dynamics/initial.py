"""The state at t = 0 of a run: q(0) and q_dot(0) from a scenario's ``initial`` table."""

from __future__ import annotations

from typing import Any

import numpy as np

from flexsat.compiled.linalg3 import euler_rate_matrix_inv
from flexsat.dynamics.plant import Plant
from flexsat.errors import ConfigError

__all__ = ["initial_state"]


def initial_state(plant: Plant, scenario: Any) -> tuple[np.ndarray, np.ndarray]:
    """q(0) and q_dot(0) from the scenario's initial state (degrees converted to radians).

    Below the drivers (:mod:`flexsat.simulate`) so that a loop stage that needs a run's
    initial state (:mod:`flexsat.control.stages.sadm_drive`) reads it without
    importing a driver; :mod:`flexsat.simulate.openloop` exports it too.

    Parameters
    ----------
    plant : Plant
        The satellite.
    scenario : OpenLoopScenario or SlewScenario
        Its ``initial`` table (:class:`flexsat.simulate.scenario.InitialState`).

    Returns
    -------
    q : ndarray, shape (n_dof,)
        Generalized coordinates [m, rad].
    q_dot : ndarray, shape (n_dof,)
        Their rates [m/s, rad/s].

    Raises
    ------
    ConfigError
        If an initial state names an appendage the satellite does not have.
    """
    init = scenario.initial
    q = plant.zeros()
    qd = plant.zeros()
    q[3:6] = np.radians(init.attitude_deg)
    omega_B = np.radians(init.rate_deg_s)
    qd[3:6] = np.array(euler_rate_matrix_inv(q[3], q[4])) @ omega_B  # Theta_dot = S^-1 omega
    configs = {a.name: (a, m) for a, m in zip(plant.config.appendages, plant.models, strict=True)}
    for (config, model), block in zip(configs.values(), plant.layout.blocks, strict=True):
        q[block.slice], qd[block.slice] = model.default_state(config)
    for entry in init.appendages:
        try:
            block = plant.layout.block(entry.name)
        except KeyError as exc:
            raise ConfigError(f"initial.appendages: {exc.args[0]}") from None
        config, model = configs[entry.name]
        try:
            q[block.slice], qd[block.slice] = model.initial_state(config, entry)
        except ValueError as exc:
            raise ConfigError(str(exc)) from None
    names = plant.dof_names()
    for index in plant.locked_coordinates():  # held at q(0): they cannot move
        if qd[index] != 0.0:
            raise ConfigError(
                f"initial.appendages: {names[index]} is locked (locked_dofs): its initial "
                "rate must be 0"
            )
    return q, qd
