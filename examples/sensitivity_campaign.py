"""
A sensitivity campaign and its statistics
=========================================

The thesis's sensitivity analysis (section 5.2.1) flies the nominal slew again
with one uncertain parameter changed at a time: no structural damping, target
frequencies and inertias +-20 %, other SADM angles. The campaign is a shipped
preset (``flexsat campaign sensitivity``); from Python it is one call, and its
store holds one row per case, a Parquet/CSV table and each case's decimated
history.
"""

# %%
# Run it
# ------
# Cases are resolved and validated before any runs; ``workers=1`` flies them in
# this process (``workers=2`` or a Dask cluster spread them out, with the same
# rows). The run length can be shortened through ``FLEXSAT_EXAMPLE_DURATION_S``.

import os
import tempfile

from flexsat import nominal
from flexsat.campaigns import CampaignStore, load_campaign, run_campaign, summarize
from flexsat.plots.campaign import plot_envelope_pointing, plot_envelope_torque

DURATION_S = float(os.environ.get("FLEXSAT_EXAMPLE_DURATION_S", 120.0))  # [s]

preset = load_campaign("sensitivity")
definition = preset.model_validate(
    {**preset.model_dump(), "base": {**preset.base, "duration_s": DURATION_S}}
)
store_dir = tempfile.mkdtemp(prefix="sensitivity-")
run_campaign(definition, nominal(), store_dir, workers=1, progress=False)

# %%
# Statistics
# ----------
# :func:`flexsat.campaigns.summarize` gives the pass rate of each requirement and
# the worst cases; the full table is a pandas DataFrame, one row per case.

summary = summarize(store_dir)
for key, value in summary.items():
    print(f"{key:26s} {value}")
table = CampaignStore(store_dir).table()  # metrics under "metrics.<key>"
keys = ["final_pointing_error_deg", "settling_time_s", "r1_pass", "r2_pass", "r3_pass"]
view = table.set_index("case_id")[[f"metrics.{key}" for key in keys]]
print(view.rename(columns=lambda c: c.removeprefix("metrics.")).to_string())

# %%
# Envelopes
# ---------
# Every case's pointing error over time, with the R1 band.

plot_envelope_pointing(store_dir)

# %%
# And every case's torque against the limit of R3.

plot_envelope_torque(store_dir)
