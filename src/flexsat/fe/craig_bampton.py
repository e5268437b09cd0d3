"""Craig–Bampton (clamped-interface) reduction of FE matrices to the modal data format.

With the interface DOFs b (those of one node, or of nodes rigidly linked to it) and
the interior DOFs i, the interface point's six rigid motions u_I = [t; r] (frame M)
move the boundary as u_b = T_b u_I. The constraint modes

    Psi = [T_b; -K_ii^-1 K_ib T_b]          (n x 6)

are the structure's rigid-body motions when K is free-free with a single interface
node (the static response to a rigid interface motion is that rigid motion), so

    M_rr = Psi^T M Psi                       the rigid mass about the interface
    K_ii phi = omega^2 M_ii phi,  phi^T M_ii phi = I     the clamped modes
    L = phi^T M_i: Psi                       the participation factors (n_modes x 6)

(Craig and Bampton 1968; docs/model.md, "Modal appendages").
"""

from __future__ import annotations

from collections.abc import Callable, Mapping, Sequence

import numpy as np
import scipy.sparse as sp
from scipy.linalg import eigh
from scipy.sparse.linalg import eigsh, splu

from flexsat.config.modal_data import FORMAT_VERSION, ModalData, modal_data_from_dict
from flexsat.errors import ConfigError

__all__ = ["craig_bampton", "rigid_interface_map"]

# The translational block of M_rr must be m I to this: the round-off of K_ii^-1 (1e-7
# for a thin solid plate) is below it, while a missing interface DOF or a structure
# that is not free-free is off by O(1).
_RIGID_RTOL = 1e-6
_DENSE_MAX = 600  # interior DOFs up to which the clamped eigenproblem is solved densely


def craig_bampton(
    M, K, interface_dofs: Sequence[int], n_modes: int, *,
    interface_map: np.ndarray | None = None, rigid_modes: np.ndarray | None = None,
    damping_ratio: float | Sequence[float] = 0.0,
    outputs: Mapping[str, tuple[Sequence[int], Sequence[float]]] | None = None,
    large_motion: Callable[[np.ndarray], dict] | None = None,
) -> ModalData:  # fmt: skip
    """Reduce FE matrices clamped at an interface to the modal data format.

    Parameters
    ----------
    M, K : ndarray or scipy.sparse matrix, shape (n, n)
        Mass and stiffness matrices of the free-free structure (SI, frame M)
        [kg, kg m, kg m^2; N/m, N/rad, N m/rad by DOF kind].
    interface_dofs : sequence of int
        The boundary DOFs b (indices into the matrices).
    n_modes : int
        Clamped-interface modes kept, the lowest first (1 .. number of interior DOFs).
    interface_map : ndarray, shape (len(interface_dofs), 6), optional
        T_b: boundary displacement per unit interface motion [tx, ty, tz, rx, ry, rz] in
        frame M (a rigid link, or signs of rotational DOFs). Default: identity (six
        DOFs of one node in that order).
    rigid_modes : ndarray, shape (n, 6), optional
        The structure's rigid motions per unit interface motion, when the caller knows
        them (from the node positions): used as the constraint modes instead of
        solving K_ii Psi_i = -K_ib T_b, whose round-off grows with the condition number
        of K_ii (1e-7 for a thin solid plate). Their boundary rows must be T_b
        [m/m, m/rad, rad/rad by DOF kind].
    damping_ratio : float or sequence of float
        Modal damping ratio zeta_k, one for all or one per mode [-].
    outputs : mapping, optional
        name -> (three DOF indices of the point's translation x, y, z in frame M, its
        undeformed position from the interface in frame M [m]).
    large_motion : callable, optional
        ``large_motion(phi)`` -> the large-motion invariants of the clamped modes
        ``phi`` (n, n_modes), zero on the interface DOFs, as modal data fields
        (``inertia_derivatives``, ``first_moment_hessian``, ``coupling_gradient``,
        ``inertia_hessian``; e.g. :attr:`flexsat.fe.BeamModel.large_motion`). Default:
        none, the first-order model.

    Returns
    -------
    ModalData

    Raises
    ------
    ConfigError
        A DOF index outside the model, a map of the wrong shape, ``n_modes`` out of
        range, or constraint modes that are not rigid motions (the message names the
        argument).
    """
    M, K = sp.csr_matrix(M, dtype=float), sp.csr_matrix(K, dtype=float)
    n = M.shape[0]
    if M.shape != (n, n) or K.shape != (n, n):
        raise ConfigError(
            f"M and K: expected square matrices of one size, got {M.shape}, {K.shape}"
        )
    b = np.asarray(interface_dofs, dtype=int)
    _check_dofs("interface_dofs", b, n)
    T_b = np.eye(6) if interface_map is None else np.asarray(interface_map, dtype=float)
    if T_b.shape != (b.size, 6):
        raise ConfigError(
            f"interface_map: expected shape ({b.size}, 6) (one row per interface DOF), "
            f"got {T_b.shape}"
        )
    i = np.setdiff1d(np.arange(n), b)
    if not 1 <= n_modes <= i.size:
        raise ConfigError(f"n_modes: must be in 1..{i.size} (interior DOFs), got {n_modes}")
    K_ii, M_ii = K[i][:, i].tocsc(), M[i][:, i].tocsc()
    psi = np.zeros((n, 6))
    psi[b] = T_b
    if rigid_modes is None:
        psi[i] = splu(K_ii).solve(-(K[i][:, b] @ T_b))  # constraint modes
    else:
        psi = np.asarray(rigid_modes, dtype=float)
        if psi.shape != (n, 6) or not np.allclose(psi[b], T_b, rtol=0.0, atol=1e-12):
            raise ConfigError(
                f"rigid_modes: expected shape ({n}, 6) with the interface_map as its interface rows"
            )
    M_rr = psi.T @ (M @ psi)
    M_rr = 0.5 * (M_rr + M_rr.T)
    mass = float(np.trace(M_rr[:3, :3]) / 3.0)
    if np.abs(M_rr[:3, :3] - mass * np.eye(3)).max() > _RIGID_RTOL * mass:
        raise ConfigError(
            "interface_dofs: the constraint modes are not rigid-body motions (the "
            "translational rigid mass is not m I); give all six DOFs of the interface node "
            "(or an interface_map linking the boundary rigidly to it) of a free-free model"
        )
    omega2, phi = _clamped_modes(K_ii, M_ii, n_modes)
    L = phi.T @ (M[i] @ psi)
    zeta = np.broadcast_to(np.asarray(damping_ratio, dtype=float), (n_modes,))
    first = M_rr[3:, :3]  # m [c]x
    com = np.array([first[2, 1], first[0, 2], first[1, 0]]) / mass
    points = []
    for name, (dofs, position) in (outputs or {}).items():
        dofs = np.asarray(dofs, dtype=int)
        _check_dofs(f"outputs[{name!r}]", dofs, n)
        if dofs.size != 3:
            raise ConfigError(f"outputs[{name!r}]: expected three DOFs (x, y, z), got {dofs.size}")
        rows = np.zeros((n_modes, 3))
        for a, dof in enumerate(dofs):
            where = np.nonzero(i == dof)[0]
            rows[:, a] = phi[where[0]] if where.size else 0.0  # an interface DOF does not move
        points.append({"name": name, "position_m": list(map(float, position)),
                       "mode_shapes": rows.tolist()})  # fmt: skip
    extra = {}
    if large_motion is not None:
        full = np.zeros((n, n_modes))
        full[i] = phi
        extra = large_motion(full)
    return modal_data_from_dict({
        **extra,
        "format_version": FORMAT_VERSION,
        "mass_kg": mass,
        "center_of_mass_m": com.tolist(),
        "inertia_interface_kg_m2": M_rr[3:, 3:].tolist(),
        "frequencies_hz": (np.sqrt(np.clip(omega2, 0.0, None)) / (2.0 * np.pi)).tolist(),
        "damping_ratios": zeta.tolist(),
        "participation": L.tolist(),
        "output_points": points,
    }, source="Craig-Bampton reduction")  # fmt: skip


