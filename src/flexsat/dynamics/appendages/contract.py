"""The appendage-model contract: what a model declares and the compiled kernels it provides.

The plant is a hub plus a list of appendages, each an instance of a registered
:class:`AppendageModel`. The engine (:mod:`flexsat.dynamics.kernels`) knows no model:
it calls each model's compiled kernels through numba first-class functions, one
call per *group* (all appendages of one model), in the general articulated-body
form:

1. ``pass1``: for every member, the wrench its joint exerts on the hub (added to
   the hub exchange array ``hub``) and, if the model transmits inertia, its
   articulated inertia as seen at the hub (6 x 6, hub frame B, about the hub centre
   of mass, ordered [force; torque] x [a_hub; omega_dot]); its wrench is then the
   one at zero hub acceleration.
2. the engine solves the hub: the bare hub's Newton-Euler equations when no
   appendage transmits inertia (a model on a full 6-DOF joint does not: the Schur
   complement collapses to the hub's own mass matrix), else the 6 x 6 system with
   the summed articulated inertias;
3. ``pass2``: the member's coordinate accelerations given the hub's acceleration.

Every kernel is a numba function compiled with its signature below: numba then types
a tuple of them by signature, so the engine's loops compile once and run any model,
built-in or a user's own from their own file, at full speed. Declared
``@njit(cache=True)``, a kernel is compiled with its signature when the first plant
uses its model (:func:`flexsat.compiled.first_class.first_class`), so importing flexsat
compiles no model a run does not use (the built-in models are declared so);
declared ``@njit(<its signature>, cache=True)``, it is compiled at import.

Arguments common to the kernels: ``q``, ``qd``, ``Q`` (n_dof,) generalized
coordinates, rates and external forces of the whole plant; ``members`` (k, 2) int64,
per member its appendage index and the offset of its first coordinate in q;
``params`` (k, p) float64, per member the row :meth:`AppendageModel.pack` built.
"""

from __future__ import annotations

from abc import ABC, abstractmethod
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import Any, ClassVar, NamedTuple

import numpy as np
from numba import types
from pydantic import BaseModel

__all__ = [
    "BIAS_SIGNATURE",
    "HUB_ACC",
    "HUB_ALPHA",
    "HUB_DISSIPATION",
    "HUB_FORCE",
    "HUB_INERTIA",
    "HUB_OMEGA",
    "HUB_SBIAS",
    "HUB_SIZE",
    "HUB_TORQUE",
    "MASS_SIGNATURE",
    "OBSERVE_SIGNATURE",
    "OBS_DISSIPATION",
    "OBS_ELASTIC",
    "OBS_KINETIC",
    "OBS_LOCKED_INERTIA",
    "OBS_MOMENTUM",
    "OBS_SIZE",
    "PASS1_SIGNATURE",
    "PASS2_SIGNATURE",
    "SIGNATURES",
    "TIPS_SIGNATURE",
    "WRENCH_SIGNATURE",
    "AppendageKernels",
    "AppendageModel",
    "Coordinate",
    "DerivedPath",
    "RigidBody",
]

# Slots of the hub exchange array ``hub`` (float64, shape (HUB_SIZE,)).
HUB_OMEGA = 0  # (3) omega_B, hub body rate, frame B [rad/s]; set by the engine
HUB_FORCE = 3  # (3) force on the hub, frame B [N] (frame N in bias_forces); accumulated
HUB_TORQUE = 6  # (3) torque on the hub about its centre of mass, frame B [N m]; accumulated
HUB_ACC = 9  # (3) a_hub, hub centre-of-mass acceleration, frame B [m/s^2]; read in pass 2
HUB_ALPHA = 12  # (3) omega_dot_B [rad/s^2]; read in pass 2
HUB_INERTIA = 15  # (36) summed articulated inertia, row-major 6 x 6; accumulated in pass 1
HUB_DISSIPATION = 51  # (1) damper power q_dot^T C q_dot [W] (eq. 2.36); accumulated in pass 1
HUB_SBIAS = 52  # (3) S_dot(Theta) Theta_dot, omega_dot at Theta_ddot = 0 [rad/s^2]; bias_forces
HUB_SIZE = 55

