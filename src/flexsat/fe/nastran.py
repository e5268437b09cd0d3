"""NASTRAN decks to the modal data format: OP4 matrices, bulk-data sets, Craig–Bampton.

A NASTRAN run writes the structure's stiffness and mass matrices to an OP4 file
(a DMAP alter's ``OUTPUT4 KAA,MAA,,,//-1/31``); the bulk data (BDF) says
which grid each matrix row belongs to and where the grids are. The rows of a
matrix of the a-, f- or g-set are that set's DOFs in NASTRAN's internal order,
which without resequencing (no ``SEQGP`` card, ``PARAM,OLDSEQ,-1``) is ascending
point id (grids and scalar points share the id space), then ascending component
(1..6 for a grid, 0 for a scalar point):

* g-set (``KGG``, ``MGG``): the six components of every GRID, the one of every SPOINT;
* f-set (``KFF``, ``MFF``): the g-set less the grids' permanent constraints (GRID
  field PS), the SPC/SPC1 components and the dependent components of RBE2 elements;
* a-set (``KAA``, ``MAA``): the DOFs of the ASET/ASET1, BSET/BSET1, CSET/CSET1 and
  QSET/QSET1 cards if the deck has any, otherwise the f-set.

The interface is one grid whose six DOFs are in the set: the one named, or else the
one grid whose six components are all in NASTRAN's b-set (the a-set less the q- and
c-sets). :func:`flexsat.fe.craig_bampton.craig_bampton` then reduces the matrices
clamped at it, with the rigid motions about it built from the grid positions (a
scalar point's rigid motion is zero: a modal coordinate of a Craig–Bampton model
NASTRAN already made, whose constraint modes are the boundary's). A SOL 103 run's
eigenvalue table (``LAMA``, from its OP2 file) can check the clamped frequencies.
Every file is read as data (pyyeti's parsers, the ``nastran`` extra): nothing in it
is executed or unpickled, INCLUDE statements are not followed, sizes are bounded.
"""

from __future__ import annotations

import io
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import scipy.sparse as sp

from flexsat.config.modal_data import ModalData
from flexsat.errors import ConfigError, shorten
from flexsat.fe.craig_bampton import craig_bampton
from flexsat.files import check_user_file, read_user_file

__all__ = [
    "BulkData",
    "NastranModel",
    "dof_set",
    "import_nastran",
    "read_bulk",
    "read_op2_frequencies",
    "read_op4_matrices",
    "rigid_motions",
]

MAX_DOFS = 200_000
"""Largest matrix order read from an OP4 header [-]."""
SYMMETRY_RTOL = 1e-9
"""|A - A^T| allowed, relative to max |A|: the round-off of 16 significant digits."""
RIGID_RTOL = 1e-8
"""|K psi| allowed, relative to max|K| max|psi|: a free-free structure's rigid motions
produce no force; a wrong grid position, a CD frame or a constraint left in K do."""
SINGULAR_RTOL = 1e-12
"""Lowest clamped eigenvalue, relative to the largest diagonal ratio K_ii / M_ii, below
which the clamped stiffness is singular (round-off is ~1e-16 of it, the lowest mode of
a thin solid plate ~1e-10)."""

_SET_CARDS = ("ASET", "ASET1", "BSET", "BSET1", "CSET", "CSET1", "QSET", "QSET1")
_UNSUPPORTED_MPC = ("RBE3", "RBAR", "RBAR1", "RBE1", "RROD", "RSPLINE", "MPC")
_SETS = {"AA": "a", "FF": "f", "GG": "g"}


@dataclass(frozen=True)
class BulkData:
    """What the import reads from a deck's bulk data.

    Attributes
    ----------
    grid_ids : ndarray, shape (n_g,), int
        GRID ids, ascending [-].
    grid_xyz_m : ndarray, shape (n_g, 3)
        Their positions in the basic frame [m] (CP = 0: the deck's length unit is
        taken as metres).
    spoint_ids : ndarray, shape (n_s,), int
        SPOINT ids, ascending [-].
    constrained : frozenset of tuple
        (id, component) removed from the g-set: GRID PS, SPC, SPC1 [-].
    dependent : frozenset of tuple
        (id, component) of RBE2 dependent DOFs [-].
    set_cards : dict
        Card kind ('a', 'b', 'c', 'q') -> frozenset of (id, component) [-].
    unsupported : tuple of str
        Constraint cards present whose dependent DOFs flexsat does not derive [-].
    """

    grid_ids: np.ndarray
    grid_xyz_m: np.ndarray
    spoint_ids: np.ndarray
    constrained: frozenset
    dependent: frozenset
    set_cards: dict
    unsupported: tuple


