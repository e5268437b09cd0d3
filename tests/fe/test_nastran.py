"""NASTRAN decks to modal data: the import against flexsat.fe's own Craig–Bampton.

References: the same structure reduced directly by :func:`flexsat.fe.craig_bampton`
(from the matrices in FE order, before they were written to an OP4 file in NASTRAN's
DOF order), and the SOL 103 eigenvalue table of an OP2 file. pyNastran cannot write
that OP2 here (its releases require numpy < 2) and pyyeti only reads OP2, so the
test writes the OP2 records itself, in the layout NASTRAN's OUTPUT2 uses, with the
clamped eigenvalues of the deck's own matrices from scipy.linalg.eigh.
"""

from __future__ import annotations

import importlib.util
from pathlib import Path

import numpy as np
import pytest
from scipy.linalg import eigh

from flexsat.config.modal_data import load_modal_data
from flexsat.errors import ConfigError
from flexsat.fe import craig_bampton
from flexsat.fe.nastran import (
    dof_set,
    import_nastran,
    read_bulk,
    read_op2_frequencies,
    read_op4_matrices,
)
from tests.fe.nastran_decks import SEED, frame, scrambled_ids, write_frame_deck, write_lama_op2

op4 = pytest.importorskip("pyyeti.nastran.op4")
bulk = pytest.importorskip("pyyeti.nastran.bulk")

DATA = Path(__file__).resolve().parents[2] / "examples" / "data"


def _same_modes(a, b, rtol: float) -> None:
    """Frequencies, rigid mass and sign-free modal quantities of two ModalData agree."""
    np.testing.assert_allclose(a.frequencies_hz, b.frequencies_hz, rtol=rtol)
    np.testing.assert_allclose(a.rigid_mass_matrix(), b.rigid_mass_matrix(), rtol=0,
                               atol=1e-12 * np.abs(b.rigid_mass_matrix()).max())  # fmt: skip
    La, Lb = a.participation_matrix(), b.participation_matrix()
    sign = np.sign(np.sum(La * Lb, axis=1))[:, None]  # a mode's sign is arbitrary
    np.testing.assert_allclose(La * sign, Lb, rtol=0, atol=rtol * np.abs(Lb).max())


def test_frame_import_is_the_direct_craig_bampton_to_round_off(tmp_path):
    print(f"frame seed {SEED}")
    # The same K and M, written in NASTRAN's order (grid ids scrambled): frequencies,
    # rigid mass and participation agree to 1e-10 relative. The frame's clamped
    # stiffness has a condition number of 1.3e5, so the eigensolver's round-off in a
    # different DOF order is ~1e-16 x 1.3e5 ~ 1e-11 (measured: frequencies 1.4e-12,
    # participation 4.9e-13, rigid mass 1.9e-16).
    K, M, xyz = frame()
    ids = scrambled_ids(len(xyz))
    bdf, path, order = write_frame_deck(tmp_path, K, M, xyz, ids)
    model = import_nastran(bdf, path, interface=int(ids[0]), n_modes=8)
    rigid = np.zeros((K.shape[0], 6))
    for k, p in enumerate(xyz):
        rigid[6 * k : 6 * k + 3, :3] = np.eye(3)
        rigid[6 * k : 6 * k + 3, 3:] = -np.array([[0, -p[2], p[1]], [p[2], 0, -p[0]],
                                                  [-p[1], p[0], 0]])  # fmt: skip
        rigid[6 * k + 3 : 6 * k + 6, 3:] = np.eye(3)
    direct = craig_bampton(M, K, np.arange(6), 8, rigid_modes=rigid)
    _same_modes(model.modal, direct, rtol=1e-10)
    assert model.interface_grid == ids[0]
    assert model.tip_grid == ids[-1]  # the farthest grid
    assert model.modal.mass_kg == pytest.approx(np.trace(M[0::6, 0::6]), rel=1e-12)  # sum m_k


