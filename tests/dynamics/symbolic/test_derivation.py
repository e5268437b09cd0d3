"""Tests of the SymPy reference equations of motion (flexsat.dynamics.symbolic).

The numeric models come from the on-disk cache after the first run (a cold run
derives two 18-DOF models and one 12-DOF model: about half a minute).
"""

from __future__ import annotations

import pickle

import numpy as np
import pytest
import sympy as sp

from flexsat.config import nominal
from flexsat.dynamics import symbolic
from flexsat.dynamics.symbolic import (
    ReferenceModel,
    ReferenceParameters,
    derive,
    reference_model,
)
from flexsat.study.thesis import PRINTED_2DP, appendix_b_mass_matrix

N_DOF = 18


@pytest.fixture(scope="module")
def nominal_params() -> ReferenceParameters:
    return ReferenceParameters.from_config(nominal(), stiffness=0.0, damping=0.0)


@pytest.fixture(scope="module")
def exact2() -> ReferenceModel:
    return reference_model(2, "exact")


@pytest.fixture(scope="module")
def small2() -> ReferenceModel:
    return reference_model(2, "small_angle")


@pytest.fixture(scope="module", params=["exact", "small_angle"])
def model2(request: pytest.FixtureRequest, exact2: ReferenceModel, small2: ReferenceModel):
    return exact2 if request.param == "exact" else small2


def random_params(rng: np.random.Generator, n: int) -> ReferenceParameters:
    """A general configuration: mount yaw, SADM angle, off-axis mounts, full hub inertia."""
    a = rng.normal(size=(3, 3))
    return ReferenceParameters(
        hub_mass=rng.uniform(50.0, 200.0),
        hub_inertia=a @ a.T + 20.0 * np.eye(3),
        mount_point=rng.uniform(-1.0, 1.0, (n, 3)),
        mount_yaw=rng.uniform(-np.pi, np.pi, n),
        sadm=rng.uniform(-np.pi, np.pi, n),
        span_sign=rng.choice([-1.0, 1.0], n),
        length=rng.uniform(1.0, 5.0, n),
        mass=rng.uniform(2.0, 10.0, n),
        inertia_diag=rng.uniform(0.5, 15.0, (n, 3)),
        stiffness=rng.uniform(1.0, 1e4, (n, 6)),
        damping=rng.uniform(0.0, 10.0, (n, 6)),
    )


def random_state(rng: np.random.Generator, n_dof: int) -> tuple[np.ndarray, np.ndarray]:
    """Random q, q_dot away from the Euler singularities (pitch angles within +-1.2 rad)."""
    q = rng.uniform(-np.pi, np.pi, n_dof)
    q[0:3] = rng.uniform(-10.0, 10.0, 3)
    for o in range(6, n_dof, 6):
        q[o : o + 3] = rng.uniform(-0.1, 0.1, 3)  # root translations [m]
    pitch = [4, *range(10, n_dof, 6)]  # theta and each rho_y
    q[pitch] = rng.uniform(-1.2, 1.2, len(pitch))
    qd = rng.normal(scale=0.5, size=n_dof)
    return q, qd


# --- thesis appendix B --------------------------------------------------------


@pytest.mark.parametrize("panel_rates", ["exact", "small_angle"])
def test_nominal_mass_matrix_at_rest_matches_appendix_b(panel_rates, nominal_params):
    M = reference_model(2, panel_rates).evaluate(nominal_params, np.zeros(N_DOF), np.zeros(N_DOF))[
        "M"
    ]
    # Printed to two decimals: half a unit of the last digit plus a hair; the
    # panel1-panel2 blocks are exactly zero in the thesis and here.
    np.testing.assert_allclose(M, appendix_b_mass_matrix(), rtol=0, atol=PRINTED_2DP)
    # The thesis prints M(11, 11) as 1.27 (appendix B) and 1.26 (text): it is
    # m (W^2 + t^2) / 12 = 1.2659 (1.2656 without the thickness). Round-off only.
    assert M[10, 10] == pytest.approx(6.75 * (1.5**2 + 0.02**2) / 12.0, rel=1e-14)


# --- structure at random states -----------------------------------------------


