"""Notch and roll-off filter on the commanded torque, designed from the modal analysis.

Per body axis, a cascade of at most :data:`MAX_SECTIONS` second-order sections
(direct form II transposed), each the bilinear transform, prewarped at its centre
frequency, of (``docs/control.md``, 'Notch and roll-off filter')::

    notch:     H(s) = (s^2 + 2 zeta_z w s + w^2) / (s^2 + 2 zeta_p w s + w^2)
               zeta_z = zeta_p 10^(-depth_db / 20): |H(i w)| = zeta_z / zeta_p
    roll-off:  H(s) = w^2 / (s^2 + sqrt(2) w s + w^2)       (2nd-order Butterworth)

unity gain at zero frequency. :func:`notch_for_modes` puts the notches on the
coupled flexible modes of a plant that move the hub (the modal analysis's modes
with a hub participation), lowest first.
"""

from __future__ import annotations

from math import pi, sqrt, tan
from typing import Annotated, Literal

import numpy as np
from numba import njit
from pydantic import Field, model_validator

from flexsat.config.models import Positive, _Frozen
from flexsat.control.registry import Channel
from flexsat.control.stages.registry import StageConfig, StageSpec

__all__ = ["MAX_SECTIONS", "NOTCH", "Notch", "NotchConfig", "notch_for_modes"]

MAX_SECTIONS = 4
"""Most second-order sections of one filter (notches plus the roll-off)."""


class Notch(_Frozen):
    """One notch: centre, depth and width (the poles' damping ratio).

    Parameters
    ----------
    frequency_hz : float
        Centre frequency [Hz].
    depth_db : float
        Attenuation at the centre, 0 < depth <= 80 [dB].
    damping : float
        zeta_p, the poles' damping ratio: the notch's width [-].
    """

    frequency_hz: Positive
    depth_db: Annotated[float, Field(gt=0.0, le=80.0)] = 20.0
    damping: Annotated[float, Field(gt=0.0, le=1.0)] = 0.3


class NotchConfig(StageConfig):
    """Notches and an optional roll-off on each axis of the commanded torque."""

    kind: Literal["notch"] = Field("notch", description="the stage's registered name")
    notches: tuple[Notch, ...] = Field((), description="the notch sections")
    rolloff_hz: Positive | None = Field(None, description="2nd-order low-pass corner [Hz]")

    @model_validator(mode="after")
    def _sections(self) -> NotchConfig:
        if len(self.notches) + (self.rolloff_hz is not None) > MAX_SECTIONS:
            raise ValueError(f"notches: at most {MAX_SECTIONS} sections with the roll-off")
        return self

    def check(self, scenario) -> None:
        nyquist = 0.5 / scenario.control_dt_s
        for i, notch in enumerate(self.notches):
            if notch.frequency_hz >= nyquist:
                raise ValueError(
                    f"notches[{i}].frequency_hz must be below the control Nyquist frequency "
                    f"{nyquist:g} Hz, got {notch.frequency_hz:g}"
                )
        if self.rolloff_hz is not None and self.rolloff_hz >= nyquist:
            raise ValueError(f"rolloff_hz must be below the control Nyquist frequency "
                             f"{nyquist:g} Hz, got {self.rolloff_hz:g}")  # fmt: skip

    def sections(self, control_dt_s: float) -> np.ndarray:
        """Discrete sections, shape (k, 5): b0, b1, b2, a1, a2 (a0 = 1)."""
        out = []
        for notch in self.notches:
            zp = notch.damping
            zz = zp * 10.0 ** (-notch.depth_db / 20.0)
            out.append(_bilinear((1.0, 2.0 * zz, 1.0), (1.0, 2.0 * zp, 1.0),
                                 notch.frequency_hz, control_dt_s))  # fmt: skip
        if self.rolloff_hz is not None:
            out.append(_bilinear((0.0, 0.0, 1.0), (1.0, sqrt(2.0), 1.0), self.rolloff_hz,
                                 control_dt_s))  # fmt: skip
        return np.array(out).reshape(-1, 5)

    def packed(self, scenario) -> np.ndarray:
        sections = self.sections(scenario.control_dt_s)
        table = np.zeros((MAX_SECTIONS, 5))
        table[: len(sections)] = sections
        return np.concatenate([[len(sections)], table.ravel()])


def _bilinear(num, den, frequency_hz: float, dt: float) -> list[float]:
    """Tustin transform of (n0 s^2 + n1 w s + n2 w^2) / (d0 s^2 + d1 w s + d2 w^2),
    prewarped so that the response at ``frequency_hz`` is exact."""
    w = 2.0 * pi * frequency_hz
    c = w / tan(w * dt / 2.0)  # s = c (z - 1) / (z + 1)

    def poly(p):
        p0, p1, p2 = p[0] * c * c, p[1] * w * c, p[2] * w * w
        return p0 + p1 + p2, 2.0 * (p2 - p0), p0 - p1 + p2

    b, a = poly(num), poly(den)
    return [b[0] / a[0], b[1] / a[0], b[2] / a[0], a[1] / a[0], a[2] / a[0]]


def notch_for_modes(plant, modes: int = 1, depth_db: float = 20.0, damping: float = 0.3,
                    rolloff_hz: float | None = None) -> NotchConfig:  # fmt: skip
    """A filter notching the ``modes`` lowest coupled flexible modes that move the hub.

    Parameters
    ----------
    plant : Plant
        The design plant; its modal analysis (:func:`flexsat.analysis.modal.modal_analysis`)
        gives the coupled frequencies.
    modes : int
        How many modes to notch, lowest first (at most :data:`MAX_SECTIONS`).
    depth_db, damping : float
        Depth [dB] and poles' damping ratio [-] of every notch.
    rolloff_hz : float, optional
        A roll-off corner above them [Hz].

    Returns
    -------
    NotchConfig
        The filter stage's parameters.
    """
    from flexsat.analysis.modal import modal_analysis

    analysis = modal_analysis(plant)
    coupled = [m.frequency_hz for m in analysis.modes
               if m.frequency_hz > 0.0 and m.hub_dof is not None]  # fmt: skip
    notches = tuple(Notch(frequency_hz=f, depth_db=depth_db, damping=damping)
                    for f in sorted(set(np.round(coupled, 9)))[:modes])  # fmt: skip
    return NotchConfig(notches=notches, rolloff_hz=rolloff_hz)


@njit(cache=True)  # compiled with ACTUATOR_SIGNATURE on first use
def notch_step(tau_cmd, t, dt, params, state, tau_applied, record):
    """Filter each axis through the sections (direct form II transposed)."""
    n = int(params[0])
    for a in range(3):
        u = tau_cmd[a]
        for k in range(n):
            c = params[1 + 5 * k : 6 + 5 * k]
            z = 2 * (MAX_SECTIONS * a + k)
            y = c[0] * u + state[z]
            state[z] = c[1] * u - c[3] * y + state[z + 1]
            state[z + 1] = c[2] * u - c[4] * y
            u = y
        tau_applied[a] = u
        record[a] = u
    return 0


NOTCH = StageSpec(
    role="actuator", name="notch", config=NotchConfig, step=notch_step,
    state_size=6 * MAX_SECTIONS,
    records=(Channel("notch_output", "N m", "the filtered torque command, each axis",
                     per_axis=True),),
    description="notch and roll-off filter on the commanded torque",
)  # fmt: skip
