"""A user's own appendage model, defined here as a user would: one class, one registration line.

The model is a rigid lumped mass fixed to the hub at a mount point: it has no
coordinates and transmits its full rigid inertia to the hub, so it exercises the
engine's articulated-inertia hub solve. Physics: hub + mass must move as one rigid
body with the combined inertia, next to the thesis plates too.
"""

from __future__ import annotations

import tomllib
from typing import Annotated, Literal

import numpy as np
import pytest
from numba import njit
from pydantic import BaseModel, ConfigDict, Field

from flexsat import ConfigError, Plant, load_config
from flexsat.compiled.linalg3 import (
    add,
    add_block,
    cross,
    dot,
    euler_rate_bias,
    euler_rate_matrix,
    load_seg,
    mm,
    mtm,
    mtv,
    mv,
    rot_zyx,
    scale,
    scale_m,
    skew,
)
from flexsat.config import preset_path, validate_config
from flexsat.dynamics.appendages import (
    AppendageKernels,
    AppendageModel,
    RigidBody,
    register_appendage_model,
)
from flexsat.dynamics.appendages.contract import (
    BIAS_SIGNATURE,
    HUB_FORCE,
    HUB_INERTIA,
    HUB_OMEGA,
    HUB_SBIAS,
    HUB_TORQUE,
    MASS_SIGNATURE,
    OBS_KINETIC,
    OBS_LOCKED_INERTIA,
    OBS_MOMENTUM,
    OBSERVE_SIGNATURE,
    PASS1_SIGNATURE,
    PASS2_SIGNATURE,
    TIPS_SIGNATURE,
    WRENCH_SIGNATURE,
)
from flexsat.dynamics.rigid import rigid_inertia
from flexsat.simulate import run_openloop
from flexsat.simulate.scenario import OpenLoopScenario

# -- the user's model -------------------------------------------------------------------


class PointMassConfig(BaseModel):
    """A point mass rigidly fixed to the hub."""

    model_config = ConfigDict(frozen=True, extra="forbid")
    name: str
    model: Literal["point_mass"] = "point_mass"
    mass_kg: Annotated[float, Field(gt=0.0)]
    position_m: tuple[float, float, float] = Field(description="from the hub CoM, frame B [m]")


@njit(PASS1_SIGNATURE, cache=True)
def _pass1(q, qd, Q, members, params, work, hub, qdd):
    # Its acceleration is a_hub + alpha x r + w x (w x r): the wrench on the hub at zero
    # hub acceleration is -m w x (w x r) at r, the articulated inertia
    # m [[I, -[r]x], [[r]x, -[r]x [r]x]].
    w = load_seg(hub, HUB_OMEGA)
    for j in range(members.shape[0]):
        m, r = params[j, 0], load_seg(params[j], 1)
        f = scale(m, cross(w, cross(w, r)))
        t = cross(r, f)
        R = skew(r)
        RR = mm(R, R)
        for a in range(3):
            hub[HUB_FORCE + a] -= f[a]
            hub[HUB_TORQUE + a] -= t[a]
            hub[HUB_INERTIA + 6 * a + a] += m
            for b in range(3):
                hub[HUB_INERTIA + 6 * a + 3 + b] -= m * R[a][b]
                hub[HUB_INERTIA + 6 * (3 + a) + b] += m * R[a][b]
                hub[HUB_INERTIA + 6 * (3 + a) + 3 + b] -= m * RR[a][b]
    return 0


@njit(PASS2_SIGNATURE, cache=True)
def _pass2(q, qd, members, params, work, hub, qdd):
    return 0  # no coordinates


@njit(MASS_SIGNATURE, cache=True)
def _mass_matrix(q, members, params, M):
    R_NB = rot_zyx(q[3], q[4], q[5])
    S = euler_rate_matrix(q[3], q[4])
    identity = ((1.0, 0.0, 0.0), (0.0, 1.0, 0.0), (0.0, 0.0, 1.0))
    for j in range(members.shape[0]):
        m, r = params[j, 0], load_seg(params[j], 1)
        A_theta = scale_m(-1.0, mm(skew(r), S))  # v = R_BN r_dot - [r]x S Theta_dot
        add_block(M, 0, 0, identity, m)
        add_block(M, 0, 3, mm(R_NB, A_theta), m)
        add_block(M, 3, 3, mtm(A_theta, A_theta), m)


@njit(BIAS_SIGNATURE, cache=True)
def _bias_forces(q, qd, members, params, hub, h):
    R_NB = rot_zyx(q[3], q[4], q[5])
    w, s_bias = load_seg(hub, HUB_OMEGA), load_seg(hub, HUB_SBIAS)
    for j in range(members.shape[0]):
        m, r = params[j, 0], load_seg(params[j], 1)
        f_B = scale(m, add(cross(s_bias, r), cross(w, cross(w, r))))
        f_N, t_B = mv(R_NB, f_B), cross(r, f_B)
        for a in range(3):
            hub[HUB_FORCE + a] += f_N[a]
            hub[HUB_TORQUE + a] += t_B[a]


