"""The compiled kernels copy arrays element by element, never by slice assignment."""

from __future__ import annotations

import ast
import inspect

import numpy as np
import pytest

from flexsat.compiled.linalg3 import copy_into
from flexsat.control.stages import delay
from flexsat.dynamics import attitude, integrators, kernels, records
from flexsat.simulate import coupled, loops

LOOP_MODULES = (kernels, attitude, integrators, records, loops, coupled, delay)


def test_copy_into_copies_every_bit():
    src = np.array([1.5, -0.0, np.nan, np.inf, -np.inf, 5e-324, np.nextafter(1.0, 2.0)])
    src[2] = np.frombuffer(np.uint64(0x7FF8_0000_DEAD_BEEF).tobytes(), dtype=np.float64)[0]
    dst = np.zeros_like(src)
    copy_into(dst, src)
    assert dst.tobytes() == src.tobytes()
    rows = np.zeros((3, src.size))
    copy_into(rows[1], src)  # a row of a 2-D array, as the records are written
    assert rows[1].tobytes() == src.tobytes() and not rows[[0, 2]].any()


def _slice_assignments_of_arrays(module) -> list[str]:
    """``a[...:...] = <not a number>`` inside the module's compiled functions."""
    found = []
    for node in ast.walk(ast.parse(inspect.getsource(module))):
        if not isinstance(node, ast.FunctionDef):
            continue
        if not any("njit" in ast.unparse(d) for d in node.decorator_list):
            continue
        for assign in ast.walk(node):
            if not isinstance(assign, ast.Assign | ast.AugAssign):
                continue
            targets = assign.targets if isinstance(assign, ast.Assign) else [assign.target]
            sliced = any(isinstance(t, ast.Subscript) and any(
                isinstance(s, ast.Slice) for s in ast.walk(t.slice)) for t in targets)  # fmt: skip
            value = assign.value
            if isinstance(value, ast.UnaryOp):
                value = value.operand
            scalar = isinstance(value, ast.Constant) or ast.unparse(value) in ("np.nan", "np.inf")
            if sliced and not scalar:
                found.append(f"{node.name}: {ast.unparse(assign)}")
    return found


@pytest.mark.parametrize("module", LOOP_MODULES, ids=lambda m: m.__name__)
def test_compiled_loops_assign_no_array_into_a_slice(module):
    # numba compiles a formatted shape-mismatch error for each array assigned into a
    # slice: seconds of a first run's compilation per process, for nothing.
    assert _slice_assignments_of_arrays(module) == []
