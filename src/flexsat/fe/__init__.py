"""Finite-element models to the modal data format: Craig–Bampton reduction.

:func:`craig_bampton` reduces a user's FE mass and stiffness matrices, clamped at an
interface node, to the modal data format (:mod:`flexsat.config.modal_data`) that the
``modal`` appendage reads; :func:`uniform_beam` builds a uniform beam with
scikit-fem (the ``fe`` extra) as a reference structure.
"""

from flexsat.fe.beam import BeamModel, uniform_beam
from flexsat.fe.craig_bampton import craig_bampton

__all__ = ["BeamModel", "craig_bampton", "uniform_beam"]
