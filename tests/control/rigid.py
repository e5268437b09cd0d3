"""A rigid-body attitude simulation for law tests: RK4, zero-order-hold command."""

from __future__ import annotations

import numpy as np

from flexsat.control import ActuatorConfig
from flexsat.control.laws import CompiledLaw


def _derivative(x, tau, J):
    q, w = x[:4], x[4:]
    p = np.array([0.0, *w])  # q_dot = q (x) (0, w) / 2, scalar first, body rate
    q_dot = 0.5 * np.array([
        q[0] * p[0] - q[1:] @ p[1:],
        *(q[0] * p[1:] + p[0] * q[1:] + np.cross(q[1:], p[1:])),
    ])  # fmt: skip
    w_dot = np.linalg.solve(J, tau - np.cross(w, J @ w))  # eq. 4.7
    return np.concatenate([q_dot, w_dot])


def fly_rigid(config, J, q_d, q0, omega0, disturbance, duration, dt=1e-3):
    """Fly ``config``'s law on the rigid body J with torque ``disturbance(t)`` [N m].

    Returns ``t`` (n,), ``tau`` (n, 3) and every diagnostic by name, (n, 3) or (n,).
    """
    law = CompiledLaw(config, ActuatorConfig(), J, q_d, dt)
    x = np.concatenate([q0, omega0])
    steps = round(duration / dt)
    out: dict[str, list] = {"t": [], "tau": []}
    for k in range(steps):
        t = k * dt
        tau = law(t, x[:4], x[4:])
        out["t"].append(t)
        out["tau"].append(tau)
        for name, value in law.diagnostics().items():
            out.setdefault(name, []).append(value)

        def f(time, state, tau=tau):
            return _derivative(state, tau + disturbance(time), J)

        k1 = f(t, x)
        k2 = f(t + dt / 2, x + dt / 2 * k1)
        k3 = f(t + dt / 2, x + dt / 2 * k2)
        k4 = f(t + dt, x + dt * k3)
        x = x + dt / 6 * (k1 + 2 * k2 + 2 * k3 + k4)
        x[:4] /= np.linalg.norm(x[:4])
    return {name: np.array(values) for name, values in out.items()}
