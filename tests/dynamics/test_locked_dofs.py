"""Locked joint DOFs (reduced models): the projection on the free coordinates."""

from __future__ import annotations

import numpy as np
import pytest

from flexsat.compiled.first_class import first_class
from flexsat.config import nominal
from flexsat.config.models import SatelliteConfig
from flexsat.dynamics import kernels
from flexsat.dynamics.appendages import plate
from flexsat.dynamics.appendages.contract import SIGNATURES
from flexsat.dynamics.plant import Plant
from flexsat.dynamics.rigid import rigid_inertia
from flexsat.errors import ConfigError
from flexsat.simulate import SlewScenario
from flexsat.simulate.openloop import initial_state

TRANSLATIONS = ["eta_x", "eta_y", "eta_z"]


def _locked(names: list[str]) -> Plant:
    data = nominal().model_dump(mode="json")
    for appendage in data["appendages"]:
        appendage["locked_dofs"] = names
    return Plant.from_config(SatelliteConfig.model_validate(data))


@pytest.mark.parametrize(
    "names",
    [TRANSLATIONS, ["eta_ry"], ["eta_y", "eta_rz"], ["eta_x", "eta_rx", "eta_ry", "eta_rz"]],
)
def test_locked_accelerations_solve_the_free_rows_of_the_full_equations(names):
    # Independent formulation: M_ff q_ddot_f = (Q - h - C q_dot - k_el)_f from the
    # plant's assembled M(q), h(q, q_dot), K and C (eqs. 2.39-2.47), numpy's solve,
    # and the constraint forces lambda_L = (M q_ddot + h - F)_L. The plate's kernels
    # instead solve the locked joint's Newton-Euler equations on its free subspace;
    # both are rounding apart: 1e-12 relative (measured at most 3e-15 for q_ddot;
    # 18 x 18 solves of a matrix with condition number ~1e3). lambda is a difference
    # of forces ~100x larger than it for a single locked rotation: 1e-11 (measured 3e-14).
    reduced, full = _locked(names), Plant.from_config(nominal())
    rng = np.random.default_rng(18)
    locked = list(reduced.locked_coordinates())
    if names == TRANSLATIONS:
        assert locked == [6, 7, 8, 12, 13, 14]
    free = [i for i in range(full.n_dof) if i not in locked]
    for _ in range(5):
        q, qd, Q = (0.1 * rng.normal(size=full.n_dof) for _ in range(3))
        q[locked], qd[locked] = 0.05 * rng.normal(size=len(locked)), 0.0  # held off zero
        force = Q - full.bias_forces(q, qd) - full.elastic_forces(q) - full.damping_forces(qd)
        M = full.mass_matrix(q)
        expected = np.zeros(full.n_dof)
        expected[free] = np.linalg.solve(M[np.ix_(free, free)], force[free])
        got = reduced.accelerations(q, qd, Q)
        assert np.max(np.abs(got - expected)) <= 1e-12 * np.max(np.abs(expected))
        assert np.all(got[locked] == 0.0)
        reaction = (M @ expected - force)[locked]
        lam = reduced.packed.reaction[1][locked]
        assert np.max(np.abs(lam - reaction)) <= 1e-11 * np.max(np.abs(reaction))


def test_the_plate_holds_its_locks_without_the_engine_projection():
    # The plate's kernels hold its locked DOFs (docs/model.md, 'Locked coordinates'):
    # no M(q) projection is packed, the 6 x 6 hub solve takes the locked joints'
    # articulated inertia.
    packed = _locked(TRANSLATIONS).packed
    assert not packed.locked and packed.constrained and packed.articulated
    assert packed.held.tolist() == [6, 7, 8, 12, 13, 14]


def test_every_joint_locked_is_the_rigid_satellite():
    # Analytic: with every joint DOF locked the satellite is rigid; from rest, a body
    # torque gives omega_dot = J_tot^-1 tau with J_tot the rigidized inertia (thesis
    # appendix A.4), the hub centre of mass staying put (the nominal satellite is
    # symmetric about it). Rounding only: 1e-12 relative.
    plant = _locked(["eta_x", "eta_y", "eta_z", "eta_rx", "eta_ry", "eta_rz"])
    tau = np.array([0.3, -1.2, 0.7])
    qdd = plant.accelerations(plant.zeros(), plant.zeros(), plant.generalized_forces(
        plant.zeros(), tau))  # fmt: skip
    expected = np.linalg.solve(rigid_inertia(plant), tau)
    assert np.max(np.abs(qdd[3:6] - expected)) <= 1e-12 * np.max(np.abs(expected))
    assert np.max(np.abs(qdd[0:3])) <= 1e-12 * np.max(np.abs(expected))
    assert np.all(qdd[6:] == 0.0)


