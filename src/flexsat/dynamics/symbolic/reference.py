"""Numeric parameters and numeric evaluation of the generated reference model."""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
from numpy.typing import ArrayLike

from flexsat.dynamics.symbolic.symbols import PanelRates

if TYPE_CHECKING:
    from flexsat.config import SatelliteConfig

__all__ = ["ReferenceModel", "ReferenceParameters"]


def _as_array(value: ArrayLike, shape: tuple[int, ...], name: str) -> np.ndarray:
    arr = np.array(value, dtype=float)
    if arr.shape != shape:
        raise ValueError(f"{name} must have shape {shape}, got {arr.shape}")
    if not np.all(np.isfinite(arr)):
        raise ValueError(f"{name} must be finite")
    arr.flags.writeable = False
    return arr


@dataclass(frozen=True, eq=False)
class ReferenceParameters:
    """Numeric parameters of the reference model (SI units, radians).

    Attributes
    ----------
    hub_mass : float
        Hub mass [kg].
    hub_inertia : ndarray, shape (3, 3)
        Symmetric hub inertia about its centre of mass, frame B [kg m^2].
    mount_point : ndarray, shape (N, 3)
        Appendage root positions from the hub centre of mass, frame B [m].
    mount_yaw : ndarray, shape (N,)
        Mount-frame rotations about Z_B [rad].
    sadm : ndarray, shape (N,)
        SADM angles [rad].
    span_sign : ndarray, shape (N,)
        +1 (span along +Y_P) or -1 (along -Y_P) [-].
    length : ndarray, shape (N,)
        Panel lengths [m].
    mass : ndarray, shape (N,)
        Panel masses [kg].
    inertia_diag : ndarray, shape (N, 3)
        Principal panel inertias about the panel centre of mass, frame P [kg m^2].
    stiffness : ndarray, shape (N, 6)
        Joint stiffness per DOF (x, y, z, rx, ry, rz) [N/m, N m/rad].
    damping : ndarray, shape (N, 6)
        Joint damping per DOF [N s/m, N m s/rad].
    """

    hub_mass: float
    hub_inertia: np.ndarray
    mount_point: np.ndarray
    mount_yaw: np.ndarray
    sadm: np.ndarray
    span_sign: np.ndarray
    length: np.ndarray
    mass: np.ndarray
    inertia_diag: np.ndarray
    stiffness: np.ndarray
    damping: np.ndarray

    def __post_init__(self) -> None:
        hub_mass = float(self.hub_mass)
        if not math.isfinite(hub_mass):
            raise ValueError("hub_mass must be finite")
        object.__setattr__(self, "hub_mass", hub_mass)
        hub_inertia = _as_array(self.hub_inertia, (3, 3), "hub_inertia")
        if not np.allclose(
            hub_inertia,
            hub_inertia.T,
            rtol=0.0,
            atol=1e-12 * max(1.0, float(np.abs(hub_inertia).max())),
        ):
            raise ValueError("hub_inertia must be symmetric")
        object.__setattr__(self, "hub_inertia", hub_inertia)
        n = np.shape(self.mount_point)[0] if np.ndim(self.mount_point) == 2 else -1
        if n < 0:
            raise ValueError(
                f"mount_point must have shape (N, 3), got {np.shape(self.mount_point)}"
            )
        shapes = {
            "mount_point": (n, 3),
            "mount_yaw": (n,),
            "sadm": (n,),
            "span_sign": (n,),
            "length": (n,),
            "mass": (n,),
            "inertia_diag": (n, 3),
            "stiffness": (n, 6),
            "damping": (n, 6),
        }
        for name, shape in shapes.items():
            object.__setattr__(self, name, _as_array(getattr(self, name), shape, name))

    @property
    def n_appendages(self) -> int:
        """Number of appendages N."""
        return int(self.mount_point.shape[0])

    @classmethod
    def from_config(
        cls, config: SatelliteConfig, stiffness: ArrayLike, damping: ArrayLike
    ) -> ReferenceParameters:
        """Parameters of a validated configuration.

        Parameters
        ----------
        config : flexsat.config.SatelliteConfig
            The satellite. Angles are converted from degrees to radians.
        stiffness, damping : array_like, shape (N, 6), (6,) or scalar
            Joint stiffness and damping per appendage and DOF (x, y, z, rx, ry,
            rz), broadcast to (N, 6). The mass matrix does not depend on them.

        Returns
        -------
        ReferenceParameters
        """
        apps = config.appendages
        n = len(apps)
        return cls(
            hub_mass=config.hub.mass_kg,
            hub_inertia=config.hub.inertia(),
            mount_point=[a.mount_point_m for a in apps],
            mount_yaw=np.radians([a.mount_yaw_deg for a in apps]),
            sadm=np.radians([a.sadm_angle_deg for a in apps]),
            span_sign=[a.span_sign() for a in apps],
            length=[a.length_m for a in apps],
            mass=[a.mass for a in apps],
            inertia_diag=[np.diag(a.centroidal_inertia()) for a in apps],
            stiffness=np.broadcast_to(np.asarray(stiffness, dtype=float), (n, 6)),
            damping=np.broadcast_to(np.asarray(damping, dtype=float), (n, 6)),
        )

    def vector(self) -> np.ndarray:
        """Flat parameter vector in the order of :attr:`SymbolicModel.parameters`.

        Hub (7): mass, J_xx, J_yy, J_zz, J_xy, J_xz, J_yz; then per appendage (23):
        mount point (3), yaw, SADM angle, span sign, length, mass, inertia
        diagonal (3), stiffness (6), damping (6).
        """
        j = self.hub_inertia
        parts = [np.array([self.hub_mass, j[0, 0], j[1, 1], j[2, 2], j[0, 1], j[0, 2], j[1, 2]])]
        for i in range(self.n_appendages):
            parts.append(
                np.concatenate(
                    [
                        self.mount_point[i],
                        [self.mount_yaw[i], self.sadm[i], self.span_sign[i]],
                        [self.length[i], self.mass[i]],
                        self.inertia_diag[i],
                        self.stiffness[i],
                        self.damping[i],
                    ]
                )
            )
        return np.concatenate(parts)


