"""Magnetorquers and magnetic momentum dumping: the wheels' momentum unloaded on the field.

At each control instant the magnetorquers command the dipole of the cross-product law
(Sidi, *Spacecraft Dynamics and Control*, sec. 7.5; Markley & Crassidis,
*Fundamentals of Spacecraft Attitude Determination and Control*, sec. 7.5;
docs/environment.md, 'Magnetorquers and momentum dumping')::

    m_cmd = k (h_w x B_B) / ‖B_B‖^2        (= -k (B_B x h_w) / ‖B_B‖^2)

with h_w the reaction wheels' stored momentum (hub frame B, the wheels' own record
``wheel_momentum_B``) and B_B the field of the ``magnetic`` model at the satellite.
Each axis is then clipped to the rods' dipole limit and rounded to the drive's
quantum (the resolution of its current command); the torque on the hub is
tau = m x B_B. Its component across the field is -k h_w,perp: the wheels, which hold
the attitude against it, lose the momentum they carry across the field at the rate
k; the component along the field cannot be dumped at that instant, but the field
turns along the orbit, so every component is dumped over an orbit.
The dipole is held until the loads' next evaluation, like them.
"""

from __future__ import annotations

from math import floor, sqrt
from typing import Annotated

from numba import njit
from pydantic import Field

from flexsat.config.models import _Frozen
from flexsat.environment.magnetic import field_at

__all__ = [
    "DUMP_SIZE",
    "MagnetorquerConfig",
    "dump_momentum",
    "dumping_dipole",
    "magnetorquer_dipole",
    "quantized",
]

_K, _MAX, _QUANTUM, _COLUMN, _MAGNETIC = 0, 1, 2, 3, 4  # packed: the dumping's parameters
DUMP_SIZE = 5


class MagnetorquerConfig(_Frozen):
    """Three magnetorquer rods along the hub axes, commanded by the cross-product law."""

    dipole_max_a_m2: Annotated[float, Field(gt=0.0, le=1e4, allow_inf_nan=False)] = Field(
        10.0, description="dipole limit of each rod [A m^2]"
    )
    quantum_a_m2: Annotated[float, Field(ge=0.0, le=1e3, allow_inf_nan=False)] = Field(
        0.0, description="dipole resolution of the drive; 0: continuous [A m^2]"
    )
    gain_1_s: Annotated[float, Field(gt=0.0, le=1.0, allow_inf_nan=False)] = Field(
        1e-3, description="k of the cross-product law [1/s]"
    )


@njit(cache=True)
def quantized(value, quantum):
    """``value`` rounded to the nearest multiple of ``quantum`` (unchanged for quantum 0).

    Parameters
    ----------
    value : float
        A dipole command [A m^2].
    quantum : float
        The drive's resolution; 0 or less: continuous [A m^2].

    Returns
    -------
    float
        quantum round(value / quantum), halves rounded up [A m^2].
    """
    if quantum <= 0.0:
        return value
    return quantum * floor(value / quantum + 0.5)


@njit(cache=True)
def dumping_dipole(B, h, k):
    """The cross-product law's dipole k (h x B) / ‖B‖^2 [A m^2] (module docstring).

    Parameters
    ----------
    B : tuple of 3 float
        The field, hub frame B [T].
    h : tuple of 3 float
        The wheels' momentum, hub frame B [N m s].
    k : float
        The law's gain [1/s].

    Returns
    -------
    tuple of 3 float
        The commanded dipole, hub frame B [A m^2] (zero in a null field).
    """
    b2 = B[0] * B[0] + B[1] * B[1] + B[2] * B[2]
    if b2 == 0.0:
        return 0.0, 0.0, 0.0
    s = k / b2
    return (s * (h[1] * B[2] - h[2] * B[1]), s * (h[2] * B[0] - h[0] * B[2]),
            s * (h[0] * B[1] - h[1] * B[0]))  # fmt: skip


@njit(cache=True)
def magnetorquer_dipole(m, limit, quantum):
    """Each axis of ``m`` clipped to +-``limit``, then rounded to ``quantum`` (E.10).

    Parameters
    ----------
    m : tuple of 3 float
        The commanded dipole, hub frame B [A m^2].
    limit : float
        Each rod's dipole limit [A m^2].
    quantum : float
        The drive's resolution; 0: continuous [A m^2].

    Returns
    -------
    tuple of 3 float
        The rods' dipole [A m^2]: on the quantum's grid, each within +-``limit`` (a
        rounding past the limit falls back to the grid's last step inside it).
    """
    top = limit if quantum <= 0.0 else quantum * floor(limit / quantum)
    out0 = quantized(min(limit, max(-limit, m[0])), quantum)
    out1 = quantized(min(limit, max(-limit, m[1])), quantum)
    out2 = quantized(min(limit, max(-limit, m[2])), quantum)
    return min(top, max(-top, out0)), min(top, max(-top, out1)), min(top, max(-top, out2))


@njit(cache=True)
def dump_momentum(dump, row, C_BN, magnetic_params, held, torque, dipole):
    """The magnetorquers' dipole and its torque at one control instant.

    Parameters
    ----------
    dump : ndarray, shape (5,)
        k [1/s], dipole limit [A m^2], quantum [A m^2], the column of
        ``wheel_momentum_B`` in ``held``, the magnetic model's index (packed).
    row : ndarray, shape (13,)
        The ephemeris at the instant [s, m, m/s, -, m, -, rad].
    C_BN : ndarray, shape (3, 3)
        ECI to hub frame B [-].
    magnetic_params : ndarray
        The ``magnetic`` model's packed parameters [SI].
    held : ndarray
        The loop's record row (the wheels' momentum at ``dump[3]``) [per channel].
    torque : ndarray, shape (3,)
        The environment's torque on the hub, frame B [N m], added to.
    dipole : ndarray, shape (3,)
        The dipole commanded, hub frame B [A m^2], written.

    Returns
    -------
    float
        ‖m‖, the dipole's magnitude [A m^2].
    """
    bx, by, bz = field_at(row, magnetic_params)
    B = (C_BN[0, 0] * bx + C_BN[0, 1] * by + C_BN[0, 2] * bz,
         C_BN[1, 0] * bx + C_BN[1, 1] * by + C_BN[1, 2] * bz,
         C_BN[2, 0] * bx + C_BN[2, 1] * by + C_BN[2, 2] * bz)  # fmt: skip
    c = int(dump[_COLUMN])
    h = (held[c], held[c + 1], held[c + 2])
    m = magnetorquer_dipole(dumping_dipole(B, h, dump[_K]), dump[_MAX], dump[_QUANTUM])
    dipole[0], dipole[1], dipole[2] = m
    torque[0] += m[1] * B[2] - m[2] * B[1]
    torque[1] += m[2] * B[0] - m[0] * B[2]
    torque[2] += m[0] * B[1] - m[1] * B[0]
    return sqrt(m[0] * m[0] + m[1] * m[1] + m[2] * m[2])
