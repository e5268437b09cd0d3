"""Appendage models: the contract, the registry and the built-in models.

The thesis's plate on its 6-DOF root joint (:mod:`.plate`), the chain of rigid
segments (:mod:`.chain`) and the modal (hybrid-coordinate) appendage (:mod:`.modal`)
are registered here; a user's model is registered the same way, from the user's own
file. The chain's module (its kernels) is imported on its first use
(:class:`~flexsat.dynamics.appendages.deferred.DeferredModel`): a satellite without
chains does not load it; ``ChainModel`` is imported on first use too (PEP 562).
"""

from flexsat._lazy import lazy_attributes
from flexsat.dynamics.appendages.chain_config import ChainConfig
from flexsat.dynamics.appendages.contract import (
    AppendageKernels,
    AppendageModel,
    Coordinate,
    DerivedPath,
    RigidBody,
)
from flexsat.dynamics.appendages.deferred import DeferredModel
from flexsat.dynamics.appendages.modal import ModalModel
from flexsat.dynamics.appendages.plate import PlateModel
from flexsat.dynamics.appendages.registry import (
    appendage_model,
    appendage_model_names,
    register_appendage_model,
)

register_appendage_model(PlateModel())
register_appendage_model(DeferredModel(f"{__name__}.chain:ChainModel", "chain", ChainConfig))
register_appendage_model(ModalModel())

__all__ = [
    "AppendageKernels",
    "AppendageModel",
    "ChainModel",
    "Coordinate",
    "DeferredModel",
    "DerivedPath",
    "ModalModel",
    "PlateModel",
    "RigidBody",
    "appendage_model",
    "appendage_model_names",
    "register_appendage_model",
]

__getattr__, __dir__ = lazy_attributes(__name__, {"ChainModel": "chain"})
