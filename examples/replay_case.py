"""
Replaying a campaign case
=========================

A campaign stores, for every case, its realised parameters, seed and the exact
plant and scenario it flew, so any one case can be flown again alone (``flexsat
campaign replay STORE CASE_ID``) with its full time history, for instance the
worst case of a Monte Carlo run. Here a small campaign of our own is defined in
Python (the tables a campaign TOML holds), run, and its worst case replayed.
"""

# %%
# A small campaign
# ----------------
# Three cases: the nominal, and the hub mass scaled by 0.8 and 1.2 (``scale`` a
# config path; ``set`` a value or draw it from a distribution).

import os
import tempfile

from flexsat import nominal
from flexsat.analysis import slew_metrics
from flexsat.campaigns import CampaignDefinition, replay_case, run_campaign, summarize
from flexsat.plots import plot_pointing

DURATION_S = float(os.environ.get("FLEXSAT_EXAMPLE_DURATION_S", 120.0))  # [s]

definition = CampaignDefinition.model_validate(
    {
        "name": "hub-mass",
        "base": {"duration_s": DURATION_S},
        "cases": [
            {"id": f"hub-mass-x{k}", "plant": [{"path": "hub.mass_kg", "op": "scale", "value": k}]}
            for k in (0.8, 1.2)
        ],
    }
)
store_dir = tempfile.mkdtemp(prefix="hub-mass-")
run_campaign(definition, nominal(), store_dir, workers=1, progress=False)
summary = summarize(store_dir)
worst = summary["worst_cases"][0]
worst_id = worst["case_id"]
print(f"worst case: {worst_id}, final pointing error {worst['final_pointing_error_deg']:.3g} deg")

# %%
# Replay it
# ---------
# The replay rebuilds the plant and the scenario from the stored inputs and flies
# them again: the same numbers, and now every recorded variable.

replayed = replay_case(store_dir, worst_id)
metrics = slew_metrics(replayed.dataset)
print(f"replayed:   final pointing error {metrics['final_pointing_error_deg']:.3g} deg")
plot_pointing(replayed.dataset)
