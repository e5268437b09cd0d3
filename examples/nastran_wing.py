"""
A wing from a NASTRAN deck
==========================

A structures team hands over a NASTRAN model: the bulk data (grids, rigid
elements, the a-set) and the stiffness and mass matrices a DMAP alter wrote to an
OP4 file. ``flexsat fe import`` (here :func:`flexsat.fe.nastran.import_nastran`)
maps the OP4 rows to the grids, clamps the structure at its interface grid,
reduces it by Craig-Bampton to the modal data format, and the satellite flies it as
a ``modal`` appendage. The deck in ``examples/data`` is flexsat.fe's own thin
aluminium plate (0.8 m x 0.3 m x 6 mm, 27-node hexahedra) written as NASTRAN
would hold it (``examples/data/make_nastran_plate.py``), so the import can be
checked against flexsat.fe's direct reduction of the same matrices.
"""

# %%
# The import
# ----------
# The OP4 holds KAA and MAA; the bulk data says the a-set is the interface grid
# 9000's six DOFs and the interior grids' translations (ASET1 cards), the root
# face slaved to grid 9000 by an RBE2. The interface is the one grid whose six DOFs
# the a-set holds as boundary; four clamped modes are kept.

import os
import runpy
from pathlib import Path

import numpy as np
from matplotlib.figure import Figure

from flexsat import Plant, SatelliteConfig, nominal
from flexsat.fe import craig_bampton
from flexsat.fe.nastran import import_nastran
from flexsat.simulate import OpenLoopScenario, run_openloop

# The gallery runs each example from its own folder, where __file__ is not defined.
DATA = Path(globals().get("__file__", "nastran_wing.py")).resolve().parent / "data"
wing = import_nastran(DATA / "nastran_plate.bdf", DATA / "nastran_plate.op4", n_modes=4,
                      damping_ratio=0.005)  # fmt: skip
print(f"{wing.stiffness_name}/{wing.mass_name}: {len(wing.dofs)} DOFs, interface grid "
      f"{wing.interface_grid}, tip grid {wing.tip_grid}, {wing.modal.mass_kg:.4f} kg")  # fmt: skip
for k, f in enumerate(wing.modal.frequencies_hz):
    share = wing.modal.participation_matrix()[k, 2] ** 2 / wing.modal.mass_kg
    print(f"mode {k + 1}: {f:8.3f} Hz, effective mass along Z {100 * share:5.1f} %")

# %%
# Against flexsat.fe's own reduction
# ----------------------------------
# The same plate reduced directly from its FE matrices: the rigid mass agrees to
# round-off, the frequencies to the eigensolver's round-off for this thin plate
# (about 1e-16 times the condition number of the clamped stiffness, 2e10).

plate = runpy.run_path(str(DATA / "make_nastran_plate.py"))["plate_model"]()
direct = craig_bampton(plate.M, plate.K, plate.interface_dofs, 4,
                       interface_map=plate.interface_map,
                       rigid_modes=plate.rigid_modes)  # fmt: skip
frequency_difference = np.max(
    np.abs(np.array(wing.modal.frequencies_hz) / np.array(direct.frequencies_hz) - 1.0)
)
mass_difference = np.max(np.abs(wing.modal.rigid_mass_matrix() - direct.rigid_mass_matrix()))
print(f"largest relative frequency difference {frequency_difference:.1e}, "
      f"rigid mass matrix difference {mass_difference:.1e}")  # fmt: skip

# %%
# Flying it
# ---------
# The nominal hub with two such wings, along +Y and (turned 180 degrees about Z)
# along -Y, takes a 1 N m roll torque for 2 s: the wings flap, and the angular
# momentum the torque gave (2 N m s about X) stays with the satellite. The run
# length is ``FLEXSAT_EXAMPLE_DURATION_S``.

base = nominal().model_dump(exclude_none=True)
wings = [
    {"name": name, "model": "modal", "mount_point_m": [0.0, side * 0.6, 0.0],
     "mount_yaw_deg": 0.0 if side > 0 else 180.0, "data": wing.modal.model_dump()}
    for name, side in (("wing_1", 1.0), ("wing_2", -1.0))
]  # fmt: skip
config = SatelliteConfig.model_validate({"name": "nastran-wings", "hub": base["hub"],
                                         "appendages": wings})  # fmt: skip
plant = Plant.from_config(config)
DURATION_S = float(os.environ.get("FLEXSAT_EXAMPLE_DURATION_S", 6.0))  # [s]
scenario = OpenLoopScenario(
    duration_s=DURATION_S,
    torque=[{"start_s": 0.0, "end_s": min(2.0, 0.5 * DURATION_S), "torque_nm": (1.0, 0.0, 0.0)}],
)
run = run_openloop(plant, scenario).dataset
momentum_x = run["angular_momentum"].values[-1, 0]  # [N m s], inertial frame
print(f"angular momentum about X at the end: {momentum_x:.6f} N m s")

fig = Figure(figsize=(7.5, 5.0), layout="constrained")
rate_ax, tip_ax = fig.subplots(2, 1, sharex=True)
time_s = run["time"].values
rate_ax.plot(time_s, np.degrees(run["omega"].values[:, 0]))
rate_ax.set_ylabel("roll rate [deg/s]")
for name in ("wing_1", "wing_2"):
    tip_m = run["tip_displacement"].sel(appendage=name, axis="z").values
    tip_ax.plot(time_s, 1e3 * tip_m, label=name)
tip_ax.set_ylabel("tip deflection z [mm]")
tip_ax.set_xlabel("time [s]")
tip_ax.legend()