def test_nothing_locked_packs_no_projection():
    packed = Plant.from_config(nominal()).packed
    assert not packed.locked and not packed.constrained and packed.free.size == 18
    assert not packed.articulated  # free plates transmit no inertia


def test_plates_that_lock_nothing_run_passes_compiled_without_the_locks():
    # The plate's group kernels: passes with the locked-joint branches pruned when no
    # plate of the group locks a DOF (they compile about 6 s faster), the general ones
    # otherwise. On a free plant the general passes never take those branches, so
    # both give the same accelerations bit for bit (tolerance 0).
    free = Plant.from_config(nominal())
    assert free.kernel_sets()[0].pass1 is plate.free_pass1
    assert free.kernel_sets()[0].pass2 is plate.free_pass2
    assert _locked(["eta_ry"]).kernel_sets()[0].pass1 is plate.pass1
    general = free.packed._replace(
        pass1=(first_class(plate.pass1, SIGNATURES.pass1),),
        pass2=(first_class(plate.pass2, SIGNATURES.pass2),),
    )
    rng = np.random.default_rng(7)
    for _ in range(3):
        q, qd, Q = (0.1 * rng.normal(size=free.n_dof) for _ in range(3))
        lean, full = np.zeros(free.n_dof), np.zeros(free.n_dof)
        assert kernels.accelerations(q, qd, Q, free.packed, lean) == 0
        assert kernels.accelerations(q, qd, Q, general, full) == 0
        np.testing.assert_array_equal(lean, full)
        assert np.max(np.abs(lean)) > 0.0


@pytest.mark.parametrize(
    ("names", "kind"),
    [([], plate.JOINT_FREE), (TRANSLATIONS, plate.JOINT_SPHERICAL),
     (["eta_x", "eta_y"], plate.JOINT_LOCKED), (["eta_ry"], plate.JOINT_LOCKED),
     ([*TRANSLATIONS, "eta_rz"], plate.JOINT_LOCKED)],
)  # fmt: skip
def test_each_plate_packs_the_kind_of_its_joint(names, kind):
    # The passes dispatch on the packed kind: the spherical equations for exactly the
    # translations locked, the general elimination for any other set.
    plant = _locked(names) if names else Plant.from_config(nominal())
    assert [row[plate.P_JOINT] for row in plant.packed.params[0]] == [kind, kind]


def test_the_spherical_joint_equations_equal_the_general_elimination():
    # Independent formulation: the translations-locked plates solved by the general
    # elimination over the free rows (the packed kind switched to JOINT_LOCKED) and by
    # the spherical joint's equations agree to rounding: 1e-12 relative for q_ddot and
    # the constraint forces (measured at most 3e-15; different operation orders).
    spherical = _locked(TRANSLATIONS)
    params = spherical.packed.params[0].copy()
    params[:, plate.P_JOINT] = plate.JOINT_LOCKED
    general = spherical.packed._replace(params=(params,), work=(np.zeros_like(
        spherical.packed.work[0]),))  # fmt: skip
    rng = np.random.default_rng(46)
    locked = list(spherical.locked_coordinates())
    for _ in range(4):
        q, qd, Q = (0.1 * rng.normal(size=spherical.n_dof) for _ in range(3))
        q[locked], qd[locked] = 0.0, 0.0
        by_sphere, by_rows = np.zeros(spherical.n_dof), np.zeros(spherical.n_dof)
        assert kernels.accelerations(q, qd, Q, spherical.packed, by_sphere) == 0
        lam_sphere = spherical.packed.reaction[1].copy()
        assert kernels.accelerations(q, qd, Q, general, by_rows) == 0
        lam_rows = general.reaction[1]
        assert np.max(np.abs(by_sphere - by_rows)) <= 1e-12 * np.max(np.abs(by_rows))
        assert np.max(np.abs(lam_sphere - lam_rows)) <= 1e-12 * np.max(np.abs(lam_rows))


@pytest.mark.parametrize(
    ("names", "fragment"),
    [(["eta_q"], "locked_dofs"), (["eta_x", "eta_x"], "names a DOF twice")],
)
def test_bad_locked_dofs_are_refused_naming_the_field(names, fragment):
    data = nominal().model_dump(mode="json")
    data["appendages"][0]["locked_dofs"] = names
    with pytest.raises(ValueError, match=fragment):
        SatelliteConfig.model_validate(data)


def test_an_initial_rate_on_a_locked_dof_is_refused():
    plant = _locked(TRANSLATIONS)
    scenario = SlewScenario.model_validate(
        {"initial": {"appendages": [{"name": "panel_1", "eta_rate_m_s": [0.01, 0.0, 0.0]}]}}
    )
    with pytest.raises(ConfigError, match=r"panel_1\.eta_x is locked"):
        initial_state(plant, scenario)
