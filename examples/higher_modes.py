"""
Higher modes: chains of segments and modal appendages
=====================================================

The thesis lumps each solar panel into one rigid plate on an elastic root joint:
one mode per joint DOF, the first flapwise, in-plane and torsion modes and no
more. Two other appendage models reach further. A ``chain`` splits the panel into
N rigid segments on elastic joints, their springs derived from the panel's bending
and torsional stiffness (EI, GJ); a ``modal`` appendage is a rigid body plus the
modes of a structural model clamped at its interface. This example measures the
chain against the Euler-Bernoulli cantilever, sets the chain satellite beside the
thesis's to see which modes it adds and how much of them the hub feels, then
writes the chain's panels as modal appendages and flies the thesis's yaw pulse
with all three models.
"""

# %%
# A panel as a chain of segments
# ------------------------------
# The ``chain`` preset is the nominal satellite with each 4.5 m panel an 8-segment
# chain whose joint springs come from the panel's beam properties: k = EI / l
# between segments of length l = L / N, twice that at the root (docs/model.md,
# 'Chain appendages'). With only the flapwise rotation free, the panel clamped at
# its root is a discretized Euler-Bernoulli cantilever, whose frequencies are
# f_n = (beta_n L)^2 sqrt(EI / (rho A L^4)) / (2 pi). An appendage's clamped modes
# (the hub held fixed) are what :func:`flexsat.linear.export.modal_data` exports;
# here they measure the chain's error for a few N.

import os

import numpy as np
from matplotlib.figure import Figure

from flexsat import Plant, SatelliteConfig, load_config, nominal
from flexsat.analysis import modal_analysis
from flexsat.config import preset_path
from flexsat.dynamics import rigid_inertia
from flexsat.linear.export import modal_data, modal_satellite
from flexsat.linear.frequency import effective_inertia
from flexsat.plots import mode_amplitude, satellite_geometry
from flexsat.simulate import OpenLoopScenario, run_openloop

BETA_L = np.array([1.875104, 4.694091, 7.854757])  # Euler-Bernoulli cantilever, beta_n L [-]
SEGMENT_COUNTS = (2, 4, 8, 16, 32)

chain_config = load_config(preset_path("chain"))
panel_table = chain_config.appendages[0].model_dump(exclude_none=True)  # panel_1, a chain
length_m = panel_table["length_m"]  # L [m]
mass_per_length_kg_m = panel_table["surface_density_kg_m2"] * panel_table["width_m"]  # rho A
ei_flap_n_m2 = panel_table["beam"]["EI_flap_N_m2"]  # EI about the chord axis X [N m^2]
euler_bernoulli_hz = (
    BETA_L**2 * np.sqrt(ei_flap_n_m2 / (mass_per_length_kg_m * length_m**4)) / (2.0 * np.pi)
)


def flapwise_cantilever(segments):
    """The nominal hub carrying panel_1 alone, a chain of ``segments`` flapwise hinges."""
    panel = {
        **panel_table,
        "segments": segments,
        "joint": {"dofs": ["rx"]},  # flapwise bending only (span Y, chord X)
        "beam": {"EI_flap_N_m2": ei_flap_n_m2},
    }
    return SatelliteConfig.model_validate(
        {"name": f"cantilever-{segments}", "hub": chain_config.hub.model_dump(),
         "appendages": [panel]}
    )  # fmt: skip


clamped_hz = {}  # N -> the first three clamped flapwise frequencies [Hz]
errors_percent = {}  # N -> their error against Euler-Bernoulli [%]
for segments in SEGMENT_COUNTS:
    plant = Plant.from_config(flapwise_cantilever(segments))
    export = modal_data(plant, "panel_1", n_modes=min(3, segments))
    clamped_hz[segments] = np.array(export.frequencies_hz)
    reference_hz = euler_bernoulli_hz[: clamped_hz[segments].size]
    errors_percent[segments] = 100.0 * (clamped_hz[segments] / reference_hz - 1.0)

print("Euler-Bernoulli [Hz]:", euler_bernoulli_hz.round(4))
print(" N   mode 1 [%]  mode 2 [%]  mode 3 [%]")
for segments, errors in errors_percent.items():
    print(f"{segments:2d}  " + "  ".join(f"{e:+9.3f}" for e in errors))

