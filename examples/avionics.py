"""
Avionics in the loop
====================

The thesis flies its 45/45/45 deg ASMC slew with an ideal sensor and an ideal
actuator (section 5.1.2, assumptions 1 and 2): the law reads the true attitude and
rate, and its torque reaches the hub at once. Here the same slew flies with real
avionics: a rate gyro and a star tracker fused by a multiplicative extended Kalman
filter (MEKF), whose estimate the law flies on, and a pyramid of four reaction
wheels that turns the law's torque into wheel momentum. Last, a computational
delay is put between the law and the wheels.

Each piece is one table of the slew scenario; the theory and every key are in
docs/control.md, "Avionics in the loop".
"""

# %%
# Two loops, one scenario each
# ----------------------------
# The ideal loop is the thesis's slew, ``SlewScenario()``. The avionics loop adds
# three sensing stages after the ideal sensor, run in order on the same
# measurement (the gyro replaces the rate, the star tracker the attitude, the MEKF
# both with its estimate), and makes the wheels the final actuator. The values
# written out are the stages' defaults, except the gyro's turn-on bias; the
# template ``flexsat config preset avionics-slew`` holds the same chain as TOML.

import os

import numpy as np
from matplotlib.figure import Figure

from flexsat import Plant, nominal
from flexsat.analysis import slew_metrics
from flexsat.plots import style
from flexsat.simulate import SlewScenario, run_slew

DURATION_S = float(os.environ.get("FLEXSAT_EXAMPLE_DURATION_S", 120.0))  # [s]
ARCSEC_PER_RAD = 180.0 / np.pi * 3600.0  # [arcsec/rad]

GYRO = {
    "kind": "gyro",
    "sample_dt_s": 0.01,  # 100 Hz [s]
    "arw_deg_rt_h": 0.01,  # angle random walk N [deg/sqrt(h)]
    "bias_instability_deg_h": 0.05,  # bias instability B [deg/h]
    "bias_deg_h": [0.05, -0.03, 0.02],  # turn-on bias per axis [deg/h]
}
STAR_TRACKER = {
    "kind": "star_tracker",
    "sample_dt_s": 0.1,  # 10 Hz [s]
    "noise_arcsec": [5.0, 5.0, 30.0],  # 1-sigma about body x, y, z (boresight) [arcsec]
}
WHEELS = {
    "kind": "wheels",
    "preset": "pyramid4",  # four spin axes 54.74 deg from +Z_B
    "spin_inertia_kg_m2": 0.1,  # I_s of each wheel [kg m^2]
    "max_torque_nm": 2.0,  # motor torque limit per wheel [N m]
    "max_speed_rpm": 6000.0,  # speed limit [rpm]: I_s Omega_max = 62.8 N m s per wheel
}
AVIONICS = {
    "name": "avionics-slew",  # the run's name, in the figures' titles
    "sensor_stages": [GYRO, STAR_TRACKER, {"kind": "mekf"}],
    "actuator": WHEELS,
}

plant = Plant.from_config(nominal())
ideal = run_slew(plant, SlewScenario(duration_s=DURATION_S))
avionics = run_slew(plant, SlewScenario.model_validate({"duration_s": DURATION_S, **AVIONICS}))
metrics = {"ideal": slew_metrics(ideal.dataset), "avionics": slew_metrics(avionics.dataset)}

# %%
# The verdicts, side by side
# --------------------------
# R1 holds with the avionics; R2 is lost, and so is R3: at the slew's start the law's
# command is clipped to 1.9 N m on every axis, and the pyramid's pseudo-inverse asks
# the wheel on (1, 1, 1)/sqrt(3) for 3/4 sqrt(3) 1.9 = 2.47 N m, more than its
# 2 N m motor gives (R3 judges a wheel cluster on what each wheel is asked, not on
# the hub torque, which holds the wheels' gyroscopic torque). The residual rate is set by the gyro's
# angle random walk: each 100 Hz rate sample carries N / sqrt(0.01 s) = 1.7e-3
# deg/s (1 sigma) of white noise, which the MEKF passes on (it removes the bias,
# not the noise) and the law turns into torque; a gyro with a third of that angle
# random walk keeps R2. Both loops fly against the scenario's disturbances, the
# thesis's environment and sloshing torques at their maximum: the wheels apply them
# as external torques, without the static actuator's 0.95 gain and its clip to
# T_max. The environment torque leaves each loop a steady pointing offset (about
# 0.0023 deg for the ideal loop, a little more with the wheels, whose bearing
# friction adds to it); the avionics loop's error moves about that offset with the
# sensors' noise, so its APE is the larger.


def shown(value) -> str:
    """A metric as printed: numbers to three significant digits."""
    return f"{value:.3g}" if isinstance(value, float) else str(value)


keys = ("r1_pass", "r2_pass", "r3_pass", "ape_deg", "max_rate_error_deg_s", "settling_time_s",
        "final_pointing_error_deg", "actuator_saturation_s")  # fmt: skip
print(f"{'':26s}{'ideal':>12s}{'avionics':>12s}")
for key in keys:
    print(f"{key:26s}" + "".join(f"{shown(metrics[loop][key]):>12s}" for loop in metrics))

