"""Write the NASTRAN plate deck of the gallery: ``nastran_plate.bdf`` and ``.op4``.

The structure is flexsat.fe's thin solid plate (:func:`flexsat.fe.solid_plate`,
27-node hexahedra, one layer through the thickness). NASTRAN has no 27-node solid
(CHEXA stops at 20 nodes), so the deck holds what the import reads: one GRID per FE
node (PS = 456, a solid node has no rotations), the interface grid 9000 at the middle
of the root edge with an RBE2 slaving the root face's translations to it, and the
a-set (ASET1): the interface's six DOFs and the interior grids' translations. The
OP4 holds KAA and MAA as a DMAP alter would write them: the plate's matrices with
the root face eliminated through the RBE2 (K_aa = T^T K T), rows in a-set order
(ascending grid id, then component), 17 significant digits (exact doubles).

Run it from the repository root: ``python examples/data/make_nastran_plate.py``
(needs the ``fe`` and ``nastran`` extras).
"""

from __future__ import annotations

import io
from pathlib import Path

import numpy as np
import scipy.sparse as sp

HERE = Path(__file__).resolve().parent
INTERFACE_GRID = 9000
FIRST_GRID = 101
PLATE = {  # aluminium, 0.8 m span x 0.3 m chord x 6 mm
    "length_m": 0.8,
    "width_m": 0.3,
    "thickness_m": 0.006,
    "density_kg_m3": 2700.0,
    "youngs_modulus_pa": 70e9,
    "poisson_ratio": 0.3,
    "elements_span": 4,
    "elements_chord": 1,
}


def plate_model():
    """The plate's FE model: :func:`flexsat.fe.solid_plate` with :data:`PLATE`."""
    from flexsat.fe import solid_plate

    return solid_plate(**PLATE)


def fe_dof_places():
    """Each FE DOF's node position [m] and component (0, 1, 2), as solid_plate numbers them."""
    from skfem import Basis, ElementHex2, ElementVector, MeshHex

    half_w, t = 0.5 * PLATE["width_m"], 0.5 * PLATE["thickness_m"]
    mesh = MeshHex.init_tensor(
        np.linspace(-half_w, half_w, PLATE["elements_chord"] + 1),
        np.linspace(0.0, PLATE["length_m"], PLATE["elements_span"] + 1),
        np.linspace(-t, t, 2),
    )
    basis = Basis(mesh, ElementVector(ElementHex2()), intorder=4)
    component = np.empty(basis.N, dtype=int)
    for axis, dofs in enumerate(basis.split_indices()):
        component[dofs] = axis
    return basis.doflocs.T.copy(), component


def deck():
    """The deck's content: (bulk data text, a-set DOFs (n, 2), K_aa, M_aa)."""
    from pyyeti.nastran import bulk

    from flexsat.fe import rigid_interface_map

    model = plate_model()
    where, component = fe_dof_places()
    if not np.array_equal(rigid_interface_map(where, component), model.rigid_modes):
        raise RuntimeError("the DOF places do not match flexsat.fe.solid_plate's")
    nodes, node_of = np.unique(np.round(where, 12), axis=0, return_inverse=True)
    node_of = node_of.ravel()
    order = np.lexsort((nodes[:, 2], nodes[:, 0], nodes[:, 1]))  # span, chord, thickness
    grid_of_node = np.empty(len(nodes), dtype=int)
    grid_of_node[order] = FIRST_GRID + np.arange(len(nodes))
    root = set(model.interface_dofs.tolist())
    root_grids = sorted({int(grid_of_node[node_of[d]]) for d in root})
    interior = [d for d in range(len(component)) if d not in root]
    # a-set: interior grids' components 1..3, then the interface grid's 1..6
    rows = sorted((int(grid_of_node[node_of[d]]), int(component[d]) + 1, d) for d in interior)
    dofs = [(g, c) for g, c, _ in rows] + [(INTERFACE_GRID, c) for c in range(1, 7)]
    n, n_a = len(component), len(dofs)
    T = sp.lil_matrix((n, n_a))
    for column, (_, _, d) in enumerate(rows):
        T[d, column] = 1.0
    for k, d in enumerate(model.interface_dofs):
        T[d, n_a - 6 :] = model.interface_map[k]
    T = T.tocsr()
    K_aa = (T.T @ model.K @ T).tocsr()
    M_aa = (T.T @ model.M @ T).tocsr()
    K_aa, M_aa = 0.5 * (K_aa + K_aa.T), 0.5 * (M_aa + M_aa.T)

    text = io.StringIO()
    text.write(bulk.mkcomment(
        "flexsat's thin solid plate (flexsat.fe.solid_plate, 27-node hexahedra): the "
        "grids, the interface and the a-set of KAA/MAA in nastran_plate.op4. Written by "
        "examples/data/make_nastran_plate.py.", surround=False))  # fmt: skip
    text.write("BEGIN BULK\n")
    for node in order:
        x, y, z = (float(v) for v in nodes[node])
        bulk.wtcard16(text, ["GRID*", int(grid_of_node[node]), "", x, y, z, "", 456])
    bulk.wtcard16(text, ["GRID*", INTERFACE_GRID, "", 0.0, 0.0, 0.0, ""])
    bulk.wtcard8(text, ["RBE2", 1, INTERFACE_GRID, 123, *root_grids])
    bulk.wtcard8(text, ["ASET1", 123456, INTERFACE_GRID])
    interior_grids = sorted({g for g, _, _ in rows})
    bulk.wtcard8(text, ["ASET1", 123, interior_grids[0], "THRU", interior_grids[-1]])
    text.write("ENDDATA\n")
    missing = set(range(interior_grids[0], interior_grids[-1] + 1)) - set(interior_grids)
    if missing:
        raise RuntimeError("the interior grids are not one id range")
    return text.getvalue(), np.array(dofs), K_aa, M_aa


def write_deck(bdf: Path = HERE / "nastran_plate.bdf", op4: Path = HERE / "nastran_plate.op4"):
    """Write the bulk data and the OP4 (ASCII, 16 digits after the point)."""
    from pyyeti.nastran import op4 as op4_file

    text, _, K_aa, M_aa = deck()
    bdf.write_text(text)
    op4_file.write(str(op4), {"KAA": K_aa.toarray(), "MAA": M_aa.toarray()}, binary=False,
                   digits=16, sparse="nonbigmat")  # fmt: skip


if __name__ == "__main__":
    write_deck()