@dataclass(frozen=True)
class NastranModel:
    """An imported NASTRAN model.

    Attributes
    ----------
    modal : ModalData
        The Craig–Bampton reduction at the interface grid, frame M = basic axes with
        its origin at the interface grid.
    dofs : ndarray, shape (n, 2), int
        (point id, component) of each matrix row [-].
    interface_grid : int
        The interface grid's id [-].
    tip_grid : int
        The grid exported as the output point ``tip`` (the farthest from the
        interface) [-].
    stiffness_name, mass_name : str
        The OP4 matrices read.
    reference_frequencies_hz : ndarray or None, shape (n_modes,)
        The OP2's SOL 103 frequencies, lowest first, when an OP2 was given [Hz].
    """

    modal: ModalData
    dofs: np.ndarray
    interface_grid: int
    tip_grid: int
    stiffness_name: str
    mass_name: str
    reference_frequencies_hz: np.ndarray | None = None

    @property
    def frequency_errors(self) -> np.ndarray | None:
        """Relative difference of the imported frequencies from the OP2's [-]."""
        if self.reference_frequencies_hz is None:
            return None
        f = np.asarray(self.modal.frequencies_hz)
        n = min(f.size, self.reference_frequencies_hz.size)
        ref = self.reference_frequencies_hz[:n]
        return (f[:n] - ref) / ref


def _pyyeti(module: str):
    try:
        from importlib import import_module

        return import_module(f"pyyeti.nastran.{module}")
    except ImportError:
        raise ConfigError(
            "reading NASTRAN files needs pyyeti: pip install 'flexsat[nastran]'"
        ) from None


def _ids(fields: list, what: str, path: Path) -> list[int]:
    """Point ids of a *SET1 / SPC1 card's id list, expanding 'THRU'."""
    ids: list[int] = []
    k = 0
    while k < len(fields):
        value = fields[k]
        if isinstance(value, str) and value.strip().upper() == "THRU":
            if not ids or k + 1 >= len(fields) or not isinstance(fields[k + 1], int):
                raise ConfigError(f"{path}: {what}: 'THRU' without an id on each side")
            last = fields[k + 1]
            if last < ids[-1] or last - ids[-1] > MAX_DOFS:
                raise ConfigError(f"{path}: {what}: 'THRU' range {ids[-1]}..{last} is refused")
            ids.extend(range(ids[-1] + 1, last + 1))
            k += 2
            continue
        if value == "":
            k += 1
            continue
        if not isinstance(value, int) or value <= 0:
            raise ConfigError(f"{path}: {what}: {shorten(str(value))!r} is not a point id")
        ids.append(value)
        k += 1
    return ids


def _components(value, what: str, path: Path) -> list[int]:
    """A component field ('123456', '0' or blank for a scalar point) as digits."""
    if value == "" or value == 0:
        return [0]
    text = str(value)
    if not isinstance(value, int) or any(c not in "123456" for c in text):
        raise ConfigError(f"{path}: {what}: component {shorten(str(value))!r} is not in 1..6")
    return sorted({int(c) for c in text})