class ReferenceModel:
    """Numeric evaluation of the symbolic equations of motion.

    Obtain one with :func:`reference_model`. The functions are generated Python
    (``math`` only) from :func:`derive` with common subexpressions eliminated;
    intended for verification, not speed (about a millisecond per call).

    Parameters
    ----------
    n_appendages : int
        Number of appendages N.
    panel_rates : {"exact", "small_angle"}
        Panel angular-velocity variant (eq. 2.31), see :func:`derive`.
    source : str
        The generated Python source.
    path : Path or None
        The cache file the source was read from or written to, if any.

    Attributes
    ----------
    n_dof : int
        ``6 + 6 * n_appendages``.
    """

    def __init__(
        self,
        n_appendages: int,
        panel_rates: PanelRates,
        source: str,
        path: Path | None = None,
    ) -> None:
        namespace: dict[str, Any] = {"__name__": f"flexsat_reference_n{n_appendages}"}
        exec(compile(source, str(path) if path else "<flexsat reference>", "exec"), namespace)
        self.n_appendages = n_appendages
        self.panel_rates = panel_rates
        self.n_dof = 6 + 6 * n_appendages
        self.source = source
        self.path = path
        self._dynamics: Callable[..., tuple[float, ...]] = namespace["dynamics"]
        self._kinetic: Callable[..., tuple[float]] = namespace["kinetic_energy"]
        self._potential: Callable[..., tuple[float]] = namespace["potential_energy"]

    def __repr__(self) -> str:
        return f"ReferenceModel(n_appendages={self.n_appendages}, panel_rates={self.panel_rates!r})"

    def _inputs(self, params: ReferenceParameters, *states: ArrayLike) -> tuple[list[float], ...]:
        if not isinstance(params, ReferenceParameters):
            raise TypeError(f"params must be ReferenceParameters, got {type(params).__name__}")
        if params.n_appendages != self.n_appendages:
            raise ValueError(
                f"params describe {params.n_appendages} appendage(s), the model {self.n_appendages}"
            )
        out = []
        for k, state in enumerate(states):
            arr = np.asarray(state, dtype=float)
            if arr.shape != (self.n_dof,):
                name = ("q", "qd")[k]
                raise ValueError(f"{name} must have shape ({self.n_dof},), got {arr.shape}")
            out.append(arr.tolist())
        return (*out, params.vector().tolist())

    def evaluate(
        self, params: ReferenceParameters, q: ArrayLike, qd: ArrayLike
    ) -> dict[str, np.ndarray]:
        """Terms of ``M q_ddot + h + C q_dot + k_el = Q`` at one state.

        Parameters
        ----------
        params : ReferenceParameters
            Numeric parameters with ``n_appendages`` appendages.
        q, qd : array_like, shape (n_dof,)
            Generalized coordinates and rates.

        Returns
        -------
        dict of str to ndarray
            ``"M"`` (n_dof, n_dof), ``"h"`` (n_dof,), ``"k_el"`` (n_dof,) and
            ``"C"`` (n_dof, n_dof).
        """
        q_, qd_, p_ = self._inputs(params, q, qd)
        flat = np.array(self._dynamics(q_, qd_, p_), dtype=float)
        n = self.n_dof
        nn = n * n
        return {
            "M": flat[:nn].reshape(n, n),
            "h": flat[nn : nn + n],
            "k_el": flat[nn + n : nn + 2 * n],
            "C": flat[nn + 2 * n :].reshape(n, n),
        }

    def kinetic_energy(self, params: ReferenceParameters, q: ArrayLike, qd: ArrayLike) -> float:
        """Kinetic energy ``T`` evaluated directly from the body velocities [J]."""
        q_, qd_, p_ = self._inputs(params, q, qd)
        return float(self._kinetic(q_, qd_, p_)[0])

    def potential_energy(self, params: ReferenceParameters, q: ArrayLike) -> float:
        """Elastic potential energy ``U`` [J]."""
        q_, p_ = self._inputs(params, q)
        return float(self._potential(q_, p_)[0])
