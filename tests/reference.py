"""Reference values from the thesis, shared by the tests (each cites its source)."""

import numpy as np

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
