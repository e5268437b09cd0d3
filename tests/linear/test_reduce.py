"""Modal and balanced truncation: sizes, kept rigid part, the error bound."""

import numpy as np
import pytest

from flexsat.errors import ConfigError
from flexsat.linear.reduce import balanced_truncation, modal_truncation

_F = np.geomspace(1e-3, 200.0, 4000)  # [Hz] through every mode of the thesis model


def _hinf(G):
    return max(np.linalg.norm(g, 2) for g in G)


@pytest.fixture(scope="module")
def rate_model(rest_model):
    return rest_model.select(outputs=["omega_x", "omega_y", "omega_z"])


@pytest.mark.parametrize("order", [14, 16, 20, 24])
def test_balanced_truncation_error_is_within_its_bound(rate_model, order):
    red = balanced_truncation(rate_model, order)
    assert red.model.n_states == order and red.n_marginal == 12  # 6 rigid DOFs x 2
    hsv = red.hankel_singular_values
    G = rate_model.frequency_response(_F)
    err = _hinf(G - red.model.frequency_response(_F))
    kept = order - red.n_marginal
    # Glover's bounds: sigma_{r+1} <= ||G - G_r||_inf <= 2 sum_{k>r} sigma_k. The
    # grid estimate of the norm can only fall short of it (lower side: 10 % slack
    # for the grid missing the exact peak of a 0.5 %-damped mode; upper side: the
    # round-off of the Schur and Sylvester transformations, ~1e-10 of ||G||).
    assert red.error_bound == pytest.approx(2 * hsv[kept:].sum(), rel=1e-12)
    assert err <= red.error_bound + 1e-8 * _hinf(G)
    if hsv[kept] > 1e-8 * _hinf(G):
        assert err >= 0.9 * hsv[kept]


def test_modal_truncation_keeps_the_low_modes_and_reports_its_error(rate_model):
    red = modal_truncation(rate_model, 16)  # rigid + the two lowest flexible modes
    lam = red.model.poles()
    f = np.sort(np.abs(lam[lam.imag > 1e-6])) / (2 * np.pi)
    full = rate_model.poles()
    f_full = np.sort(np.abs(full[full.imag > 1e-6])) / (2 * np.pi)
    np.testing.assert_allclose(f, f_full[:2], rtol=1e-9)  # exact invariant subspace
    err = _hinf(rate_model.frequency_response(_F) - red.model.frequency_response(_F))
    # The reported number is the discarded part's peak on a finer grid around its
    # poles: the same quantity, within the grid's reach (5 %).
    assert err == pytest.approx(red.error_bound, rel=0.05)
    # Low-frequency behaviour (rigid + first modes) is kept: 1 % at 0.05 Hz.
    G, Gr = rate_model.frequency_response(0.05), red.model.frequency_response(0.05)
    assert np.linalg.norm(G - Gr) <= 0.01 * np.linalg.norm(G)


@pytest.mark.parametrize("reduce", [modal_truncation, balanced_truncation])
@pytest.mark.parametrize(("order", "message"), [(40, "between 12"), (8, "between 12")])
def test_orders_out_of_range_give_one_clear_message(rate_model, reduce, order, message):
    with pytest.raises(ConfigError, match=message):
        reduce(rate_model, order)


def test_balanced_truncation_refuses_an_undamped_model(plant):
    from flexsat.linear import linearize

    undamped = plant.with_joints(plant.stiffness, np.zeros_like(plant.damping))
    with pytest.raises(ConfigError, match="damping_ratio > 0"):
        balanced_truncation(linearize(undamped, outputs=["rate"]), 16)