def test_mass_matrix_symmetric_positive_definite(model2, nominal_params):
    rng = np.random.default_rng(11)
    for params in (nominal_params, random_params(rng, 2), random_params(rng, 2)):
        for _ in range(3):
            q, qd = random_state(rng, N_DOF)
            M = model2.evaluate(params, q, qd)["M"]
            # M is the full Jacobian dp/dq_dot, so each triangle is computed from
            # its own expression: equal up to round-off of O(1e2)-sized sums.
            np.testing.assert_allclose(M, M.T, rtol=0, atol=1e-12 * np.abs(M).max())
            eig = np.linalg.eigvalsh(0.5 * (M + M.T))
            # Positive definite with margin: the smallest eigenvalue is a panel
            # inertia-sized quantity (> 1e-2), far above round-off of ~1e-13.
            assert eig[0] > 1e-6 * eig[-1]


def test_variants_agree_at_zero_root_rotation(exact2, small2):
    """S(0) = I, so both panel-rate variants coincide at rho = 0, rho_dot = 0."""
    rng = np.random.default_rng(12)
    params = random_params(rng, 2)
    for _ in range(3):
        q, qd = random_state(rng, N_DOF)
        for o in (9, 15):
            q[o : o + 3] = 0.0
            qd[o : o + 3] = 0.0
        a = exact2.evaluate(params, q, qd)
        b = small2.evaluate(params, q, qd)
        for key in ("M", "h", "k_el", "C"):
            scale = max(1.0, np.abs(a[key]).max())
            # Identical mathematically; the two generated codes differ in operation
            # order only, so allow a few ulps of the largest entry.
            np.testing.assert_allclose(a[key], b[key], rtol=0, atol=1e-13 * scale, err_msg=key)


def test_variants_differ_away_from_zero_root_rotation(exact2, small2):
    rng = np.random.default_rng(13)
    params = random_params(rng, 2)
    q, qd = random_state(rng, N_DOF)
    a = exact2.evaluate(params, q, qd)["M"]
    b = small2.evaluate(params, q, qd)["M"]
    # rho of O(1) rad: the variants differ by O(1) in the rho blocks, not round-off.
    assert np.abs(a[9:12, 9:12] - b[9:12, 9:12]).max() > 1e-3


def test_bias_vanishes_at_zero_rates(model2, nominal_params):
    rng = np.random.default_rng(14)
    for params in (nominal_params, random_params(rng, 2)):
        q, _ = random_state(rng, N_DOF)
        h = model2.evaluate(params, q, np.zeros(N_DOF))["h"]
        # Every term of h carries two rate factors, so it is exactly zero.
        assert np.all(h == 0.0)


def test_kinetic_energy_is_the_mass_matrix_quadratic_form(model2, nominal_params):
    rng = np.random.default_rng(15)
    for params in (nominal_params, random_params(rng, 2)):
        for _ in range(3):
            q, qd = random_state(rng, N_DOF)
            M = model2.evaluate(params, q, qd)["M"]
            T = model2.kinetic_energy(params, q, qd)
            # Two evaluation orders of the same positive quantity: round-off only.
            assert 0.5 * qd @ M @ qd == pytest.approx(T, rel=1e-12)
            assert T > 0.0


def test_bias_is_mdot_qdot_minus_dT_dq(model2):
    """h = M_dot q_dot - (dT/dq)^T (eqs. 2.43-2.44), checked by central differences."""
    rng = np.random.default_rng(16)
    params = random_params(rng, 2)
    q, qd = random_state(rng, N_DOF)
    eps = 1e-6
    M_plus = model2.evaluate(params, q + eps * qd, qd)["M"]
    M_minus = model2.evaluate(params, q - eps * qd, qd)["M"]
    mdot_qdot = (M_plus - M_minus) @ qd / (2.0 * eps)
    dT_dq = np.empty(N_DOF)
    for j in range(N_DOF):
        step = np.zeros(N_DOF)
        step[j] = eps
        dT_dq[j] = (
            model2.kinetic_energy(params, q + step, qd)
            - model2.kinetic_energy(params, q - step, qd)
        ) / (2.0 * eps)
    h = model2.evaluate(params, q, qd)["h"]
    scale = max(np.abs(mdot_qdot).max(), np.abs(dT_dq).max())
    # Central differences with eps = 1e-6: truncation O(eps^2) ~ 1e-12 and
    # cancellation ~ 1e-16 / eps ~ 1e-10 relative; 1e-7 leaves a wide margin
    # while any wrong term would be O(1) relative.
    np.testing.assert_allclose(h, mdot_qdot - dT_dq, rtol=0, atol=1e-7 * scale)


