"""Computational delay: the command reaches the next stage whole control periods late.

The law's command computed at instant k is passed on at instant k + D (zero before
the first D instants), held in between (zero-order hold): the loop's transport
delay is D control periods, e^(-s D T) on the loop gain (``docs/control.md``,
'Timing'). A ring buffer of at most :data:`MAX_DELAY_PERIODS` commands.
"""

from __future__ import annotations

from typing import Annotated, Literal

from numba import njit
from pydantic import Field

from flexsat.compiled.linalg3 import copy_into
from flexsat.control.registry import Channel
from flexsat.control.stages.registry import StageConfig, StageSpec

__all__ = ["DELAY", "MAX_DELAY_PERIODS", "DelayConfig"]

MAX_DELAY_PERIODS = 1000
"""Longest delay, in control periods (the stage's state holds that many commands)."""


class DelayConfig(StageConfig):
    """A delay of ``periods`` whole control periods between the law and the actuator."""

    kind: Literal["delay"] = Field("delay", description="the stage's registered name")
    periods: Annotated[int, Field(ge=0, le=MAX_DELAY_PERIODS)] = Field(
        1, description="D, the delay in control periods"
    )

    def check(self, scenario) -> None:
        delay = self.periods * scenario.control_dt_s
        if delay >= scenario.duration_s:
            raise ValueError(
                f"periods: a delay of {self.periods} control periods ({delay:g} s) is not "
                f"shorter than the run (duration_s = {scenario.duration_s:g} s)"
            )

    def packed(self, scenario) -> list[float]:
        return [float(self.periods)]


@njit(cache=True)  # compiled with ACTUATOR_SIGNATURE on first use
def delay_step(tau_cmd, t, dt, params, state, tau_applied, record):
    """tau_applied(k) = tau_cmd(k - D); state: [instants seen, ring of D commands]."""
    periods = int(params[0])
    if periods == 0:
        copy_into(tau_applied, tau_cmd)
        return 0
    k = int(state[0])
    slot = 1 + 3 * (k % periods)
    for a in range(3):
        tau_applied[a] = state[slot + a]  # stored D instants ago (zero at first)
        state[slot + a] = tau_cmd[a]
    state[0] = k + 1
    record[0] = periods * dt
    return 0


DELAY = StageSpec(
    role="actuator", name="delay", config=DelayConfig, step=delay_step,
    state_size=1 + 3 * MAX_DELAY_PERIODS,
    records=(Channel("control_delay", "s", "the computational delay D T"),),
    description="computational delay of whole control periods",
)  # fmt: skip
