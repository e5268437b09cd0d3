"""
A random Monte Carlo and the statistics a review signs off
==========================================================

The thesis's Monte Carlo (section 5.2.2) flies 24 critical corners; a random
Monte Carlo draws every uncertain parameter from a distribution instead: target
frequencies, hub and panel inertia, damping, SADM angles of each panel, actuator
gains and disturbances (the ``montecarlo-random`` preset). Here 60 of its draws
and the nominal are flown on the reduced model of the campaigns (root translations
locked, 20 ms step), and read as a review reads them: pass rates with their exact
confidence intervals, the number of cases a claim needs, percentiles, the
parameters in physical units, the figures; then a worst-case search looks for
what the random draws missed, and its worst case is flown again.
"""

# %%
# Fly the cases
# -------------
# The preset with a ``[reduced]`` table (its defaults: the three root translations
# of every panel locked, 20 ms step and control period, 40 ms records). The
# ensemble runner flies the cases in this process, a batch at a time in one
# compiled call across two threads; the pool of worker processes and Dask store the
# same rows. From the command line: a copy of the preset with a ``[reduced]`` table,
# ``flexsat campaign mc.toml --cases 60 --runner ensemble --workers 2``. The run
# length can be shortened through ``FLEXSAT_EXAMPLE_DURATION_S``.

import os
import tempfile

from flexsat import nominal
from flexsat.analysis import slew_metrics
from flexsat.campaigns import (
    CampaignDefinition,
    CampaignStore,
    load_campaign,
    replay_case,
    run_campaign,
)
from flexsat.campaigns.statistics import (
    cases_needed,
    metric_statistics,
    parameter_table,
    pass_rate_interval,
    requirement_statistics,
)
from flexsat.plots import plot_pointing
from flexsat.plots.campaign import plot_envelope_rate
from flexsat.plots.campaign_statistics import plot_metric_cdfs, plot_tornado

DURATION_S = float(os.environ.get("FLEXSAT_EXAMPLE_DURATION_S", 120.0))  # [s]
N_RANDOM = 60  # random draws, besides the nominal case
# R1 and R2 are judged over the last quarter of the run: the thesis's 90-120 s
# window at full length, and still a window when the run is shortened.
BASE = {"duration_s": DURATION_S, "requirements": {"settling_deadline_s": 0.75 * DURATION_S}}

preset = load_campaign("montecarlo-random")
definition = preset.model_validate({**preset.model_dump(), "base": BASE, "reduced": {}})
store_dir = tempfile.mkdtemp(prefix="montecarlo-")
run = run_campaign(definition, nominal(), store_dir, workers=2, n_random=N_RANDOM,
                   runner="ensemble", progress=False)  # fmt: skip
store = CampaignStore(store_dir)
table = store.table()  # one row per case; metrics under "metrics.<key>"
print(f"{run['cases']} cases flown, {run['failed']} failed to run")

# %%
# Pass rates and their exact intervals
# ------------------------------------
# A pass rate measured on n cases is an estimate of the probability that a case
# meets the requirement. Its Clopper–Pearson interval is exact (no normal
# approximation: it holds at 0 or n passes too). Below its lower end, a pass
# probability would give as many passes as observed less than 2.5 % of the time;
# above its upper end, as few. "R1: 61 of 61, 95 % interval [0.941, 1]" says the
# cases exclude an R1 pass probability below 94.1 % at 97.5 % one-sided
# confidence, not that R1 always holds. R2 fails in 6 of the 61 cases: the upper
# end of its interval, 0.963, already excludes a 99.73 % pass probability under
# these dispersions, at 97.5 % confidence.

requirements = requirement_statistics(table)  # two-sided 95 % intervals
for row in requirements.itertuples():
    print(f"{row.description:36s} {row.passes:3d}/{row.cases}  pass rate {row.pass_rate:6.1%}"
          f"  95 % interval [{row.ci_low:.3f}, {row.ci_high:.3f}]")  # fmt: skip
r2_failing = requirements.set_index("requirement").loc["r2_pass", "failing"]
print(f"R2 fails in {len(r2_failing)} cases: {', '.join(r2_failing[:10])}"
      f"{', ...' if len(r2_failing) > 10 else ''}")  # fmt: skip

# %%
# How many cases a claim needs
# ----------------------------
# A requirement is often stated as a probability at a confidence, for instance
# 99.73 % (3 sigma) at 95 %. With no failure, n cases demonstrate ``P(pass) >= p``
# at confidence c once p^n <= 1 - c (a pass probability below p would give n
# passes in a row less often than 1 - c):
# :func:`~flexsat.campaigns.statistics.cases_needed` gives the smallest such n,
# and the larger n when some failures are allowed. A clean campaign of 61 cases
# shows much less: its one-sided 95 % bound is the lower end of the two-sided 90 %
# interval.

for failures in (0, 1, 2):
    n_needed = cases_needed(0.9973, 0.95, failures=failures)
    print(f"99.73 % at 95 % confidence with {failures} failure(s) allowed: {n_needed} cases")
n_cases = len(table)
lower_bound, _ = pass_rate_interval(n_cases, n_cases, confidence=0.90)
print(f"no failure in {n_cases} cases: P(pass) >= {lower_bound:.4f} at 95 % confidence")

# %%
# Percentiles of the metrics
# --------------------------
# Minimum, 5/50/95 % percentiles and maximum over the cases that ran: the 95 %
# percentile is what 1 case in 20 exceeds, the maximum depends on how many cases
# were flown.

statistics = metric_statistics(table).set_index("metric")
keys = ["final_pointing_error_deg", "ape_deg", "max_rate_error_deg_s", "settling_time_s",
        "r2_settling_time_s", "peak_tip_displacement_m"]  # fmt: skip