# %%
# The error falls as 1/N^2 and is always negative: a chain of rigid segments is
# softer than the beam. At the preset's N = 8 the first mode is 0.7 % low, the
# third 3.9 %.

fig = Figure(figsize=(6.4, 4.2), layout="constrained")
ax = fig.subplots()
for mode in range(3):
    counts = [n for n in SEGMENT_COUNTS if errors_percent[n].size > mode]
    below_percent = [-errors_percent[n][mode] for n in counts]
    ax.loglog(counts, below_percent, "o-", label=f"mode {mode + 1}")
counts = np.array(SEGMENT_COUNTS, dtype=float)
ax.loglog(counts, 40.0 / counts**2, ":", color="grey", label="slope 1/N^2")
ax.set_xticks(SEGMENT_COUNTS, [str(n) for n in SEGMENT_COUNTS])
ax.tick_params(axis="x", which="minor", bottom=False, labelbottom=False)
ax.set_xlabel("segments N [-]")
ax.set_ylabel("frequency below Euler-Bernoulli [%]")
ax.set_title("Clamped flapwise cantilever as a chain of N segments")
ax.grid(which="both", alpha=0.3)
ax.legend()

# %%
# The chain satellite beside the thesis's
# ---------------------------------------
# Both satellites carry the same mass in the same places: their rigid design
# inertia J_tot is the same. The preset's chain joints free the three rotations
# (flapwise bending, torsion, in-plane bending) and lock the translations, so the
# plate's 50 Hz root-translation modes have no counterpart.

plate_plant = Plant.from_config(nominal())
chain_plant = Plant.from_config(chain_config)
print("J_tot diagonal, plate [kg m^2]:", np.diag(rigid_inertia(plate_plant)).round(3))
print("J_tot diagonal, chain [kg m^2]:", np.diag(rigid_inertia(chain_plant)).round(3))
print(f"coordinates: plate {plate_plant.n_dof}, chain {chain_plant.n_dof}")

plate_modes = modal_analysis(plate_plant)
chain_modes = modal_analysis(chain_plant)
LISTED_BELOW_HZ = 5.0  # [Hz]
for label, analysis in (("plate", plate_modes), ("chain", chain_modes)):
    print(f"{label}: coupled modes below {LISTED_BELOW_HZ:g} Hz")
    for mode in analysis.modes[6:]:
        if mode.frequency_hz < LISTED_BELOW_HZ:
            print(f"  {mode.index:2d} {mode.frequency_hz:6.3f} Hz  {mode.kind:9s} "
                  f"{mode.symmetry:13s} -> {mode.hub_dof or 'hub at rest'}")  # fmt: skip

# %%
# Up to 1.3 Hz both have the same six modes: a symmetric and an antisymmetric
# flapping, in-plane and torsion mode. The chain's hub-coupled ones are lower (the
# antisymmetric flapping mode that rolls the hub: 0.470 Hz against the plate's
# 0.521 Hz, see "What the hub feels" below). Above them the chain adds the panels'
# second and third bending and torsion modes, ten more below 5 Hz.
#
# Mode shapes
# -----------
# The symmetric flapping modes, panel_1 seen along X: the plate's one rigid tilt
# and the chain's first three bending shapes, each scaled so that the panel moves
# by 15 % of its length (:func:`flexsat.plots.modal.mode_amplitude`); the hub's own
# motion in the mode is included.


def panel_centreline(plant, q, segment_count):
    """Mid-chord points of panel_1, root to tip, frame N, shape (count + 1, 3) [m]."""
    quads = satellite_geometry(plant, q).panels[:segment_count]  # panel_1's come first
    roots = 0.5 * (quads[:, 0] + quads[:, 1])
    tip = 0.5 * (quads[-1, 2] + quads[-1, 3])
    return np.vstack([roots, tip])


def flapping_shape(analysis, mode, segment_count):
    """panel_1's centreline in ``mode`` at the amplitude of a 15 % panel motion [m]."""
    q = mode_amplitude(analysis, mode.index) * analysis.shapes[:, mode.index - 1]
    points = panel_centreline(analysis.plant, q, segment_count)
    if points[-1, 2] < 0.0:  # one sign convention: the tip up
        points = panel_centreline(analysis.plant, -q, segment_count)
    return points


