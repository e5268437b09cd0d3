"""The compiled toolkit every layer's numba code draws on: 3-vector algebra, loops
without reference counting, first-class kernels, status codes and typed calls.

It sits below the physics: the plant's kernels, the control laws, the loop stages and
the simulation loops all use it, and it imports nothing of flexsat.
"""

from __future__ import annotations

from flexsat.compiled.first_class import FirstClassKernel, first_class
from flexsat.compiled.no_refcount import borrowed

__all__ = ["FirstClassKernel", "borrowed", "first_class"]
