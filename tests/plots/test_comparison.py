"""The controller-comparison figure: one labelled line per run."""

from __future__ import annotations

import matplotlib.pyplot as plt

from flexsat.config import nominal
from flexsat.dynamics.plant import Plant
from flexsat.plots.comparison import plot_controller_comparison
from flexsat.simulate import SlewScenario, run_slew


def test_runs_of_one_law_keep_the_callers_labels():
    # Keyed by the law's name, a run is drawn as the law's label; keyed by a label of
    # the caller's (two gains of one law), as that label, so the lines stay apart.
    plant = Plant.from_config(nominal())
    ds = run_slew(plant, SlewScenario(duration_s=0.5), progress=False).dataset
    fig = plot_controller_comparison({"asmc": ds, "asmc, slower": ds})
    labels = [line.get_label() for line in fig.axes[0].get_lines()]
    assert labels[0].startswith("ASMC: final") and labels[1].startswith("asmc, slower: final")
    plt.close(fig)