# Slots of the observables vector ``out`` of ``observe`` (float64, shape (OBS_SIZE,)).
OBS_KINETIC = 0  # (1) kinetic energy T [J] (eqs. 2.32-2.34)
OBS_MOMENTUM = 1  # (3) angular momentum about the inertial origin, frame N [N m s]
OBS_LOCKED_INERTIA = 4  # (9) locked inertia J(eta) about the hub centre of mass, frame B
OBS_ELASTIC = 13  # (1) elastic energy U [J] (eq. 2.35)
OBS_DISSIPATION = 14  # (1) damper power q_dot^T C q_dot [W] (eq. 2.36)
OBS_SIZE = 15

_v = types.float64[::1]
_m = types.float64[:, ::1]
_i = types.int64[:, ::1]

PASS1_SIGNATURE = types.int64(_v, _v, _v, _i, _m, _m, _v, _v)
"""``pass1(q, qd, Q, members, params, work, hub, qdd) -> status``: joint wrench on the
hub (added to ``hub[HUB_FORCE]``, ``hub[HUB_TORQUE]``), articulated inertia (added to
``hub[HUB_INERTIA]``), damper power (added to ``hub[HUB_DISSIPATION]``); may keep
intermediate results in its own rows of ``qdd`` and in ``work`` (k, work_size), its
scratch for pass 2."""
PASS2_SIGNATURE = types.int64(_v, _v, _i, _m, _m, _v, _v)
"""``pass2(q, qd, members, params, work, hub, qdd) -> status``: the member's rows of
q_ddot from ``hub[HUB_ACC]`` and ``hub[HUB_ALPHA]``."""
MASS_SIGNATURE = types.void(_v, _i, _m, _m)
"""``mass_matrix(q, members, params, M)``: add the member's share of M(q) (eq. 2.39):
its blocks and its share of the hub block."""
BIAS_SIGNATURE = types.void(_v, _v, _i, _m, _v, _v)
"""``bias_forces(q, qd, members, params, hub, h)``: add its share of h(q, q_dot)
(eq. 2.43): its rows of ``h``, the force on the hub in frame N to
``hub[HUB_FORCE]``, the torque in B to ``hub[HUB_TORQUE]``; reads ``hub[HUB_OMEGA]``
and ``hub[HUB_SBIAS]``."""
OBSERVE_SIGNATURE = types.void(_v, _v, _i, _m, _v)
"""``observe(q, qd, members, params, out)``: add to the observables (``OBS_*`` slots)."""
WRENCH_SIGNATURE = types.int64(_v, _v, _v, _v, _i, _m, _v)
"""``joint_wrench(q, qd, qdd, Q, members, params, out) -> status``: add the wrench its
root joint transmits to the hub, ``out`` (6,) = [force_B, torque_B about the hub centre
of mass] (tau_flex): its elastic, damping and external generalized forces ``Q`` and,
where the joint does not free a direction, its constraint reaction. ``qdd`` (n_dof,) is
the whole plant's q_ddot at (q, qd) (hub rows included), for a model whose reaction
depends on the accelerations; a model that needs none ignores it. The model reads
its own rows of ``Q`` (n_dof,): the generalized forces on its coordinates (joint
actuations, the constraint forces of coordinates the engine locks); a model whose
wrench comes from ``qdd`` has their effect there already and ignores ``Q``."""
TIPS_SIGNATURE = types.void(_v, _i, _m, _m)
"""``tips(q, members, params, out)``: write row ``members[j, 0]`` of ``out`` (n, 3): the
tip displacement from the undeformed place, mount frame [m]."""


