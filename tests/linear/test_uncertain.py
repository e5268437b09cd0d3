"""The satellite's uncertain model (LFT) against the linearization of perturbed plants."""

import numpy as np
import pytest

from flexsat.config import nominal
from flexsat.dynamics.plant import Plant
from flexsat.errors import ConfigError
from flexsat.linear import linearize
from flexsat.linear.uncertain import UncertainParameter, uncertain_model, with_sadm_angle
from flexsat.study.mu import perturbed_config

SEED = 20261207  # fixed, printed by the sampled test


@pytest.fixture(scope="module")
def lft():
    return uncertain_model(nominal())


def _perturbed(config, factors):
    """The satellite the campaign modifiers make from the same factors."""
    return Plant.from_config(perturbed_config(config, factors))


def test_nominal_point_is_the_linearized_model(lft):
    """At the nominal factors the LFT is linearize's A and B; eigenvalues to 1e-9."""
    nominal_model = linearize(Plant.from_config(nominal()), outputs=("attitude", "rate"))
    m = lft.evaluate(lft.nominal_delta())
    # Both come from M(0), K and C by one solve each: equal to round-off.
    assert np.max(np.abs(m.A - nominal_model.A)) <= 1e-12 * np.max(np.abs(nominal_model.A))
    assert np.max(np.abs(m.B - nominal_model.B)) <= 1e-12 * np.max(np.abs(nominal_model.B))
    lam, ref = np.sort_complex(np.linalg.eigvals(m.A)), np.sort_complex(nominal_model.poles())
    # The acceptance bound: 1e-9 of the largest mode's |lambda| (~630 rad/s).
    assert np.max(np.abs(lam - ref)) <= 1e-9 * np.max(np.abs(ref))
    np.testing.assert_array_equal(m.C, nominal_model.C)


def test_sampled_points_are_the_perturbed_plants(lft):
    """At random points of the box the LFT is the perturbed plant's linearization, 1e-6."""
    rng = np.random.default_rng(SEED)
    print(f"seed {SEED}")
    for _ in range(3):
        delta = rng.uniform(-1.0, 1.0, len(lft.parameters))
        factors = {p.name: p.centre + p.half_range * d
                   for p, d in zip(lft.parameters, delta, strict=True)}  # fmt: skip
        ref = linearize(_perturbed(nominal(), factors), outputs=("attitude", "rate"))
        m = lft.evaluate(delta)
        # The acceptance bound 1e-6 relative; the LFT is exact algebra, measured ~1e-15.
        assert np.max(np.abs(m.A - ref.A)) <= 1e-6 * np.max(np.abs(ref.A)), factors
        assert np.max(np.abs(m.B - ref.B)) <= 1e-6 * np.max(np.abs(ref.B)), factors


def test_block_structure_follows_the_physics(lft):
    """One channel per joint and factor link, three for the hub, the panels' mass rank."""
    n_joint = 12  # two plates, six joint coordinates each
    # frequency: k ~ s_f^2 (two links) and c ~ s_f (one) on the 6 rotations.
    assert lft.block_sizes[0] == 3 * 6
    assert lft.block_sizes[1] == n_joint  # damping: one link per joint's c
    assert lft.block_sizes[2] == 3  # the hub's inertia tensor
    # panel mass: k and c of every joint, and the rank of M_p (12: each plate's 6 x 6
    # joint block is positive definite, its coupling to the hub is of the same rank).
    assert lft.block_sizes[3] == 2 * n_joint + 12
    assert lft.n_channels == sum(lft.block_sizes)


def test_statespace_and_mat_export(lft, tmp_path):
    """python-control's P closed by Delta gives the same A; the .mat holds P and its blocks."""
    from scipy.io import loadmat

    P = lft.to_statespace()
    delta = np.array([0.5, -0.3, 0.9, -0.7])
    n_w = lft.n_channels
    assert P.ninputs == n_w + 3 and P.noutputs == n_w + 6
    A, B, C, D = (np.asarray(m) for m in (P.A, P.B, P.C, P.D))
    Dl = lft.delta_matrix(delta)
    X = np.linalg.solve(np.eye(n_w) - Dl @ D[:n_w, :n_w], Dl)
    A_closed = A + B[:, :n_w] @ X @ C[:n_w]
    ref = lft.evaluate(delta).A
    assert np.max(np.abs(A_closed - ref)) <= 1e-12 * np.max(np.abs(ref))
    data = loadmat(lft.save_mat(tmp_path / "lft.mat"))
    np.testing.assert_array_equal(data["A"], A)
    assert data["block_sizes"].ravel().tolist() == list(lft.block_sizes)
    assert [str(x[0][0]) for x in data["block_names"]] == [p.name for p in lft.parameters]


def test_sadm_angle_is_fixed_per_model():
    """A model at 45 deg is the linearization of the satellite turned to 45 deg."""
    config = with_sadm_angle(nominal(), 45.0)
    lft = uncertain_model(config, [UncertainParameter("hub_inertia", 0.8, 1.2)])
    ref = linearize(Plant.from_config(config), outputs=("attitude", "rate"))
    m = lft.evaluate(lft.nominal_delta())
    assert np.max(np.abs(m.A - ref.A)) <= 1e-12 * np.max(np.abs(ref.A))
    assert lft.sadm_angle_deg == (45.0, 45.0)


@pytest.mark.parametrize(
    ("make", "message"),
    [
        (lambda: UncertainParameter("mass", 0.8, 1.2), "parameters: unknown parameter 'mass'"),
        (lambda: UncertainParameter("frequency", 1.2, 0.8), "frequency: the factor range"),
        (lambda: UncertainParameter("damping", -0.1, 1.0), "damping: the factor range"),
        (lambda: uncertain_model(nominal(), [UncertainParameter("damping", 0.0, 1.0)] * 2),
         "each parameter at most once"),
        (lambda: uncertain_model(nominal(), outputs=("tip",)), "outputs: unknown output 'tip'"),
    ],
)  # fmt: skip
def test_bad_requests(make, message):
    with pytest.raises(ConfigError, match=message):
        make()
