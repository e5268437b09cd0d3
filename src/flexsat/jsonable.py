"""Strict JSON for flexsat's outputs: one conversion shared by every writer."""

from __future__ import annotations

import math

__all__ = ["jsonable"]


def jsonable(value):
    """``value`` with every non-finite float (NaN, inf) replaced by None, recursively.

    NaN stands for a quantity that does not exist (e.g. a settling time never
    reached); strict JSON has no NaN, so it is written as null.

    Parameters
    ----------
    value : float, int, bool, str, None, dict, list or tuple
        A JSON-like structure [any units].

    Returns
    -------
    object
        The same structure (tuples as lists), safe for
        ``json.dumps(allow_nan=False)``.
    """
    if isinstance(value, float) and not math.isfinite(value):
        return None
    if isinstance(value, dict):
        return {key: jsonable(item) for key, item in value.items()}
    if isinstance(value, list | tuple):
        return [jsonable(item) for item in value]
    return value
