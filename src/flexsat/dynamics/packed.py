"""The plant packed for the compiled code: one named, numba-typeable structure.

:class:`PackedPlant` replaces the positional argument tuples of earlier versions.
numba types it as a named tuple of arrays and of tuples of first-class functions
(typed by signature, see :mod:`flexsat.dynamics.appendages.contract`), so the RK4
loops compile once per number of appendage groups and are cached on disk.

Appendages are grouped by model: one kernel call processes a whole group.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
from numba import types
from numba.core.datamodel.models import TupleModel
from numba.core.typing.typeof import typeof_impl
from numba.extending import register_model

__all__ = ["PackedPlant", "only"]


class PackedPlant(NamedTuple):
    """Hub, groups of appendages and their kernels, for :mod:`flexsat.dynamics.kernels`.

    Attributes
    ----------
    n_dof : int
        Number of generalized coordinates.
    hub_mass : float
        [kg].
    hub_J, hub_J_inv : ndarray, shape (3, 3)
        Hub inertia about its centre of mass, frame B, and its inverse [kg m^2].
    articulated : bool
        True if an appendage transmits articulated inertia (then the hub solve is the
        6 x 6 system, solved by 3 x 3 block elimination; else the bare hub's
        Newton-Euler equations).
    hub : ndarray, shape (HUB_SIZE,)
        Exchange array between the engine and the kernels (scratch, overwritten by
        every evaluation; slots in the contract module) [SI per slot].
    constrained : bool
        True if some appendage coordinates are locked (held at their initial value) [-];
        ``reaction[1]`` then holds their constraint forces.
    held : ndarray, shape (n_held,), int64
        Indices [-] of the locked coordinates whose model holds them itself (``holds_locked``): its
        pass 2 leaves their constraint forces in ``qdd``.
    locked : bool
        True if some locked coordinates belong to a model that does not hold them:
        q_ddot is then projected on the free coordinates (:mod:`flexsat.dynamics.kernels`).
    free : ndarray, shape (n_free,), int64
        Indices of the free coordinates (all of them when nothing is locked) [-].
    mass : ndarray, shape (n_dof, n_dof)
        Scratch of M(q) for the projection (1 x 1 when nothing is locked) [kg, kg m,
        kg m^2].
    reduced : ndarray, shape (n_free, n_free + 1)
        Scratch of the free-coordinate solve (1 x 2 when nothing is locked) [SI].
    is_free : ndarray, shape (n_dof,), bool
        Per coordinate: free (True) or locked [-].
    reaction : ndarray, shape (2, n_dof)
        Scratch: the unconstrained q_ddot, then the generalized constraint forces of
        the locked coordinates left by the last evaluation (2 x 1 when none)
        [m/s^2, rad/s^2; N, N m].
    members : tuple of ndarray, shape (k_g, 2), int64
        Per group: appendage index and offset of its first coordinate in q [-].
    params : tuple of ndarray, shape (k_g, p_g)
        Per group: each member's packed parameter row [SI, per the model's layout].
    work : tuple of ndarray, shape (k_g, w_g)
        Per group: scratch rows pass 1 leaves for pass 2 (``work_size`` of the model)
        [SI].
    pass1, pass2, mass_matrix, bias_forces, observe, joint_wrench, tips : tuple
        Per group: the model's compiled kernels.
    """

    n_dof: int
    hub_mass: float
    hub_J: np.ndarray
    hub_J_inv: np.ndarray
    articulated: bool
    hub: np.ndarray
    constrained: bool
    held: np.ndarray
    locked: bool
    free: np.ndarray
    mass: np.ndarray
    reduced: np.ndarray
    is_free: np.ndarray
    reaction: np.ndarray
    members: tuple
    params: tuple
    work: tuple
    pass1: tuple
    pass2: tuple
    mass_matrix: tuple
    bias_forces: tuple
    observe: tuple
    joint_wrench: tuple
    tips: tuple


class PackedPlantType(types.NamedTuple):
    """numba type of a :class:`PackedPlant`: a named tuple whose hash is computed once.

    numba hashes an argument's type on every call from Python; for this deeply nested
    type (tuples of first-class function types) that alone would cost tens of
    microseconds per call.
    """

    def __hash__(self) -> int:
        cached = self.__dict__.get("_hash")
        if cached is None:
            cached = self.__dict__["_hash"] = hash(self.key)
        return cached

    def __reduce__(self):
        # The cached hash is per process (it hashes class objects): never pickle it.
        rebuild, (reconstructor, args, state) = super().__reduce__()
        state = {k: v for k, v in (state or {}).items() if k != "_hash"}
        return rebuild, (reconstructor, args, state)


register_model(PackedPlantType)(TupleModel)

_KERNEL_FIELDS = ("pass1", "pass2", "mass_matrix", "bias_forces", "observe", "joint_wrench",
                  "tips")  # fmt: skip
_TYPES: dict[tuple[int, ...], PackedPlantType] = {}


def only(packed: PackedPlant, *kernels: str) -> PackedPlant:
    """``packed`` with only the named kernel tuples kept (the others empty).

    A call from Python unboxes every first-class function it is given (a few
    microseconds each); a single-kernel evaluation such as M(q) passes only its own.

    Parameters
    ----------
    packed : PackedPlant
        The full packed plant.
    *kernels : str
        Names of the kernel tuples to keep (``"mass_matrix"``, ``"observe"``...).

    Returns
    -------
    PackedPlant
        A copy sharing every array, the other kernel tuples empty.
    """
    return packed._replace(**{name: () for name in _KERNEL_FIELDS if name not in kernels})


@typeof_impl.register(PackedPlant)
def _typeof_packed(value: PackedPlant, context) -> PackedPlantType:
    """numba type of a PackedPlant, computed once per number of groups.

    The type depends on the number of groups and of kernels in each tuple only
    (:meth:`flexsat.dynamics.plant.Plant._pack` always builds the same dtypes and
    layouts, and every kernel has its contract signature), so it is cached by those
    numbers instead of typing every field on every call.
    """
    shape = (*(len(getattr(value, name)) for name in _KERNEL_FIELDS), len(value.members))
    if shape not in _TYPES:
        generic = typeof_impl.dispatch(tuple)(value, context)
        _TYPES[shape] = PackedPlantType(generic.types, PackedPlant)
    return _TYPES[shape]
