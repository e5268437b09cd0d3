"""
Frequency-domain design with the linear model
=============================================

Linearizes the nominal satellite about rest, closes the PD law's loop one axis at a
time and reports its margins, ranks the appendage modes by effective inertia, and
builds a balanced reduced model of torque -> rate, checked against its error bound.
``run(out_dir)`` also writes every figure of the linear analysis into ``out_dir``.
"""

# %%
# The design, as one function
# ---------------------------

from pathlib import Path

import numpy as np

from flexsat.config import nominal
from flexsat.control.laws.pd import PDConfig
from flexsat.dynamics.plant import Plant
from flexsat.linear import (
    balanced_truncation,
    effective_inertia,
    law_gains,
    linearize,
    loop_margins,
    pd_loop,
    rigid_model,
)
from flexsat.plots.linear import plot_bode, plot_loops


def run(out_dir: str | Path | None = None, natural_frequency_rad_s: float = 0.3) -> dict:
    """Margins per axis, the three strongest appendage modes and a 16-state model.

    Parameters
    ----------
    out_dir : str or Path, optional
        Where to write the figures (none written without it).
    natural_frequency_rad_s : float
        Bandwidth of the PD law [rad/s].

    Returns
    -------
    dict
        ``margins`` (per axis), ``strongest_modes`` (frequency [Hz], axis, J_eff
        [kg m^2]), ``reduced_error_bound`` and ``reduced_peak_error`` (H-infinity,
        [rad/s / N m]).
    """
    plant = Plant.from_config(nominal())
    model = linearize(plant)  # exact about rest
    law = PDConfig(natural_frequency_rad_s=natural_frequency_rad_s, damping_ratio=0.9)
    K = law_gains(plant, law)
    loops = {axis: pd_loop(model, K, axis) for axis in "xyz"}
    margins = {axis: loop_margins(loop) for axis, loop in loops.items()}
    f_modes, J_eff, _ = effective_inertia(plant)
    k, a = np.unravel_index(np.argsort(-J_eff, axis=None)[:3], J_eff.shape)
    rate = model.select(outputs=["omega_x", "omega_y", "omega_z"])
    reduced = balanced_truncation(rate, 16)
    f = np.geomspace(1e-3, 200.0, 3000)  # [Hz]
    error = rate.frequency_response(f) - reduced.model.frequency_response(f)
    if out_dir is not None:
        from flexsat.plots.linear import write_linear_figures

        write_linear_figures(out_dir, model, rigid_model(plant), (f_modes, J_eff), loops, margins)
    return {
        "margins": {axis: m.to_dict() for axis, m in margins.items()},
        "strongest_modes": [
            (float(f_modes[i]), "xyz"[j], float(J_eff[i, j])) for i, j in zip(k, a, strict=True)
        ],
        "reduced_error_bound": reduced.error_bound,
        "reduced_peak_error": float(max(np.linalg.norm(e, 2) for e in error)),
    }


# %%
# Margins, modes and a reduced model
# ----------------------------------

summary = run()
for axis, m in summary["margins"].items():
    print(
        f"axis {axis}: phase margin {m['phase_margin_deg']:.1f} deg, delay margin "
        f"{m['delay_margin_s']:.3f} s at {m['delay_crossover_hz']:.2f} Hz"
    )
for f_hz, axis, J in summary["strongest_modes"]:
    print(f"mode {f_hz:.3f} Hz: effective inertia {J:.1f} kg m^2 about {axis}")
print(f"16-state model: peak error {summary['reduced_peak_error']:.3g}, "
      f"bound {summary['reduced_error_bound']:.3g}")  # fmt: skip

# %%
# Bode diagrams
# -------------
# Torque to rate about each axis, flexible and rigid: the appendage modes are the
# peaks and notches the rigid model does not have.

plant = Plant.from_config(nominal())
model = linearize(plant)
plot_bode(model, rigid_model(plant))

# %%
# Loop gains
# ----------
# The PD loop per axis, with its crossovers and the flexible modes marked.

K = law_gains(plant, PDConfig(natural_frequency_rad_s=0.3, damping_ratio=0.9))
loops = {axis: pd_loop(model, K, axis) for axis in "xyz"}
margins = {axis: loop_margins(loop) for axis, loop in loops.items()}
plot_loops(loops, margins, effective_inertia(plant)[0])  # flexible modes marked [Hz]
