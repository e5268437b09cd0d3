"""NASTRAN decks for the tests: a free-free frame as BDF + OP4, and an OP2 eigenvalue table.

Shared by tests/fe/test_nastran.py and the bad-input table of the command line. The
OP2 is written here because pyNastran's releases require numpy < 2 and pyyeti only
reads OP2: the records follow the layout NASTRAN's OUTPUT2 uses.
"""

from __future__ import annotations

import io
import struct
from pathlib import Path

import numpy as np

SEED = 20261207  # the frame's grid-id permutation and section properties

# --- a well-conditioned frame: 3D beam elements along Y, lumped masses --------------


def frame_element(length: float, ea: float, gj: float, ei_x: float, ei_z: float) -> np.ndarray:
    """12 x 12 stiffness of a beam element along Y, DOFs (tx ty tz rx ry rz) x 2 nodes.

    Bending in the X-Y plane: w_x with slope dw_x/dy = -r_z; in the Y-Z plane: w_z
    with slope dw_z/dy = +r_x (a rigid rotation r moves a point at y by r x (0, y, 0)).
    """
    k = np.zeros((12, 12))

    def bar(dofs, stiffness):
        k[np.ix_(dofs, dofs)] += stiffness / length * np.array([[1.0, -1.0], [-1.0, 1.0]])

    def bend(w, r, sign, ei):
        L = length
        h = np.array([[12, 6 * L, -12, 6 * L], [6 * L, 4 * L**2, -6 * L, 2 * L**2],
                      [-12, -6 * L, 12, -6 * L], [6 * L, 2 * L**2, -6 * L, 4 * L**2]])  # fmt: skip
        h *= ei / L**3
        t = np.diag([1.0, sign, 1.0, sign])
        dofs = [w, r, w + 6, r + 6]
        k[np.ix_(dofs, dofs)] += t @ h @ t

    bar([1, 7], ea)
    bar([4, 10], gj)
    bend(0, 5, -1.0, ei_z)
    bend(2, 3, +1.0, ei_x)
    return k


def frame(n_nodes: int = 6, length: float = 2.0, elements: int | None = None,
          detached: bool = False):  # fmt: skip
    """A free-free frame of ``n_nodes`` grids on Y (node 0 at the origin, the interface).

    ``elements``: how many of the ``n_nodes - 1`` elements to assemble (fewer: the last
    grids hang free); ``detached``: without the first element (the other grids form
    a free body that the interface does not hold).
    """
    rng = np.random.default_rng(SEED)
    y = np.linspace(0.0, length, n_nodes)
    K = np.zeros((6 * n_nodes, 6 * n_nodes))
    for e in range(n_nodes - 1):
        props = rng.uniform(0.5, 2.0, 4) * np.array([1e6, 2e3, 3e3, 1e3])  # EA, GJ, EI_x, EI_z
        if (elements is not None and e >= elements) or (detached and e == 0):
            continue
        dofs = np.r_[6 * e : 6 * e + 12]
        K[np.ix_(dofs, dofs)] += frame_element(y[e + 1] - y[e], *props)
    masses = rng.uniform(0.5, 1.5, n_nodes)
    M = np.diag(np.repeat(masses, 6) * np.tile([1, 1, 1, 0.01, 0.02, 0.01], n_nodes))
    xyz = np.column_stack([np.zeros(n_nodes), y, np.zeros(n_nodes)])
    return K, M, xyz


def write_frame_deck(tmp_path: Path, K, M, xyz, ids, extra: str = "", names=("KGG", "MGG"),
                     binary: bool = False):  # fmt: skip
    """BDF with GRID ``ids[k]`` at ``xyz[k]``; OP4 with K, M in ascending-id order."""
    from pyyeti.nastran import bulk, op4

    text = io.StringIO()
    text.write("BEGIN BULK\n")
    for gid, (x, y, z) in zip(ids, xyz, strict=True):
        bulk.wtcard16(text, ["GRID*", int(gid), "", float(x), float(y), float(z), ""])
    text.write(extra)
    text.write("ENDDATA\n")
    bdf = tmp_path / "frame.bdf"
    bdf.write_text(text.getvalue())
    order = np.repeat(6 * np.argsort(ids), 6) + np.tile(np.arange(6), len(ids))
    path = tmp_path / "frame.op4"
    op4.write(str(path), {names[0]: K[np.ix_(order, order)], names[1]: M[np.ix_(order, order)]},
              binary=binary, digits=16)  # fmt: skip
    return bdf, path, order


