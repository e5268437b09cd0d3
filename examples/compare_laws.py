"""
Comparing control laws
======================

Every registered law flies the same slew from the same scenario table; only the
``[controller]`` table changes. Here the thesis's three (ASMC, SMC, PD) and the
two sliding-mode variants flexsat adds (super-twisting STSMC and integral ISMC)
fly the 45/45/45 deg slew, and their pointing, residual rate and torque are set
side by side.
"""

# %%
# Fly every law
# -------------

import os

from flexsat import Plant, nominal
from flexsat.analysis import slew_metrics
from flexsat.control import law_names
from flexsat.plots.comparison import plot_controller_comparison
from flexsat.simulate import SlewScenario, run_slew

DURATION_S = float(os.environ.get("FLEXSAT_EXAMPLE_DURATION_S", 120.0))  # [s]

plant = Plant.from_config(nominal())
datasets, metrics = {}, {}
for law in law_names():
    scenario = SlewScenario.model_validate({"duration_s": DURATION_S, "controller": {"kind": law}})
    datasets[law] = run_slew(plant, scenario).dataset
    metrics[law] = slew_metrics(datasets[law])

# %%
# The numbers
# -----------

keys = ("final_pointing_error_deg", "settling_time_s", "r1_pass", "r2_pass", "r3_pass")


def cell(value) -> str:
    """A number to four significant digits, exponent kept; a verdict as it is."""
    return f"{value:>26.4g}" if isinstance(value, float) else f"{value!s:>26s}"


print(f"{'law':6s}" + "".join(f"{k:>26s}" for k in keys))
for law, m in metrics.items():
    print(f"{law:6s}" + "".join(cell(m[k]) for k in keys))

# %%
# Side by side
# ------------

plot_controller_comparison(datasets)