@njit(OBSERVE_SIGNATURE, cache=True)
def _observe(q, qd, members, params, out):
    R_NB = rot_zyx(q[3], q[4], q[5])
    w = mv(euler_rate_matrix(q[3], q[4]), load_seg(qd, 3))
    for j in range(members.shape[0]):
        m, r = params[j, 0], load_seg(params[j], 1)
        v = add(mtv(R_NB, load_seg(qd, 0)), cross(w, r))
        out[OBS_KINETIC] += 0.5 * m * dot(v, v)
        H = cross(add(load_seg(q, 0), mv(R_NB, r)), scale(m, mv(R_NB, v)))
        for a in range(3):
            out[OBS_MOMENTUM + a] += H[a]
            for b in range(3):
                out[OBS_LOCKED_INERTIA + 3 * a + b] -= m * r[a] * r[b]
            out[OBS_LOCKED_INERTIA + 4 * a] += m * dot(r, r)


@njit(WRENCH_SIGNATURE, cache=True)
def _joint_wrench(q, qd, qdd, Q, members, params, out):
    # A rigid mount transmits the mass's whole inertial load: -m a at r, with its
    # acceleration a = a_hub + alpha x r + w x (w x r) read from the plant's q_ddot.
    S = euler_rate_matrix(q[3], q[4])
    w = mv(S, load_seg(qd, 3))
    alpha = add(mv(S, load_seg(qdd, 3)), euler_rate_bias(q[3], q[4], qd[3], qd[4], qd[5]))
    a_hub = mtv(rot_zyx(q[3], q[4], q[5]), load_seg(qdd, 0))
    for j in range(members.shape[0]):
        m, r = params[j, 0], load_seg(params[j], 1)
        f = scale(m, add(a_hub, add(cross(alpha, r), cross(w, cross(w, r)))))
        t = cross(r, f)
        for a in range(3):
            out[a] -= f[a]
            out[3 + a] -= t[a]
    return 0


@njit(TIPS_SIGNATURE, cache=True)
def _tips(q, members, params, out):
    for j in range(members.shape[0]):
        out[members[j, 0], :] = 0.0


class PointMass(AppendageModel):
    name = "point_mass"
    config_class = PointMassConfig
    kernels = AppendageKernels(
        _pass1, _pass2, _mass_matrix, _bias_forces, _observe, _joint_wrench, _tips
    )
    transmits_inertia = True

    def coordinates(self, config):
        return ()

    def pack(self, config):
        return np.array([config.mass_kg, *config.position_m])

    def rigid_body(self, params):
        return RigidBody(float(params[0]), params[1:4].copy(), np.zeros((3, 3)))


register_appendage_model(PointMass())

# -- the tests ---------------------------------------------------------------------------

MASS = 40.0  # [kg]
POSITION = (0.4, -0.3, 0.7)  # [m], frame B, off every axis


def _nominal() -> dict:
    return tomllib.loads(preset_path("nominal").read_text())


def _with_mass() -> dict:
    data = _nominal()
    data["appendages"].append(
        {"name": "ballast", "model": "point_mass", "mass_kg": MASS, "position_m": list(POSITION)}
    )
    return data


def _folded() -> dict:
    """The same satellite with the mass folded into the hub: its centre of mass moves to
    c = m r / (m_h + m), so the plates' mount points move by -c in the new hub frame."""
    data = _nominal()
    hub = Plant.from_config(validate_config(data)).config.hub
    m_h, r = hub.mass_kg, np.array(POSITION)
    c = MASS * r / (m_h + MASS)
    mu = m_h * MASS / (m_h + MASS)
    J = hub.inertia() + mu * (r @ r * np.eye(3) - np.outer(r, r))  # about the new CoM
    data["hub"] = {"mass_kg": m_h + MASS, "inertia_kg_m2": J.tolist()}
    for app in data["appendages"]:
        app["mount_point_m"] = (np.array(app["mount_point_m"]) - c).tolist()
    return data


@pytest.fixture(scope="module")
def with_mass() -> Plant:
    return Plant.from_config(validate_config(_with_mass()))


def test_layout_and_dataset_know_a_model_without_coordinates(with_mass):
    assert with_mass.n_dof == 18  # the mass adds no coordinate
    assert [b.count for b in with_mass.layout.blocks] == [6, 6, 0]
    assert with_mass.packed.articulated
    assert with_mass.config.appendages[2].model == "point_mass"


