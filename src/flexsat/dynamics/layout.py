"""Where every piece of the integrated state lives.

The plant builds one :class:`StateLayout`; every consumer (initial states, records,
results, modal classification, plots) asks it instead of re-deriving offsets. The
integrated (augmented) state is::

    x = [q (n_dof), q_dot (n_dof), W_in, W_diss]

with q = [hub (6): r_N (3) [m], Theta (3) ZYX Euler angles [rad]; then each
appendage's coordinate block, in config order]. W_in is the work of the applied
torque and W_diss the energy dissipated by the dampers [J], both integrated with the
motion (:mod:`flexsat.dynamics.integrators`).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

from flexsat.errors import ConfigError

__all__ = ["HUB_DOFS", "HUB_UNITS", "CoordinateBlock", "StateLayout"]

HUB_DOFS = ("x", "y", "z", "phi", "theta", "psi")
HUB_UNITS = ("m", "m", "m", "rad", "rad", "rad")


@dataclass(frozen=True)
class CoordinateBlock:
    """The coordinates of one appendage: q[offset : offset + count].

    Parameters
    ----------
    appendage : str
        The appendage's name.
    model : str
        Its model's registry key (``"plate"``, ``"chain"``, ``"modal"``...).
    offset : int
        Index of its first coordinate in q.
    names : tuple of str
        Its coordinates' names, in order.
    units : tuple of str
        Their units (``"m"``, ``"rad"``, ``"m sqrt(kg)"``...).
    """

    appendage: str
    model: str
    offset: int
    names: tuple[str, ...]
    units: tuple[str, ...]

    @property
    def count(self) -> int:
        return len(self.names)

    @property
    def slice(self) -> slice:
        return slice(self.offset, self.offset + self.count)


@dataclass(frozen=True)
class StateLayout:
    """Offsets of q, q_dot, each appendage's coordinates and the energy accumulators.

    Parameters
    ----------
    blocks : tuple of CoordinateBlock
        One per appendage, in config order (the hub's six coordinates come first).
    """

    blocks: tuple[CoordinateBlock, ...]

    hub = slice(0, 6)
    position = slice(0, 3)  # r_N, hub centre of mass, frame N [m]
    attitude = slice(3, 6)  # Theta, ZYX Euler angles [rad]

    @classmethod
    def build(cls, appendages: list[tuple[str, str, tuple[str, ...], tuple[str, ...]]]
              ) -> StateLayout:  # fmt: skip
        """From (appendage name, model name, coordinate names, units), in config order."""
        blocks, offset = [], len(HUB_DOFS)
        for name, model, names, units in appendages:
            blocks.append(CoordinateBlock(name, model, offset, tuple(names), tuple(units)))
            offset += len(names)
        return cls(tuple(blocks))

    @property
    def n_dof(self) -> int:
        """Number of generalized coordinates."""
        return len(HUB_DOFS) + sum(b.count for b in self.blocks)

    @property
    def flexible(self) -> slice:
        """All appendage coordinates, q[6:]."""
        return slice(len(HUB_DOFS), self.n_dof)

    @property
    def q(self) -> slice:
        return slice(0, self.n_dof)

    @property
    def qd(self) -> slice:
        return slice(self.n_dof, 2 * self.n_dof)

    @property
    def work_in(self) -> int:
        """Index of W_in in x."""
        return 2 * self.n_dof

    @property
    def dissipated(self) -> int:
        """Index of W_diss in x."""
        return 2 * self.n_dof + 1

    @property
    def size(self) -> int:
        """Length of the augmented state x."""
        return 2 * self.n_dof + 2

    def block(self, appendage: str) -> CoordinateBlock:
        """The block of the appendage called ``appendage``."""
        for b in self.blocks:
            if b.appendage == appendage:
                return b
        raise KeyError(
            f"unknown appendage {appendage!r} (the satellite has "
            f"{', '.join(b.appendage for b in self.blocks)})"
        )

    def dof_names(self) -> list[str]:
        """Hub DOF names, then ``<appendage>.<coordinate>``."""
        names = list(HUB_DOFS)
        for b in self.blocks:
            names += [f"{b.appendage}.{n}" for n in b.names]
        return names

    def appendage_indices(self, names: Sequence[str], field: str) -> list[int]:
        """Indices in q of named appendage coordinates, each once, in the order named.

        Parameters
        ----------
        names : sequence of str
            ``"<appendage>.<coordinate>"``, or ``"<coordinate>"`` for that coordinate
            of every appendage that has it.
        field : str
            The configuration field or argument the names come from (for the message).

        Raises
        ------
        ConfigError
            For a name that is no appendage coordinate; the message lists them.
        """
        all_names = self.dof_names()
        out: list[int] = []
        for name in names:
            if "." in name:
                found = [all_names.index(name)] if name in all_names[6:] else []
            else:
                found = [i for i, full in enumerate(all_names) if full.split(".", 1)[-1] == name
                         and "." in full]  # fmt: skip
            if not found:
                raise ConfigError(f"{field}: unknown coordinate {name!r} (the plant's appendage "
                                  f"coordinates: {', '.join(all_names[6:])})")  # fmt: skip
            out += [i for i in found if i not in out]
        return out

    def dof_units(self) -> list[str]:
        units = list(HUB_UNITS)
        for b in self.blocks:
            units += list(b.units)
        return units
