"""
Your own compiled control law
=============================

A quaternion PID with gyroscopic compensation and a 3-axis integral state, flying
inside flexsat's compiled closed loop. The law is this file: a parameter model, a
compiled step of the law signature and one registration line
(``docs/control.md``, "Contracts: your own law, sensor or actuator"). Once
registered it runs at the speed of a built-in law, from a scenario table
(``[controller] kind = "qpid"``) and from ``--controller qpid``.
"""

# %%
# The parameters and the packed gains
# -----------------------------------
# The law's parameter model is a pydantic model like every built-in law's: it
# validates the ``[controller]`` table and packs the gains the compiled step reads.

import os
from typing import Literal, NamedTuple

import numpy as np
from numba import njit
from pydantic import Field

from flexsat import Plant, nominal
from flexsat.control import Channel, LawConfig, LawSpec, register_law
from flexsat.control.laws import LAW_SIGNATURE
from flexsat.control.quaternion import quaternion_error
from flexsat.plots import plot_pointing
from flexsat.simulate import SlewScenario, run_slew


class PIDGains(NamedTuple):
    """The packed gains, in order (SI)."""

    limit: float  # software torque limit RF * T_max [N m]
    kp: float  # [1/s^2]
    ki: float  # [1/s^3]
    kd: float  # [1/s]
    window: float  # |q_v,e| below which the error is integrated [-]


G = PIDGains(*range(len(PIDGains._fields)))  # index of each gain


class PIDConfig(LawConfig):
    """tau = w x Jw - J (kp q_v,e + ki int q_v,e dt + kd w), clipped to RF * T_max."""

    kind: Literal["qpid"] = "qpid"
    natural_frequency_rad_s: float = Field(0.3, gt=0.0, description="omega_n [rad/s]")
    damping_ratio: float = Field(0.9, gt=0.0)
    ki: float = Field(0.02, ge=0.0, description="integral gain [1/s^3]")
    window_deg: float = Field(2.0, gt=0.0, description="integrate below this error [deg]")

    def gains(self, actuator) -> np.ndarray:
        wn = self.natural_frequency_rad_s
        # q_v,e ~ theta / 2 for small errors: kp = 2 wn^2 gives theta'' = -wn^2 theta.
        return np.array(PIDGains(
            actuator.reduction_factor * actuator.t_max_nm, 2.0 * wn**2, self.ki,
            2.0 * self.damping_ratio * wn, np.sin(np.radians(self.window_deg) / 2.0),
        ))  # fmt: skip


# %%
# The compiled step
# -----------------
# One control instant, with the law signature: it reads the target, the measured
# attitude and rate, the design inertia and the gains, updates its state and
# writes the commanded torque and its diagnostics into arrays the loop owns.


@njit(LAW_SIGNATURE, cache=True)
def pid_step(q_d, omega_d, omega_dot_d, q, omega_B, J, gains, state, t, dt, tau_cmd, diag):
    """One control instant; ``state`` is the integral of q_v,e [s], also the diagnostic."""
    e = quaternion_error(q_d, q)  # q_d^-1 (x) q, shorter rotation (eq. 4.1)
    if e[1] ** 2 + e[2] ** 2 + e[3] ** 2 < gains[G.window] ** 2:  # no wind-up while slewing
        for a in range(3):
            state[a] += e[1 + a] * dt
    u0 = gains[G.kp] * e[1] + gains[G.ki] * state[0] + gains[G.kd] * omega_B[0]
    u1 = gains[G.kp] * e[2] + gains[G.ki] * state[1] + gains[G.kd] * omega_B[1]
    u2 = gains[G.kp] * e[3] + gains[G.ki] * state[2] + gains[G.kd] * omega_B[2]
    w0, w1, w2 = omega_B[0], omega_B[1], omega_B[2]
    Jw0 = J[0, 0] * w0 + J[0, 1] * w1 + J[0, 2] * w2
    Jw1 = J[1, 0] * w0 + J[1, 1] * w1 + J[1, 2] * w2
    Jw2 = J[2, 0] * w0 + J[2, 1] * w1 + J[2, 2] * w2
    tau = (
        w1 * Jw2 - w2 * Jw1 - (J[0, 0] * u0 + J[0, 1] * u1 + J[0, 2] * u2),
        w2 * Jw0 - w0 * Jw2 - (J[1, 0] * u0 + J[1, 1] * u1 + J[1, 2] * u2),
        w0 * Jw1 - w1 * Jw0 - (J[2, 0] * u0 + J[2, 1] * u1 + J[2, 2] * u2),
    )
    limit = gains[G.limit]
    for a in range(3):
        tau_cmd[a] = min(limit, max(-limit, tau[a]))
        diag[a] = state[a]
    return 0


# %%
# One registration line
# ---------------------


QPID = register_law(LawSpec(
    name="qpid", label="QPID", config=PIDConfig, step=pid_step, state_size=3,
    diagnostics=(Channel("pid_integral", "s", "integral of q_v,e", per_axis=True),),
    description="quaternion PID with gyroscopic compensation",
))  # fmt: skip


# %%
# Fly the thesis slew with it
# ---------------------------
# The integral removes the standing error a PD leaves under the constant
# disturbances. The run length can be shortened through
# ``FLEXSAT_EXAMPLE_DURATION_S``.

DURATION_S = float(os.environ.get("FLEXSAT_EXAMPLE_DURATION_S", 120.0))  # [s]

scenario = SlewScenario.model_validate({"duration_s": DURATION_S, "controller": {"kind": "qpid"}})
result = run_slew(Plant.from_config(nominal()), scenario)
metrics = result.metrics()  # the requirements of the stored scenario
for key in ("final_pointing_error_deg", "settling_time_s", "r1_pass", "r2_pass", "r3_pass"):
    print(f"{key:26s} {metrics[key]}")
plot_pointing(result.dataset)