def test_omega_dot_is_the_combined_rigid_body(with_mass):
    # At rest and undeformed the plates' joints exert nothing: hub + mass is one free
    # rigid body under a pure couple, omega_dot = J_c^-1 tau with J_c about the combined
    # centre of mass c, and the hub centre of mass accelerates as alpha x (0 - c).
    tau = np.array([0.3, -1.2, 2.0])  # [N m]
    qdd = with_mass.accelerations(with_mass.zeros(), with_mass.zeros(),
                                  with_mass.generalized_forces(with_mass.zeros(), tau))  # fmt: skip
    m_h, r = with_mass.hub_mass, np.array(POSITION)
    mu = m_h * MASS / (m_h + MASS)
    J_c = with_mass.hub_J + mu * (r @ r * np.eye(3) - np.outer(r, r))
    alpha = np.linalg.solve(J_c, tau)
    c = MASS * r / (m_h + MASS)
    # At zero attitude and rate, Theta_ddot = omega_dot and N = B. Round-off of a 6 x 6
    # elimination: 1e-12 relative.
    np.testing.assert_allclose(qdd[3:6], alpha, rtol=1e-12, atol=1e-15)
    np.testing.assert_allclose(qdd[0:3], np.cross(alpha, -c), rtol=1e-12, atol=1e-15)


def test_tau_flex_is_the_hubs_own_newton_euler(with_mass):
    # The wrench the mass and the plates put on the hub is what moves the hub alone:
    # m_h a_hub = f and J_h omega_dot + w x J_h w = tau_flex + tau at a deformed, spinning
    # state. Both sides are the same 6 x 6 solve's round-off apart: 1e-12 of the largest
    # term.
    rng = np.random.default_rng(3)
    q = rng.normal(scale=0.1, size=with_mass.n_dof)
    qd = rng.normal(scale=0.1, size=with_mass.n_dof)
    tau = np.array([0.3, -1.2, 2.0])  # [N m]
    Q = with_mass.generalized_forces(q, tau)
    qdd = with_mass.accelerations(q, qd, Q)
    force, torque = with_mass.joint_wrench_on_hub(q, qd, Q)
    S = np.array(euler_rate_matrix(q[3], q[4]))
    w = S @ qd[3:6]
    w_dot = S @ qdd[3:6] + np.array(euler_rate_bias(q[3], q[4], qd[3], qd[4], qd[5]))
    J = with_mass.hub_J
    euler = J @ w_dot + np.cross(w, J @ w) - tau
    newton = with_mass.hub_mass * np.array(rot_zyx(q[3], q[4], q[5])).T @ qdd[0:3]
    scale_ = max(np.abs(euler).max(), np.abs(newton).max())
    np.testing.assert_allclose(torque, euler, rtol=0, atol=1e-12 * scale_)
    np.testing.assert_allclose(force, newton, rtol=0, atol=1e-12 * scale_)


def test_rigid_design_inertia_includes_the_mass(with_mass):
    plates = Plant.from_config(validate_config(_nominal()))
    r = np.array(POSITION)
    expected = rigid_inertia(plates) + MASS * (r @ r * np.eye(3) - np.outer(r, r))
    np.testing.assert_allclose(rigid_inertia(with_mass), expected, rtol=1e-14)


def test_mass_matrix_and_bias_agree_with_the_accelerations(with_mass):
    # M q_ddot + h + C q_dot + k_el = Q at a random state: the kernels of the contract
    # (M, h) and the articulated-body solve are two independent routes; 1e-9 relative
    # covers the conditioning of M (stiff joint translations).
    rng = np.random.default_rng(7)
    q = rng.normal(scale=0.1, size=with_mass.n_dof)
    qd = rng.normal(scale=0.1, size=with_mass.n_dof)
    Q = rng.normal(size=with_mass.n_dof)
    rhs = (Q - with_mass.bias_forces(q, qd) - with_mass.damping_forces(qd)
           - with_mass.elastic_forces(q))  # fmt: skip
    expected = np.linalg.solve(with_mass.mass_matrix(q), rhs)
    got = with_mass.accelerations(q, qd, Q)
    np.testing.assert_allclose(got, expected, rtol=1e-9, atol=1e-9 * np.abs(expected).max())


def test_run_matches_the_mass_folded_into_the_hub(with_mass):
    # Same physical satellite, two descriptions: the attitude, the rates and the plates'
    # motion must agree (tau_flex is not compared: it is taken about another point). Only
    # round-off differs (6 x 6 solve vs. bare hub, another hub origin), grown over
    # 3 000 steps: 1e-9 of each variable's largest magnitude.
    folded = Plant.from_config(validate_config(_folded()))
    scenario = OpenLoopScenario(duration_s=3.0)
    a = run_openloop(with_mass, scenario).dataset
    b = run_openloop(folded, scenario).dataset
    for name in ("euler_deg", "omega", "omega_dot", "eta", "rho", "tip_displacement"):
        scale_ = np.abs(b[name].values).max()
        got = a[name].values
        if name in ("eta", "rho", "tip_displacement"):
            got = got[:, :2]  # the plates; the folded plant has no third appendage
        np.testing.assert_allclose(got, b[name].values, atol=1e-9 * scale_, err_msg=name)
    np.testing.assert_allclose(a["tip_displacement"].values[:, 2], 0.0)


