"""The true hub attitude and body rate read from the plant state, for the stages.

One place that knows how the plant state holds the hub's attitude: the ZYX Euler
angles Theta at q[3:6] and their rates at q_dot[3:6] (eqs. 2.25, 2.28).
"""

from __future__ import annotations

from numba import njit

from flexsat.compiled.linalg3 import euler_rate_matrix, load_seg, mv
from flexsat.control.quaternion import euler_zyx_to_quaternion

__all__ = ["true_attitude", "true_body_rate"]


@njit(cache=True, inline="always")
def true_attitude(x, n_dof):
    """q_NB, scalar first (4-tuple), of the plant state ``x``."""
    return euler_zyx_to_quaternion(x[3], x[4], x[5])


@njit(cache=True, inline="always")
def true_body_rate(x, n_dof):
    """omega_BN_B = S(Theta) Theta_dot (eq. 2.28), 3-tuple [rad/s]."""
    return mv(euler_rate_matrix(x[3], x[4]), load_seg(x, n_dof + 3))