def test_elastic_forces_and_damping_matrix(model2):
    rng = np.random.default_rng(17)
    params = random_params(rng, 2)
    q, qd = random_state(rng, N_DOF)
    out = model2.evaluate(params, q, qd)
    k = np.concatenate([np.zeros(6), params.stiffness.ravel()])
    c = np.concatenate([np.zeros(6), params.damping.ravel()])
    # k_el = K q and C = diag(c): one multiplication each, so exact up to one rounding.
    np.testing.assert_allclose(out["k_el"], k * q, rtol=1e-15, atol=0)
    np.testing.assert_array_equal(out["C"], np.diag(c))
    # U = q^T K q / 2: a short sum, round-off only.
    assert model2.potential_energy(params, q) == pytest.approx(0.5 * q @ (k * q), rel=1e-13)


# --- symbolic model and generated code ----------------------------------------


@pytest.fixture(scope="module")
def model1() -> symbolic.SymbolicModel:
    return derive(1)


def test_generated_code_matches_symbolic_model(model1):
    """The generated Python evaluates the very expressions derive() returns."""
    rng = np.random.default_rng(18)
    params = random_params(rng, 1)
    q, qd = random_state(rng, 12)
    values = dict(zip(model1.q, q, strict=True))
    values.update(zip(model1.qd, qd, strict=True))
    values.update(zip(model1.parameters, params.vector(), strict=True))
    values = {s: sp.Float(v, 30) for s, v in values.items()}
    out = reference_model(1).evaluate(params, q, qd)
    for key, expr in (("M", model1.M), ("h", model1.h), ("k_el", model1.k_el)):
        expected = np.array(expr.xreplace(values).evalf(20), dtype=float).reshape(out[key].shape)
        scale = max(1.0, np.abs(expected).max())
        # Float evaluation of the same expressions after CSE vs 30-digit arithmetic:
        # double-precision round-off of sums of ~1e3 terms.
        np.testing.assert_allclose(out[key], expected, rtol=0, atol=1e-12 * scale, err_msg=key)


def test_symbolic_model_structure(model1):
    assert model1.n_dof == 12
    assert model1.M.shape == (12, 12)
    assert model1.h.shape == (12, 1)
    assert model1.k_el.shape == (12, 1)
    assert model1.C_damp.shape == (12, 12)
    assert len(model1.parameters) == 7 + 23
    assert len(set(model1.parameters)) == len(model1.parameters)
    assert model1.T == sp.Add(*model1.T_bodies)
    # Elastic and damping terms are exactly diagonal and linear.
    app = model1.appendages[0]
    assert model1.k_el[6 + 3] == app.stiffness[3] * model1.q[9]
    assert model1.C_damp == sp.diag(0, 0, 0, 0, 0, 0, *app.damping)
    # The mass matrix does not depend on the rates; the hub position is cyclic.
    assert not model1.M.free_symbols & (set(model1.qd) | set(model1.q[0:3]))


def test_mass_matrix_at_rest_is_tidy(model1):
    M0 = model1.M_at_rest(simplify=True)
    app = model1.appendages[0]
    # Translational block of one panel: m I, once sin^2 + cos^2 = 1 is used.
    assert M0[6:9, 6:9] == app.mass * sp.eye(3)
    assert M0[0, 0] == model1.hub.mass + app.mass
    assert M0[10, 10] == app.inertia_diag[1]  # torsion: J_yy about the span axis


def test_equations_text(model1):
    latex = model1.equations_text("latex")
    pretty = model1.equations_text("pretty")
    assert r"M(q)\, \ddot{q} + h(q, \dot{q}) + C \dot{q} + k_{el}(q) &= Q" in latex
    assert r"\begin{align*}" in latex and r"T_h &=" in latex and r"M_{r_{x},\, r_{x}}" in latex
    assert "M(q) q̈ + h(q, q̇) + C q̇ + k_el(q) = Q" in pretty
    assert "M[rₓ, rₓ] = m₁ + mₕ" in pretty
    # A readable export, not a dump of every expression.
    assert len(latex) < 500_000 and len(pretty) < 500_000
    with pytest.raises(ValueError, match="format"):
        model1.equations_text("html")


