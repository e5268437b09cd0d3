"""The hybrid law: the ASMC slews, a linear controller from a file holds the target.

The ASMC (:mod:`flexsat.control.laws.asmc`) flies the large-angle slew; the first
control instant at which the pointing error is below ``switch_pointing_deg`` and the
body-rate error below ``switch_rate_deg_s``, the discrete state-space controller of
``file`` (:mod:`flexsat.control.laws.statespace`, e.g. the H-infinity design of
``flexsat robust synthesize``) takes over, for good: the switch is latched, so the
loop cannot chatter between the two laws. Bumpless transfer: at that instant the
command is still the ASMC's, tau_s, and the linear controller's state is set to the
least-norm x with C x + D y = tau_s (x = C^+ (tau_s - D y), C^+ the pseudo-inverse,
computed once when the gains are packed), then advanced with this instant's input:
the linear controller starts from the command the ASMC left. One law composing the
two, not a switch stage, because the transfer needs both laws' outputs and the
linear state at the same instant (``docs/control.md``, "The hybrid controller").
"""

from __future__ import annotations

from typing import Literal

import numpy as np
from numba import njit
from pydantic import Field

from flexsat.config.models import Positive
from flexsat.control.laws._sliding import SLIDING_DIAGNOSTICS
from flexsat.control.laws.asmc import ASMCConfig, asmc_step
from flexsat.control.laws.registry import LawSpec
from flexsat.control.laws.statespace import (
    MAX_ORDER,
    ControllerFileConfig,
    controller_input,
    pack_controller,
    ss_output,
    ss_update,
)
from flexsat.control.registry import Channel

__all__ = ["HYBRID", "HybridConfig"]

# packed gains: header, then the ASMC's gains, the controller's (statespace layout),
# then C^+ (n x 3) row-major
_N_ASMC, _THETA_S, _RATE_S, _HEADER = 0, 1, 2, 3
_N_SLIDING = sum(c.size for c in SLIDING_DIAGNOSTICS)
# state: the mode (0 ASMC, 1 linear), the ASMC's 2, x (MAX_ORDER), scratch (MAX_ORDER)
_MODE, _ASMC_STATE, _X = 0, 1, 3


class HybridConfig(ControllerFileConfig):
    """ASMC for the slew, a linear controller near the target (module docstring)."""

    kind: Literal["hybrid"] = Field("hybrid", description="the law's registered name")
    asmc: ASMCConfig = Field(default_factory=ASMCConfig, description="the slewing ASMC")
    switch_pointing_deg: Positive = Field(
        0.5, description="pointing error below which the linear controller takes over [deg]"
    )
    switch_rate_deg_s: Positive = Field(
        0.05, description="body-rate error below which it may take over [deg/s]"
    )

    def gains(self, actuator) -> np.ndarray:
        asmc = self.asmc.gains(actuator)
        k = self.controller
        head = np.array([asmc.size, np.radians(self.switch_pointing_deg),
                         np.radians(self.switch_rate_deg_s)])  # fmt: skip
        ss = pack_controller(k, actuator.t_max_nm, actuator.reduction_factor)
        return np.concatenate([head, asmc, ss, np.linalg.pinv(k.C).ravel()])

    def plot_attributes(self) -> dict[str, float | str]:
        return self.asmc.plot_attributes()


@njit(cache=True)  # compiled with LAW_SIGNATURE on first use
def hybrid_step(q_d, omega_d, omega_dot_d, q, omega_B, J, gains, state, t, dt, tau_cmd, diag):
    """The hybrid command (law contract in :mod:`flexsat.control.laws.registry`)."""
    n_asmc = int(gains[_N_ASMC])
    s0 = _HEADER + n_asmc  # the controller's packed gains: T_max, RF, n, dt, A, B, C, D
    n = int(gains[s0 + 2])
    off = s0 + 4
    d_off = off + n * n + 6 * n + 3 * n
    cp = d_off + 18
    x = state[_X : _X + MAX_ORDER]
    scratch = state[_X + MAX_ORDER :]
    y = controller_input(q_d, omega_d, omega_dot_d, q, omega_B)
    lin = diag[_N_SLIDING : _N_SLIDING + 3]
    status = 0
    if state[_MODE] == 0.0:
        status = asmc_step(q_d, omega_d, omega_dot_d, q, omega_B, J, gains[_HEADER:s0],
                           state[_ASMC_STATE:_X], t, dt, tau_cmd, diag[:_N_SLIDING])  # fmt: skip
        theta = np.sqrt(y[0] ** 2 + y[1] ** 2 + y[2] ** 2)
        rate = np.sqrt(y[3] ** 2 + y[4] ** 2 + y[5] ** 2)
        if theta < gains[_THETA_S] and rate < gains[_RATE_S]:
            # bumpless transfer: x = C^+ (tau_s - D y), so that C x + D y = tau_s
            for i in range(3):
                acc = tau_cmd[i]
                for j in range(6):
                    acc -= gains[d_off + i * 6 + j] * y[j]
                lin[i] = acc  # the residual, reused as scratch
            for i in range(n):
                x[i] = (gains[cp + 3 * i] * lin[0] + gains[cp + 3 * i + 1] * lin[1]
                        + gains[cp + 3 * i + 2] * lin[2])  # fmt: skip
            ss_output(gains, off, n, x, y, lin)  # = tau_s (C full row rank)
            ss_update(gains, off, n, x, y, scratch)
            state[_MODE] = 1.0
        else:
            lin[0] = lin[1] = lin[2] = 0.0  # not running
    else:
        limit = gains[s0 + 1] * gains[s0]
        ss_output(gains, off, n, x, y, lin)
        ss_update(gains, off, n, x, y, scratch)
        for a in range(3):
            tau_cmd[a] = min(limit, max(-limit, lin[a]))
        for c in range(_N_SLIDING):
            diag[c] = 0.0  # the ASMC no longer runs (a NaN would end the run's finite part)
    diag[_N_SLIDING + 3] = state[_MODE]
    return status


HYBRID = LawSpec(
    name="hybrid", label="ASMC+H-inf", config=HybridConfig, step=hybrid_step,
    state_size=_X + 2 * MAX_ORDER,
    diagnostics=(
        *SLIDING_DIAGNOSTICS,
        Channel("tau_linear", "N m", "the linear controller's C x + D y before the clip "
                "(0 before the switch; the ASMC's channels are 0 after it)",
                per_axis=True),
        Channel("linear_mode", "-", "1 once the linear controller holds the target"),
    ),
    description="the ASMC for the slew, a linear controller from a file near the target",
)  # fmt: skip
