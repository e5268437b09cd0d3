"""
A spinning beam stiffens
========================

A uniform cantilever, radial on a hub spinning at Omega, is stiffened by its
centrifugal tension: its flap frequency rises as omega^2 = omega_0^2 + K Omega^2,
with Southwell's coefficient K = 1.193 when the root is on the spin axis and more
when it sits at a radius R. A set of modes linear in the deflection cannot produce
this stiffness from its kinetic energy; the modal appendage gets it from the data's
large-motion invariants (docs/model.md, 'Large motion'), which
:func:`flexsat.fe.craig_bampton` writes for the scikit-fem beam. Here K from the
Craig-Bampton beam, linearized about the steady spin, against the rotating-beam
equation (:func:`flexsat.fe.beam.rotating_cantilever_frequencies`), for root offsets
from 0 to 2 L.
"""

# %%
# The beam and its satellite
# --------------------------
# A 2 m cantilever of 4 kg (EI 500 N m^2 flapwise, 2000 in plane), 16 Hermite
# elements, 10 clamped modes with their large-motion invariants, on a hub heavy
# enough that the spin stays as prescribed.

import numpy as np
from matplotlib.figure import Figure

from flexsat import Plant
from flexsat.config import validate_config
from flexsat.fe import craig_bampton, uniform_beam
from flexsat.fe.beam import rotating_cantilever_frequencies
from flexsat.linear import linearize

L, MASS, EI = 2.0, 4.0, 500.0  # [m], [kg], [N m^2]
UNIT = np.sqrt(EI / (MASS / L * L**4))  # sqrt(EI / (rho A L^4)) [rad/s]
OMEGA_BAR_0 = rotating_cantilever_frequencies(0.0)[0]  # 3.516 (beta_1 L)^2
OMEGA_0 = OMEGA_BAR_0 * UNIT  # first flap frequency at rest [rad/s]

beam = uniform_beam(L, 16, mass_per_length_kg_m=MASS / L, bending_stiffness_x_n_m2=EI,
                    bending_stiffness_z_n_m2=2000.0, axial_stiffness_n=1e8,
                    torsional_stiffness_n_m2=400.0, polar_inertia_per_length_kg_m=1e-4)  # fmt: skip
data = craig_bampton(beam.M, beam.K, beam.interface_dofs, 10,
                     interface_map=beam.interface_map, large_motion=beam.large_motion)  # fmt: skip


def spinning_satellite(offset_ratio: float) -> Plant:
    """The beam radial along Y_B at R = offset_ratio L on a hub of 5e6 kg m^2."""
    return Plant.from_config(validate_config({
        "hub": {"mass_kg": 1e7, "inertia_kg_m2": [[5e6, 0, 0], [0, 5e6, 0], [0, 0, 5e6]]},
        "appendages": [{"name": "beam", "model": "modal", "data": data.model_dump(),
                        "mount_point_m": [0.0, offset_ratio * L, 0.0]}],
    }))  # fmt: skip


def southwell(plant: Plant, spin_ratio: float, offset_ratio: float) -> float:
    """K of the flap mode about a steady spin Omega = spin_ratio omega_0 about Z_B."""
    spin = spin_ratio * OMEGA_0
    guess = rotating_cantilever_frequencies(spin / UNIT, offset_ratio)[0] * UNIT
    system = linearize(plant, about=[0.0, 0.0, spin], outputs=("rate",))
    rates = np.abs(np.linalg.eigvals(system.A).imag)
    omega = rates[np.argmin(np.abs(rates - guess))]
    return float((omega**2 - OMEGA_0**2) / spin**2)


# %%
# K against the root offset
# -------------------------
# The reference's K at two spins (the mode shape changes with the spin, so K falls a
# little as it grows), and the modal appendage's at Omega = omega_0 / 4 and 2 omega_0.

offsets = np.array([0.0, 0.25, 0.5, 1.0, 2.0])
spins = (0.25, 2.0)
measured = {s: [] for s in spins}
for R in offsets:
    plant = spinning_satellite(R)
    for s in spins:
        measured[s].append(southwell(plant, s, R))
fine = np.linspace(0.0, 2.0, 41)


def reference_k(spin_ratio: float, offset_ratio: float) -> float:
    spin_bar = spin_ratio * OMEGA_BAR_0
    omega_bar = rotating_cantilever_frequencies(spin_bar, offset_ratio)[0]
    return float((omega_bar**2 - OMEGA_BAR_0**2) / spin_bar**2)


k_at_rest = measured[0.25][0]  # Southwell's 1.193 at R = 0
print(f"K at R = 0, Omega = omega_0 / 4: {k_at_rest:.4f} (Southwell: 1.193)")
for R, k_low, k_high in zip(offsets, measured[0.25], measured[2.0], strict=True):
    print(f"R/L = {R:4.2f}: K = {k_low:.4f} (reference {reference_k(0.25, R):.4f}), "
          f"at 2 omega_0 {k_high:.4f} (reference {reference_k(2.0, R):.4f})")  # fmt: skip

fig = Figure(figsize=(7.0, 4.5), layout="constrained")
ax = fig.subplots()
for s, colour in zip(spins, ("C0", "C1"), strict=True):
    ax.plot(fine, [reference_k(s, R) for R in fine], color=colour,
            label=f"rotating-beam equation, Omega = {s:g} omega_0")  # fmt: skip
    ax.plot(offsets, measured[s], "o", color=colour, mfc="none",
            label=f"Craig-Bampton beam with its invariants, Omega = {s:g} omega_0")  # fmt: skip
ax.set_xlabel("root offset R / L [-]")
ax.set_ylabel("Southwell coefficient K [-]")
ax.set_title("Flap stiffening of a spinning cantilever: omega^2 = omega_0^2 + K Omega^2")
ax.legend()
