"""A package's public names imported on first use (PEP 562).

A package ``__init__`` lists each name with the submodule it comes from and takes
its ``__getattr__`` and ``__dir__`` from :func:`lazy_attributes`: importing the
package then loads none of those submodules, and a name, once asked for, is stored
in the package like an eager import would (docs/performance.md, 'Start-up').
"""

from __future__ import annotations

import importlib
import sys
from collections.abc import Callable, Mapping

__all__ = ["lazy_attributes"]


def lazy_attributes(
    package: str, sources: Mapping[str, str]
) -> tuple[Callable[[str], object], Callable[[], list[str]]]:
    """The module-level ``__getattr__`` and ``__dir__`` of a package with lazy names.

    Parameters
    ----------
    package : str
        The package's ``__name__``.
    sources : mapping of str to str
        Each lazy name and the submodule it comes from, relative to ``package``.

    Returns
    -------
    getattr : callable
        ``__getattr__(name)``: imports the name's submodule, stores the name in the
        package and returns it; AttributeError for any other name.
    dir : callable
        ``__dir__()``: the package's names and its ``__all__``, sorted.
    """

    def __getattr__(name: str) -> object:
        if name in sources:
            value = getattr(importlib.import_module(f"{package}.{sources[name]}"), name)
            setattr(sys.modules[package], name, value)
            return value
        raise AttributeError(f"module {package!r} has no attribute {name!r}")

    def __dir__() -> list[str]:
        module = sys.modules[package]
        return sorted({*vars(module), *getattr(module, "__all__", ())})

    return __getattr__, __dir__
