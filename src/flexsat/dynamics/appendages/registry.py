"""The registry of appendage models: a new model is one module plus one registration line.

Nothing outside a model's module names it: the plant, the records, the results and
the plots look each appendage's model up here by its config's ``model`` key. An
installed package adds its models through the entry-point group
``flexsat.appendages``: each entry point names a module whose import registers one.
"""

from __future__ import annotations

from flexsat.config.models import load_appendage_plugins, register_appendage_config
from flexsat.dynamics.appendages.contract import AppendageModel

__all__ = ["appendage_model", "appendage_model_names", "register_appendage_model"]

_MODELS: dict[str, AppendageModel] = {}


def register_appendage_model(model: AppendageModel) -> AppendageModel:
    """Register ``model`` under ``model.name``; appendage tables may then say
    ``model = "<name>"``. Registering a name again replaces the model. Returns it."""
    if not isinstance(model, AppendageModel):
        raise TypeError(f"expected an AppendageModel instance, got {type(model).__name__}")
    register_appendage_config(model.name, model.config_class)
    _MODELS[model.name] = model
    return model


def appendage_model(name: str) -> AppendageModel:
    """The registered model called ``name`` (installed ``flexsat.appendages`` entry points
    are imported on the first miss)."""
    if name not in _MODELS:
        load_appendage_plugins()
    try:
        return _MODELS[name]
    except KeyError:
        raise KeyError(
            f"unknown appendage model {name!r} (registered: {', '.join(_MODELS)})"
        ) from None


def appendage_model_names() -> tuple[str, ...]:
    """Names of the registered models, in registration order."""
    return tuple(_MODELS)
