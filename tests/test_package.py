"""The package surface: its version from the metadata, the public API named in each package."""

from __future__ import annotations

import ast
import importlib
import importlib.metadata
import pkgutil
from pathlib import Path

import pytest

import flexsat
from flexsat._version import UNKNOWN_VERSION, package_version

PACKAGES = sorted(
    name for _, name, is_package in pkgutil.walk_packages(flexsat.__path__, "flexsat.")
    if is_package
)  # fmt: skip


def test_version_is_the_installed_distributions():
    assert flexsat.__version__ == importlib.metadata.version("flexsat")


def test_version_of_a_source_tree_that_is_not_installed():
    assert package_version("flexsat-not-an-installed-distribution") == UNKNOWN_VERSION


def test_every_package_is_listed():
    root = Path(flexsat.__file__).parent
    on_disk = {
        ".".join(("flexsat", *init.parent.relative_to(root).parts))
        for init in root.rglob("__init__.py")
        if "__pycache__" not in init.parts and init.parent != root
    }
    assert set(PACKAGES) == on_disk


@pytest.mark.parametrize("name", ["flexsat", *PACKAGES])
def test_package_reexports_its_public_names_explicitly(name):
    package = importlib.import_module(name)
    source = Path(package.__file__).read_text()
    tree = ast.parse(source)
    star = [node for node in ast.walk(tree) if isinstance(node, ast.ImportFrom)
            and any(alias.name == "*" for alias in node.names)]  # fmt: skip
    assert not star, f"{name} star-imports"
    assert package.__doc__, f"{name} has no docstring"
    assert package.__all__, f"{name} names no public API"
    for public in package.__all__:
        assert hasattr(package, public), f"{name}.__all__ lists {public!r}, which it lacks"


def test_analysis_exports_the_requirement_metrics():
    from flexsat import analysis

    for public in ("Requirements", "slew_metrics", "settling_time", "openloop_metrics",
                   "modal_analysis"):  # fmt: skip
        assert public in analysis.__all__