def scrambled_ids(n: int) -> np.ndarray:
    rng = np.random.default_rng(SEED)
    return 10 + rng.permutation(n) * 7  # ids not in node order, not contiguous


# --- the OP2 check --------------------------------------------------------------------


def _key(value: int) -> bytes:
    return struct.pack("<iii", 4, value, 4)


def _record(data: bytes) -> bytes:
    return struct.pack("<i", len(data)) + data + struct.pack("<i", len(data))


def write_lama_op2(path: Path, eigenvalues: np.ndarray, table: bool = True) -> None:
    """An OP2 file (32-bit, little-endian) holding one LAMA table, as OUTPUT2 writes it.

    ``table=False``: the file header alone (an OP2 without eigenvalues).
    """
    out = [_key(3), _record(struct.pack("<3i", 12, 7, 26)), _key(7),
           _record(b"NASTRAN FORT TAPE ID CODE - "), _key(2), _record(b"XXXXXXXX"),
           _key(-1), _key(0)]  # fmt: skip
    if not table:
        path.write_bytes(b"".join(out) + _key(0))
        return
    out += [
        _key(2),
        _record(b"LAMA    "),
        _key(-1),
        _key(7),
        _record(struct.pack("<7i", 101, *[0] * 6)),
    ]
    out += [_key(-2), _key(1), _key(0), _key(2), _record(b"LAMA    "), _key(-3), _key(1), _key(0)]
    header = struct.pack("<146i", 21, 7, 0, *[0] * 143)
    out += [_key(146), _record(header), _key(-4), _key(1), _key(0)]
    rows = b"".join(
        struct.pack("<2i5f", k + 1, k + 1, lam, np.sqrt(lam), np.sqrt(lam) / (2 * np.pi), 1.0, lam)
        for k, lam in enumerate(eigenvalues)
    )
    out += [_key(len(rows) // 4), _record(rows), _key(-5), _key(1), _key(0), _key(0)]
    path.write_bytes(b"".join(out))


def deck_files(change: str = "") -> dict[str, bytes]:
    """A 4-grid frame deck as file contents: ``d.bdf``, ``m.op4`` (KGG/MGG), ``x.op2``.

    ``change``: "" (a good deck, interface grid 10), "singular" (the last grid hangs
    free), "asymmetric" (K[7, 13] off by 1e-3 of max |K|), "grounded" (springs to
    ground on every DOF), "size" (one more GRID in
    the BDF), "binary" (a BDF that is no text), "garbage" (an OP4 that is no OP4);
    the OP2 holds no eigenvalue table.
    """
    import tempfile

    K, M, xyz = frame(4, elements=2 if change == "singular" else None)
    if change == "asymmetric":
        K = K.copy()
        K[7, 13] += 1e-3 * np.abs(K).max()
    if change == "grounded":
        K = K + np.diag(np.full(K.shape[0], 1e-3 * np.abs(K).max()))
    ids = np.array([10, 20, 30, 40])
    with tempfile.TemporaryDirectory() as folder:
        bdf, op4, _ = write_frame_deck(Path(folder), K, M, xyz, ids)
        write_lama_op2(Path(folder) / "x.op2", np.ones(1), table=False)
        files = {
            "d.bdf": bdf.read_bytes(),
            "m.op4": op4.read_bytes(),
            "x.op2": (Path(folder) / "x.op2").read_bytes(),
        }
    if change == "size":
        files["d.bdf"] = files["d.bdf"].replace(b"ENDDATA", b"GRID,50,,9.,9.,9.\nENDDATA")
    if change == "binary":
        files["d.bdf"] = b"\x00\xff\x10 not text"
    if change == "garbage":
        files["m.op4"] = b"hello\n"
    return files
