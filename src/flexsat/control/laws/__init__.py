"""Control laws: one module each, found through one registry.

Built in: the thesis's ASMC (:mod:`~flexsat.control.laws.asmc`), the classical SMC
and the quaternion PD it is compared with, and the super-twisting and integral
sliding modes the thesis proposes beyond it (:mod:`~flexsat.control.laws.stsmc`,
:mod:`~flexsat.control.laws.ismc`). Write your own law in your own file
(see ``docs/control.md``): a parameter model, a compiled step of
:data:`LAW_SIGNATURE` and one :func:`register_law` line; it then runs inside the
compiled loop, from the scenario TOML and from ``--controller``.
"""

from __future__ import annotations

import numpy as np

from flexsat.control.laws.asmc import ASMC
from flexsat.control.laws.hybrid import HYBRID
from flexsat.control.laws.ismc import ISMC
from flexsat.control.laws.pd import PD
from flexsat.control.laws.registry import (
    LAW_SIGNATURE,
    LAWS,
    LawConfig,
    LawSpec,
    get_law,
    law_names,
    register_law,
    validate_law_config,
)
from flexsat.control.laws.smc import SMC
from flexsat.control.laws.statespace import STATESPACE
from flexsat.control.laws.stsmc import STSMC
from flexsat.control.registry import channel_columns

__all__ = [
    "LAWS",
    "LAW_SIGNATURE",
    "CompiledLaw",
    "LawConfig",
    "LawSpec",
    "get_law",
    "law_names",
    "register_law",
    "validate_law_config",
]

register_law(ASMC, default=True)
register_law(SMC)
register_law(PD)
register_law(STSMC)
register_law(ISMC)
register_law(STATESPACE)
register_law(HYBRID)


class CompiledLaw:
    """A registered law as a plain-Python controller (the ``Controller`` protocol).

    Calls the same compiled step the closed loop runs, so a slew flown through the
    Python-callback path with it reproduces the compiled loop; useful to check a
    custom loop or to wrap a law.

    Parameters
    ----------
    config : LawConfig
        Parameters of any registered law.
    actuator : ActuatorStageConfig
        Gives the software limit RF * T_max.
    J : ndarray, shape (3, 3)
        Design inertia, hub frame B [kg m^2].
    q_d : ndarray, shape (4,)
        Target quaternion, scalar first [-].
    control_dt : float
        Control period [s].
    """

    def __init__(self, config: LawConfig, actuator, J, q_d, control_dt: float) -> None:
        self.spec = get_law(config.kind)
        self.gains = np.ascontiguousarray(config.gains(actuator), dtype=float)
        self.J = np.ascontiguousarray(J, dtype=float)
        self.q_d = np.array(q_d, dtype=float)
        self.omega_d = np.zeros(3)
        self.omega_dot_d = np.zeros(3)
        self.dt = float(control_dt)
        self.state = np.zeros(self.spec.state_size)
        self.diag = np.empty(self.spec.diag_size)

    def __call__(self, t: float, q: np.ndarray, omega_B: np.ndarray) -> np.ndarray:
        tau = np.empty(3)
        self.spec.step(
            self.q_d, self.omega_d, self.omega_dot_d, np.array(q, dtype=float),
            np.array(omega_B, dtype=float), self.J, self.gains, self.state, float(t), self.dt,
            tau, self.diag,
        )  # fmt: skip
        return tau

    def diagnostics(self) -> dict[str, np.ndarray | float]:
        """The last call's diagnostics by name: (3,) arrays per axis, floats otherwise."""
        out: dict[str, np.ndarray | float] = {}
        for channel, columns in channel_columns(self.spec.diagnostics).items():
            values = self.diag[columns]
            out[channel] = values.copy() if values.size > 1 else float(values[0])
        return out