@pytest.mark.parametrize("binary", [False, True])
def test_dof_order_round_trip(tmp_path, binary):
    print(f"frame seed {SEED}")
    # The rows the import assigns to (grid, component) put the OP4 matrix back into
    # the frame's own order exactly (no arithmetic: 0 difference), from a formatted
    # (16 digits) or a binary (double) OP4.
    K, M, xyz = frame(4)
    ids = scrambled_ids(4)
    bdf, path, order = write_frame_deck(tmp_path, K, M, xyz, ids, binary=binary)
    dofs = dof_set(read_bulk(bdf), "g")
    _, _, K_op4, _ = read_op4_matrices(path)
    node = {int(g): k for k, g in enumerate(ids)}
    fe_index = np.array([6 * node[g] + c - 1 for g, c in dofs])
    back = np.empty_like(K)
    back[np.ix_(fe_index, fe_index)] = K_op4.toarray()
    assert np.array_equal(back, K)
    assert np.array_equal(fe_index, order)


def test_sets_follow_nastran_rules(tmp_path):
    deck = tmp_path / "sets.bdf"
    deck.write_text(
        "SOL 103\nCEND\nMPC = 2\nSPC = 1\n"  # case control: not bulk data
        "BEGIN BULK\n"
        "GRID,30,,0.,0.,0.,,456\n"
        "GRID,10,,1.,0.,0.\n"
        "GRID,20,,2.,0.,0.\n"
        "SPOINT,15,16\n"
        "SPC1,1,3,10\n"
        "RBE2,1,10,12,20\n"
        "ENDDATA\n"
    )
    data = read_bulk(deck)
    g = dof_set(data, "g")
    assert [tuple(d) for d in g[:8]] == [(10, c) for c in range(1, 7)] + [(15, 0), (16, 0)]
    f = [tuple(d) for d in dof_set(data, "f")]
    removed = {(10, 3), (20, 1), (20, 2), (30, 4), (30, 5), (30, 6)}  # SPC1, RBE2, PS
    assert f == [tuple(d) for d in g if tuple(d) not in removed]
    deck.write_text(
        deck.read_text().replace("ENDDATA", "ASET1,123456,30\nQSET1,0,15,THRU,16\nENDDATA")
    )
    a = [tuple(d) for d in dof_set(read_bulk(deck), "a")]
    assert a == [(15, 0), (16, 0)] + [(30, c) for c in range(1, 7)]


def _plate_deck():
    spec = importlib.util.spec_from_file_location(
        "make_nastran_plate", DATA / "make_nastran_plate.py"
    )
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_shipped_plate_deck_is_flexsats_plate():
    # The stored OP4 holds the plate's K_aa = T^T K T exactly as the script computes
    # it today (17 significant digits: a double's exact decimal round trip), the
    # stored BDF is the script's text; and the imported reduction is the direct
    # Craig-Bampton of the FE matrices. The rigid mass matrix agrees to 1e-12 (same
    # rigid motions, measured 5e-16); the frequencies to the eigensolver's round-off,
    # eps x cond(K_ii) = 2.2e-16 x 2.2e10 ~ 5e-6 for this 6 mm plate in another DOF
    # order (measured 2e-6), hence rtol 2e-5.
    pytest.importorskip("skfem")
    maker = _plate_deck()
    text, dofs, K_aa, M_aa = maker.deck()
    assert (DATA / "nastran_plate.bdf").read_text() == text
    _, _, K_file, M_file = read_op4_matrices(DATA / "nastran_plate.op4")
    assert abs(K_file - K_aa).max() <= 1e-15 * abs(K_aa).max()
    assert abs(M_file - M_aa).max() <= 1e-15 * abs(M_aa).max()
    model = import_nastran(DATA / "nastran_plate.bdf", DATA / "nastran_plate.op4", n_modes=6)
    assert np.array_equal(model.dofs, dofs)
    plate = maker.plate_model()
    direct = craig_bampton(plate.M, plate.K, plate.interface_dofs, 6,
                           interface_map=plate.interface_map,
                           rigid_modes=plate.rigid_modes)  # fmt: skip
    _same_modes(model.modal, direct, rtol=2e-5)
    p = maker.PLATE
    mass = p["length_m"] * p["width_m"] * p["thickness_m"] * p["density_kg_m3"]
    assert model.modal.mass_kg == pytest.approx(mass, rel=1e-12)  # rho L w t, exact
    assert model.interface_grid == maker.INTERFACE_GRID


