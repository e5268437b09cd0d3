"""The order the gallery shows its examples in: from a satellite of your own to the
closed loop, then campaigns and linear analysis. An example not listed comes after
these, alphabetically."""

from __future__ import annotations

READING_ORDER = (
    "own_satellite.py",
    "three_panels.py",
    "higher_modes.py",
    "nastran_wing.py",
    "openloop_validation.py",
    "slew_requirements.py",
    "compare_laws.py",
    "compiled_law.py",
    "python_controller.py",
    "avionics.py",
    "sensitivity_campaign.py",
    "montecarlo_statistics.py",
    "replay_case.py",
    "linear_design.py",
    "microvibration.py",
)


class ReadingOrder:
    """Sort key of sphinx-gallery's ``within_subsection_order``."""

    def __init__(self, src_dir: str) -> None:
        self.src_dir = src_dir

    def __call__(self, filename: str) -> tuple[int, str]:
        rank = READING_ORDER.index(filename) if filename in READING_ORDER else len(READING_ORDER)
        return rank, filename
