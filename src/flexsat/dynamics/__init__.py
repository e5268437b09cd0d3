"""The physics: the plant built from a config, its compiled kernels and the rigid design model.

The compiled kernels (:mod:`flexsat.dynamics.kernels`, :mod:`flexsat.dynamics.integrators`)
and the SymPy reference derivation (:mod:`flexsat.dynamics.symbolic`) are imported from
their modules; the user-level names are here.
"""

from flexsat.dynamics.plant import Plant
from flexsat.dynamics.rigid import gyroscopic_torque, rigid_inertia

__all__ = ["Plant", "gyroscopic_torque", "rigid_inertia"]
