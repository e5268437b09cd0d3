"""The packed plant's first-class kernels: compiled with their contract signature on
first use, with one clear error when a kernel cannot take it."""

from __future__ import annotations

import pickle
import subprocess
import sys

import pytest
from numba import njit, types

from flexsat.compiled.first_class import first_class
from flexsat.dynamics.appendages.contract import TIPS_SIGNATURE


@njit(cache=True)
def _lazy_tips(q, members, params, out):
    out[0, 0] = q[0]


@njit(types.void(types.float64[::1]), cache=True)
def _other_signature(x):
    x[0] = 1.0


def test_a_kernel_declared_without_its_signature_is_compiled_with_it_on_first_use() -> None:
    assert TIPS_SIGNATURE.args not in _lazy_tips.signatures
    kernel = first_class(_lazy_tips, TIPS_SIGNATURE)
    assert TIPS_SIGNATURE.args in _lazy_tips.signatures
    assert first_class(_lazy_tips, TIPS_SIGNATURE) is kernel  # cached: compiled once


def test_an_equal_signature_from_another_process_finds_the_same_kernel() -> None:
    # A kernel unpickled in a worker brings an equal signature that is a new object: it
    # must find the entry made for the module's own signature (looked up by its text),
    # and the module's own signature keeps finding it (looked up by identity).
    kernel = first_class(_lazy_tips, TIPS_SIGNATURE)
    copy = pickle.loads(pickle.dumps(TIPS_SIGNATURE))
    assert copy is not TIPS_SIGNATURE and str(copy) == str(TIPS_SIGNATURE)
    assert first_class(_lazy_tips, copy) is kernel
    assert first_class(_lazy_tips, TIPS_SIGNATURE) is kernel
    assert pickle.loads(pickle.dumps(kernel)) is kernel  # first_class again, by text


def test_a_kernel_that_cannot_take_its_signature_is_named_in_one_error() -> None:
    expected = r"'_other_signature' must compile with its contract signature \(Array\(float64"
    with pytest.raises(TypeError, match=expected + r".*compilation disabled"):
        first_class(_other_signature, TIPS_SIGNATURE)


def test_importing_flexsat_compiles_no_appendage_model() -> None:
    """The built-in models' kernels wait for the first plant that uses them: a fresh
    process that imports flexsat holds none of them compiled."""
    code = ("import flexsat\n"
            "from flexsat.dynamics.appendages import appendage_model, appendage_model_names\n"
            "print(sum(len(k.signatures) for name in appendage_model_names()\n"
            "          for k in appendage_model(name).kernels))\n")  # fmt: skip
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                         check=True).stdout  # fmt: skip
    assert out.strip() == "0"