class DerivedPath(NamedTuple):
    """A campaign modifier path that an appendage model computes instead of reading a
    config field (``appendages[*].<name>``, the name possibly dotted).

    It lets one campaign file disperse any appendage model: the thesis's dispersions
    (``damping_ratio``, ``target_frequencies_hz.flapping``, ``sadm_angle_deg``, ...)
    are the plate's own fields, and a chain maps them to its joints, its beam table
    and its mount (docs/campaigns.md, 'Modifier paths on any appendage model').

    Attributes
    ----------
    apply : callable
        ``apply(table, value)`` changes the appendage's plain-dict table in place [-].
    ops : tuple of str
        The modifier ops it takes, ``"set"`` and/or ``"scale"`` [-].
    factor : bool
        True when the value is a scale factor (the campaign tables then label its
        column ``[factor]``); False when it is the physical value, in the unit its
        name states [-].
    """

    apply: Callable[[dict, float], None]
    ops: tuple[str, ...] = ("set", "scale")
    factor: bool = True


class AppendageKernels(NamedTuple):
    """The compiled kernels of one model, each with the signature of the same name.

    Attributes
    ----------
    pass1 : numba dispatcher
        Outward pass of q̈: the appendage's reaction on the hub.
    pass2 : numba dispatcher
        Inward pass: the appendage's accelerations once the hub's are known.
    mass_matrix : numba dispatcher
        Its blocks of M(q).
    bias_forces : numba dispatcher
        Its part of h(q, q̇).
    observe : numba dispatcher
        Its energies, momentum and locked inertia.
    joint_wrench : numba dispatcher
        The wrench its root joint puts on the hub.
    tips : numba dispatcher
        Displacement of its tip points.
    """

    pass1: Any
    pass2: Any
    mass_matrix: Any
    bias_forces: Any
    observe: Any
    joint_wrench: Any
    tips: Any


SIGNATURES = AppendageKernels(
    PASS1_SIGNATURE, PASS2_SIGNATURE, MASS_SIGNATURE, BIAS_SIGNATURE, OBSERVE_SIGNATURE,
    WRENCH_SIGNATURE, TIPS_SIGNATURE,
)  # fmt: skip
"""The signature each kernel of :class:`AppendageKernels` must be compiled with."""


@dataclass(frozen=True)
class Coordinate:
    """One generalized coordinate of an appendage: its name and SI unit.

    Attributes
    ----------
    name : str
        Name in the state layout and the result (e.g. ``"flapping"``).
    unit : str
        Its SI unit (``"m"``, ``"rad"``).
    """

    name: str
    unit: str


@dataclass(frozen=True)
class RigidBody:
    """An appendage frozen undeformed.

    Attributes
    ----------
    mass : float
        Its mass [kg].
    r_B : ndarray, shape (3,)
        Its centre of mass from the hub centre of mass, hub frame B [m].
    J_B : ndarray, shape (3, 3)
        Its inertia about its own centre of mass, hub frame B [kg m^2].
    """

    mass: float
    r_B: np.ndarray
    J_B: np.ndarray


