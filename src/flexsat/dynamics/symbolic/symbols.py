"""Parameter and coordinate symbols of the reference model, and the topology check."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal

import numpy as np
import sympy as sp

__all__ = ["AppendageSymbols", "HubSymbols", "PanelRates"]

PanelRates = Literal["exact", "small_angle"]
_PANEL_RATES = ("exact", "small_angle")

_AXES = ("x", "y", "z")
_JOINT_AXES = ("x", "y", "z", "rx", "ry", "rz")


def _sym(name: str) -> sp.Symbol:
    return sp.Symbol(name)


@dataclass(frozen=True, eq=False)
class HubSymbols:
    """Parameter symbols of the hub.

    Attributes
    ----------
    mass : Symbol
        Hub mass ``m_h`` [kg].
    inertia : ImmutableMatrix
        Symmetric 3x3 inertia about the hub centre of mass in frame B, built from
        the six symbols ``J_hxx, J_hyy, J_hzz, J_hxy, J_hxz, J_hyz`` [kg m^2].
    """

    mass: sp.Symbol
    inertia: sp.ImmutableMatrix

    def flat(self) -> tuple[sp.Symbol, ...]:
        """Symbols in parameter-vector order: m_h, J_xx, J_yy, J_zz, J_xy, J_xz, J_yz."""
        j = self.inertia
        return (self.mass, j[0, 0], j[1, 1], j[2, 2], j[0, 1], j[0, 2], j[1, 2])


@dataclass(frozen=True, eq=False)
class AppendageSymbols:
    """Parameter symbols of one appendage (index ``i`` is 1-based in the names).

    Attributes
    ----------
    mount_point : ImmutableMatrix
        Root position ``r_m,i`` from the hub centre of mass, frame B (3x1) [m].
    mount_yaw : Symbol
        Mount-frame rotation ``gamma_i`` about Z_B [rad].
    sadm : Symbol
        SADM angle ``alpha_i`` about the yawed Y axis [rad].
    span_sign : Symbol
        ``s_i = +1`` when the plate spans along +Y_P, -1 along -Y_P.
    length : Symbol
        Panel length ``L_i`` [m].
    mass : Symbol
        Panel mass ``m_i`` [kg].
    inertia_diag : tuple of Symbol
        Principal inertia ``(J_ixx, J_iyy, J_izz)`` about the panel CoM, frame P [kg m^2].
    stiffness, damping : tuple of Symbol
        Joint stiffness ``k_i`` and damping ``c_i`` per DOF, order
        ``(x, y, z, rx, ry, rz)``.
    """

    mount_point: sp.ImmutableMatrix
    mount_yaw: sp.Symbol
    sadm: sp.Symbol
    span_sign: sp.Symbol
    length: sp.Symbol
    mass: sp.Symbol
    inertia_diag: tuple[sp.Symbol, sp.Symbol, sp.Symbol]
    stiffness: tuple[sp.Symbol, ...]
    damping: tuple[sp.Symbol, ...]

    def flat(self) -> tuple[sp.Symbol, ...]:
        """Symbols in parameter-vector order (23): r_m (3), gamma, alpha, s, L, m,
        J_p diagonal (3), k (6), c (6)."""
        return (
            *self.mount_point,
            self.mount_yaw,
            self.sadm,
            self.span_sign,
            self.length,
            self.mass,
            *self.inertia_diag,
            *self.stiffness,
            *self.damping,
        )


def _hub_symbols() -> HubSymbols:
    jxx, jyy, jzz, jxy, jxz, jyz = (_sym(f"J_h{a}") for a in ("xx", "yy", "zz", "xy", "xz", "yz"))
    inertia = sp.ImmutableMatrix([[jxx, jxy, jxz], [jxy, jyy, jyz], [jxz, jyz, jzz]])
    return HubSymbols(mass=_sym("m_h"), inertia=inertia)


def _appendage_symbols(i: int) -> AppendageSymbols:
    k = i + 1
    return AppendageSymbols(
        mount_point=sp.ImmutableMatrix([_sym(f"r_m{k}{a}") for a in _AXES]),
        mount_yaw=_sym(f"gamma_{k}"),
        sadm=_sym(f"alpha_{k}"),
        span_sign=_sym(f"s_{k}"),
        length=_sym(f"L_{k}"),
        mass=_sym(f"m_{k}"),
        inertia_diag=tuple(_sym(f"J_{k}{a}{a}") for a in _AXES),
        stiffness=tuple(_sym(f"k_{k}{a}") for a in _JOINT_AXES),
        damping=tuple(_sym(f"c_{k}{a}") for a in _JOINT_AXES),
    )


def _coordinates(n_appendages: int) -> tuple[list[sp.Symbol], list[sp.Symbol]]:
    q = [_sym(f"r_{a}") for a in _AXES] + [_sym(a) for a in ("phi", "theta", "psi")]
    qd = [_sym(f"rdot_{a}") for a in _AXES] + [_sym(f"{a}dot") for a in ("phi", "theta", "psi")]
    for i in range(n_appendages):
        k = i + 1
        q += [_sym(f"eta_{k}{a}") for a in _AXES] + [_sym(f"rho_{k}{a}") for a in _AXES]
        qd += [_sym(f"etadot_{k}{a}") for a in _AXES]
        qd += [_sym(f"rhodot_{k}{a}") for a in _AXES]
    return q, qd


def _check_topology(n_appendages: int, panel_rates: str) -> None:
    if isinstance(n_appendages, bool) or not isinstance(n_appendages, int | np.integer):
        raise TypeError(f"n_appendages must be an int, got {type(n_appendages).__name__}")
    if n_appendages < 0:
        raise ValueError(f"n_appendages must be >= 0, got {n_appendages}")
    if panel_rates not in _PANEL_RATES:
        raise ValueError(f"panel_rates must be 'exact' or 'small_angle', got {panel_rates!r}")