def _check_dofs(field: str, dofs: np.ndarray, n: int) -> None:
    if dofs.size == 0:
        raise ConfigError(f"{field}: no DOFs given")
    outside = dofs[(dofs < 0) | (dofs >= n)]
    if outside.size:
        raise ConfigError(
            f"{field}: DOF {int(outside[0])} is not in the model (its DOFs are 0..{n - 1}); "
            "is the interface node in the mesh?"
        )
    if np.unique(dofs).size != dofs.size:
        raise ConfigError(f"{field}: a DOF is given twice")


def _clamped_modes(K_ii, M_ii, n_modes: int) -> tuple[np.ndarray, np.ndarray]:
    """The n_modes lowest clamped modes, mass-normalized, ascending."""
    if K_ii.shape[0] <= _DENSE_MAX:
        omega2, phi = eigh(K_ii.toarray(), M_ii.toarray(), subset_by_index=(0, n_modes - 1))
    else:
        omega2, phi = eigsh(K_ii, k=n_modes, M=M_ii, sigma=0.0, which="LM")
        order = np.argsort(omega2)
        omega2, phi = omega2[order], phi[:, order]
        phi /= np.sqrt(np.einsum("ik,ik->k", phi, M_ii @ phi))
    return omega2, phi


def rigid_interface_map(points_m: np.ndarray, components: np.ndarray) -> np.ndarray:
    """T_b of boundary DOFs rigidly linked to the interface point (an RBE2 link).

    Parameters
    ----------
    points_m : ndarray, shape (n_b, 3)
        Each boundary DOF's node position from the interface point, frame M [m].
    components : ndarray, shape (n_b,), int
        Each DOF's translation component (0, 1, 2 for x, y, z) [-].

    Returns
    -------
    ndarray, shape (n_b, 6)
        u_b = T_b [t; r]: u = t + r x p, so row j is e_c then the row c of -[p]x.
    """
    p = np.asarray(points_m, dtype=float)
    c = np.asarray(components, dtype=int)
    rows = np.zeros((len(c), 6))
    rows[np.arange(len(c)), c] = 1.0
    skew = np.zeros((len(c), 3, 3))
    skew[:, 0, 1], skew[:, 0, 2], skew[:, 1, 2] = -p[:, 2], p[:, 1], -p[:, 0]
    skew[:, 1, 0], skew[:, 2, 0], skew[:, 2, 1] = p[:, 2], -p[:, 1], p[:, 0]
    rows[:, 3:] = -skew[np.arange(len(c)), c]
    return rows
