"""Actuator and disturbance model between the command and the plant (compiled).

Order (docs/control.md, 'Torque budget, Λ and saturation order'): tau_cmd is already
clipped to the software limit RF * T_max by the law; the applied torque is
clip_Tmax(G_act tau_cmd + environment + sloshing + residual), with sloshing_i =
ratio * tau_cmd,i * sin(2 pi f t) (proportional to the effort, so it vanishes at rest).

Packed parameters ``dist`` (DIST_SIZE,): actuator gain (3), environment torque (3)
[N m], sloshing ratio [-], sloshing frequency [Hz], residual torque (3) [N m], T_max
[N m].
"""

from __future__ import annotations

from math import pi, sin

from numba import njit

__all__ = ["DIST_SIZE", "applied_torque"]

DIST_SIZE = 12


@njit(cache=True)
def applied_torque(tau_cmd, t, dist):
    """Torque the actuators deliver to the hub, body frame [N m], per axis within T_max."""
    slosh = dist[6] * sin(2.0 * pi * dist[7] * t)
    return (_axis(tau_cmd, dist, slosh, 0), _axis(tau_cmd, dist, slosh, 1),
            _axis(tau_cmd, dist, slosh, 2))  # fmt: skip


@njit(cache=True)
def _axis(tau_cmd, dist, slosh, a):
    value = dist[a] * tau_cmd[a] + dist[3 + a] + slosh * tau_cmd[a] + dist[8 + a]
    return min(dist[11], max(-dist[11], value))