def read_bulk(path: str | Path) -> BulkData:
    """Read the grids, scalar points, constraints and DOF sets of a bulk data file.

    Parameters
    ----------
    path : str or Path
        The BDF (small, large or free field; INCLUDE statements are not followed;
        of a whole deck, the lines between BEGIN BULK and ENDDATA).

    Returns
    -------
    BulkData

    Raises
    ------
    ConfigError
        Not a readable text file, no GRID card, a GRID in a local frame (CP or CD),
        a point id twice, a malformed set card (the message names the card).
    """
    path = Path(path)
    raw = read_user_file(path, "NASTRAN bulk data")
    try:
        text = raw.decode("ascii")
    except UnicodeDecodeError:
        raise ConfigError(
            f"{path}: not a NASTRAN bulk data file (not ASCII text: a binary file?)"
        ) from None
    bulk = _pyyeti("bulk")
    lines = text.splitlines()
    upper = [line.lstrip().upper() for line in lines]
    start = next((k + 1 for k, line in enumerate(upper) if line.startswith("BEGIN BULK")), 0)
    end = next((k for k, line in enumerate(upper) if line.startswith("ENDDATA")), len(lines))
    handle = io.StringIO("\n".join(lines[start:end]) + "\n")  # case control is not bulk data

    def cards(name: str) -> list[list]:
        pattern = rf"{name}\*?(?=[ ,\t]|$)"
        try:
            found = bulk.rdcards(handle, pattern, regex=True, return_var="list", blank="",
                                 follow_includes=False)  # fmt: skip
        except (ValueError, IndexError, TypeError) as exc:
            raise ConfigError(f"{path}: a {name} card does not parse ({exc})") from None
        return found or []

    grids = cards("GRID")
    if not grids:
        raise ConfigError(f"{path}: no GRID card: is it a NASTRAN bulk data file?")
    ids, xyz, constrained = [], [], set()
    for fields in grids:
        fields = list(fields) + [""] * (7 - len(fields))
        gid, cp, x, y, z, cd, ps = fields[:7]
        if not isinstance(gid, int) or gid <= 0:
            raise ConfigError(
                f"{path}: GRID {shorten(str(gid))!r}: the id must be a positive integer"
            )
        for name, frame in (("CP", cp), ("CD", cd)):
            if frame not in ("", 0):
                raise ConfigError(
                    f"{path}: GRID {gid}: {name} = {shorten(str(frame))}; flexsat reads grids "
                    "in the basic frame only (CP and CD blank or 0)"
                )
        position = [0.0 if v == "" else v for v in (x, y, z)]
        if not all(isinstance(v, (int, float)) and np.isfinite(v) for v in position):
            raise ConfigError(f"{path}: GRID {gid}: coordinates must be numbers")
        ids.append(gid)
        xyz.append(position)
        if ps != "":
            constrained.update((gid, c) for c in _components(ps, f"GRID {gid} PS", path))
    spoints: list[int] = []
    for fields in cards("SPOINT"):
        spoints.extend(_ids(fields, "SPOINT", path))
    every = np.array(ids + spoints)
    if np.unique(every).size != every.size:
        values, counts = np.unique(every, return_counts=True)
        raise ConfigError(f"{path}: point {int(values[counts > 1][0])} is defined twice")
    if cards("SEQGP"):
        raise ConfigError(
            f"{path}: SEQGP resequences the points; the OP4 rows would not be in id order"
        )
    for fields in cards("SPC1"):
        where = _components(fields[1] if len(fields) > 1 else "", "SPC1", path)
        constrained.update((g, c) for g in _ids(fields[2:], "SPC1", path) for c in where)
    for fields in cards("SPC"):
        for k in range(1, len(fields) - 1, 3):
            if isinstance(fields[k], int):
                constrained.update((fields[k], c) for c in _components(fields[k + 1], "SPC", path))
    dependent = set()
    for fields in cards("RBE2"):
        if len(fields) < 4:
            raise ConfigError(
                f"{path}: RBE2 {fields[:1]}: expected EID, GN, CM and dependent grids"
            )
        where = _components(fields[2], "RBE2 CM", path)
        members = [v for v in fields[3:] if isinstance(v, int)]  # a real is ALPHA
        dependent.update((g, c) for g in members for c in where)
    sets: dict[str, set] = {"a": set(), "b": set(), "c": set(), "q": set()}
    for card in _SET_CARDS:
        kind = card[0].lower()
        for fields in cards(card):
            if card.endswith("1"):
                where = _components(fields[0] if fields else "", card, path)
                sets[kind].update((g, c) for g in _ids(fields[1:], card, path) for c in where)
            else:
                for k in range(0, len(fields) - 1, 2):
                    if isinstance(fields[k], int):
                        sets[kind].update(
                            (fields[k], c) for c in _components(fields[k + 1], card, path)
                        )
    unsupported = tuple(name for name in _UNSUPPORTED_MPC if cards(name))
    order = np.argsort(ids)
    return BulkData(
        grid_ids=np.asarray(ids, dtype=np.int64)[order],
        grid_xyz_m=np.asarray(xyz, dtype=float).reshape(-1, 3)[order],
        spoint_ids=np.sort(np.asarray(spoints, dtype=np.int64)),
        constrained=frozenset(constrained),
        dependent=frozenset(dependent),
        set_cards={k: frozenset(v) for k, v in sets.items()},
        unsupported=unsupported,
    )


