"""
Wheel microvibration: jitter against wheel speed
================================================

Four pyramid wheels with an imbalance and harmonic table (the study's illustrative
one, ``flexsat.study.jitter.DEFAULT_MICROVIBRATION``) on the nominal satellite under
its ASMC: each harmonic is a line carried through the closed flexible loop, the
jitter is their RMS, and a sweep over the wheels' speed finds where a harmonic
crosses a flexible mode (docs/pointing.md, 'Microvibration'). Far above the loop's
bandwidth a line's jitter is the structure's own answer: ``run()`` also gives one
wheel's dynamic imbalance alone under a slow PD law, which the gallery's test
compares with the receptance (K - Omega^2 M)^-1 of the satellite's mass and
stiffness.
"""

# %%
# The analysis, as one function
# -----------------------------

import numpy as np

from flexsat.config import nominal
from flexsat.control.laws.pd import PDConfig
from flexsat.control.stages.wheels import WheelsConfig
from flexsat.dynamics.plant import Plant
from flexsat.linear.jitter import closed_loop, jitter_rms, line_response, speed_sweep, wheel_lines
from flexsat.plots.jitter import plot_campbell
from flexsat.study.jitter import jitter_scenario

ARCSEC = 180.0 / np.pi * 3600.0  # [arcsec per rad]


def run(speed_rpm: float = 2000.0, probe_rpm: float = 1200.0) -> dict:
    """The default wheels' jitter, their speed sweep and one line under a slow loop.

    Parameters
    ----------
    speed_rpm : float
        The wheels' speed for the jitter [rpm].
    probe_rpm : float
        The speed of the single-line probe [rpm].

    Returns
    -------
    dict
        ``rms_arcsec`` per hub axis at ``speed_rpm``, the ``sweep``
        (:class:`~flexsat.linear.jitter.SpeedSweep`), and ``probe``: wheel 1's dynamic
        imbalance at ``probe_rpm`` under a 0.3 rad/s PD law, its torque line ``torque``
        [N m] and the hub's answer ``angles`` [rad] (complex, per axis).
    """
    plant = Plant.from_config(nominal())
    scenario = jitter_scenario(speed_rpm)
    wheels = scenario.actuator
    momentum = wheels.spin_axes().sum(axis=0) * wheels.spin_inertia_kg_m2 * speed_rpm * np.pi / 30
    model = closed_loop(plant, scenario.controller, momentum, (), wheels.motor_time_constant_s)
    rms = jitter_rms(model, wheel_lines(wheels, speed_rpm)) * ARCSEC
    sweep = speed_sweep(model, wheels, np.linspace(60.0, wheels.max_speed_rpm, 300))

    slow = closed_loop(plant, PDConfig(natural_frequency_rad_s=0.3, damping_ratio=0.9))
    one = WheelsConfig.model_validate(
        {"kind": "wheels", "microvibration": {"dynamic_imbalance_kg_m2": 1e-4, "wheels": [1]}}
    )
    lines = wheel_lines(one, probe_rpm)
    _, angles = line_response(slow, lines)
    probe = {"speed_rpm": probe_rpm, "torque": lines.amplitude[0, :3], "angles": angles[0]}
    return {"rms_arcsec": rms, "sweep": sweep, "probe": probe, "plant": plant}


# %%
# Jitter at 2000 rpm and the worst speeds
# ---------------------------------------

result = run()
rms = result["rms_arcsec"]
print(f"RMS jitter at 2000 rpm: x {rms[0]:.4f}, y {rms[1]:.4f}, z {rms[2]:.4f} arcsec")
sweep = result["sweep"]
for speed, worst in zip(sweep.worst_rpm, sweep.worst_rms * ARCSEC, strict=True):
    print(f"worst speed {speed:7.1f} rpm: {worst:.4f} arcsec")
probe = result["probe"]
print(f"wheel 1's dynamic imbalance alone at {probe['speed_rpm']:g} rpm: "
      f"{np.abs(probe['angles']) * ARCSEC} arcsec per axis")  # fmt: skip

# %%
# The Campbell diagram
# --------------------
# Each harmonic is a line f = h Omega / 60 coloured by the jitter it causes; the
# closed loop's lightly damped modes are the dashed lines, a resonance where a
# harmonic crosses one. Below, the RMS jitter against the speed.

plot_campbell(sweep)
