"""The flexible-satellite plant: a validated config packed for the compiled kernels.

:class:`Plant` is the user-level face of the compiled kernels in
:mod:`flexsat.dynamics.kernels`: it looks each appendage's model up in the registry
(:mod:`flexsat.dynamics.appendages`), packs the hub and the models' parameter rows
once (geometry, inertia, tuned joint stiffness and damping) into
:attr:`Plant.packed`, and offers the model's terms at any state. Every method takes
and returns SI arrays; generalized coordinates are laid out as :attr:`Plant.layout`
says.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from flexsat.compiled.first_class import first_class
from flexsat.compiled.linalg3 import euler_rate_matrix
from flexsat.compiled.status import STATUS_OK, status_message
from flexsat.config.models import SatelliteConfig
from flexsat.dynamics import kernels
from flexsat.dynamics.appendages import AppendageModel, appendage_model
from flexsat.dynamics.appendages.contract import (
    HUB_SIZE,
    OBS_DISSIPATION,
    OBS_ELASTIC,
    OBS_KINETIC,
    OBS_LOCKED_INERTIA,
    OBS_MOMENTUM,
    OBS_SIZE,
    SIGNATURES,
    AppendageKernels,
)
from flexsat.dynamics.appendages.plate import JOINT_DOFS
from flexsat.dynamics.layout import HUB_DOFS, StateLayout
from flexsat.dynamics.packed import PackedPlant, only
from flexsat.errors import ConfigError, SimulationError

__all__ = ["HUB_DOFS", "JOINT_DOFS", "Plant"]


@dataclass(frozen=True, eq=False)
class Plant:
    """Hub plus appendages, packed for the compiled kernels.

    Build it with :meth:`from_config`; ``layout`` says where each appendage's
    coordinates live in the state, ``packed`` is what the compiled code takes.

    Parameters
    ----------
    config : SatelliteConfig
        The validated satellite it was built from.
    hub_mass : float
        Hub mass m_h [kg].
    hub_J : ndarray, shape (3, 3)
        Hub inertia about its centre of mass, hub frame B [kg m^2].
    models : tuple of AppendageModel
        ``models[i]`` is appendage i's model (from the appendage registry).
    params : tuple of ndarray
        ``params[i]`` is appendage i's packed parameter row (SI, the model's layout) [-].
    """

    config: SatelliteConfig
    hub_mass: float
    hub_J: np.ndarray
    models: tuple[AppendageModel, ...]
    params: tuple[np.ndarray, ...]
    layout: StateLayout = field(init=False)
    packed: PackedPlant = field(init=False)

    def __post_init__(self) -> None:
        entries = []
        for app, model in zip(self.config.appendages, self.models, strict=True):
            coords = model.coordinates(app)
            names, units = tuple(c.name for c in coords), tuple(c.unit for c in coords)
            entries.append((app.name, model.name, names, units))
        layout = StateLayout.build(entries)
        object.__setattr__(self, "layout", layout)
        object.__setattr__(self, "packed", self._pack())
        # Per evaluation, the plant with only the kernels it calls (cheaper from Python).
        views = {
            "mass_matrix": ("mass_matrix",), "bias_forces": ("bias_forces",),
            "accelerations": ("pass1", "pass2", "mass_matrix"), "observe": ("observe",),
            "joint_wrench": ("pass1", "pass2", "mass_matrix", "joint_wrench"),
            "tips": ("tips",),
        }  # fmt: skip
        object.__setattr__(self, "_views", {k: only(self.packed, *v) for k, v in views.items()})

    @classmethod
    def from_config(cls, config: SatelliteConfig) -> Plant:
        """Pack a validated config and tune each appendage to its targets.

        The stiffness and damping follow eqs. 2.14-2.15 with J_eq taken from
        diag M(0) of this very configuration (thesis section 2.2.3). A plate on a drive
        (its ``drive`` key) is built as its two-segment chain, the joints tuned as the
        undriven plate's (:func:`~flexsat.dynamics.appendages.sadm.expand_drives`);
        ``config`` of the result is then the satellite so written.
        """
        from flexsat.dynamics.appendages.sadm import expand_drives

        expanded = expand_drives(config, cls.from_config)
        if expanded is not config:
            return cls.from_config(expanded)
        models = tuple(appendage_model(app.model) for app in config.appendages)
        untuned = cls(
            config=config,
            hub_mass=float(config.hub.mass_kg),
            hub_J=config.hub.inertia(),
            models=models,
            params=tuple(m.pack(app) for m, app in zip(models, config.appendages, strict=True)),
        )
        _check_dense_size(untuned.n_dof)
        diag = np.diag(untuned.mass_matrix())
        tuned = tuple(
            model.tune(app, row, diag[block.slice])
            for model, app, row, block in zip(
                models, config.appendages, untuned.params, untuned.layout.blocks, strict=True
            )
        )
        return untuned._with_params(tuned)

    def _with_params(self, params: tuple[np.ndarray, ...]) -> Plant:
        return Plant(self.config, self.hub_mass, self.hub_J, self.models, params)

    def with_joints(self, stiffness: np.ndarray, damping: np.ndarray) -> Plant:
        """A copy with other joint stiffness and damping, each the diagonal of K_sys and
        C_damp over the appendage coordinates (any shape of n_dof - 6 values)."""
        stiffness = np.asarray(stiffness, dtype=float).ravel()
        damping = np.asarray(damping, dtype=float).ravel()
        start = self.layout.flexible.start
        rows = tuple(
            model.with_joints(row, stiffness[b.slice.start - start : b.slice.stop - start],
                              damping[b.slice.start - start : b.slice.stop - start])
            for model, row, b in zip(self.models, self.params, self.layout.blocks, strict=True)
        )  # fmt: skip
        return self._with_params(rows)

    def _groups(self) -> list[list[int]]:
        """The appendages' indices grouped by model (one kernel call per group)."""
        groups: dict[str, list[int]] = {}
        for i, model in enumerate(self.models):
            groups.setdefault(model.name, []).append(i)
        return list(groups.values())

    def kernel_sets(self) -> tuple[AppendageKernels, ...]:
        """The compiled kernels of each group of appendages
        (:meth:`~flexsat.dynamics.appendages.contract.AppendageModel.group_kernels`).

        Returns
        -------
        tuple of AppendageKernels
            One per group, in the order of ``packed``'s groups.
        """
        return tuple(self.models[g[0]].group_kernels([self.params[i] for i in g])
                     for g in self._groups())  # fmt: skip

    def _pack(self) -> PackedPlant:
        """Group the appendages by model (one kernel call per group) and pack them."""
        members, params, work = [], [], []
        kernel_sets = self.kernel_sets()
        for indices in self._groups():
            offsets = [self.layout.blocks[i].offset for i in indices]
            members.append(np.array([indices, offsets], dtype=np.int64).T.copy())
            # Rows of one model may differ in length (a chain's grows with its segments):
            # the group's array is as wide as its widest row, zero-padded.
            rows = [self.params[i] for i in indices]
            stacked = np.zeros((len(rows), max(len(r) for r in rows)))
            for k, r in enumerate(rows):
                stacked[k, : len(r)] = r
            params.append(stacked)
            model = self.models[indices[0]]
            work.append(np.zeros((len(rows), max(1, *(model.work_columns(r) for r in rows)))))
        hub_J = np.ascontiguousarray(self.hub_J, dtype=float)
        locked = self.locked_coordinates()
        free = np.array([i for i in range(self.layout.n_dof) if i not in locked], dtype=np.int64)
        blocks = enumerate(self.layout.blocks)
        owner = {i: k for k, b in blocks for i in range(b.offset, b.offset + b.count)}
        held = [i for i in locked if self.models[owner[i]].holds_locked]
        projected = len(held) < len(locked)  # some model leaves its locks to the engine
        size = (self.layout.n_dof, free.size) if projected else (1, 1)
        locking = {owner[i] for i in held}  # a joint holding locks transmits inertia
        return PackedPlant(
            n_dof=self.layout.n_dof,
            hub_mass=self.hub_mass,
            hub_J=hub_J,
            hub_J_inv=np.linalg.inv(hub_J),
            articulated=any(m.transmits_inertia or k in locking
                            for k, m in enumerate(self.models)),
            hub=np.zeros(HUB_SIZE),
            constrained=bool(locked),
            held=np.array(held, dtype=np.int64),
            locked=projected,
            free=free,
            mass=np.zeros((size[0], size[0])),
            reduced=np.zeros((size[1], size[1] + 1)),
            is_free=np.isin(np.arange(self.layout.n_dof), free),
            reaction=np.zeros((2, self.layout.n_dof if locked else 1)),
            members=tuple(members),
            params=tuple(params),
            work=tuple(work),
            **{name: tuple(first_class(getattr(k, name), signature) for k in kernel_sets)
               for name, signature in SIGNATURES._asdict().items()},
        )  # fmt: skip

    def locked_coordinates(self) -> tuple[int, ...]:
        """Indices in q of the coordinates held rigid (each appendage's ``locked_dofs``).

        Raises
        ------
        ConfigError
            An appendage locks a name that is not one of its model's coordinates.
        """
        indices = []
        for k, (app, block) in enumerate(zip(self.config.appendages, self.layout.blocks,
                                             strict=True)):  # fmt: skip
            for name in getattr(app, "locked_dofs", ()):
                if name not in block.names:
                    raise ConfigError(
                        f"appendages[{k}].locked_dofs: {name!r} is not a coordinate of a "
                        f"{block.model!r} appendage (allowed: {', '.join(block.names)})"
                    )
                indices.append(block.offset + block.names.index(name))
        return tuple(sorted(indices))

    # -- sizes ----------------------------------------------------------------------------

    @property
    def n_appendages(self) -> int:
        return len(self.models)

    @property
    def n_dof(self) -> int:
        return self.layout.n_dof

    @property
    def stiffness(self) -> np.ndarray:
        """Diagonal of K_sys over the appendage coordinates, shape (n_dof - 6,)."""
        return np.concatenate([m.stiffness(p) for m, p in self._rows()])

    @property
    def damping(self) -> np.ndarray:
        """Diagonal of C_damp over the appendage coordinates, shape (n_dof - 6,)."""
        return np.concatenate([m.damping(p) for m, p in self._rows()])

    def _rows(self) -> zip:
        return zip(self.models, self.params, strict=True)

    def dof_names(self) -> list[str]:
        """Names of the generalized coordinates: hub DOFs, then ``<appendage>.<coordinate>``."""
        return self.layout.dof_names()

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
        kernels.mass_matrix(self._state(q), self._views["mass_matrix"], out)
        return out

    def bias_forces(self, q: np.ndarray, qd: np.ndarray) -> np.ndarray:
        """Coriolis and centrifugal vector h(q, q_dot), shape (n_dof,) (eq. 2.43)."""
        out = np.empty(self.n_dof)
        kernels.bias_forces(self._state(q), self._state(qd), self._views["bias_forces"], out)
        return out

    def stiffness_matrix(self) -> np.ndarray:
        """K_sys = diag(0_6, K_1, ..., K_n), shape (n_dof, n_dof) (eq. 3.4)."""
        return np.diag(np.concatenate([np.zeros(6), self.stiffness]))

    def damping_matrix(self) -> np.ndarray:
        """C_damp = blockdiag(0_6, C_1, ..., C_n), shape (n_dof, n_dof) (eq. 2.47).

        Each appendage's block is its model's ``damping_block``: diagonal, or a modal
        appendage's full modal damping matrix. The kernels apply the diagonal
        (:meth:`damping_forces`) and the rest of a full block in the bias forces h, so
        about rest dh/dq_dot holds that rest and C_damp is the whole damping.
        """
        C = np.zeros((self.n_dof, self.n_dof))
        for model, row, block in zip(self.models, self.params, self.layout.blocks, strict=True):
            C[block.slice, block.slice] = model.damping_block(row)
        return C

    def elastic_forces(self, q: np.ndarray) -> np.ndarray:
        """k_el(q) = K_sys q, shape (n_dof,) (eq. 2.46)."""
        q = self._state(q)
        return np.concatenate([np.zeros(6), self.stiffness * q[6:]])

    def damping_forces(self, qd: np.ndarray) -> np.ndarray:
        """diag(C_damp) q_dot, shape (n_dof,) (eq. 2.47): the damping the kernels apply
        with the joints (a full modal block's off-diagonal rest is in the bias forces)."""
        qd = self._state(qd)
        return np.concatenate([np.zeros(6), self.damping * qd[6:]])

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
            self._state(q), self._state(qd), self._state(Q), self._views["accelerations"], out
        )
        if status != STATUS_OK:
            raise SimulationError(status_message(status))
        return out

    # -- energies, momentum, loads, displacements -----------------------------------------

    def _observe(self, q: np.ndarray, qd: np.ndarray | None = None) -> np.ndarray:
        out = np.empty(OBS_SIZE)
        kernels.observe(self._state(q), self._state(qd), self._views["observe"], out)
        return out

    def kinetic_energy(self, q: np.ndarray, qd: np.ndarray) -> float:
        """T = 1/2 q_dot^T M q_dot, from the bodies' velocities [J] (eq. 2.32)."""
        return float(self._observe(q, qd)[OBS_KINETIC])

    def elastic_energy(self, q: np.ndarray) -> float:
        """U = 1/2 sum_i q_i^T K_i q_i [J] (eq. 2.35)."""
        return float(self._observe(q)[OBS_ELASTIC])

    def dissipation_power(self, qd: np.ndarray) -> float:
        """Power dissipated by the joint dampers, q_dot^T C q_dot = 2 D [W] (eq. 2.36)."""
        return float(self._observe(None, qd)[OBS_DISSIPATION])

    def angular_momentum(self, q: np.ndarray, qd: np.ndarray) -> np.ndarray:
        """Total angular momentum about the inertial origin, frame N, shape (3,) [N m s]."""
        return self._observe(q, qd)[OBS_MOMENTUM : OBS_MOMENTUM + 3].copy()

    def locked_inertia(self, q: np.ndarray) -> np.ndarray:
        """Inertia of the satellite frozen in shape q about the hub centre of mass, B, (3, 3)."""
        return self._observe(q)[OBS_LOCKED_INERTIA : OBS_LOCKED_INERTIA + 9].reshape(3, 3)

    def joint_wrench_on_hub(
        self, q: np.ndarray, qd: np.ndarray, Q: np.ndarray | None = None
    ) -> tuple[np.ndarray, np.ndarray]:
        """Force and torque tau_flex the joints exert on the hub (about its centre of mass).

        The whole wrench each root joint transmits, as the records report it: its
        elastic, damping and external generalized forces and the constraint reactions
        of the directions it does not free (and of locked coordinates), which depend on
        the accelerations q_ddot = M^-1 (Q - h - C q_dot - k_el) the forces ``Q`` give.

        Parameters
        ----------
        q, qd : ndarray, shape (n_dof,)
            Generalized coordinates [m, rad] and rates [m/s, rad/s].
        Q : ndarray, shape (n_dof,), optional
            External generalized forces, hub rows included (:meth:`generalized_forces`)
            [N, N m per coordinate]; default none.

        Returns
        -------
        force_B, torque_B : ndarray, shape (3,)
            In hub frame B [N], [N m]; zero at rest and undeformed.

        Raises
        ------
        SimulationError
            At a ZYX Euler-angle singularity of the hub or of a joint.
        """
        q, qd, Q = self._state(q), self._state(qd), self._state(Q)
        view = self._views["joint_wrench"]
        qdd, joint, out = np.empty(self.n_dof), np.empty(self.n_dof), np.empty(6)
        status = kernels.accelerations(q, qd, Q, view, qdd)
        if status == STATUS_OK:
            kernels.joint_forces(Q, view, joint)  # as the records do
            status = kernels.hub_joint_wrench(q, qd, qdd, joint, view, out)
        if status != STATUS_OK:
            raise SimulationError(status_message(status))
        return out[:3].copy(), out[3:].copy()

    def tip_displacement(self, q: np.ndarray) -> np.ndarray:
        """Tip displacement of each appendage from its undeformed place, mount frames,
        (n, 3) [m]."""
        out = np.zeros((self.n_appendages, 3))
        kernels.tip_displacement(self._state(q), self._views["tips"], out)
        return out


# The dense n x n float64 arrays the modal analysis holds at once: M, K and C, the
# eigenvectors and the generalized eigensolver's own copies of M and K.
_DENSE_COPIES = 6


def _check_dense_size(n_dof: int) -> None:
    """Refuse, before any n x n matrix is built, a plant whose modal analysis cannot fit
    in half the machine's memory; the message gives the estimate."""
    import os

    need = _DENSE_COPIES * 8.0 * float(n_dof) ** 2
    try:
        memory = float(os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES"))
    except (ValueError, OSError, AttributeError):  # not reported: assume 8 GiB
        memory = 8.0 * 2**30
    if need > 0.5 * memory:
        raise ConfigError(
            f"appendages: the satellite has {n_dof} coordinates; its dense {n_dof} x {n_dof} "
            f"matrices (mass, stiffness, damping, modes) need about {need / 2**30:.1f} GiB, "
            f"more than half this machine's memory ({0.5 * memory / 2**30:.1f} GiB): use "
            "fewer appendages or segments"
        )