def dof_set(bulk: BulkData, which: str) -> np.ndarray:
    """The DOFs of a NASTRAN set in matrix-row order.

    Parameters
    ----------
    bulk : BulkData
        The deck.
    which : {'g', 'f', 'a'}
        The set (see the module docstring).

    Returns
    -------
    ndarray, shape (n, 2), int
        (point id, component) per row: ascending id, then component [-].

    Raises
    ------
    ConfigError
        A set card naming a point the deck does not define, or an f/a-set of a deck
        with MPC-type cards flexsat does not derive (RBE3, RBAR, MPC...).
    """
    g = [(int(i), c) for i in bulk.grid_ids for c in range(1, 7)]
    g += [(int(i), 0) for i in bulk.spoint_ids]
    if which == "g":
        chosen = g
    else:
        if bulk.unsupported:
            raise ConfigError(
                f"the deck has {', '.join(bulk.unsupported)}: flexsat derives the dependent "
                "DOFs of RBE2 only; write KGG/MGG of a deck without them, or list the a-set "
                "with ASET1 cards"
            )
        known = set(g)
        named = set().union(*bulk.set_cards.values())
        if which == "a" and named:
            stray = sorted(named - known)
            if stray:
                raise ConfigError(
                    f"ASET/QSET: point {stray[0][0]} component {stray[0][1]} is not in the deck"
                )
            chosen = sorted(named)
        else:
            removed = bulk.constrained | bulk.dependent
            chosen = [dof for dof in g if dof not in removed]
    return np.array(sorted(chosen), dtype=np.int64).reshape(-1, 2)


def read_op4_matrices(
    path: str | Path, stiffness: str | None = None, mass: str | None = None
) -> tuple[str, str, sp.csr_matrix, sp.csr_matrix]:
    """Read a stiffness and a mass matrix from an OP4 file (ASCII or binary).

    Parameters
    ----------
    path : str or Path
        The OP4 file.
    stiffness, mass : str, optional
        The matrices' names; default the first pair present of KAA/MAA, KFF/MFF,
        KGG/MGG.

    Returns
    -------
    tuple
        (stiffness name, mass name, K, M), K and M sparse, shape (n, n) [N/m...; kg...].

    Raises
    ------
    ConfigError
        Not an OP4 file, a named matrix absent, sizes that differ or exceed
        :data:`MAX_DOFS`, non-finite entries, non-symmetric matrices.
    """
    path = check_user_file(path, "OP4")
    op4 = _pyyeti("op4")
    try:
        names, sizes, _, _ = op4.dir(str(path), verbose=False)
    except Exception as exc:
        raise ConfigError(f"{path}: not an OP4 file ({shorten(str(exc), 120)})") from None
    names = [n.upper() for n in names]
    if stiffness is None and mass is None:
        pair = next(((k, m) for k, m in (("KAA", "MAA"), ("KFF", "MFF"), ("KGG", "MGG"))
                     if k in names and m in names), None)  # fmt: skip
        if pair is None:
            raise ConfigError(
                f"{path}: holds no KAA/MAA, KFF/MFF or KGG/MGG pair (it holds "
                f"{shorten(', '.join(names) or 'nothing', 120)}); name them with --stiffness/--mass"
            )
        stiffness, mass = pair
    stiffness = (stiffness or mass[:1].replace("M", "K") + mass[1:]).upper()
    mass = (mass or "M" + stiffness[1:]).upper()
    for name in (stiffness, mass):
        if name not in names:
            raise ConfigError(
                f"{path}: no matrix {shorten(name)!r} "
                f"(it holds {shorten(', '.join(names) or 'nothing', 120)})"
            )
    shape = {n: s for n, s in zip(names, sizes, strict=True)}
    for name in (stiffness, mass):
        rows, cols = shape[name]
        if rows != cols:
            raise ConfigError(f"{path}: {name} is {rows} x {cols}, not square")
        if rows > MAX_DOFS:
            raise ConfigError(
                f"{path}: {name} has {rows} rows, more than the {MAX_DOFS} flexsat reads"
            )
    if shape[stiffness] != shape[mass]:
        raise ConfigError(
            f"{path}: {stiffness} is {shape[stiffness][0]} x {shape[stiffness][1]} but {mass} is "
            f"{shape[mass][0]} x {shape[mass][1]}: the two matrices must have one size"
        )
    try:
        found = op4.read(str(path), [stiffness.lower(), mass.lower()], sparse=True)
    except Exception as exc:
        raise ConfigError(
            f"{path}: cannot read {stiffness}/{mass} ({shorten(str(exc), 120)})"
        ) from None
    matrices = []
    for name in (stiffness, mass):
        matrix = sp.csr_matrix(found[name.lower()], dtype=float)
        if not np.all(np.isfinite(matrix.data)):
            raise ConfigError(f"{path}: {name} has a non-finite entry")
        scale = abs(matrix).max()
        if scale == 0.0:
            raise ConfigError(f"{path}: {name} is zero")
        asym = abs(matrix - matrix.T).max()
        if asym > SYMMETRY_RTOL * scale:
            raise ConfigError(
                f"{path}: {name} is not symmetric (max |A - A^T| = {asym:.3g}, "
                f"{asym / scale:.3g} of its largest entry; allowed {SYMMETRY_RTOL:g})"
            )
        matrices.append(0.5 * (matrix + matrix.T))
    return stiffness, mass, matrices[0].tocsr(), matrices[1].tocsr()


