"""Strict JSON: ``dumps`` writes exactly what ``json.dumps(jsonable(...))`` writes.

Reference: the recursive conversion itself, on random JSON-like structures with and
without non-finite floats. The comparison is of the text, exact.
"""

from __future__ import annotations

import json
import math

from hypothesis import given
from hypothesis import strategies as st

from flexsat.strict_json import dumps, jsonable

_scalars = st.none() | st.booleans() | st.integers() | st.text(max_size=8) | st.floats()
_trees = st.recursive(
    _scalars,
    lambda inner: (
        st.lists(inner, max_size=4)
        | st.tuples(inner, inner)
        | st.dictionaries(st.text(max_size=6), inner, max_size=4)
    ),
    max_leaves=30,
)


@given(_trees)
def test_dumps_is_the_strict_text_of_jsonable(value):
    text = dumps(value)
    assert text == json.dumps(jsonable(value), allow_nan=False)
    json.loads(text, parse_constant=_no_constants)  # no NaN or Infinity token


@given(_trees)
def test_dumps_keeps_its_keyword_arguments(value):
    assert dumps(value, indent=2) == json.dumps(jsonable(value), indent=2)


def test_non_finite_floats_are_null_finite_ones_kept():
    row = {"settling_time_s": math.nan, "peak": [1.5, -math.inf], "id": ("a", 2)}
    assert json.loads(dumps(row)) == {"settling_time_s": None, "peak": [1.5, None],
                                      "id": ["a", 2]}  # fmt: skip


def _no_constants(token: str):
    raise AssertionError(f"{token} in strict JSON")
