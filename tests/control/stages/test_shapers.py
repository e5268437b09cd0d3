"""Input shapers against their defining property: the residual vibration of a damped mode."""

from __future__ import annotations

import numpy as np
import pytest

from flexsat.control.stages.shapers import residual_vibration, shaper, shaper_for_modes

F_HZ, ZETA = 0.52, 0.01  # the nominal satellite's antisymmetric flapping mode, roughly


@pytest.mark.parametrize("kind", ["zv", "zvd", "ei"])
def test_amplitudes_sum_to_one_and_times_start_at_zero(kind):
    A, t = shaper(kind, F_HZ, ZETA)
    assert A.sum() == pytest.approx(1.0, abs=1e-15)
    assert t[0] == 0.0 and np.all(np.diff(t) > 0.0) and np.all(A > 0.0)


@pytest.mark.parametrize("kind", ["zv", "zvd"])
def test_zero_residual_vibration_at_the_design_mode(kind):
    # ZV and ZVD cancel the damped mode exactly (Singer and Seering 1990); 1e-14 is
    # round-off on sums of three unit-size phasors.
    A, t = shaper(kind, F_HZ, ZETA)
    assert residual_vibration(A, t, F_HZ, ZETA) < 1e-14


def test_zvd_is_insensitive_to_frequency_and_zv_is_not():
    # ZVD also zeroes dV/df at the design frequency: at +-20 % its residual is
    # (analytically, undamped) sin^2(0.2 pi / 2)-like ~ 0.095, ZV's |cos(0.6 pi)| ~ 0.31.
    zv, zvd = shaper("zv", F_HZ, ZETA), shaper("zvd", F_HZ, ZETA)
    for scale in (0.8, 1.2):
        v_zv = residual_vibration(*zv, scale * F_HZ, ZETA)
        v_zvd = residual_vibration(*zvd, scale * F_HZ, ZETA)
        assert v_zvd < 0.1 and v_zv > 0.3
        assert v_zvd < v_zv / 3.0


def test_ei_holds_its_tolerance_over_a_band():
    # EI: V = 5 % at the design frequency (Singhose et al. 1994) and below 5 % over
    # roughly +-10 % either side of the two zeros; 5e-3 absorbs the damped form's
    # approximation at zeta = 0.01.
    A, t = shaper("ei", F_HZ, ZETA)
    assert residual_vibration(A, t, F_HZ, ZETA) == pytest.approx(0.05, abs=5e-3)
    band = [residual_vibration(A, t, s * F_HZ, ZETA) for s in np.linspace(0.9, 1.1, 21)]
    assert max(band) <= 0.055


def test_multi_mode_convolution_cancels_every_mode():
    # The convolution of per-mode ZVD shapers cancels each mode (residual a product of
    # factors, one of them zero): 1e-13 is round-off over 3^3 impulses.
    modes, ratios = [0.258, 0.52, 1.23], [0.005, 0.01, 0.012]
    A, t = shaper_for_modes("zvd", modes, ratios)
    assert A.size == 27 and A.sum() == pytest.approx(1.0, abs=1e-14)
    for f, zeta in zip(modes, ratios, strict=True):
        assert residual_vibration(A, t, f, zeta) < 1e-13