def rigid_motions(dofs: np.ndarray, bulk: BulkData, origin_m: np.ndarray) -> np.ndarray:
    """Each DOF's motion per unit rigid motion [t; r] about a point.

    Parameters
    ----------
    dofs : ndarray, shape (n, 2), int
        (point id, component) per row [-].
    bulk : BulkData
        The grid positions.
    origin_m : ndarray, shape (3,)
        The point, basic frame [m].

    Returns
    -------
    ndarray, shape (n, 6)
        Translation c of a grid at p: e_c + (r x p)_c; rotation c: r_c; a scalar
        point: 0 [m/m, m/rad, rad/rad].
    """
    position = dict(zip(bulk.grid_ids.tolist(), bulk.grid_xyz_m - origin_m, strict=True))
    psi = np.zeros((len(dofs), 6))
    for row, (point, component) in enumerate(dofs):
        if component == 0:
            continue
        c = component - 1
        if c < 3:
            p = position[int(point)]
            psi[row, c] = 1.0
            r = np.eye(3)
            psi[row, 3:] = np.cross(r, p)[:, c]  # (e_k x p)_c for k = x, y, z
        else:
            psi[row, c] = 1.0
    return psi


def _interface(bulk: BulkData, dofs: np.ndarray, interface: int | None) -> int:
    in_set = {tuple(d) for d in dofs.tolist()}
    if interface is not None:
        if interface not in set(bulk.grid_ids.tolist()):
            raise ConfigError(f"interface: grid {interface} is not in the deck")
        missing = [c for c in range(1, 7) if (interface, c) not in in_set]
        if missing:
            raise ConfigError(
                f"interface: grid {interface}'s component(s) {''.join(map(str, missing))} are "
                "not in the matrices' set; the interface needs all six"
            )
        return interface
    sets = bulk.set_cards
    boundary = sets["b"] | (sets["a"] - sets["c"] - sets["q"]) if any(sets.values()) else in_set
    full = [int(g) for g in bulk.grid_ids if all((int(g), c) in boundary for c in range(1, 7))]
    full = [g for g in full if all((g, c) in in_set for c in range(1, 7))]
    if len(full) != 1:
        found = "none" if not full else shorten(", ".join(map(str, full)), 80)
        raise ConfigError(
            f"interface: the deck's b-set names one grid's six DOFs {len(full)} times "
            f"(grids: {found}); give the interface grid (--interface GRID)"
        )
    return full[0]


