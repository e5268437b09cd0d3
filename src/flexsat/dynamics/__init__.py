"""The physics: the plant built from a config, its compiled kernels and the rigid design model.

The compiled kernels (:mod:`flexsat.dynamics.kernels`, :mod:`flexsat.dynamics.integrators`)
and the SymPy reference derivation (:mod:`flexsat.dynamics.symbolic`) are imported from
their modules; the user-level names are here, imported on first use (PEP 562): a module
that imports one kernel module does not load the plant, its appendage models and
SciPy's rotations with it (docs/performance.md, 'Start-up').
"""

from flexsat._lazy import lazy_attributes

_LAZY = {
    "Plant": "plant",
    "gyroscopic_torque": "rigid",
    "rigid_inertia": "rigid",
}
"""The public names imported on first use, and the submodule each comes from."""

__all__ = ["Plant", "gyroscopic_torque", "rigid_inertia"]


__getattr__, __dir__ = lazy_attributes(__name__, _LAZY)
