"""flexsat._lazy: a package's names imported on first use, stored once imported."""

from __future__ import annotations

import subprocess
import sys

import pytest


def test_a_lazy_name_is_its_submodule_s_object_and_stays_in_the_package() -> None:
    """In a fresh process: the package alone does not import the submodule; asking for
    the name does, returns the submodule's object and stores it in the package."""
    code = (
        "import sys, flexsat.study as s\n"
        "assert 'flexsat.study.report' not in sys.modules\n"
        "assert 'format_value' in dir(s) and 'format_value' not in vars(s)\n"
        "f = s.format_value\n"
        "from flexsat.study.report import format_value\n"
        "assert f is format_value and vars(s)['format_value'] is f\n"
    )
    subprocess.run([sys.executable, "-c", code], check=True)


def test_an_unknown_name_is_an_attribute_error() -> None:
    import flexsat.dynamics

    with pytest.raises(AttributeError, match=r"module 'flexsat\.dynamics' has no attribute 'Nope'"):
        flexsat.dynamics.Nope  # noqa: B018