def test_op2_frequencies_check_the_import(tmp_path):
    print(f"frame seed {SEED}")
    # The OP2 holds the clamped eigenvalues of the deck's own K and M (scipy eigh,
    # interface rows and columns removed), in single precision as OUTPUT2 writes
    # them: the import's frequencies agree to float32 round-off (2^-24 = 6e-8 on an
    # eigenvalue, half that on a frequency; tolerance 1e-7).
    K, M, xyz = frame()
    ids = scrambled_ids(len(xyz))
    bdf, path, order = write_frame_deck(tmp_path, K, M, xyz, ids)
    lam = eigh(K[6:, 6:], M[6:, 6:], eigvals_only=True)
    op2 = tmp_path / "modes.op2"
    write_lama_op2(op2, lam)
    f = read_op2_frequencies(op2)
    np.testing.assert_allclose(f, np.sqrt(lam) / (2 * np.pi), rtol=1e-7)
    model = import_nastran(bdf, path, interface=int(ids[0]), n_modes=5, op2=op2)
    assert model.frequency_errors.shape == (5,)
    assert np.abs(model.frequency_errors).max() < 1e-7


def test_imported_file_loads_as_modal_data(tmp_path):
    model = import_nastran(DATA / "nastran_plate.bdf", DATA / "nastran_plate.op4", n_modes=4)
    from flexsat.config.modal_data import save_modal_data

    path = save_modal_data(model.modal, tmp_path / "wing.npz")
    back = load_modal_data(path)
    assert back.frequencies_hz == model.modal.frequencies_hz
    assert back.output_points[0].name == "tip"


# --- bad decks ------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("change", "message"),
    [
        ("interface", "grid 999 is not in the deck"),
        ("singular", "singular stiffness"),
        ("detached", "singular stiffness with grid"),
        ("size", "the matrices are not this deck's"),
        ("asymmetric", "is not symmetric"),
        ("name", "no matrix 'KXX'"),
        ("bdf", "not a NASTRAN bulk data file"),
        ("op4", "not an OP4 file"),
        ("op2", "no eigenvalue table (LAMA)"),
        ("no-interface", "give the interface grid"),
        ("not-free", "are not free"),
    ],
)
def test_bad_decks_are_refused_with_one_message(tmp_path, change, message):
    print(f"frame seed {SEED}")
    # singular: the last grid hangs free (no stiffness on its DOFs); detached: grids
    # 2-4 form a free body (every diagonal stiffness > 0, six zero eigenvalues).
    K, M, xyz = frame(4, elements=2 if change == "singular" else None,
                      detached=change == "detached")  # fmt: skip
    ids = scrambled_ids(4)
    kwargs = {"interface": int(ids[0])}
    if change == "asymmetric":
        K = K.copy()
        K[7, 13] += 1e-3 * np.abs(K).max()
    if change == "not-free":
        K = K + np.diag(np.full(K.shape[0], 1e-3 * np.abs(K).max()))
    bdf, path, _ = write_frame_deck(tmp_path, K, M, xyz, ids)
    if change == "interface":
        kwargs["interface"] = 999
    if change == "size":
        write_frame_deck(tmp_path, K, M, xyz, ids)
        bdf.write_text(bdf.read_text().replace("ENDDATA", "GRID,5000,,9.,9.,9.\nENDDATA"))
    if change == "name":
        kwargs["stiffness"] = "KXX"
    if change == "bdf":
        bdf.write_bytes(b"\x00\xff\x10binary")
    if change == "op4":
        path.write_text("hello\n")
    if change == "op2":
        kwargs["op2"] = tmp_path / "x.op2"
        write_lama_op2(kwargs["op2"], np.ones(2), table=False)
    if change == "no-interface":
        kwargs.pop("interface")
    with pytest.raises(ConfigError, match=message.replace("(", r"\(").replace(")", r"\)")):
        import_nastran(bdf, path, n_modes=3, **kwargs)


def test_without_pyyeti_one_message_names_the_extra(monkeypatch):
    monkeypatch.setitem(__import__("sys").modules, "pyyeti.nastran.bulk", None)  # not importable
    with pytest.raises(ConfigError, match=r"pip install 'flexsat\[nastran\]'"):
        read_bulk(DATA / "nastran_plate.bdf")
