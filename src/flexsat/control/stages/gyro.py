"""Rate gyro: scale factor, turn-on bias, bias instability, rate random walk and angle
random walk, sampled at its own rate, each axis its own seeded noise.

At each sample (period Delta, a whole number of control periods; held in between),
a rate-integrating gyro's mean rate over the interval just ended::

    omega_meas = (1 + s) mean(omega_true) + b_0 + b_GM + b_RW + n_ARW

(mean by the trapezoidal rule over the control instants of the interval; the first
sample, at t = 0, is the rate then).
n_ARW is white with std N / sqrt(Delta) (angle random walk N, the Allan deviation
N / sqrt(tau) at short tau). The bias instability B is modelled as a first-order
Gauss-Markov bias b_GM of correlation time T_c: its Allan deviation peaks at
0.6174 sigma_b at tau = 1.89 T_c, and sigma_b = 0.664 B / 0.6174 puts that peak at
0.664 B, the IEEE Std 952 plateau of a flicker bias of instability B: reading the
bias plateau of the Allan deviation the standard way gives B. b_RW is a rate
random walk of density K (Allan deviation K sqrt(tau / 3)).
``docs/control.md``, 'Sensors and estimation'.
"""

from __future__ import annotations

from math import exp, pi, sqrt
from typing import Annotated, Literal

import numpy as np
from numba import njit
from pydantic import Field

from flexsat.config.models import Positive, Vector3
from flexsat.control.registry import Channel
from flexsat.control.stages._sampling import control_periods
from flexsat.control.stages._truth import true_body_rate
from flexsat.control.stages.noise import normal
from flexsat.control.stages.registry import StageConfig, StageSpec

__all__ = ["GYRO", "GyroConfig"]

NonNegative = Annotated[float, Field(ge=0.0, allow_inf_nan=False)]
_DEG_H = pi / 180.0 / 3600.0  # [rad/s per deg/h]
_DEG_RT_H = pi / 180.0 / 60.0  # [rad/sqrt(s) per deg/sqrt(h)]
_GM_PEAK = 0.6174  # max over tau of the Gauss-Markov Allan deviation / sigma_b
_FLICKER_FLOOR = 0.664  # IEEE Std 952: Allan floor of flicker bias = 0.664 B
# packed: every, seed, ARW std per sample, GM sigma, GM phi, RRW std per sample,
# scale factor, turn-on bias (3)
_EVERY, _SEED, _ARW, _GM, _PHI, _RRW, _SF, _B0 = range(8)
# state: instants seen, samples drawn, held rate (3), b_GM (3), b_RW (3), rate sum (3)
_COUNT, _DRAWN, _HELD, _BGM, _BRW, _SUM = 0, 1, 2, 5, 8, 11


class GyroConfig(StageConfig):
    """A three-axis rate gyro (module docstring); replaces the measured body rate."""

    kind: Literal["gyro"] = Field("gyro", description="the stage's registered name")
    sample_dt_s: Positive = Field(0.01, description="Delta, sample period [s]")
    arw_deg_rt_h: NonNegative = Field(0.01, description="angle random walk N [deg/sqrt(h)]")
    bias_instability_deg_h: NonNegative = Field(0.05, description="B [deg/h]")
    bias_correlation_s: Positive = Field(100.0, description="T_c of the bias instability [s]")
    rrw_deg_h_rt_h: NonNegative = Field(0.0, description="rate random walk K [deg/h/sqrt(h)]")
    scale_factor_ppm: Annotated[float, Field(ge=-1e5, le=1e5)] = Field(
        0.0, description="scale-factor error s [ppm]"
    )
    bias_deg_h: Vector3 = Field((0.0, 0.0, 0.0), description="turn-on bias b_0 [deg/h]")
    seed: Annotated[int, Field(ge=0, lt=2**53)] = Field(1, description="noise stream")

    def check(self, scenario) -> None:
        control_periods("sample_dt_s", self.sample_dt_s, scenario)

    def estimator_noise(self) -> dict[str, float]:
        """Rate-noise densities an estimator fed by this gyro assumes [SI]: ARW
        [rad/sqrt(s)] and the bias's random-walk density [rad/s/sqrt(s)], the
        Gauss-Markov bias counted by its driving density sigma_b sqrt(2 / T_c)."""
        sigma_b = _FLICKER_FLOOR * self.bias_instability_deg_h * _DEG_H / _GM_PEAK
        rrw = self.rrw_deg_h_rt_h * _DEG_H / 60.0
        return {"arw": self.arw_deg_rt_h * _DEG_RT_H,
                "rrw": sqrt(rrw**2 + 2.0 * sigma_b**2 / self.bias_correlation_s)}  # fmt: skip

    def packed(self, scenario) -> np.ndarray:
        every = control_periods("sample_dt_s", self.sample_dt_s, scenario)
        delta = every * scenario.control_dt_s
        sigma_b = _FLICKER_FLOOR * self.bias_instability_deg_h * _DEG_H / _GM_PEAK
        return np.array([
            every, self.seed, self.arw_deg_rt_h * _DEG_RT_H / sqrt(delta), sigma_b,
            exp(-delta / self.bias_correlation_s),
            self.rrw_deg_h_rt_h * _DEG_H / 60.0 * sqrt(delta), self.scale_factor_ppm * 1e-6,
            *(np.array(self.bias_deg_h) * _DEG_H),
        ])  # fmt: skip


@njit(cache=True)  # compiled with SENSOR_SIGNATURE on first use
def gyro_step(x, n_dof, t, params, state, q_meas, omega_meas, record):
    """A new sample every ``every`` control instants, held in between."""
    p, s = params, state
    w = true_body_rate(x, n_dof)
    if int(s[_COUNT]) % int(p[_EVERY]) == 0:
        first = s[_DRAWN] == 0.0
        for a in range(3):
            mean = w[a] if first else (s[_SUM + a] + 0.5 * w[a]) / p[_EVERY]
            s[_SUM + a] = 0.5 * w[a]
            base = 9.0 * s[_DRAWN] + 3.0 * a  # three draws per axis and sample
            if first:  # the Gauss-Markov bias starts in its stationary distribution
                s[_BGM + a] = p[_GM] * normal(p[_SEED], base)
            else:
                drive = p[_GM] * sqrt(1.0 - p[_PHI] ** 2)
                s[_BGM + a] = p[_PHI] * s[_BGM + a] + drive * normal(p[_SEED], base)
                s[_BRW + a] += p[_RRW] * normal(p[_SEED], base + 1.0)
            bias = p[_B0 + a] + s[_BGM + a] + s[_BRW + a]
            s[_HELD + a] = ((1.0 + p[_SF]) * mean + bias
                            + p[_ARW] * normal(p[_SEED], base + 2.0))  # fmt: skip
        s[_DRAWN] += 1.0
    else:
        for a in range(3):
            s[_SUM + a] += w[a]
    s[_COUNT] += 1.0
    for a in range(3):
        omega_meas[a] = s[_HELD + a]
        record[a] = p[_B0 + a] + s[_BGM + a] + s[_BRW + a]
    return 0


GYRO = StageSpec(
    role="sensor", name="gyro", config=GyroConfig, step=gyro_step, state_size=14,
    records=(Channel("gyro_bias", "rad/s", "b_0 + b_GM + b_RW, the true gyro bias",
                     per_axis=True),),
    description="rate gyro: ARW, bias instability, rate random walk, scale factor",
    overwrites=("omega_meas",), leaves=("q_meas",),
)  # fmt: skip
