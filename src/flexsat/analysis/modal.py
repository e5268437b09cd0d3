"""Modal analysis of the linearized, undamped coupled system (thesis section 3.2).

Solves K_sys phi = omega^2 M(0) phi (eq. 3.3) with ``scipy.linalg.eigh`` and
classifies each flexible mode automatically:

- ``kind``: the joint DOF type holding most of the mode's strain energy
  (flapping = rotation about X_M, torsion = about Y_M, in-plane bending = about
  Z_M, translation = any root translation).
- ``symmetry``: for a plant with a mirror symmetry (the two-panel case is symmetric
  about the hub XZ plane), the parity of the mode under the reflection:
  ``symmetric`` (the panels move as mirror images) or ``antisymmetric`` (as
  opposite images); ``none`` when the plant has no mirror symmetry, the mode has
  no parity, or the mode is not a motion of mirror pairs: an appendage that is its
  own mirror image (a third panel in the plane beside a mirrored pair) has no
  partner to move with, so a mode in which such appendages carry at least half of
  the appendages' mass-weighted motion (:data:`_PAIRED_MIN`) is labelled ``none``.
- ``hub_dof``: the hub DOF the mode drives most (mass-weighted amplitude), if it
  carries at least 10 % of the mode's largest mass-weighted amplitude.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
from scipy.linalg import eigh

from flexsat.dynamics.plant import HUB_DOFS, JOINT_DOFS, Plant
from flexsat.dynamics.rigid import rigid_inertia
from flexsat.dynamics.symmetry import mirror_operator, mirror_partners
from flexsat.errors import SimulationError

__all__ = [
    "HUB_DOFS",
    "JOINT_DOFS",
    "ModalAnalysis",
    "Mode",
    "dof_names",
    "effective_mass_table",
    "effective_masses",
    "modal_analysis",
]

_PARITY_MIN = 0.9  # |<phi, P phi>_M| above this: the mode has a definite mirror parity
_PAIRED_MIN = 0.5
"""Share of a mode's appendage motion (sum of its squared mass-weighted amplitudes over
the appendages' coordinates) the mirror pairs must carry for the mode to be labelled
symmetric or antisymmetric: more than the appendages that are their own image."""
_DOMINANT_MIN = 0.5  # normalized mass-weighted amplitude for a DOF to count as dominant
_HUB_COUPLING_MIN = 0.1


def dof_names(plant: Plant) -> list[str]:
    """Names of the generalized coordinates (see :meth:`Plant.dof_names`).

    Parameters
    ----------
    plant : Plant
        The satellite.

    Returns
    -------
    list of str
        One name per coordinate, in state order.
    """
    return plant.dof_names()


@dataclass(frozen=True)
class Mode:
    """One mode of the coupled system (1-based ``index``, ascending frequency).

    Attributes
    ----------
    index : int
        1-based rank of the mode by frequency.
    frequency_hz : float
        Natural frequency [Hz] (0 for a rigid-body mode).
    kind : str
        ``"rigid"`` or the dominant joint motion (``"flapping"``, ``"torsion"``...).
    symmetry : str
        Mirror parity of the shape: ``"symmetric"``, ``"antisymmetric"`` or ``"none"``.
    dominant_dofs : list of str
        The coordinates with the largest mass-weighted amplitude.
    hub_dof : str or None
        The hub coordinate the mode drives most; None if it leaves the hub at rest.
    """

    index: int
    frequency_hz: float
    kind: str
    symmetry: str
    dominant_dofs: list[str]
    hub_dof: str | None

    def to_dict(self) -> dict:
        return {
            "index": self.index,
            "frequency_hz": self.frequency_hz,
            "kind": self.kind,
            "symmetry": self.symmetry,
            "dominant_dofs": self.dominant_dofs,
            "hub_dof": self.hub_dof,
        }


@dataclass(frozen=True)
class ModalAnalysis:
    """Result of :func:`modal_analysis`.

    Attributes
    ----------
    plant : Plant
        The plant analysed.
    mass_matrix : ndarray, shape (n_dof, n_dof)
        M(0), the mass matrix at rest (eq. 3.2) [SI: kg, kg m, kg m^2].
    stiffness_matrix : ndarray, shape (n_dof, n_dof)
        K, the joint stiffness matrix (eq. 3.2) [SI: N/m, N m/rad].
    frequencies_hz : ndarray, shape (n_dof,)
        Natural frequencies, ascending; the rigid-body modes (the hub's six, plus one per
        free joint such as a drive's angle) are exactly 0 [Hz].
    shapes : ndarray, shape (n_dof, n_dof)
        Mass-normalized mode shapes in columns (phi^T M phi = 1) [SI / sqrt(kg)].
    participation : ndarray, shape (n_dof, n_dof)
        Mass-weighted amplitudes ‖phi_j‖ sqrt(M_jj), each column scaled to max 1:
        the modal interaction map (thesis fig. 3.2) [-].
    modes : list of Mode
        Classification of each mode, in the order of ``frequencies_hz``.
    dof_names : list of str
        Name of each generalized coordinate (rows of ``shapes``).
    """

    plant: Plant
    mass_matrix: np.ndarray
    stiffness_matrix: np.ndarray
    frequencies_hz: np.ndarray
    shapes: np.ndarray
    participation: np.ndarray
    modes: list[Mode]
    dof_names: list[str] = field(default_factory=list)

    def to_dict(self) -> dict:
        """JSON-ready summary (SI units, frequencies in Hz)."""
        return {
            "config_name": self.plant.config.name,
            "dof_names": self.dof_names,
            "mass_matrix": self.mass_matrix.tolist(),
            "stiffness_diag": np.diag(self.stiffness_matrix).tolist(),
            "damping_diag": np.diag(self.plant.damping_matrix()).tolist(),
            "frequencies_hz": self.frequencies_hz.tolist(),
            "modes": [m.to_dict() for m in self.modes],
            "rigid_inertia": rigid_inertia(self.plant).tolist(),
            "mode_shapes": self.shapes.T.tolist(),
            "modal_damping_ratios": self.damping_ratios().tolist(),
            "effective_masses": effective_mass_table(self.plant),
        }

    def damping_ratios(self) -> np.ndarray:
        """Modal damping ratio of each coupled mode, shape (n_dof,): the diagonal of
        phi^T C phi / 2 omega (0 for the rigid-body modes) [-]."""
        C = self.plant.damping_matrix()
        omega = 2.0 * np.pi * self.frequencies_hz
        modal = np.sum(self.shapes * (C @ self.shapes), axis=0)  # diag(phi^T C phi)
        return np.where(omega > 0.0, modal / np.where(omega > 0.0, 2.0 * omega, 1.0), 0.0)


_DIRECTIONS = ("x", "y", "z", "rx", "ry", "rz")


def effective_masses(plant: Plant) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Modal effective masses and inertias of the hub-fixed appendage modes, 6 directions.

    As :func:`flexsat.linear.frequency.effective_inertia` (which reads it from here,
    as does :func:`effective_mass_table`), for every hub direction: translations x, y, z
    (L_k,a^2 [kg]) and rotations about the hub centre of mass x, y, z ([kg m^2]).

    Parameters
    ----------
    plant : Plant
        The satellite.

    Returns
    -------
    frequencies_hz : ndarray, shape (n_flex,)
        Frequencies of the hub-fixed appendage modes, ascending [Hz].
    effective : ndarray, shape (n_flex, 6)
        L_k,a^2 per mode and direction [kg] x 3, [kg m^2] x 3.
    residual : ndarray, shape (6,)
        diag(M_hh - M_hf M_ff^-1 M_fh), what no mode carries [kg] x 3, [kg m^2] x 3.
    """
    M0 = plant.mass_matrix()
    K = plant.stiffness_matrix()
    M_ff, M_fh, K_ff = M0[6:, 6:], M0[6:, :6], K[6:, 6:]
    omega2, phi = eigh(K_ff, M_ff)
    L = phi.T @ M_fh
    residual = M0[:6, :6] - M_fh.T @ np.linalg.solve(M_ff, M_fh)
    return np.sqrt(np.clip(omega2, 0.0, None)) / (2 * np.pi), L**2, np.diag(residual).copy()


def effective_mass_table(plant: Plant) -> dict:
    """The hub-fixed appendage modes' effective masses and inertias (JSON-ready).

    Per mode and hub direction (x, y, z [kg]; rx, ry, rz about the hub centre of mass
    [kg m^2]), with the cumulative fraction of the satellite's total in that direction
    (diag of M(0) at the hub: total mass, locked inertia; modes plus residual), see
    :func:`effective_masses`.

    Parameters
    ----------
    plant : Plant
        The satellite.

    Returns
    -------
    dict
        Plain lists and numbers, ready for ``json.dumps``.
    """
    frequencies, effective, residual = effective_masses(plant)
    total = effective.sum(axis=0) + residual
    cumulative = np.cumsum(effective, axis=0) / np.where(total > 0.0, total, 1.0)
    return {
        "directions": list(_DIRECTIONS),
        "units": ["kg"] * 3 + ["kg m^2"] * 3,
        "frequencies_hz": frequencies.tolist(),
        "effective": effective.tolist(),
        "cumulative_fraction": cumulative.tolist(),
        "residual": residual.tolist(),
        "total": total.tolist(),
    }


# Relative residual |K phi - lambda M phi| / |lambda M phi| allowed for a flexible mode: it
# bounds the relative error of lambda, so the frequency is good to about 5e-5 (the
# nominal satellite: 3e-11).
_RESIDUAL_MAX = 1e-4


def _rigid_count(K: np.ndarray) -> int:
    """The rigid-body modes: K_sys's zero rows, the hub's six and each free joint's (a
    solar-array drive's angle: no stiffness, a mechanism)."""
    return int(np.count_nonzero(~np.any(K != 0.0, axis=1)))


def _check_conditioning(K, M0, eigenvalues, shapes, n_rigid: int = 6) -> None:
    """Refuse flexible modes that round-off has destroyed (reported as 0 Hz or wrong)."""
    flexible = slice(n_rigid, None)
    lam, phi = eigenvalues[flexible], shapes[:, flexible]
    scale = np.abs(eigenvalues).max()
    residual = np.linalg.norm(K @ phi - (M0 @ phi) * lam, axis=0)
    size = np.linalg.norm((M0 @ phi) * lam, axis=0)
    bad = (lam <= 1e-12 * scale) | ~(residual <= _RESIDUAL_MAX * np.maximum(size, 1e-300))
    if bad.any():
        ratio = K.diagonal()[K.diagonal() > 0]
        spread = np.log10(ratio.max() / ratio.min()) if ratio.size else float("nan")
        raise SimulationError(
            f"modal analysis ill-conditioned: {int(bad.sum())} flexible mode(s) cannot be "
            f"resolved in double precision (the joint stiffnesses span {spread:.0f} orders "
            "of magnitude); bring the target frequencies and masses closer together"
        )


def modal_analysis(plant: Plant) -> ModalAnalysis:
    """Modes of the coupled satellite linearized at q = 0, q_dot = 0 (eqs. 3.2-3.4).

    Parameters
    ----------
    plant : Plant
        The satellite.

    Returns
    -------
    ModalAnalysis

    Raises
    ------
    SimulationError
        If the eigenproblem is too ill-conditioned for the flexible frequencies
        to be trusted (a flexible mode computed as zero or with a large residual).
    """
    M0 = plant.mass_matrix()
    K = plant.stiffness_matrix()
    eigenvalues, shapes = eigh(K, M0)
    n_rigid = _rigid_count(K)  # six, plus one per free joint (a drive)
    _check_conditioning(K, M0, eigenvalues, shapes, n_rigid)
    eigenvalues[:n_rigid] = 0.0  # K_sys's zero rows: the rigid-body modes
    frequencies = np.sqrt(np.clip(eigenvalues, 0.0, None)) / (2.0 * np.pi)
    weighted = np.abs(shapes) * np.sqrt(np.diag(M0))[:, None]
    participation = weighted / weighted.max(axis=0, keepdims=True)
    names = dof_names(plant)
    mirror = mirror_operator(plant)
    paired = _paired_coordinates(plant)
    kinds = _coordinate_kinds(plant)
    modes = []
    for k in range(plant.n_dof):
        phi = shapes[:, k]
        rigid = k < n_rigid
        order = np.argsort(-participation[:, k])
        modes.append(
            Mode(
                index=k + 1,
                frequency_hz=float(frequencies[k]),
                kind="rigid" if rigid else _kind(plant, phi, kinds),
                symmetry="none" if rigid else _symmetry(phi, M0, mirror, paired),
                dominant_dofs=[names[j] for j in order if participation[j, k] >= _DOMINANT_MIN],
                hub_dof=None if rigid else _hub_dof(participation[:, k]),
            )
        )
    return ModalAnalysis(
        plant=plant,
        mass_matrix=M0,
        stiffness_matrix=K,
        frequencies_hz=frequencies,
        shapes=shapes,
        participation=participation,
        modes=modes,
        dof_names=names,
    )


def _coordinate_kinds(plant: Plant) -> list[str]:
    """The kind of each appendage coordinate, as its model labels it."""
    return [k for app, m in zip(plant.config.appendages, plant.models, strict=True)
            for k in m.mode_kinds(app)]  # fmt: skip


def _kind(plant: Plant, phi: np.ndarray, kinds: list[str] | None = None) -> str:
    """The kind (each model labels its coordinates) holding most of the strain energy;
    ``kinds``: :func:`_coordinate_kinds`, computed once for every mode of a plant."""
    strain = plant.stiffness * phi[6:] ** 2
    kinds = _coordinate_kinds(plant) if kinds is None else kinds
    energy: dict[str, float] = {}
    for dof, kind in enumerate(kinds):
        energy[kind] = energy.get(kind, 0.0) + strain[dof]
    return max(energy, key=energy.get)


def _paired_coordinates(plant: Plant) -> np.ndarray | None:
    """Mask over q of the coordinates of appendages with a mirror partner other than
    themselves (None without a mirror symmetry)."""
    partners = mirror_partners(plant)
    if partners is None:
        return None
    mask = np.zeros(plant.n_dof, dtype=bool)
    for i, j in enumerate(partners):
        mask[plant.layout.blocks[i].slice] = i != j
    return mask


def _symmetry(phi: np.ndarray, M0: np.ndarray, mirror: np.ndarray | None,
              paired: np.ndarray | None) -> str:  # fmt: skip
    """The mode's mirror parity, if the mirror pairs carry it (:data:`_PAIRED_MIN`)."""
    if mirror is None or paired is None:
        return "none"
    motion = (phi * np.sqrt(np.diag(M0))) ** 2  # squared mass-weighted amplitudes
    appendages = motion[6:].sum()
    if appendages > 0.0 and motion[paired].sum() < _PAIRED_MIN * appendages:
        return "none"  # mostly appendages that are their own image: no pair moves
    parity = float(phi @ M0 @ (mirror @ phi)) / float(phi @ M0 @ phi)
    if parity >= _PARITY_MIN:
        return "symmetric"
    if parity <= -_PARITY_MIN:
        return "antisymmetric"
    return "none"


def _hub_dof(participation: np.ndarray) -> str | None:
    hub = participation[:6]
    j = int(np.argmax(hub))
    return HUB_DOFS[j] if hub[j] >= _HUB_COUPLING_MIN else None