def import_nastran(bdf: str | Path, op4: str | Path, *, interface: int | None = None,
                   n_modes: int | None = None, op2: str | Path | None = None,
                   stiffness: str | None = None, mass: str | None = None,
                   damping_ratio: float = 0.0) -> NastranModel:  # fmt: skip
    """Import a NASTRAN model: OP4 matrices, BDF sets, Craig–Bampton at the interface.

    Parameters
    ----------
    bdf : str or Path
        The bulk data (grids, constraints, sets).
    op4 : str or Path
        The matrices (see :func:`read_op4_matrices`); the set (a, f or g) follows
        the stiffness name's last two letters.
    interface : int, optional
        The interface grid id; default the one grid of the deck's b-set.
    n_modes : int, optional
        Clamped modes kept, the lowest first; default all, at most 2000.
    op2 : str or Path, optional
        A SOL 103 OP2 of the deck clamped at the interface: its eigenvalues are
        read to check the frequencies.
    stiffness, mass : str, optional
        The OP4 matrices' names.
    damping_ratio : float
        Modal damping ratio of every mode [-].

    Returns
    -------
    NastranModel
        Frame M: basic axes, origin the interface grid.

    Raises
    ------
    ConfigError
        Each bad deck with one message: see :func:`read_bulk`,
        :func:`read_op4_matrices`, a size that does not match the set, a missing
        interface, matrices that are not free-free about the grids, a singular
        clamped stiffness.
    """
    bulk = read_bulk(bdf)
    k_name, m_name, K, M = read_op4_matrices(op4, stiffness, mass)
    reference = None if op2 is None else read_op2_frequencies(op2)
    which = _SETS.get(k_name[-2:])
    if which is None:
        raise ConfigError(
            f"stiffness: {shorten(k_name)!r} names no set flexsat knows; the name must end "
            "in AA, FF or GG (a-, f- or g-set rows)"
        )
    if which == "g" and (bulk.unsupported or bulk.dependent):
        raise ConfigError(
            f"{k_name}: the g-set holds the deck's rigid elements' dependent DOFs unconstrained; "
            "write KAA/MAA (or KFF/MFF) instead"
        )
    dofs = dof_set(bulk, which)
    if K.shape[0] != len(dofs):
        raise ConfigError(
            f"{k_name} is {K.shape[0]} x {K.shape[0]} but the deck's {which}-set has "
            f"{len(dofs)} DOFs: the matrices are not this deck's"
        )
    if which == "g":  # the permanent and single-point constraints leave the g-set
        keep = np.array([tuple(d) not in bulk.constrained for d in dofs.tolist()])
        K, M, dofs = K[keep][:, keep], M[keep][:, keep], dofs[keep]
    grid = _interface(bulk, dofs, interface)
    origin = bulk.grid_xyz_m[np.searchsorted(bulk.grid_ids, grid)]
    b = np.array([np.nonzero((dofs[:, 0] == grid) & (dofs[:, 1] == c))[0][0] for c in range(1, 7)])
    interior = np.setdiff1d(np.arange(len(dofs)), b)
    if interior.size == 0:
        raise ConfigError(f"{k_name}: the set holds only the interface grid's six DOFs: no modes")
    psi = rigid_motions(dofs, bulk, origin)
    residual = abs(K @ psi).max()
    if residual > RIGID_RTOL * abs(K).max() * max(1.0, np.abs(psi).max()):
        raise ConfigError(
            f"{k_name}: rigid motions about grid {grid} are not free (max |K psi| = "
            f"{residual:.3g}): the matrices are not free-free at the grids' positions "
            "(a constraint in K, a grid in the wrong place, a local CD frame)"
        )
    K_ii, M_ii = K[interior][:, interior], M[interior][:, interior]
    diag_k, diag_m = K_ii.diagonal(), M_ii.diagonal()
    dead = np.nonzero(diag_k <= 0.0)[0]
    if dead.size:
        point, component = dofs[interior[dead[0]]]
        raise ConfigError(
            f"{k_name}: singular stiffness: point {point} component {component} has no "
            f"stiffness with grid {grid} clamped"
        )
    if np.any(diag_m < 0.0):
        raise ConfigError(f"{m_name}: a negative diagonal mass")
    count = interior.size if n_modes is None else n_modes
    count = min(count, 2000) if n_modes is None else count
    if not 1 <= count <= interior.size:
        raise ConfigError(f"modes: must be in 1..{interior.size} (the interior DOFs), got {count}")
    moving = set(map(tuple, dofs[interior].tolist()))
    tip_candidates = [int(g) for g in bulk.grid_ids
                      if all((int(g), c) in moving for c in (1, 2, 3))]  # fmt: skip
    outputs = None
    tip = grid
    if tip_candidates:
        where = bulk.grid_xyz_m[np.searchsorted(bulk.grid_ids, tip_candidates)] - origin
        tip = tip_candidates[int(np.argmax(np.linalg.norm(where, axis=1)))]
        row = {tuple(d): k for k, d in enumerate(dofs.tolist())}
        tip_dofs = [row[(tip, c)] for c in (1, 2, 3)]
        outputs = {"tip": (tip_dofs, where[tip_candidates.index(tip)])}
    positive = diag_m > 0.0
    scale = float(np.max(diag_k[positive] / diag_m[positive])) if positive.any() else 1.0
    _check_clamped(K_ii, M_ii, SINGULAR_RTOL * scale, k_name, m_name, grid)
    try:
        modal = craig_bampton(M, K, b, count, rigid_modes=psi, damping_ratio=damping_ratio,
                              outputs=outputs)  # fmt: skip
    except (np.linalg.LinAlgError, RuntimeError) as exc:
        raise ConfigError(
            f"{m_name}: the clamped eigenproblem failed ({shorten(str(exc), 80)}): a massless "
            "or unconstrained DOF; keep only DOFs with mass in the a-set (ASET1)"
        ) from None
    return NastranModel(modal, dofs, grid, tip, k_name, m_name, reference)