# %%
# What the filter sees
# --------------------
# Left, per axis: the MEKF's error (its estimate against the true attitude)
# inside its own +-3 sigma. Right: the gyro bias it estimates beside the true one.
# Bottom: the NEES against its chi-square interval (a consistent filter has 95 %
# of it inside, mean 3), and the filter's 1 sigma. One star-tracker sample errs by
# 5, 5 and 30 arcsec (1 sigma); the filter, carrying the attitude from sample to
# sample with the gyro, averages many of them and errs by a fifth of that or less.

error_arcsec = avionics.dataset["estimation_error"].values * ARCSEC_PER_RAD
rms_arcsec = np.sqrt(np.mean(error_arcsec**2, axis=0))
print("MEKF attitude error RMS per axis [arcsec]:", rms_arcsec.round(2))
print("star-tracker noise per axis [arcsec]:     ", STAR_TRACKER["noise_arcsec"])
avionics.plot("mekf")

# %%
# The wheels
# ----------
# Top: the cluster's momentum in the hub frame. The wheels start at rest and take
# up the satellite's momentum during the slew; the disturbances act with them as
# external torques, so the cluster also takes up their impulse: once the satellite
# is at rest its momentum grows by the environment torque, 0.005 N m per axis, to
# about 0.6 N m s per axis after 120 s. Middle: the fullest wheel against its speed
# limit; a wheel at 99.9 % of it is saturated, R3 then fails and the metric
# ``actuator_saturation_s`` says when each wheel first was. Third: each wheel's
# speed against +-6000 rpm, with its zero crossings (where the bearing friction
# changes sign) and the largest motor torque asked of a wheel, R3's ratio. Bottom:
# the wheels' kinetic energy, the motor work and the friction loss.

fullest = avionics.dataset["wheel_speed_ratio"].values  # max |h_i| / (I_s Omega_max) [-]
cluster = avionics.dataset["wheel_momentum_B"].values  # sum a_i h_i, hub frame [N m s]
momentum = np.linalg.norm(cluster, axis=1)  # [N m s]
print(f"fullest wheel: {100.0 * fullest.max():.1f} % of its speed limit")
print(f"largest cluster momentum: {momentum.max():.2f} N m s")
print("cluster momentum at the end, per axis [N m s]:", cluster[-1].round(2))
avionics.plot("wheels")

# %%
# A computational delay
# ---------------------
# A ``delay`` stage between the law and the wheels passes each command on whole
# control periods late: 100 periods of 1 ms here. The loop still points within R1,
# but the delay eats its phase margin: it oscillates about Z to the end of the run.

DELAY = {"kind": "delay", "periods": 100}  # 100 control periods of 1 ms: 0.1 s
delayed_fields = {**AVIONICS, "name": "avionics-slew-delayed", "actuator_stages": [DELAY]}
delayed = run_slew(plant, SlewScenario.model_validate({"duration_s": DURATION_S, **delayed_fields}))
metrics["avionics + 0.1 s delay"] = slew_metrics(delayed.dataset)
for key in ("r1_pass", "r2_pass", "ape_deg", "max_rate_error_deg_s", "settling_time_s"):
    print(f"{key:26s}{shown(metrics['avionics + 0.1 s delay'][key]):>12s}")

# %%
# Pointing, side by side
# ----------------------
# The true pointing error and residual rate of the three loops, with the R1 and R2
# bands (the requirements travel with each result's scenario).


def plot_loops(runs: dict) -> Figure:
    """Pointing error [deg] and residual rate [deg/s] of each run on log axes, with the
    R1 and R2 bands of the first run's scenario, in flexsat's figure style."""
    first = next(iter(runs.values())).dataset
    requirements = SlewScenario.model_validate_json(first.attrs["scenario"]).requirements
    fig, axes = style.figure(2, 1, size=(11.0, 7.5))  # [in]
    panels = (
        ("pointing_error_deg", "pointing error [deg]", requirements.pointing_deg, "R1"),
        ("rate_error_deg_s", "residual rate [deg/s]", requirements.jitter_deg_s, "R2"),
    )
    for ax, (name, label, bound, tag) in zip(axes[:, 0], panels, strict=True):
        for layer, ((loop, result), colour) in enumerate(
            zip(runs.items(), ("black", "tab:blue", "tab:red"), strict=False)
        ):
            values = style.positive(result.dataset[name].values)  # zeros left out: log axis
            style.line(ax, style.time_s(result.dataset), values, color=colour, linewidth=0.9,
                       label=loop, zorder=len(runs) - layer)  # fmt: skip
        ax.axhline(bound, color=style.BAND, linestyle="--", linewidth=1.0, label=f"{tag} bound")
        ax.set_yscale("log")
        ax.set_ylabel(label)
        ax.legend(loc="upper right", fontsize=8)
    style.finish_time_axis(axes, style.time_s(first))
    fig.suptitle("45/45/45 deg ASMC slew: the ideal loop and the avionics chain", fontsize=11)
    return fig


plot_loops({"ideal": ideal, "avionics": avionics, "avionics + 0.1 s delay": delayed})