print(statistics.reindex(keys)[["min", "p5", "p50", "p95", "max"]].to_string(float_format="%.4g"))

# %%
# Parameters in physical units
# ----------------------------
# A case stores each realised modifier: a scale factor for a ``scale`` modifier.
# :func:`~flexsat.campaigns.statistics.parameter_table` puts the physical value
# (its unit from the config path's suffix) beside it; the derived paths
# (``hub.inertia``, ``appendages[*].inertia``) keep their factor. Here the case
# with the largest residual rate:

residual_rate = table.set_index("case_id")["metrics.max_rate_error_deg_s"]  # [deg/s]
worst_r2 = residual_rate.sort_values(na_position="first").index[-1]
parameters = parameter_table(store.rows()).set_index("case_id")
# the physical value of each path, and the factor of a path that has none
factor_columns = [c for c in parameters if c.endswith(" [factor]")]
paths_with_value = {c.rsplit(" [", 1)[0] for c in parameters if c not in factor_columns}
shown = [c for c in parameters if c not in factor_columns
         or c.removesuffix(" [factor]") not in paths_with_value]  # fmt: skip
print(f"case {worst_r2}:")
print(parameters.loc[worst_r2, shown].to_string(float_format="%.4g"))

# %%
# Distributions
# -------------
# The empirical CDF of every metric: at any value on the x axis, the fraction of
# cases at or below it. A metric's requirement is read off it directly (the
# fraction below the R2 bound of 1e-3 deg/s in ``max_rate_error_deg_s``);
# :func:`~flexsat.plots.campaign_statistics.plot_metric_histograms` draws the same
# data as histograms with the 5, 50 and 95 % lines. Constant metrics (the step
# count, the observation window) give a single step.

plot_metric_cdfs(store_dir)

# %%
# What drives a metric
# --------------------
# The tornado chart ranks the dispersed parameters by the Spearman rank
# correlation of a metric with each, here the largest residual rate of the
# observation window (R2); a target frequency appears twice, as its factor and in
# Hz, with the same ranks. With n cases, the correlation of a parameter that has
# no effect scatters by about 1/sqrt(n - 1), 0.13 here: among some twenty
# parameters, a bar or two near twice that come by chance, and none is longer. A
# rank correlation sees the monotonic effect of one parameter at a time;
# the two panels' SADM angles act together instead. With the rest nominal, panels
# at equal SADM angles keep the residual rate near 3e-5 deg/s, and some pairs 30 deg
# apart bring it to the R2 bound of 1e-3 deg/s: no single-parameter bar shows
# that, nor does the scatter of the metric against each parameter
# (:func:`~flexsat.plots.campaign_statistics.plot_parameter_scatter`).

plot_tornado(store_dir, metric="max_rate_error_deg_s")

# %%
# The envelope
# ------------
# Every case's residual rate over time: the min–max band, the 5–95 % band of the
# cases inside it, the nominal case's line and the R2 bound. The nominal satellite,
# its two panels alike, runs near the bottom of the band.

plot_envelope_rate(store_dir)

# %%
# A worst-case search
# -------------------
# Random draws sample the box; an optimizer searches it. A ``[worst_case]`` table
# runs scipy's differential evolution (seeded) over the box of its parameters,
# maximizing one metric: here the largest residual rate, over the SADM angle of
# each panel and a factor on the flapping frequencies of both, the rest of the
# satellite and the disturbances nominal, on the same reduced slew. Every
# evaluation is a stored case (``de-00000``, ...). An initial population of 9 and
# one generation keep it short: a short search finds a lower bound of the worst
# case, not the worst; here it finds a larger residual rate than any of the 61
# random cases, in 18 evaluations.

search_definition = CampaignDefinition.model_validate(
    {
        "name": "worst-residual-rate",
        "base": BASE,
        "reduced": {},
        "worst_case": {
            "metric": "max_rate_error_deg_s",
            "seed": 2026,
            "maxiter": 1,  # generations after the initial population
            "popsize": 3,  # population = 3 x 3 parameters
            "parameters": [
                {"path": "appendages[0].sadm_angle_deg", "bounds": [0.0, 90.0]},  # [deg]
                {"path": "appendages[1].sadm_angle_deg", "bounds": [0.0, 90.0]},  # [deg]
                {
                    "path": "appendages[*].target_frequencies_hz.flapping",
                    "op": "scale",
                    "bounds": [0.8, 1.2],  # factor [-]
                },
            ],
        },
    }
)
search_dir = tempfile.mkdtemp(prefix="worst-case-")
found = run_campaign(search_definition, nominal(), search_dir, workers=1)
random_worst = statistics.loc["max_rate_error_deg_s", "max"]  # [deg/s]
print(f"{found['cases']} evaluations, worst {found['case_id']}: "
      f"max_rate_error_deg_s = {found['value']:.4g} deg/s "
      f"(random draws: {random_worst:.4g} deg/s)")  # fmt: skip
for path, value in found["parameters"].items():
    print(f"  {path:48s} {value:.4g}")

# %%
# Replay the worst case
# ---------------------
# The worst case is a stored case like any other: flown again alone from its
# stored inputs (``flexsat campaign replay STORE CASE_ID``), the same metric, now
# with every recorded variable.

replayed = replay_case(search_dir, found["case_id"])
replayed_metrics = slew_metrics(replayed.dataset)
r2 = {True: "met", False: "not met", None: "not judged"}[replayed_metrics["r2_pass"]]
print(f"replayed {found['case_id']}: max_rate_error_deg_s = "
      f"{replayed_metrics['max_rate_error_deg_s']:.4g} deg/s, R2 {r2}")  # fmt: skip
plot_pointing(replayed.dataset)
