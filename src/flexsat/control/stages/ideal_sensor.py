"""The thesis's ideal sensor: the true hub attitude and body rate, without error.

q_meas is the quaternion of the ZYX Euler state (R_NB = Rz(psi) Ry(theta) Rx(phi),
eq. 2.25) and omega_meas = S(Theta) Theta_dot (eq. 2.28).
"""

from __future__ import annotations

from typing import Literal

from numba import njit

from flexsat.compiled.linalg3 import euler_rate_matrix, load_seg, mv
from flexsat.control.quaternion import euler_zyx_to_quaternion
from flexsat.control.stages.registry import StageConfig, StageSpec

__all__ = ["IDEAL_SENSOR", "IdealSensorConfig"]


class IdealSensorConfig(StageConfig):
    """The ideal sensor has no parameters.

    Parameters
    ----------
    kind : str
        The stage's registered name, ``"ideal"``.
    """

    kind: Literal["ideal"] = "ideal"


@njit(cache=True)  # compiled with SENSOR_SIGNATURE on first use
def ideal_sensor_step(x, n_dof, t, params, state, q_meas, omega_meas, record):
    """Exact attitude and rate (stage contract in :mod:`flexsat.control.stages.registry`)."""
    q_meas[0], q_meas[1], q_meas[2], q_meas[3] = euler_zyx_to_quaternion(x[3], x[4], x[5])
    omega = mv(euler_rate_matrix(x[3], x[4]), load_seg(x, n_dof + 3))
    omega_meas[0], omega_meas[1], omega_meas[2] = omega
    return 0


IDEAL_SENSOR = StageSpec(
    role="sensor", name="ideal", config=IdealSensorConfig, step=ideal_sensor_step,
    description="true attitude quaternion and body rate (the thesis's)",
    overwrites=("q_meas", "omega_meas"),
)  # fmt: skip