class AppendageModel(ABC):
    """Contract of an appendage model. Subclass it, then register one instance with
    :func:`flexsat.dynamics.appendages.register_appendage_model`.

    Attributes
    ----------
    name : str
        The ``model = "<name>"`` key of the satellite TOML's appendage table.
    config_class : type[pydantic.BaseModel]
        The validated parameters of one appendage; must have ``name: str`` and
        ``model: Literal["<name>"]``.
    kernels : AppendageKernels
        The compiled kernels (signatures in this module), right for any group of
        the model's appendages (:meth:`group_kernels` may pick leaner ones).
    transmits_inertia : bool
        False for a model on a full 6-DOF joint (the engine then skips the 6 x 6
        hub solve); True when ``pass1`` adds an articulated inertia.
    holds_locked : bool
        True when the model's kernels hold its locked coordinates themselves
        (docs/model.md, 'Locked coordinates'): :meth:`pack` marks them in the row,
        ``pass1`` then adds the locked joint's articulated inertia (the engine runs
        the 6 x 6 hub solve for a plant with such a member) and ``pass2`` leaves in
        each locked row of ``qdd`` its constraint force lambda, which the engine
        moves to the plant's constraint forces and replaces by 0. False (default):
        the engine projects the kernels' unconstrained answer with M(q).
    holds_drive : bool
        True when the model's own coordinates and kernels hold a solar-array drive (its
        config's ``drive`` key; the modal model): the plant builds it as it is, without
        :meth:`on_drive`. False (default): a driven appendage is rewritten by
        :meth:`on_drive`.
    work_size : int
        Columns of the scratch rows ``work`` that pass 1 may leave for pass 2 (see
        :meth:`work_columns` for a scratch that grows with the appendage).
    modifiers : dict
        Derived campaign modifier paths beyond the config's own fields: name (dotted
        for a nested path) -> :class:`DerivedPath` (``appendages[*].<name>``). A
        config field of the same name takes precedence.
    """

    name: ClassVar[str]
    config_class: ClassVar[type[BaseModel]]
    kernels: ClassVar[AppendageKernels]
    transmits_inertia: ClassVar[bool] = False
    holds_locked: ClassVar[bool] = False
    holds_drive: ClassVar[bool] = False
    modifiers: ClassVar[dict[str, DerivedPath]] = {}
    work_size: ClassVar[int] = 0

    @abstractmethod
    def coordinates(self, config: BaseModel) -> tuple[Coordinate, ...]:
        """The appendage's generalized coordinates, in their order in q."""

    @abstractmethod
    def pack(self, config: BaseModel) -> np.ndarray:
        """The packed parameter row of one appendage, shape (p,), before tuning."""

    @abstractmethod
    def rigid_body(self, params: np.ndarray) -> RigidBody:
        """The appendage frozen undeformed (rigid design model, thesis appendix A.4)."""

    def rigid_body_at(self, params: np.ndarray, q_block: np.ndarray) -> RigidBody:
        """The appendage frozen at its coordinates ``q_block`` (count,) [m, rad].

        What a design model that follows a moving mount (a solar-array drive's angle)
        asks. Default: the undeformed body, only at ``q_block`` = 0 (ValueError
        otherwise); a model whose rigid shape follows its coordinates (the chain)
        overrides it.
        """
        if np.any(q_block):
            raise ValueError(f"the {self.name!r} model freezes only undeformed (q = 0)")
        return self.rigid_body(params)

    def tune(self, config: BaseModel, params: np.ndarray, inertia_diag: np.ndarray) -> np.ndarray:
        """The parameter row with stiffness and damping tuned (thesis section 2.2.3).

        ``inertia_diag`` is the appendage's block of diag M(0), shape (count,).
        Default: nothing to tune.
        """
        return params

    def stiffness(self, params: np.ndarray) -> np.ndarray:
        """Diagonal of its block of K_sys (eq. 3.4), shape (count,). Default: none."""
        return np.zeros(0)

    def damping(self, params: np.ndarray) -> np.ndarray:
        """Diagonal of its block of C_damp (eq. 2.47), shape (count,). Default: none."""
        return np.zeros(0)

    def damping_block(self, params: np.ndarray) -> np.ndarray:
        """Its whole block of C_damp (eq. 2.47), shape (count, count). Default:
        ``diag(damping(params))``; a model with coupled damping gives the full block (its
        kernels apply the diagonal with the joints, the rest in their bias forces h)."""
        return np.diag(self.damping(params))

    def with_joints(self, params: np.ndarray, stiffness: np.ndarray, damping: np.ndarray
                    ) -> np.ndarray:  # fmt: skip
        """The parameter row with other stiffness and damping diagonals, each (count,)."""
        if np.size(stiffness) or np.size(damping):
            raise ValueError(f"a {self.name!r} appendage has no stiffness or damping")
        return params

    def initial_state(self, config: BaseModel, entry: Any) -> tuple[np.ndarray, np.ndarray]:
        """Its rows of q(0) and q_dot(0) from a scenario's ``initial.appendages`` entry."""
        raise ValueError(
            f"initial.appendages: {config.name!r} is a {self.name!r} appendage, which has "
            "no initial state to set"
        )

    def group_kernels(self, rows: Sequence[np.ndarray]) -> AppendageKernels:
        """The kernels one group of this model's appendages runs, from their packed
        rows (each (p,)). Default: :attr:`kernels`; a model may return a set compiled
        for what the group needs (the plate without locked joint DOFs)."""
        return self.kernels

    def work_columns(self, params: np.ndarray) -> int:
        """Columns of the scratch row one member with packed row ``params`` needs (a
        model whose scratch grows with its size overrides it). Default: ``work_size``."""
        return self.work_size

    def default_state(self, config: BaseModel) -> tuple[np.ndarray, np.ndarray]:
        """Its rows of q(0) and q_dot(0) before any scenario entry (a model whose config
        holds an initial state overrides it). Default: at rest, undeformed."""
        count = len(self.coordinates(config))
        return np.zeros(count), np.zeros(count)

    def describe(self, config: BaseModel, params: np.ndarray) -> dict:
        """Derived properties for reports and ``flexsat config`` (JSON-ready). Default:
        the rigid body's mass [kg] and inertia about its centre of mass in B [kg m^2]."""
        body = self.rigid_body(params)
        return {"mass_kg": body.mass, "inertia_B_kg_m2": body.J_B.tolist()}

    def shape_points(self, config: BaseModel, params: np.ndarray, q_block: np.ndarray
                     ) -> np.ndarray:  # fmt: skip
        """Drawable points at coordinates ``q_block`` (count,), hub frame B [m], shape (6, 3).

        Rows 0-3: a closed quadrilateral outline; row 4: its root (where the arm from
        the hub surface ends); row 5: its tip. Default: all at its undeformed centre
        of mass (a rigid body drawn as a point).
        """
        return np.tile(self.rigid_body(params).r_B, (6, 1))

    def target_frequencies(self, config: BaseModel) -> tuple[tuple[str, float], ...]:
        """The clamped-root target frequencies its config asks for, as (label, Hz) pairs
        (labels such as ``flapping``, ``in-plane``, ``translation x``). Default: none."""
        return ()

    def outlines(self, config: BaseModel, params: np.ndarray, q_block: np.ndarray
                 ) -> np.ndarray:  # fmt: skip
        """The quadrilaterals it is drawn as at ``q_block``, hub frame B [m], shape (k, 4, 3)
        (a model of several bodies draws each). Default: the outline of
        :meth:`shape_points`."""
        return self.shape_points(config, params, q_block)[None, 0:4]

    def extent(self, config: BaseModel) -> float:
        """Characteristic length [m] that plots relate tip motion to; 0: none."""
        return 0.0

    def mode_kinds(self, config: BaseModel) -> tuple[str, ...]:
        """A label per coordinate for modal classification: a mode is of the kind whose
        coordinates hold most of its strain energy. Default: the coordinate names."""
        return tuple(c.name for c in self.coordinates(config))

    def root_motion(self, q_block: np.ndarray, names: tuple[str, ...] = ()
                    ) -> tuple[np.ndarray, np.ndarray]:  # fmt: skip
        """Root translation eta [m] and rotation rho [rad] of its joint, each (m, 3),
        from recorded coordinates (or rates) ``q_block`` (m, count) named ``names`` (its
        coordinate names, in order). Default: NaN (the model has no root joint of that
        form)."""
        nan = np.full((q_block.shape[0], 3), np.nan)
        return nan, nan.copy()

    def on_drive(self, config: BaseModel, params: np.ndarray) -> BaseModel | None:
        """The appendage on its solar-array drive, written as a model without one, or None.

        A model whose config has a ``drive`` key (a
        :class:`~flexsat.config.models.DriveConfig`) returns, when it is set, the
        appendage as a chain whose segment 0 is the drive rotor on a free revolute
        joint (``eta_ry_0``, the drive angle) and whose joints keep the stiffness and
        damping of ``params``, the row tuned with the drive held (docs/model.md,
        'Driven mount coordinate (SADM)'). The plant builds every driven appendage
        through this hook (:func:`flexsat.dynamics.appendages.sadm.expand_drives`).
        Default: None, the mount is fixed.
        """
        return None

    def mirror_block(self, params_i: np.ndarray, params_j: np.ndarray, reflect: np.ndarray,
                     rtol: float) -> np.ndarray | None:  # fmt: skip
        """The map from appendage i's coordinates to j's under a hub reflection, or None.

        ``reflect`` (3, 3) is the reflection in B. None when j is not i's mirror image.
        """
        return None
