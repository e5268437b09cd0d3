"""Min-max allocation along a null direction: against a linear program, and on the pyramid."""

from __future__ import annotations

import numpy as np
import pytest
from scipy.optimize import linprog

from flexsat.control.stages._allocation import minmax_shift, null_direction
from flexsat.control.stages.wheels import MAX_WHEELS, wheel_axes

SEED = 20261207


def _lp_minmax(u, d):
    """min t s.t. -t <= u_i + s d_i <= t: the same problem as a linear program (HiGHS)."""
    n = u.size
    A_ub = np.vstack([np.column_stack([d, -np.ones(n)]), np.column_stack([-d, -np.ones(n)])])
    b_ub = np.concatenate([-u, u])
    res = linprog([0.0, 1.0], A_ub=A_ub, b_ub=b_ub, bounds=[(None, None), (0.0, None)])
    return res.fun


def test_the_shift_is_the_linear_programs_optimum():
    # 500 random problems of 2..6 wheels (seed printed): the largest |u_i + s d_i| at
    # the returned step equals the LP optimum to 1e-9 (HiGHS's default tolerances are
    # 1e-7 relative; measured agreement ~1e-15), and is never above max |u| (s = 0).
    rng = np.random.default_rng(SEED)
    print(f"seed {SEED}")
    for _ in range(500):
        n = int(rng.integers(2, MAX_WHEELS + 1))
        u, d = rng.normal(size=n), rng.normal(size=n)
        d[rng.random(n) < 0.2] = 0.0  # wheels the direction leaves alone
        s = minmax_shift(u, d, n)
        got = np.abs(u + s * d).max()
        assert got <= np.abs(u).max() + 1e-15
        assert got == pytest.approx(_lp_minmax(u, d), abs=1e-9)


def test_the_pyramid_needs_two_thirds_of_the_pseudo_inverses_worst_motor_torque():
    # Four wheels at 54.7356 deg: A A^T = (4/3) I, so A^+ = (3/4) A^T, and 1.9 N m on
    # all three axes asks one motor for (3/4) sqrt(3) 1.9 = 2.468 N m. The null
    # direction is (-1, 1, -1, 1)/2; the min-max allocation spreads the demand to
    # sqrt(3) 1.9 / 2 = 1.6454 N m on every motor (the torque delivered unchanged:
    # A u to round-off). 1e-6: the preset's half-angle 54.7356 deg is the magic angle
    # arccos(1/sqrt 3) = 54.735610 deg to 1.7e-7 rad, so the four motors differ by ~5e-7.
    axes = wheel_axes("pyramid4")
    A = axes.T
    pinv = np.linalg.pinv(A)
    projector = np.eye(4) - pinv @ A
    d = np.zeros(4)
    assert null_direction(projector.ravel(), 4, 4, d)
    np.testing.assert_allclose(np.abs(d), 0.5, atol=1e-12)
    tau = np.full(3, 1.9)
    u = pinv @ tau
    assert np.abs(u).max() == pytest.approx(0.75 * np.sqrt(3.0) * 1.9, rel=1e-6)
    shifted = u + minmax_shift(u, d, 4) * d
    np.testing.assert_allclose(np.abs(shifted), np.sqrt(3.0) * 1.9 / 2.0, rtol=1e-6)
    np.testing.assert_allclose(A @ shifted, tau, atol=1e-14)


def test_three_orthogonal_wheels_have_no_null_direction():
    d = np.ones(3)
    assert not null_direction(np.zeros(9), 3, 3, d)
    np.testing.assert_array_equal(d, 0.0)
