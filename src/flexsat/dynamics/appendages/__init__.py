"""Appendage models: the contract, the registry and the built-in models.

The thesis's plate on its 6-DOF root joint (:mod:`.plate`), the chain of rigid
segments (:mod:`.chain`) and the modal (hybrid-coordinate) appendage (:mod:`.modal`)
are registered here; a user's model is registered the same way, from the user's own
file.
"""

from flexsat.dynamics.appendages.chain import ChainModel
from flexsat.dynamics.appendages.contract import (
    AppendageKernels,
    AppendageModel,
    Coordinate,
    DerivedPath,
    RigidBody,
)
from flexsat.dynamics.appendages.modal import ModalModel
from flexsat.dynamics.appendages.plate import PlateModel
from flexsat.dynamics.appendages.registry import (
    appendage_model,
    appendage_model_names,
    register_appendage_model,
)

register_appendage_model(PlateModel())
register_appendage_model(ChainModel())
register_appendage_model(ModalModel())

__all__ = [
    "AppendageKernels",
    "AppendageModel",
    "ChainModel",
    "Coordinate",
    "DerivedPath",
    "ModalModel",
    "PlateModel",
    "RigidBody",
    "appendage_model",
    "appendage_model_names",
    "register_appendage_model",
]
