"""
Three panels
============

Nothing in flexsat counts panels: a configuration with three appendages is one
more table. Here three identical panels stand 120 deg apart around the hub, each
in its own mount frame M_i (the hub frame B turned by ``mount_yaw_deg`` about
Z_B). The three-fold symmetry shows in the results: equal rigid inertia about X
and Y, and flexible modes in degenerate pairs.
"""

# %%
# The configuration
# -----------------

import numpy as np
from matplotlib.figure import Figure

from flexsat import Plant, SatelliteConfig, nominal
from flexsat.analysis import modal_analysis
from flexsat.dynamics import rigid_inertia
from flexsat.plots import hub_outline, plot_frequencies, satellite_geometry

base = nominal().model_dump()  # the thesis's hub and panel, as plain tables
panel = base["appendages"][0]
appendages = []
for k, yaw_deg in enumerate((0.0, 120.0, 240.0)):  # mount yaw [deg]
    yaw = np.radians(yaw_deg)
    # the root 0.8 m out along the mount frame's Y axis [m]
    root = [-0.8 * np.sin(yaw), 0.8 * np.cos(yaw), 0.0]
    appendages.append(
        {**panel, "name": f"panel_{k + 1}", "mount_yaw_deg": yaw_deg, "mount_point_m": root,
         "span_direction": "+y"}
    )  # fmt: skip
config = SatelliteConfig.model_validate({**base, "name": "three-panels", "appendages": appendages})
plant = Plant.from_config(config)

# %%
# Top view
# --------
# :func:`flexsat.plots.satellite_geometry` gives the drawable satellite in the
# inertial frame N at any generalized coordinates (here undeformed).

geometry = satellite_geometry(plant)
fig = Figure(figsize=(5, 5), layout="constrained")
ax = fig.subplots()
for line in hub_outline(plant).lines:
    ax.plot(line[:, 0], line[:, 1], color="grey", linewidth=0.8)
for corners in geometry.panels:
    loop = np.vstack([corners, corners[:1]])
    ax.fill(loop[:, 0], loop[:, 1], alpha=0.4)
    ax.plot(loop[:, 0], loop[:, 1], color="black", linewidth=0.8)
ax.set_aspect("equal")
ax.set_xlabel("X_N [m]")
ax.set_ylabel("Y_N [m]")
ax.set_title("Three panels 120 deg apart (top view)")

# %%
# Symmetry in the numbers
# -----------------------

J_tot = rigid_inertia(plant)  # [kg m^2]
print("J_tot diagonal [kg m^2]:", np.diag(J_tot).round(3))
analysis = modal_analysis(plant)
print("first flexible modes [Hz]:", analysis.frequencies_hz[6:14].round(4))
plot_frequencies(analysis)
