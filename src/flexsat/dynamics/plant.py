"""The flexible-satellite plant: a validated config packed into the kernels' arrays.

:class:`Plant` is the user-level face of the compiled kernels in
:mod:`flexsat.dynamics.kernels`: it builds the packed arrays once (geometry,
inertia, tuned joint stiffness and damping) and offers the model's terms at any
state. Every method takes and returns SI arrays; generalized coordinates are laid
out as in the kernels' module docstring.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.spatial.transform import Rotation

from flexsat.config.models import SatelliteConfig
from flexsat.dynamics import kernels
from flexsat.dynamics.linalg3 import euler_rate_matrix
from flexsat.dynamics.tuning import tune_joints
from flexsat.errors import SimulationError

__all__ = ["HUB_DOFS", "JOINT_DOFS", "Plant"]

HUB_DOFS = ("x", "y", "z", "phi", "theta", "psi")
JOINT_DOFS = ("eta_x", "eta_y", "eta_z", "eta_rx", "eta_ry", "eta_rz")

_STATUS_MESSAGES = {
    kernels.STATUS_HUB_GIMBAL_LOCK: "hub pitch reached +-90 deg (ZYX Euler-angle singularity)",
    kernels.STATUS_JOINT_GIMBAL_LOCK: "a joint root rotation rho_y reached +-90 deg",
}


@dataclass(frozen=True, eq=False)
class Plant:
    """Hub plus appendages, packed for the compiled kernels.

    Build it with :meth:`from_config`. Array attributes (``n`` appendages):
    ``mount_point`` (n, 3) [m] in hub frame B; ``R_BM`` (n, 3, 3) mount -> hub;
    ``com_offset`` (n, 3) [m] root -> panel centre of mass in panel frame;
    ``panel_mass`` (n,) [kg]; ``panel_J`` (n, 3, 3) [kg m^2] about the panel centre
    of mass; ``stiffness``/``damping`` (n, 6) per joint DOF; ``tip_point`` (n, 3) [m]
    the panel tip (mid-chord of the free edge) in panel frame.
    """

    config: SatelliteConfig
    hub_mass: float
    hub_J: np.ndarray
    hub_J_inv: np.ndarray
    mount_point: np.ndarray
    R_BM: np.ndarray
    com_offset: np.ndarray
    panel_mass: np.ndarray
    panel_J: np.ndarray
    panel_J_inv: np.ndarray
    stiffness: np.ndarray
    damping: np.ndarray
    tip_point: np.ndarray

    @classmethod
    def from_config(cls, config: SatelliteConfig) -> Plant:
        """Pack a validated config and tune the joints to its target frequencies.

        The stiffness and damping follow eqs. 2.14-2.15 with J_eq taken from
        diag M(0) of this very configuration (thesis section 2.2.3).
        """
        apps = config.appendages
        n = len(apps)
        hub_J = config.hub.inertia()
        sign = np.array([a.span_sign() for a in apps])
        length = np.array([a.length_m for a in apps])
        panel_J = np.stack([a.centroidal_inertia() for a in apps])
        angles = np.radians([[a.mount_yaw_deg, a.sadm_angle_deg] for a in apps])
        untuned = cls(
            config=config,
            hub_mass=float(config.hub.mass_kg),
            hub_J=hub_J,
            hub_J_inv=np.linalg.inv(hub_J),
            mount_point=np.array([a.mount_point_m for a in apps], dtype=float),
            # R_BM = Rz(yaw) Ry(alpha_sadm): intrinsic Z then Y.
            R_BM=Rotation.from_euler("ZY", angles).as_matrix().reshape(n, 3, 3),
            com_offset=np.column_stack([np.zeros(n), 0.5 * sign * length, np.zeros(n)]),
            panel_mass=np.array([a.mass for a in apps]),
            panel_J=panel_J,
            panel_J_inv=np.linalg.inv(panel_J),
            stiffness=np.zeros((n, 6)),
            damping=np.zeros((n, 6)),
            tip_point=np.column_stack([np.zeros(n), sign * length, np.zeros(n)]),
        )
        stiffness, damping = tune_joints(
            untuned.mass_matrix(),
            np.stack([a.target_frequencies_hz.per_dof() for a in apps]),
            np.array([a.damping_ratio for a in apps]),
        )
        return untuned.with_joints(stiffness, damping)

    def with_joints(self, stiffness: np.ndarray, damping: np.ndarray) -> Plant:
        """A copy with other joint stiffness and damping, each shape (n, 6)."""
        fields = {name: getattr(self, name) for name in self.__dataclass_fields__}
        fields["stiffness"] = np.array(stiffness, dtype=float).reshape(self.n_appendages, 6)
        fields["damping"] = np.array(damping, dtype=float).reshape(self.n_appendages, 6)
        return Plant(**fields)

    # -- sizes and packed argument lists -------------------------------------------------

    @property
    def n_appendages(self) -> int:
        return int(self.panel_mass.shape[0])

    @property
    def n_dof(self) -> int:
        return 6 + 6 * self.n_appendages

    @property
    def inertia_args(self) -> tuple:
        """Arguments of the kernels that need the inertia only."""
        return (
            self.hub_mass, self.hub_J, self.mount_point, self.R_BM, self.com_offset,
            self.panel_mass, self.panel_J,
        )  # fmt: skip

    @property
    def dynamics_args(self) -> tuple:
        """Arguments of :func:`flexsat.dynamics.kernels.accelerations` after (q, qd, Q)."""
        return (
            self.hub_mass, self.hub_J, self.hub_J_inv, self.mount_point, self.R_BM,
            self.com_offset, self.panel_mass, self.panel_J, self.panel_J_inv,
            self.stiffness, self.damping,
        )  # fmt: skip

    def dof_names(self) -> list[str]:
        """Names of the generalized coordinates: hub DOFs, then ``<appendage>.<joint DOF>``."""
        names = list(HUB_DOFS)
        for app in self.config.appendages:
            names += [f"{app.name}.{dof}" for dof in JOINT_DOFS]
        return names

    def zeros(self) -> np.ndarray:
        """A zero generalized vector, shape (n_dof,)."""
        return np.zeros(self.n_dof)

    def _state(self, q: np.ndarray | None) -> np.ndarray:
        if q is None:
            return self.zeros()
        q = np.ascontiguousarray(q, dtype=float)
        if q.shape != (self.n_dof,):
            raise ValueError(f"expected a vector of shape ({self.n_dof},), got {q.shape}")
        return q

    # -- terms of M q_ddot + h + C q_dot + k_el = Q (eq. 2.22) ---------------------------

    def mass_matrix(self, q: np.ndarray | None = None) -> np.ndarray:
        """M(q), shape (n_dof, n_dof) (eq. 2.39); ``q=None`` gives M(0)."""
        out = np.empty((self.n_dof, self.n_dof))
        kernels.mass_matrix(self._state(q), *self.inertia_args, out)
        return out

    def bias_forces(self, q: np.ndarray, qd: np.ndarray) -> np.ndarray:
        """Coriolis and centrifugal vector h(q, q_dot), shape (n_dof,) (eq. 2.43)."""
        out = np.empty(self.n_dof)
        kernels.bias_forces(self._state(q), self._state(qd), *self.inertia_args, out)
        return out

    def stiffness_matrix(self) -> np.ndarray:
        """K_sys = diag(0_6, K_flex,1, ..., K_flex,n), shape (n_dof, n_dof) (eq. 3.4)."""
        return np.diag(np.concatenate([np.zeros(6), self.stiffness.ravel()]))

    def damping_matrix(self) -> np.ndarray:
        """C_damp = diag(0_6, C_flex,1, ..., C_flex,n), shape (n_dof, n_dof) (eq. 2.47)."""
        return np.diag(np.concatenate([np.zeros(6), self.damping.ravel()]))

    def elastic_forces(self, q: np.ndarray) -> np.ndarray:
        """k_el(q) = K_sys q, shape (n_dof,) (eq. 2.46)."""
        q = self._state(q)
        return np.concatenate([np.zeros(6), self.stiffness.ravel() * q[6:]])

    def damping_forces(self, qd: np.ndarray) -> np.ndarray:
        """C_damp q_dot, shape (n_dof,) (eq. 2.47)."""
        qd = self._state(qd)
        return np.concatenate([np.zeros(6), self.damping.ravel() * qd[6:]])

    def generalized_forces(
        self, q: np.ndarray, torque_B: np.ndarray, force_N: np.ndarray | None = None
    ) -> np.ndarray:
        """Generalized forces of a body torque (and force) on the hub, by virtual work.

        Parameters
        ----------
        q : ndarray, shape (n_dof,)
        torque_B : ndarray, shape (3,)
            Torque on the hub, hub frame B [N m].
        force_N : ndarray, shape (3,), optional
            Force through the hub centre of mass, inertial frame N [N].

        Returns
        -------
        ndarray, shape (n_dof,)
            Q with Q_r = force_N and Q_Theta = S(Theta)^T torque_B.
        """
        q = self._state(q)
        S = np.array(euler_rate_matrix(q[3], q[4]))  # eq. 2.28
        out = self.zeros()
        if force_N is not None:
            out[0:3] = force_N
        out[3:6] = S.T @ np.asarray(torque_B, dtype=float)
        return out

    def accelerations(
        self, q: np.ndarray, qd: np.ndarray, Q: np.ndarray | None = None
    ) -> np.ndarray:
        """q_ddot = M^-1 (Q - h - C q_dot - k_el) (eq. 2.50), shape (n_dof,).

        Raises
        ------
        SimulationError
            At a ZYX Euler-angle singularity of the hub or of a joint.
        """
        out = np.empty(self.n_dof)
        status = kernels.accelerations(
            self._state(q), self._state(qd), self._state(Q), *self.dynamics_args, out
        )
        if status != kernels.STATUS_OK:
            raise SimulationError(_STATUS_MESSAGES[status])
        return out

    # -- energies, momentum, loads, displacements -----------------------------------------

    def kinetic_energy(self, q: np.ndarray, qd: np.ndarray) -> float:
        """T = 1/2 q_dot^T M q_dot, from the bodies' velocities [J] (eq. 2.32)."""
        return float(kernels.kinetic_energy(self._state(q), self._state(qd), *self.inertia_args))

    def elastic_energy(self, q: np.ndarray) -> float:
        """U = 1/2 sum_i q_i^T K_i q_i [J] (eq. 2.35)."""
        flex = self._state(q)[6:]
        return float(0.5 * np.dot(self.stiffness.ravel() * flex, flex))

    def dissipation_power(self, qd: np.ndarray) -> float:
        """Power dissipated by the joint dampers, q_dot^T C q_dot = 2 D [W] (eq. 2.36)."""
        flex = self._state(qd)[6:]
        return float(np.dot(self.damping.ravel() * flex, flex))

    def angular_momentum(self, q: np.ndarray, qd: np.ndarray) -> np.ndarray:
        """Total angular momentum about the inertial origin, frame N, shape (3,) [N m s]."""
        out = np.empty(3)
        kernels.system_angular_momentum(
            self._state(q), self._state(qd), *self.inertia_args, out
        )
        return out

    def locked_inertia(self, q: np.ndarray) -> np.ndarray:
        """Inertia of the satellite frozen in shape q about the hub centre of mass, B, (3, 3)."""
        out = np.empty((3, 3))
        kernels.locked_inertia(
            self._state(q), self.hub_J, self.mount_point, self.R_BM, self.com_offset,
            self.panel_mass, self.panel_J, out,
        )  # fmt: skip
        return out

    def joint_wrench_on_hub(
        self, q: np.ndarray, qd: np.ndarray, Q: np.ndarray | None = None
    ) -> tuple[np.ndarray, np.ndarray]:
        """Force and torque tau_flex the joints exert on the hub (about its centre of mass).

        Returns
        -------
        force_B, torque_B : ndarray, shape (3,)
            In hub frame B [N], [N m]; zero at rest and undeformed.
        """
        out = np.empty(6)
        status = kernels.hub_joint_wrench(
            self._state(q), self._state(qd), self._state(Q), self.mount_point, self.R_BM,
            self.com_offset, self.stiffness, self.damping, out,
        )  # fmt: skip
        if status != kernels.STATUS_OK:
            raise SimulationError(_STATUS_MESSAGES[status])
        return out[:3].copy(), out[3:].copy()

    def tip_displacement(self, q: np.ndarray) -> np.ndarray:
        """Tip displacement of each panel from its undeformed place, mount frames, (n, 3) [m]."""
        out = np.empty((self.n_appendages, 3))
        kernels.tip_displacement(self._state(q), self.tip_point, out)
        return out