def symmetric_flapping(analysis):
    return [m for m in analysis.modes if m.kind == "flapping" and m.symmetry == "symmetric"]


chain_segments = panel_table["segments"]
fig = Figure(figsize=(8.0, 3.6), layout="constrained")
ax = fig.subplots()
rest = panel_centreline(chain_plant, None, chain_segments)
ax.plot(rest[:, 1], rest[:, 2], color="0.6", linewidth=0.8, label="undeformed")
plate_flap = symmetric_flapping(plate_modes)[0]
points = flapping_shape(plate_modes, plate_flap, 1)
ax.plot(points[:, 1], points[:, 2], "k--",
        label=f"plate, mode {plate_flap.index}, {plate_flap.frequency_hz:.3f} Hz")  # fmt: skip
for mode in symmetric_flapping(chain_modes)[:3]:
    points = flapping_shape(chain_modes, mode, chain_segments)
    ax.plot(points[:, 1], points[:, 2], "o-", markersize=3,
            label=f"chain, mode {mode.index}, {mode.frequency_hz:.3f} Hz")  # fmt: skip
ax.set_xlabel("Y_N [m]")
ax.set_ylabel("Z_N [m]")
ax.set_title("Symmetric flapping modes of panel_1 (markers: the chain's joints)")
ax.grid(alpha=0.3)
ax.legend(fontsize=8, loc="center left", bbox_to_anchor=(1.0, 0.5))

# %%
# What the hub feels
# ------------------
# A mode matters to the attitude controller in proportion to its modal effective
# inertia about each body axis
# (:func:`flexsat.linear.frequency.effective_inertia`: the appendage modes with the
# hub held fixed, one marker per panel). The plate puts nearly all of a panel's
# flexible inertia about an axis into one mode; the chain moves a part of it into
# its higher modes. Its first modes carry less, so the hub raises their coupled
# frequencies less than the plate's.

fig = Figure(figsize=(9.0, 3.6), layout="constrained")
axes = fig.subplots(1, 3, sharex=True)
MARKERS = {
    "plate": {"marker": "s", "markersize": 9, "markerfacecolor": "none", "color": "C0"},
    "chain": {"marker": "o", "markersize": 5, "color": "C1"},
}
SHOWN_ABOVE_KG_M2 = 1e-3  # smallest effective inertia drawn [kg m^2]
effective = {}  # label -> (hub-fixed frequencies [Hz], effective inertia (n, 3) [kg m^2])
for label, plant in (("plate", plate_plant), ("chain", chain_plant)):
    frequencies_hz, inertia_kg_m2, _ = effective_inertia(plant)
    effective[label] = (frequencies_hz, inertia_kg_m2)
    for axis_index, ax in enumerate(axes):
        shown = inertia_kg_m2[:, axis_index] > SHOWN_ABOVE_KG_M2
        ax.vlines(frequencies_hz[shown], SHOWN_ABOVE_KG_M2, inertia_kg_m2[shown, axis_index],
                  color=MARKERS[label]["color"], linewidth=1.0)  # fmt: skip
        ax.plot(frequencies_hz[shown], inertia_kg_m2[shown, axis_index], linestyle="none",
                label=label, **MARKERS[label])  # fmt: skip
for ax, title in zip(axes, ("roll, about X_B", "pitch, about Y_B", "yaw, about Z_B"), strict=True):
    ax.set_xscale("log")
    ax.set_xlim(0.15, 12.0)
    ax.set_yscale("log")
    ax.set_ylim(5e-3, 300.0)
    ax.set_title(title)
    ax.set_xlabel("hub-fixed mode frequency [Hz]")
    ax.grid(which="both", alpha=0.3)
axes[0].set_ylabel("effective inertia [kg m^2]")
axes[0].legend()
for label, (frequencies_hz, inertia_kg_m2) in effective.items():
    strongest = np.argmax(inertia_kg_m2[:, 0])
    print(f"{label}: about X, {inertia_kg_m2[strongest, 0]:.2f} kg m^2 per panel at "
          f"{frequencies_hz[strongest]:.4f} Hz of {inertia_kg_m2[:, 0].sum() / 2:.2f} "
          "in all its modes")  # fmt: skip

