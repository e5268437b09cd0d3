"""Finite-element models to the modal data format: Craig–Bampton reduction.

:func:`craig_bampton` reduces a user's FE mass and stiffness matrices, clamped at an
interface node, to the modal data format (:mod:`flexsat.config.modal_data`) that the
``modal`` appendage reads; :func:`uniform_beam` and :func:`solid_plate` build a
uniform beam and a thin plate with scikit-fem (the ``fe`` extra) as reference
structures, and
:func:`euler_bernoulli_hub_frequencies` is its analytic counterpart on a hub.
"""

from flexsat.fe.beam import BeamModel, euler_bernoulli_hub_frequencies, uniform_beam
from flexsat.fe.craig_bampton import craig_bampton, rigid_interface_map
from flexsat.fe.plate import SolidPlateModel, solid_plate

__all__ = [
    "BeamModel",
    "SolidPlateModel",
    "craig_bampton",
    "euler_bernoulli_hub_frequencies",
    "rigid_interface_map",
    "solid_plate",
    "uniform_beam",
]
