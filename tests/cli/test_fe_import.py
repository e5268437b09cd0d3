"""``flexsat fe import``: a NASTRAN deck to a modal data file, its table and OP2 check."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from flexsat.config.modal_data import load_modal_data
from flexsat.fe.nastran import import_nastran
from tests.cli.harness import flexsat
from tests.fe.nastran_decks import deck_files, frame, write_lama_op2

pytest.importorskip("pyyeti")

DATA = Path(__file__).resolve().parents[2] / "examples" / "data"


def test_plate_deck_to_modal_file(tmp_path, capsys):
    bdf, op4 = DATA / "nastran_plate.bdf", DATA / "nastran_plate.op4"
    out = tmp_path / "wing.npz"
    outcome = flexsat(["fe", "import", str(bdf), "--op4", str(op4), "--modes", "5", "-o", str(out)],
                      capsys)  # fmt: skip
    assert outcome.code == 0, outcome.stderr
    assert "KAA/MAA: 222 DOFs, clamped at grid 9000" in " ".join(outcome.stdout.split())
    assert f"wrote {out}" in outcome.stdout
    written = load_modal_data(out)
    direct = import_nastran(bdf, op4, n_modes=5)
    # The file holds the import's numbers (an NPZ stores the doubles themselves).
    assert written.frequencies_hz == direct.modal.frequencies_hz
    np.testing.assert_array_equal(
        written.participation_matrix(), direct.modal.participation_matrix()
    )


def _frame_with_op2(tmp_path, scale: float = 1.0) -> list[str]:
    for name, content in deck_files().items():
        (tmp_path / name).write_bytes(content)
    K, M, _ = frame(4)
    from scipy.linalg import eigh

    lam = eigh(K[6:, 6:], M[6:, 6:], eigvals_only=True)  # grid 10 (node 0) clamped
    write_lama_op2(tmp_path / "modes.op2", scale * lam)
    return ["fe", "import", str(tmp_path / "d.bdf"), "--op4", str(tmp_path / "m.op4"),
            "--interface", "10", "--modes", "4", "--op2", str(tmp_path / "modes.op2"),
            "-o", str(tmp_path / "w.toml")]  # fmt: skip


def test_op2_frequencies_are_reported_beside_the_imported_ones(tmp_path, capsys):
    # The OP2 holds the deck's own clamped eigenvalues in single precision: the
    # frequencies agree to float32 round-off (tolerance 1e-7, see tests/fe).
    outcome = flexsat([*_frame_with_op2(tmp_path), "--json"], capsys)
    assert outcome.code == 0, outcome.stderr
    summary = json.loads(outcome.stdout)
    np.testing.assert_allclose(summary["op2_frequencies_hz"], summary["frequencies_hz"], rtol=1e-7)
    assert summary["interface_grid"] == 10 and summary["matrices"] == ["KGG", "MGG"]
    assert load_modal_data(tmp_path / "w.toml").n_modes == 4


def test_an_op2_of_another_model_is_flagged(tmp_path, capsys):
    # Eigenvalues 21 % off (frequencies 10 %): far above the 1e-4 warning threshold.
    outcome = flexsat(_frame_with_op2(tmp_path, scale=1.21), capsys)
    assert outcome.code == 0, outcome.stderr
    assert "-0.09091" in outcome.stdout  # the table's rel. diff: 1 / sqrt(1.21) - 1
    assert "warning: the OP2's frequencies differ by up to 0.091" in " ".join(
        outcome.stdout.split()
    )
