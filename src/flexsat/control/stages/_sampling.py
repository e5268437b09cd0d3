"""What the sampled sensors share: their sample period against the control period."""

from __future__ import annotations

from typing import Any

__all__ = ["control_periods"]


def control_periods(field: str, value_s: float, scenario: Any, allow_zero: bool = False) -> int:
    """``value_s`` in whole control periods of ``scenario``; ValueError naming ``field``
    if it is not a whole multiple (at least one period unless ``allow_zero``)."""
    ratio = value_s / scenario.control_dt_s
    periods = round(ratio)
    if abs(ratio - periods) > 1e-6 * max(ratio, 1.0) or (periods < 1 and not allow_zero):
        raise ValueError(
            f"{field} must be a whole multiple of control_dt_s ({scenario.control_dt_s:g} s, "
            f"itself a multiple of dt_s), got {value_s:g} s"
        )
    return periods
