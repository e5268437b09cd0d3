"""No joint actuator: the appendages' coordinates receive no applied force (the thesis's)."""

from __future__ import annotations

from typing import Literal

from numba import njit

from flexsat.control.stages.registry import (
    JointActuatorConfig,
    StageSpec,
)

__all__ = ["NO_JOINT_ACTUATOR", "NoJointActuatorConfig"]


class NoJointActuatorConfig(JointActuatorConfig):
    """Hub-only control: no parameters.

    Parameters
    ----------
    kind : str
        The stage's registered name, ``"none"``.
    """

    kind: Literal["none"] = "none"


@njit(cache=True)  # compiled with JOINT_ACTUATOR_SIGNATURE on first use
def no_joint_actuator_step(x, n_dof, t, dt, q_d, J_design, params, state, Q, record):
    """Leaves Q[6:] at zero and J_design as it is (contract in ``stages.registry``)."""
    return 0


NO_JOINT_ACTUATOR = StageSpec(
    role="joint_actuator", name="none", config=NoJointActuatorConfig,
    step=no_joint_actuator_step, description="no actuator on the appendages (hub-only control)",
)  # fmt: skip
