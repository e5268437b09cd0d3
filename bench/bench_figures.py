"""Benchmark: writing the figure sets of the thesis's open-loop run and slew (PNG files).

Times ``write_openloop_figures`` (9 figures, with the modal analysis for the
spectrogram's lines) and ``write_slew_figures`` (13 figures) at their default
resolution, each on a fresh folder, best of ``REPEATS``; the runs themselves are
simulated once beforehand and not timed. Run with ``python bench/bench_figures.py``.
"""

from __future__ import annotations

import tempfile
from pathlib import Path

import harness
from flexsat import Plant, nominal
from flexsat.analysis import modal_analysis
from flexsat.simulate import run_openloop, run_slew

REPEATS = 3


def _best(write) -> float:
    """Best of :data:`REPEATS` writes [s], each into a fresh folder."""
    with tempfile.TemporaryDirectory() as root:
        return harness.best_of(write, REPEATS,
                               setup=lambda: Path(tempfile.mkdtemp(dir=root)))[0]  # fmt: skip


@harness.register(
    "writing the figure sets of the thesis open-loop run (9 PNG) and slew (13 PNG): wall time "
    "per set and per figure"
)
def main() -> dict:
    """Print the table; return the wall time of each figure set [s] and its figure count."""
    from flexsat.plots.openloop import write_openloop_figures
    from flexsat.plots.slew import write_slew_figures

    plant = Plant.from_config(nominal())
    openloop = run_openloop(plant).dataset
    analysis = modal_analysis(plant)
    slew = run_slew(plant).dataset
    sets = {
        "open loop": lambda out: write_openloop_figures(openloop, analysis, out),
        "slew": lambda out: write_slew_figures(slew, out),
    }
    numbers = {}
    table = harness.table(
        f"Figure sets of the thesis runs, PNG, best of {REPEATS}",
        ("figure set", "figures", "wall s", "s per figure"),
    )
    for name, write in sets.items():
        with tempfile.TemporaryDirectory() as folder:
            count = len(write(Path(folder)))  # warm-up: imports, font cache
        wall = _best(write)
        numbers[name] = {"figures": count, "wall_s": wall}
        table.add_row(name, str(count), f"{wall:.2f}", f"{wall / count:.2f}")
    harness.console().print(table)
    return numbers


if __name__ == "__main__":
    main()
