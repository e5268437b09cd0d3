"""flexsat's intrinsic Euler rotations are SciPy's, bit for bit (docs/performance.md, 'Start-up').

The plate packs R_BM with :class:`flexsat.dynamics.rotation.EulerRotation` instead of
SciPy's ``Rotation`` so that building a plant does not import :mod:`scipy.spatial`;
the packed parameters, and so every run, must not change by one bit.
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from flexsat.dynamics.rotation import EulerRotation, euler_matrix

SEED = 20261207
"""The random angles' seed (fixed, printed by the tests that use it)."""

# Angles a configuration uses (mount yaws, SADM angles) and their neighbours: exact
# multiples of 90 deg, where a last-bit difference would show as a non-zero zero.
SPECIAL_DEG = (0.0, 1e-9, 30.0, 45.0, 60.0, 90.0, -90.0, 180.0, -180.0, 270.0, 360.0, 1e3)


@pytest.mark.parametrize("seq", ["Z", "Y", "X", "ZY", "ZYX", "XYZ", "YZ", "ZXZ"])
def test_equal_to_scipy_bit_for_bit(seq):
    print(f"seed = {SEED}")
    rng = np.random.default_rng(SEED)
    random = rng.uniform(-7.0, 7.0, size=(2000, len(seq)))  # [rad], past +-2 pi
    special = np.radians(rng.choice(SPECIAL_DEG, size=(500, len(seq))))
    for angles in (random, special):
        expected = Rotation.from_euler(seq, angles).as_matrix()
        assert np.array_equal(euler_matrix(seq, angles), expected)  # exact: same arithmetic
        for row in angles[:50]:  # one rotation at a time, as the plate packs it
            one = Rotation.from_euler(seq, row).as_matrix()
            assert np.array_equal(EulerRotation.from_euler(seq, row).as_matrix(), one)


def test_a_single_axis_takes_a_scalar():
    expected = Rotation.from_euler("Z", 0.3).as_matrix()
    assert np.array_equal(euler_matrix("Z", 0.3), expected)


def test_the_matrix_is_a_rotation_about_the_named_axes():
    # Independent check, not SciPy: Rz(a) Ry(b) from their elementary matrices; a few
    # round-offs of order-one values, hence 1e-15 absolute.
    a, b = 0.7, -1.2
    Rz = np.array([[np.cos(a), -np.sin(a), 0.0], [np.sin(a), np.cos(a), 0.0], [0.0, 0.0, 1.0]])
    Ry = np.array([[np.cos(b), 0.0, np.sin(b)], [0.0, 1.0, 0.0], [-np.sin(b), 0.0, np.cos(b)]])
    np.testing.assert_allclose(euler_matrix("ZY", [a, b]), Rz @ Ry, rtol=0.0, atol=1e-15)


@pytest.mark.parametrize(
    ("seq", "angles", "words"),
    [("zy", [0.1, 0.2], "intrinsic"), ("ZZ", [0.1, 0.2], "repeat"), ("", [], "intrinsic"),
     ("ZY", [0.1], "angles")],
)  # fmt: skip
def test_bad_sequences_and_angle_counts_are_refused(seq, angles, words):
    with pytest.raises(ValueError, match=words):
        euler_matrix(seq, angles)
