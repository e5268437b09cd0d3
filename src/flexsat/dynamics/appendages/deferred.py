"""A registered appendage model whose module is imported on first use.

A model's config class is all that validating a satellite needs; its module (the
model class and its compiled kernels) is needed only once a plant has an appendage of
that model. :class:`DeferredModel` is registered like the model itself, with the
model's name and config class, and imports the model's module the first time anything
else is asked of it: a satellite of plates never imports the chain's kernels
(docs/performance.md, 'Start-up').
"""

from __future__ import annotations

import importlib

from pydantic import BaseModel

from flexsat.dynamics.appendages.contract import AppendageModel

__all__ = ["DeferredModel"]

_OWN = frozenset({"name", "config_class", "_source", "_model", "_load"})
"""The attributes a :class:`DeferredModel` answers itself; every other one is the
model's."""


class DeferredModel(AppendageModel):
    """Stands in the registry for a model whose module is imported on first use.

    ``name`` and ``config_class`` are its own; any other attribute (its kernels, its
    class-level flags, its methods) is the model's, whose module is imported the
    first time one is asked for, then kept. A plant built from the registry holds
    this object; pickled, it travels as registered (its module imported on use).

    Parameters
    ----------
    source : str
        ``"package.module:ClassName"`` of the model class [-].
    name : str
        The model's registered name (``model = "<name>"``) [-].
    config_class : type[pydantic.BaseModel]
        The model's config class (must be the model class's own) [-].
    """

    def __init__(self, source: str, name: str, config_class: type[BaseModel]) -> None:
        object.__setattr__(self, "_source", source)
        object.__setattr__(self, "_model", None)
        object.__setattr__(self, "name", name)
        object.__setattr__(self, "config_class", config_class)

    def _load(self) -> AppendageModel:
        model = object.__getattribute__(self, "_model")
        if model is None:
            module, cls = object.__getattribute__(self, "_source").split(":")
            model = getattr(importlib.import_module(module), cls)()
            name, config = (object.__getattribute__(self, k) for k in ("name", "config_class"))
            if model.name != name or model.config_class is not config:
                raise TypeError(f"{module}.{cls} is {model.name!r} with "
                                f"{model.config_class.__name__}, registered as {name!r} "
                                f"with {config.__name__}")  # fmt: skip
            object.__setattr__(self, "_model", model)
        return model

    def __getattribute__(self, attr: str):
        if attr in _OWN or attr.startswith("__"):  # its own dunders (pickling included)
            return object.__getattribute__(self, attr)
        return getattr(object.__getattribute__(self, "_load")(), attr)

    def __reduce_ex__(self, protocol):  # pickled as it was registered: loads on first use
        get = object.__getattribute__
        return DeferredModel, (get(self, "_source"), get(self, "name"), get(self, "config_class"))

    # The contract's abstract methods, never reached (every attribute is the model's).
    def coordinates(self, config):
        return self._load().coordinates(config)

    def pack(self, config):
        return self._load().pack(config)

    def rigid_body(self, params):
        return self._load().rigid_body(params)
