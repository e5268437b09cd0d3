"""Rotation matrices of intrinsic Euler sequences, without SciPy's rotations at import.

Importing :mod:`scipy.spatial.transform` loads :mod:`scipy.spatial` (its k-d trees,
:mod:`scipy.sparse`): about 0.25 s of every command's start-up. A plate is packed on
every plant build, and the one rotation it needs there, R_BM = Rz(yaw) Ry(alpha_sadm),
is an intrinsic Euler sequence. :class:`EulerRotation` builds it with the same
arithmetic as SciPy's ``Rotation.from_euler(seq, angles).as_matrix()`` for an
intrinsic ``seq`` (the elementary quaternions cos(a/2), sin(a/2) composed left to
right, then the quaternion's matrix, unnormalized): the same bits, which
``tests/dynamics/test_rotation.py`` checks against SciPy (docs/performance.md,
'Start-up').
"""

from __future__ import annotations

import itertools

import numpy as np

__all__ = ["EulerRotation", "euler_matrix"]

_AXES = "XYZ"


def _elementary(axis: int, angle: np.ndarray) -> np.ndarray:
    """Scalar-last quaternion of a rotation by ``angle`` [rad] about basis ``axis``."""
    quat = np.zeros((*angle.shape, 4))
    quat[..., 3] = np.cos(angle / 2.0)
    quat[..., axis] = np.sin(angle / 2.0)
    return quat


def _compose(p: np.ndarray, q: np.ndarray) -> np.ndarray:
    """Scalar-last quaternion product p (x) q (the rotation q, then p)."""
    cross = np.cross(p[..., :3], q[..., :3])
    qx = p[..., 3] * q[..., 0] + q[..., 3] * p[..., 0] + cross[..., 0]
    qy = p[..., 3] * q[..., 1] + q[..., 3] * p[..., 1] + cross[..., 1]
    qz = p[..., 3] * q[..., 2] + q[..., 3] * p[..., 2] + cross[..., 2]
    qw = (
        p[..., 3] * q[..., 3]
        - p[..., 0] * q[..., 0]
        - p[..., 1] * q[..., 1]
        - p[..., 2] * q[..., 2]
    )
    return np.stack([qx, qy, qz, qw], axis=-1)


def _matrix(quat: np.ndarray) -> np.ndarray:
    """Rotation matrix of a scalar-last unit quaternion, shape (..., 3, 3)."""
    x, y, z, w = quat[..., 0], quat[..., 1], quat[..., 2], quat[..., 3]
    x2, y2, z2, w2 = x * x, y * y, z * z, w * w
    xy, zw, xz, yw, yz, xw = x * y, z * w, x * z, y * w, y * z, x * w
    elements = [
        x2 - y2 - z2 + w2, 2 * (xy - zw), 2 * (xz + yw),
        2 * (xy + zw), -x2 + y2 - z2 + w2, 2 * (yz - xw),
        2 * (xz - yw), 2 * (yz + xw), -x2 - y2 + z2 + w2,
    ]  # fmt: skip
    return np.stack(elements, axis=-1).reshape(*quat.shape[:-1], 3, 3)


def euler_matrix(seq: str, angles) -> np.ndarray:
    """R = R_a1(angles[0]) R_a2(angles[1]) ... of an intrinsic Euler sequence.

    Parameters
    ----------
    seq : str
        One to three intrinsic axes from ``"XYZ"``, no axis twice in a row
        (``"ZYX"``: R = Rz(angles[0]) Ry(angles[1]) Rx(angles[2])).
    angles : array_like, shape (..., len(seq))
        The angles [rad]; a single rotation's may be a scalar when ``seq`` has one axis.

    Returns
    -------
    ndarray, shape (..., 3, 3)
        The rotation matrices [-], bit for bit SciPy's
        ``Rotation.from_euler(seq, angles).as_matrix()``.

    Raises
    ------
    ValueError
        If ``seq`` is not an intrinsic sequence of one to three axes or ``angles``
        does not have one angle per axis.
    """
    if not 1 <= len(seq) <= 3 or any(c not in _AXES for c in seq):
        raise ValueError(f"seq must be 1 to 3 intrinsic axes from 'XYZ', got {seq!r}")
    if any(a == b for a, b in itertools.pairwise(seq)):
        raise ValueError(f"seq must not repeat an axis consecutively, got {seq!r}")
    angles = np.asarray(angles, dtype=float)
    angles = angles.reshape(1) if angles.ndim == 0 else angles
    if angles.shape[-1] != len(seq):
        raise ValueError(f"angles must end with {len(seq)} angles for {seq!r}, "
                         f"got shape {angles.shape}")  # fmt: skip
    quat = _elementary(_AXES.index(seq[0]), angles[..., 0])
    for k in range(1, len(seq)):
        quat = _compose(quat, _elementary(_AXES.index(seq[k]), angles[..., k]))
    return _matrix(quat)


class EulerRotation:
    """The rotation of an intrinsic Euler sequence, with SciPy's ``Rotation`` calls.

    Only ``EulerRotation.from_euler(seq, angles).as_matrix()``: what a module that
    packs a configuration needs, without importing :mod:`scipy.spatial`.

    Parameters
    ----------
    matrix : ndarray, shape (..., 3, 3)
        The rotation matrices [-].
    """

    def __init__(self, matrix: np.ndarray) -> None:
        self._matrix = matrix

    @classmethod
    def from_euler(cls, seq: str, angles) -> EulerRotation:
        """The rotation R = R_a1(angles[0]) R_a2(angles[1]) ... (:func:`euler_matrix`).

        Parameters
        ----------
        seq : str
            One to three intrinsic axes from ``"XYZ"``.
        angles : array_like, shape (..., len(seq))
            The angles [rad].

        Returns
        -------
        EulerRotation
        """
        return cls(euler_matrix(seq, angles))

    def as_matrix(self) -> np.ndarray:
        """The rotation matrices, shape (..., 3, 3) [-]."""
        return self._matrix.copy()