def test_angular_momentum_is_conserved_torque_free(with_mass):
    # No torque, spinning and deformed: H about the inertial origin is an exact
    # invariant; RK4 at dt = 1e-4 s holds it to 1e-9 relative over 5 s (the same bound
    # as the plates alone, tests/simulate/test_openloop.py).
    scenario = OpenLoopScenario.model_validate({
        "torque": [], "duration_s": 5.0, "dt_s": 1e-4,
        "initial": {"rate_deg_s": [0.5, -1.0, 2.0],
                    "appendages": [{"name": "panel_1", "rho_deg": [0.5, -0.3, 0.8]}]},
    })  # fmt: skip
    ds = run_openloop(with_mass, scenario).dataset
    H = ds["angular_momentum"].values
    assert np.abs(H - H[0]).max() <= 1e-9 * np.linalg.norm(H[0])
    # the energy balance closes too (damped plates): E - E0 + W_diss to 1e-7 of E0
    balance = ds["energy_balance_error"].values
    assert np.abs(balance).max() <= 1e-7 * ds["total_energy"].values[0]


def test_a_toml_config_names_the_model(tmp_path, with_mass):
    text = preset_path("nominal").read_text() + (
        '\n[[appendages]]\nname = "ballast"\nmodel = "point_mass"\n'
        f"mass_kg = {MASS}\nposition_m = {list(POSITION)}\n"
    )
    path = tmp_path / "with_ballast.toml"
    path.write_text(text)
    config = load_config(path)
    assert isinstance(config.appendages[2], PointMassConfig)
    plant = Plant.from_config(config)
    np.testing.assert_array_equal(plant.mass_matrix(), with_mass.mass_matrix())
    # the config survives its JSON form (stored with every result and campaign case)
    again = validate_config(config.model_dump(mode="json"))
    assert again == config


def test_model_mistakes_are_config_errors():
    data = _with_mass()
    data["appendages"][2]["model"] = "pointmass"
    with pytest.raises(ConfigError, match=r"appendages\[2\].*unknown appendage model 'pointmass'"):
        validate_config(data)
    data["appendages"][2]["model"] = "point_mass"
    data["appendages"][2]["mass_kg"] = -1.0
    with pytest.raises(ConfigError, match=r"appendages\[2\]\.mass_kg"):
        validate_config(data)


def test_an_initial_state_for_a_model_without_coordinates_is_refused(with_mass):
    scenario = OpenLoopScenario.model_validate(
        {"duration_s": 0.01, "initial": {"appendages": [{"name": "ballast", "rho_deg": [1, 0, 0]}]}}
    )
    with pytest.raises(ConfigError, match="'ballast' is a 'point_mass' appendage"):
        run_openloop(with_mass, scenario)


def test_consumers_ask_the_model(with_mass):
    # Geometry, modal analysis, the mirror operator, derived properties and campaign
    # modifiers take the mixed plant without assuming six coordinates per appendage.
    from flexsat.analysis.modal import modal_analysis
    from flexsat.campaigns.modifiers import Modifier, apply_modifiers
    from flexsat.dynamics.symmetry import mirror_operator
    from flexsat.plots.geometry import satellite_geometry
    from flexsat.study.outputs import derived_properties

    g = satellite_geometry(with_mass)
    np.testing.assert_allclose(g.tips[2], POSITION, atol=1e-12)  # drawn as a point
    modes = modal_analysis(with_mass)
    assert len(modes.modes) == with_mass.n_dof
    assert mirror_operator(with_mass) is None  # the ballast has no mirror image
    described = derived_properties(with_mass)["appendages"][2]
    assert described["model"] == "point_mass" and described["mass_kg"] == MASS
    realised: dict = {}
    data = apply_modifiers(
        _with_mass(),
        [Modifier(path="appendages[2].mass_kg", op="scale", value=2.0),
         Modifier(path="appendages[0].inertia", op="scale", value=1.5)],
        np.random.default_rng(0), realised,
    )  # fmt: skip
    assert data["appendages"][2]["mass_kg"] == 2 * MASS
    assert data["appendages"][0]["surface_density_kg_m2"] == 1.5  # the plate's derived path
    assert set(realised) == {"appendages[2].mass_kg", "appendages[0].inertia"}
    with pytest.raises(KeyError, match="inertia"):
        apply_modifiers(_with_mass(), [Modifier(path="appendages[2].inertia", value=2.0)],
                        np.random.default_rng(0), {})  # fmt: skip