# --- parameters and validation -----------------------------------------------


def test_parameters_from_nominal_config(nominal_params):
    p = nominal_params
    assert p.n_appendages == 2
    assert p.hub_mass == 150.0
    np.testing.assert_allclose(np.diag(p.hub_inertia), [41.625, 41.625, 27.0], rtol=1e-15)
    np.testing.assert_array_equal(p.span_sign, [1.0, -1.0])
    np.testing.assert_array_equal(p.mass, [6.75, 6.75])
    np.testing.assert_array_equal(p.mount_point, [[0.0, 0.8, 0.0], [0.0, -0.8, 0.0]])
    assert p.stiffness.shape == (2, 6) and not p.stiffness.any()
    assert p.vector().shape == (7 + 2 * 23,)
    with pytest.raises(ValueError):
        p.mass[0] = 1.0  # read-only


def test_input_validation(exact2, nominal_params):
    with pytest.raises(ValueError, match="n_appendages"):
        derive(-1)
    with pytest.raises(TypeError, match="n_appendages"):
        reference_model(2.0)  # type: ignore[arg-type]
    with pytest.raises(ValueError, match="panel_rates"):
        reference_model(2, "linear")  # type: ignore[arg-type]
    with pytest.raises(ValueError, match="appendage"):
        reference_model(1).evaluate(nominal_params, np.zeros(12), np.zeros(12))
    with pytest.raises(ValueError, match="shape"):
        exact2.evaluate(nominal_params, np.zeros(12), np.zeros(18))
    with pytest.raises(ValueError, match="symmetric"):
        ReferenceParameters(**{**vars(nominal_params), "hub_inertia": np.triu(np.ones((3, 3)))})


# --- disk cache ---------------------------------------------------------------


def test_disk_cache_roundtrip(tmp_path, monkeypatch, nominal_params):
    fresh = symbolic._load_reference(1, "exact", tmp_path)
    files = sorted(p.name for p in tmp_path.iterdir())
    assert len(files) == 1 and files[0].startswith("reference-n1-exact-")  # no temp files left
    assert fresh.path == tmp_path / files[0]

    def refuse(model):
        raise AssertionError("regenerated although a valid cache file exists")

    monkeypatch.setattr(symbolic, "_generate_source", refuse)
    params = random_params(np.random.default_rng(19), 1)
    q, qd = random_state(np.random.default_rng(20), 12)
    loaded = symbolic._load_reference(1, "exact", tmp_path)
    for key, value in fresh.evaluate(params, q, qd).items():
        np.testing.assert_array_equal(loaded.evaluate(params, q, qd)[key], value)  # same code
    monkeypatch.undo()

    # A damaged file (e.g. from an older flexsat) is regenerated, not trusted.
    fresh.path.write_text("def dynamics(:\n", encoding="utf-8")
    repaired = symbolic._load_reference(1, "exact", tmp_path)
    np.testing.assert_array_equal(
        repaired.evaluate(params, q, qd)["M"], fresh.evaluate(params, q, qd)["M"]
    )
    assert "# key: " in fresh.path.read_text(encoding="utf-8")


def test_model_cache_roundtrip(tmp_path, model1):
    path = symbolic._cache_path(tmp_path, "model", 1, "exact", ".pickle")
    symbolic._write_atomic(path, pickle.dumps(model1))
    loaded = symbolic._load_model(1, "exact", tmp_path)
    assert loaded is not model1
    assert loaded.M == model1.M and loaded.h == model1.h and loaded.T == model1.T


def test_cache_dir_from_environment(tmp_path, monkeypatch):
    monkeypatch.setenv("FLEXSAT_CACHE_DIR", str(tmp_path))
    assert symbolic.cache_dir() == tmp_path
    monkeypatch.delenv("FLEXSAT_CACHE_DIR")
    assert symbolic.cache_dir().name == "flexsat"
