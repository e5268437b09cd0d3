"""What every pluggable control-loop piece shares: recorded channels, a named registry
and the validation of its parameter tables.

Control laws (:mod:`flexsat.control.laws`) and loop stages
(:mod:`flexsat.control.stages`) are each found through a :class:`Registry`. A piece
is one module that builds its specification and registers it with one line; nothing
else in flexsat names it. Third-party pieces in an installed package are found
through the entry-point groups ``flexsat.laws``, ``flexsat.sensors`` and
``flexsat.actuators``: each entry point names a module whose import registers it.
"""

from __future__ import annotations

import difflib
from collections.abc import Callable, Iterator
from dataclasses import dataclass
from importlib.metadata import entry_points
from typing import Any, Generic, TypeVar

from pydantic import BaseModel
from pydantic_core import PydanticCustomError

__all__ = ["Channel", "Registry", "channel_columns"]


@dataclass(frozen=True)
class Channel:
    """One recorded quantity of a law (a diagnostic) or of a stage.

    Parameters
    ----------
    name : str
        Variable name in the result dataset (``sliding_variable``).
    units : str
        Units of the value as recorded (SI: ``rad/s``, ``N m``, ``1``).
    description : str
        One line for the dataset and the docs.
    per_axis : bool
        True: three columns (body axes x, y, z, dims ``(time, axis)``); False: one.
    per_unit : int
        More than 0 (and not ``per_axis``): one column for each of that many units of
        the stage, e.g. the wheels of a cluster (dims ``(time, unit)``, column k for
        unit k + 1; a stage with fewer units records NaN in the others).
    """

    name: str
    units: str
    description: str
    per_axis: bool = False
    per_unit: int = 0

    @property
    def size(self) -> int:
        return 3 if self.per_axis else max(self.per_unit, 1)


def channel_columns(channels: tuple[Channel, ...]) -> dict[str, slice]:
    """Columns of each channel in a record row holding ``channels`` in order.

    Parameters
    ----------
    channels : tuple of Channel
        The channels, in record order.

    Returns
    -------
    dict of str to slice
        Each channel's columns, by name.
    """
    columns, start = {}, 0
    for c in channels:
        columns[c.name] = slice(start, start + c.size)
        start += c.size
    return columns


Spec = TypeVar("Spec")


class Registry(Generic[Spec]):
    """Named specifications of one kind of piece (laws, sensors or actuators).

    Parameters
    ----------
    what : str
        What the pieces are, for messages (``"control law"``).
    group : str
        Entry-point group searched once, on first look-up, for installed pieces.
    """

    def __init__(self, what: str, group: str) -> None:
        self.what, self.group = what, group
        self._specs: dict[str, Spec] = {}
        self._unlisted: set[str] = set()
        self._default: str | None = None
        self._discovered = False

    def register(self, name: str, spec: Spec, default: bool = False, listed: bool = True) -> Spec:
        """Add (or replace) ``spec`` under ``name``; ``default``: used when a table has no kind;
        ``listed=False``: a table may name it, but :meth:`names` (what runs "every piece",
        e.g. the laws compared) leaves it out."""
        self._specs[name] = spec
        self._unlisted.discard(name)
        if not listed:
            self._unlisted.add(name)
        if default:
            self._default = name
        return spec

    def unregister(self, name: str) -> Spec:
        """Remove the specification registered as ``name`` and return it."""
        if name not in self._specs:
            raise ValueError(f"no {self.what} {name!r} is registered")
        spec = self._specs.pop(name)
        self._unlisted.discard(name)
        if self._default == name:
            self._default = None
        return spec

    def names(self) -> tuple[str, ...]:
        """Every listed name, built-ins first, in registration order."""
        self._discover()
        return tuple(name for name in self._specs if name not in self._unlisted)

    def get(self, name: str) -> Spec:
        """The specification registered as ``name``; ValueError listing the names if none."""
        self._discover()
        try:
            return self._specs[name]
        except KeyError:
            raise ValueError(
                f"unknown {self.what} {name!r}: must be one of {', '.join(self._specs)}"
            ) from None

    @property
    def default(self) -> str:
        self._discover()
        if self._default is None:
            raise LookupError(f"no default {self.what} registered")
        return self._default

    def __iter__(self) -> Iterator[Spec]:
        return iter(self._specs[name] for name in self.names())

    def _discover(self) -> None:
        if self._discovered:
            return
        self._discovered = True
        for point in entry_points(group=self.group):
            point.load()  # importing the module registers its pieces

    def validate_table(self, value: Any, config_of: Callable[[Spec], type[BaseModel]]) -> Any:
        """Validate a parameter table (a dict from TOML) as the model of the piece it names.

        A model instance of a registered piece passes through; a dict is validated by
        the model of its ``kind`` (the default piece when absent). An unknown kind or
        an unknown key gives one error that lists the allowed kinds or keys. Used as a
        pydantic ``mode="before"`` validator, so pieces registered after import count.
        """
        if isinstance(value, BaseModel):
            kind = getattr(value, "kind", None)
        elif isinstance(value, dict):
            kind = value.get("kind", self.default)
        else:
            raise PydanticCustomError("model_type", "expected a TOML table (section)")
        self._discover()
        if kind not in self._specs:
            raise PydanticCustomError(
                "union_tag_invalid", "unknown kind",
                {"expected_tags": ", ".join(self._specs), "tag": kind},
            )  # fmt: skip
        model = config_of(self._specs[kind])
        if isinstance(value, BaseModel):
            if not isinstance(value, model):
                raise PydanticCustomError(
                    "model_type", "expected the model of the {kind} {what}",
                    {"kind": kind, "what": self.what},
                )  # fmt: skip
            return value
        allowed = sorted(
            {f.alias or name for name, f in model.model_fields.items()} | set(model.model_fields)
        )
        for key in value:
            if key not in allowed:
                hint = difflib.get_close_matches(str(key), allowed, n=1)
                suggestion = f"; did you mean {hint[0]!r}?" if hint else ""
                raise PydanticCustomError(
                    "unknown_key",
                    "unknown key '{key}' of the {kind} {what}{suggestion} "
                    "(allowed here: {allowed})",
                    {"key": key, "kind": kind, "what": self.what, "suggestion": suggestion,
                     "allowed": ", ".join(allowed)},
                )  # fmt: skip
        return model.model_validate(value)