def _check_clamped(K_ii, M_ii, floor: float, k_name: str, m_name: str, grid: int) -> None:
    """Refuse a singular clamped stiffness or a mass that is not positive definite."""
    from scipy.linalg import LinAlgError, cholesky, eigh
    from scipy.sparse.linalg import splu

    singular = ConfigError(
        f"{k_name}: singular stiffness with grid {grid} clamped (a mechanism, or points "
        "not connected to the interface)"
    )
    if K_ii.shape[0] <= 2000:
        try:
            cholesky(M_ii.toarray())
        except LinAlgError:
            raise ConfigError(
                f"{m_name}: the mass of the interior DOFs is not positive definite (massless "
                "DOFs: keep only DOFs with mass in the a-set, ASET1)"
            ) from None
        lowest = eigh(K_ii.toarray(), M_ii.toarray(), eigvals_only=True, subset_by_index=(0, 0))
        if lowest[0] < floor:
            raise singular
        return
    try:
        splu(K_ii.tocsc())
    except RuntimeError:
        raise singular from None


def read_op2_frequencies(path: str | Path) -> np.ndarray:
    """The natural frequencies of a SOL 103 OP2 file's eigenvalue table (LAMA).

    Parameters
    ----------
    path : str or Path
        The OP2 file (``PARAM,POST,-1`` or ``-2``).

    Returns
    -------
    ndarray, shape (n,)
        Frequencies, ascending [Hz].

    Raises
    ------
    ConfigError
        Not an OP2 file, or no LAMA table in it.
    """
    path = check_user_file(path, "OP2")
    op2 = _pyyeti("op2")
    try:
        with op2.OP2(str(path)) as handle:
            names = list(handle.dbdct)
            lama = next((n for n in names if n.upper().startswith("LAMA")), None)
            if lama is None:
                raise ConfigError(
                    f"{path}: no eigenvalue table (LAMA) in the OP2 (it holds "
                    f"{shorten(', '.join(names) or 'nothing', 120)}): not a SOL 103 output"
                )
            handle.set_position(lama)
            handle.rdop2nt()
            table = np.asarray(handle._rdop2lama(), dtype=float)
    except ConfigError:
        raise
    except Exception as exc:
        raise ConfigError(f"{path}: not a readable OP2 file ({shorten(str(exc), 120)})") from None
    if table.ndim != 2 or table.shape[1] != 7:
        raise ConfigError(f"{path}: the LAMA table has {table.shape} entries, expected 7 per mode")
    eigenvalues = table[:, 2]
    if not np.all(np.isfinite(eigenvalues)) or np.any(eigenvalues < 0.0):
        raise ConfigError(f"{path}: the LAMA table has a negative or non-finite eigenvalue")
    return np.sort(np.sqrt(eigenvalues) / (2.0 * np.pi))