# %%
# A modal appendage from the chain
# --------------------------------
# A ``modal`` appendage is a rigid body plus n modes clamped at its interface, the
# data a structures team hands over (docs/modal_format.md). Any flexsat appendage
# exports to it; here each chain panel keeps its clamped modes below 5 Hz. The
# export shows the modal damping the chain's joint dampers give: the preset's
# damping ratio 0.005 is per joint DOF, not per mode.

full_export = modal_data(chain_plant, "panel_1")
KEPT_BELOW_HZ = 5.0  # [Hz]
kept_modes = int(np.sum(np.array(full_export.frequencies_hz) < KEPT_BELOW_HZ))
print(f"panel_1: {full_export.n_modes} clamped modes, {kept_modes} below {KEPT_BELOW_HZ:g} Hz")
print("  frequencies [Hz]:  ", np.array(full_export.frequencies_hz[:kept_modes]).round(4))
print("  damping ratios [-]:", np.array(full_export.damping_ratios[:kept_modes]).round(4))

modal_plant = Plant.from_config(modal_satellite(chain_plant, n_modes=kept_modes))
modal_modes = modal_analysis(modal_plant)
print(f"coordinates: chain {chain_plant.n_dof}, modal {modal_plant.n_dof}")
print("coupled modes: chain [Hz]  modal [Hz]  relative difference")
for chain_hz, modal_hz in zip(chain_modes.frequencies_hz[6:18], modal_modes.frequencies_hz[6:18],
                              strict=True):  # fmt: skip
    print(f"{chain_hz:23.4f}  {modal_hz:10.4f}  {modal_hz / chain_hz - 1.0:+.1e}")

# %%
# The yaw pulse with three models
# -------------------------------
# The thesis's open-loop run (section 3.3): 1 N m about Z_B for 10 s, then free.
# The yaw torque drives the antisymmetric in-plane modes: the plate's one at
# 1.23 Hz, the chain's at 1.02 Hz and, far more weakly, 3.05 and 6.66 Hz. The modal
# satellite follows the chain with 22 coordinates instead of 54, at a fraction of
# its cost per step; what remains between them is the modes it dropped, its
# diagonal modal damping (the chain's joint dampers do not damp mode by mode) and
# the motion-dependent terms the modal model leaves out (docs/model.md, 'Modal
# appendages'). The run length can be shortened through
# ``FLEXSAT_EXAMPLE_DURATION_S``.

DURATION_S = float(os.environ.get("FLEXSAT_EXAMPLE_DURATION_S", 20.0))  # [s]

scenario = OpenLoopScenario(duration_s=DURATION_S)
runs = {}
for label, plant in (("plate", plate_plant), ("chain", chain_plant), ("modal", modal_plant)):
    runs[label] = run_openloop(plant, scenario).dataset
    print(f"{label}: {plant.n_dof} coordinates, integrated in "
          f"{runs[label].attrs['wall_time_s']:.2f} s")  # fmt: skip

fig = Figure(figsize=(7.5, 5.5), layout="constrained")
rate_ax, tip_ax = fig.subplots(2, 1, sharex=True)
for label, style in (("plate", "--"), ("chain", "-"), ("modal", ":")):
    dataset = runs[label]
    time_s = dataset["time"].values
    rate_ax.plot(time_s, np.degrees(dataset["omega"].values[:, 2]), style, label=label)
    tip_in_plane_m = dataset["tip_displacement"].sel(appendage="panel_1", axis="x").values
    tip_ax.plot(time_s, 1e3 * tip_in_plane_m, style, label=label)
rate_ax.set_ylabel("yaw rate omega_z [deg/s]")
tip_ax.set_ylabel("panel_1 tip, in-plane X_M [mm]")
tip_ax.set_xlabel("time [s]")
rate_ax.legend()
rate_ax.grid(alpha=0.3)
tip_ax.grid(alpha=0.3)
rate_ax.set_title("1 N m yaw pulse for 10 s: plate, chain and modal panels")

chain_tip_m = runs["chain"]["tip_displacement"].sel(appendage="panel_1", axis="x").values
modal_tip_m = runs["modal"]["tip_displacement"].sel(appendage="panel_1", axis="x").values
tip_difference = np.abs(modal_tip_m - chain_tip_m).max() / np.abs(chain_tip_m).max()
print(f"panel_1 in-plane tip, modal against chain: {tip_difference:.1%} of the chain's peak")
