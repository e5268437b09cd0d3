"""Star tracker: the true attitude seen through a small random rotation per axis,
sampled at its own rate, delivered after its latency.

A sample taken at t_k is q_meas = q_true(t_k) (x) [1, dtheta / 2] (normalized),
dtheta ~ N(0, diag(sigma_x^2, sigma_y^2, sigma_z^2)) in the hub frame (the
tracker's boresight noise is typically several times its cross-boresight noise),
and reaches the loop at t_k + latency; the output is held until the next one. The
sample at t = 0 is delivered at once (a fix acquired before the run).
``docs/control.md``, 'Sensors and estimation'.
"""

from __future__ import annotations

from math import pi, sqrt
from typing import Annotated, Literal

import numpy as np
from numba import njit
from pydantic import Field

from flexsat.config.models import Positive
from flexsat.control.registry import Channel
from flexsat.control.stages._sampling import control_periods
from flexsat.control.stages._truth import true_attitude
from flexsat.control.stages.noise import normal
from flexsat.control.stages.registry import StageConfig, StageSpec

__all__ = ["STAR_TRACKER", "StarTrackerConfig"]

_ARCSEC = pi / 180.0 / 3600.0  # [rad per arcsec]
NonNegative = Annotated[float, Field(ge=0.0, allow_inf_nan=False)]
_EVERY, _SEED, _LAT, _SIGMA = 0, 1, 2, 3  # packed: every, seed, latency periods, sigma (3)
# state: instants seen, samples drawn, held quaternion (4), pending quaternion (4),
# instant the pending sample is delivered at (-1: none)
_COUNT, _DRAWN, _HELD, _PENDING, _DUE = 0, 1, 2, 6, 10


class StarTrackerConfig(StageConfig):
    """A star tracker (module docstring); replaces the measured attitude."""

    kind: Literal["star_tracker"] = Field("star_tracker", description="the stage's registered name")
    sample_dt_s: Positive = Field(0.1, description="sample period [s]")
    noise_arcsec: tuple[NonNegative, NonNegative, NonNegative] = Field(
        (5.0, 5.0, 30.0), description="1-sigma noise about body x, y, z [arcsec]"
    )
    latency_s: NonNegative = Field(0.0, description="delivery delay of each sample [s]")
    seed: Annotated[int, Field(ge=0, lt=2**53)] = Field(2, description="noise stream")

    def check(self, scenario) -> None:
        control_periods("sample_dt_s", self.sample_dt_s, scenario)
        if control_periods("latency_s", self.latency_s, scenario, allow_zero=True) * (
            scenario.control_dt_s) >= self.sample_dt_s - 1e-12:  # fmt: skip
            raise ValueError(f"latency_s must be shorter than sample_dt_s "
                             f"({self.sample_dt_s:g} s), got {self.latency_s:g} s")  # fmt: skip

    def estimator_noise(self) -> dict[str, tuple[float, float, float]]:
        """The attitude noise an estimator fed by this tracker assumes [rad], per axis."""
        return {"star_tracker": tuple(float(s) * _ARCSEC for s in self.noise_arcsec)}

    def packed(self, scenario) -> np.ndarray:
        every = control_periods("sample_dt_s", self.sample_dt_s, scenario)
        latency = control_periods("latency_s", self.latency_s, scenario, allow_zero=True)
        return np.array([every, self.seed, latency, *(np.array(self.noise_arcsec) * _ARCSEC)])


@njit(cache=True)  # compiled with SENSOR_SIGNATURE on first use
def star_tracker_step(x, n_dof, t, params, state, q_meas, omega_meas, record):
    """Sample every ``every`` instants, deliver ``latency`` instants later, hold."""
    p, s = params, state
    count = s[_COUNT]
    if int(count) % int(p[_EVERY]) == 0:
        q = true_attitude(x, n_dof)
        base = 3.0 * s[_DRAWN]
        d0 = 0.5 * p[_SIGMA] * normal(p[_SEED], base)
        d1 = 0.5 * p[_SIGMA + 1] * normal(p[_SEED], base + 1.0)
        d2 = 0.5 * p[_SIGMA + 2] * normal(p[_SEED], base + 2.0)
        # q (x) [1, d]: the error rotation in the hub frame
        w = q[0] - q[1] * d0 - q[2] * d1 - q[3] * d2
        v0 = q[0] * d0 + q[1] + q[2] * d2 - q[3] * d1
        v1 = q[0] * d1 - q[1] * d2 + q[2] + q[3] * d0
        v2 = q[0] * d2 + q[1] * d1 - q[2] * d0 + q[3]
        norm = sqrt(w * w + v0 * v0 + v1 * v1 + v2 * v2)
        s[_PENDING], s[_PENDING + 1], s[_PENDING + 2], s[_PENDING + 3] = (
            w / norm, v0 / norm, v1 / norm, v2 / norm)  # fmt: skip
        s[_DUE] = count if s[_DRAWN] == 0.0 else count + p[_LAT]
        s[_DRAWN] += 1.0
    if s[_DUE] == count:
        for j in range(4):
            s[_HELD + j] = s[_PENDING + j]
        record[0], record[1], record[2] = 2.0 * d0, 2.0 * d1, 2.0 * d2
    s[_COUNT] = count + 1.0
    for j in range(4):
        q_meas[j] = s[_HELD + j]
    return 0


STAR_TRACKER = StageSpec(
    role="sensor", name="star_tracker", config=StarTrackerConfig, step=star_tracker_step,
    state_size=11,
    records=(Channel("star_tracker_noise", "rad", "dtheta of the last sample, hub frame",
                     per_axis=True),),
    description="star tracker: per-axis arcsec noise, own rate, latency",
    overwrites=("q_meas",), leaves=("omega_meas",),
)  # fmt: skip
