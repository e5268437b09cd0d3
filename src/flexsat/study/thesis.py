"""The reference thesis's published numbers, transcribed once with their sources.

The thesis is *Multi-Body Dynamic Modeling and Robust Sliding Mode Control of Flexible
Satellites*. The study report prints its numbers beside flexsat's results; the test
suite checks the model against them. Each value cites the equation, table, figure or
section it was read from, and says how it was printed (its precision sets the tests'
tolerances).
"""

from __future__ import annotations

import numpy as np

__all__ = [
    "CAMPAIGNS",
    "CLOSED_LOOP",
    "J_TOT_NOMINAL",
    "M0_HUB",
    "M0_HUB_P1",
    "M0_HUB_P2",
    "M0_P1",
    "M0_P2",
    "OPEN_LOOP",
    "PRINTED_2DP",
    "TABLE_3_3",
    "TRANSLATION_MODES_MIN_HZ",
    "appendix_b_mass_matrix",
]

CAMPAIGNS = ("sensitivity", "montecarlo-critical", "deployment-shock")
"""The thesis's three campaigns (chapter 5), in the order of the report: the names of
their presets (:func:`flexsat.campaigns.load_campaign`)."""

# Appendix B, eqs. B.2-B.6: M(0) of the nominal case, printed to 2 decimals.
M0_HUB = np.diag([163.50, 163.50, 163.50, 189.99, 44.16, 177.90])  # eq. B.2
M0_HUB_P1 = np.array(  # eq. B.3
    [
        [6.75, 0, 0, 0, 0, -15.19],
        [0, 6.75, 0, 0, 0, 0],
        [0, 0, 6.75, 15.19, 0, 0],
        [0, 0, 20.59, 57.71, 0, 0],
        [0, 0, 0, 0, 1.27, 0],
        [-20.59, 0, 0, 0, 0, 58.98],
    ]
)
M0_HUB_P2 = np.array(  # eq. B.4
    [
        [6.75, 0, 0, 0, 0, 15.19],
        [0, 6.75, 0, 0, 0, 0],
        [0, 0, 6.75, -15.19, 0, 0],
        [0, 0, -20.59, 57.71, 0, 0],
        [0, 0, 0, 0, 1.27, 0],
        [20.59, 0, 0, 0, 0, 58.98],
    ]
)
M0_P1 = np.array(  # eq. B.5
    [
        [6.75, 0, 0, 0, 0, -15.19],
        [0, 6.75, 0, 0, 0, 0],
        [0, 0, 6.75, 15.19, 0, 0],
        [0, 0, 15.19, 45.56, 0, 0],
        [0, 0, 0, 0, 1.27, 0],
        [-15.19, 0, 0, 0, 0, 46.83],
    ]
)
M0_P2 = np.array(  # eq. B.6
    [
        [6.75, 0, 0, 0, 0, 15.19],
        [0, 6.75, 0, 0, 0, 0],
        [0, 0, 6.75, -15.19, 0, 0],
        [0, 0, -15.19, 45.56, 0, 0],
        [0, 0, 0, 0, 1.27, 0],
        [15.19, 0, 0, 0, 0, 46.83],
    ]
)


def appendix_b_mass_matrix() -> np.ndarray:
    """The full 18x18 M(0) assembled from the printed blocks (eq. B.1)."""
    M = np.zeros((18, 18))
    M[0:6, 0:6] = M0_HUB
    M[0:6, 6:12] = M0_HUB_P1
    M[0:6, 12:18] = M0_HUB_P2
    M[6:12, 0:6] = M0_HUB_P1.T
    M[12:18, 0:6] = M0_HUB_P2.T
    M[6:12, 6:12] = M0_P1
    M[12:18, 12:18] = M0_P2
    return M


# Printed to 2 decimals: a value v stands for [v - 0.005, v + 0.005]. A hair above
# half a unit in the last place absorbs the binary representation of the bound.
PRINTED_2DP = 0.005 + 1e-9

# Section 3.1 / appendix A.4: rigid design inertia about the hub centre of mass.
J_TOT_NOMINAL = np.diag([189.99, 44.16, 177.90])

# Table 3.3: coupled modes 7-12 (frequency printed to 2 decimals, kind, symmetry,
# hub DOF named in the text of section 3.2.2).
TABLE_3_3 = [
    (7, 0.26, "flapping", "symmetric", "z"),
    (8, 0.52, "in_plane", "symmetric", "x"),
    (9, 0.52, "flapping", "antisymmetric", "phi"),
    (10, 0.80, "torsion", "antisymmetric", None),
    (11, 0.82, "torsion", "symmetric", "theta"),
    (12, 1.23, "in_plane", "antisymmetric", "psi"),
]
TRANSLATION_MODES_MIN_HZ = 50.0  # table 3.3: modes 13-18 at or above 50 Hz

# Section 3.3 and figs. 3.8-3.14: the open-loop run (1 N m yaw torque for 10 s, then
# free, to 120 s). Keys are openloop_metrics' keys; the value is what the thesis prints
# or reads off a figure, with the text it comes from.
OPEN_LOOP = {
    "final_angular_momentum_nms": (10.0, "fig. 3.12: H_z = 10 N m s (the torque impulse)"),
    "final_rate_deg_s": (3.22, "section 3.3: yaw rate ~3.22 deg/s after the pulse"),
    "total_energy_j": (0.28, "section 3.3: E_tot ~0.28 J"),
    "peak_elastic_energy_j": (0.9e-3, "section 3.3: peak elastic energy ~0.9 mJ"),
    "dissipated_energy_j": (0.55e-3, "section 3.3: dissipated energy ~0.55 mJ"),
    "peak_flex_torque_nm": (1.5, "fig. 3.11: tau_flex,z peaks close to +-1.5 N m"),
    "peak_root_rotation_deg": (0.1, "section 3.3: root in-plane rotation almost 0.1 deg"),
    "peak_tip_displacement_m": (6.0e-3, "section 3.3: tip displacement just over 6 mm"),
    "dominant_frequency_hz": (1.23, "fig. 3.14: the free response rings at ~1.23 Hz"),
}

# Section 5.1.3: the nominal 45/45/45 deg ASMC slew. Keys are slew_metrics' keys.
CLOSED_LOOP = {
    "final_pointing_error_deg": (2.50e-3, "section 5.1.3: 2.50e-3 deg at the end"),
    "settling_time_s": (45.0, "section 5.1.3: inside R1 from t ~ 45 s"),
    "lambda_switch_time_s": (30.0, "section 5.1.3: Lambda leaves its minimum around 30 s"),
    "r1_pass": (True, "section 5.1.3: R1 (< 0.05 deg) met"),
    "r2_pass": (True, "section 5.1.3: R2 (< 1e-3 deg/s) met"),
    "r3_pass": (True, "section 5.1.3: R3 (|tau| <= 2 N m) met"),
}
