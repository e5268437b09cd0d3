"""Drawable geometry of the satellite at any generalized-coordinate vector.

:func:`satellite_geometry` turns a plant and a vector ``q`` (layout of
:mod:`flexsat.dynamics.kernels`) into points and polylines in the inertial frame
N, ready to be drawn or animated: the hub outline, the massless arms from the hub
surface to the appendage roots, each panel as a rectangle, the panel tips and the
hub body axes. Pure numpy, no plotting; every array is in metres, frame N.

Kinematics (exact, no small-angle approximation): a point ``x_P`` of panel ``i``
given in its panel frame P_i sits in the hub frame B at
``r_m + R_BM (eta + R_MP x_P)`` and in N at ``r + R_NB (that)``, with
``R_NB = Rz(psi) Ry(theta) Rx(phi)`` and ``R_MP = Rz(rho_z) Ry(rho_y) Rx(rho_x)``.

The number of polylines and their sizes depend on the plant only, never on ``q``,
so an animation can create its artists once and update their data per frame.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.spatial.transform import Rotation

from flexsat.dynamics.plant import Plant

__all__ = [
    "HubOutline",
    "SatelliteGeometry",
    "hub_outline",
    "panel_corners_local",
    "rot_zyx",
    "satellite_geometry",
]

_CIRCLE_POINTS = 49  # points per hub circle, closed (first == last)
_GENERATORS = 8  # vertical lines on the hub cylinder
_AXIS_SCALE = 2.0  # body-axis length in units of the hub's largest half-size


def rot_zyx(angles: np.ndarray) -> np.ndarray:
    """Rotation matrices Rz(a2) Ry(a1) Rx(a0), vectorized over leading dimensions.

    Parameters
    ----------
    angles : array_like, shape (..., 3)
        ZYX Euler angles (about X, about Y, about Z) [rad], in the order of the
        generalized coordinates (phi, theta, psi) or (rho_x, rho_y, rho_z).

    Returns
    -------
    ndarray, shape (..., 3, 3)
        Child (body) components -> parent components [-]; the same matrix as
        :func:`flexsat.compiled.linalg3.rot_zyx`.
    """
    a = np.asarray(angles, dtype=float)
    flat = Rotation.from_euler("ZYX", a.reshape(-1, 3)[:, ::-1]).as_matrix()
    return flat.reshape(*a.shape[:-1], 3, 3)


@dataclass(frozen=True)
class HubOutline:
    """Wireframe of the hub in its own frame B (see :func:`hub_outline`).

    Attributes
    ----------
    kind : {"cylinder", "box"}
        ``cylinder`` for a hub given by radius and height; ``box`` for the
        inertia-equivalent uniform box of a hub given by an explicit inertia.
    lines : tuple of ndarray, each shape (k, 3)
        Polylines in hub frame B [m].
    half_size : float
        Largest distance of the outline from the hub centre along a B or
        principal axis [m]; sets the body-axis length.
    """

    kind: str
    lines: tuple[np.ndarray, ...]
    half_size: float
    _radius: float = 0.0
    _half_height: float = 0.0
    _principal: np.ndarray | None = None  # (3, 3) columns: box axes in B
    _half_extent: np.ndarray | None = None  # (3,) box half-sides [m]

    def clip_ray(self, p: np.ndarray) -> np.ndarray:
        """Where the ray from the hub centre towards ``p`` (frame B) leaves the hub.

        Returns ``p`` itself when ``p`` lies inside the hub. Shape (3,) [m].
        """
        p = np.asarray(p, dtype=float)
        with np.errstate(divide="ignore"):
            if self.kind == "cylinder":
                t = min(
                    self._radius / np.hypot(p[0], p[1]),
                    self._half_height / abs(p[2]),
                )
            else:
                u = np.abs(self._principal.T @ p)
                t = float(np.min(self._half_extent / u))
        return p * t if t < 1.0 else p.copy()


def hub_outline(plant: Plant) -> HubOutline:
    """Wireframe of the hub in hub frame B.

    A hub configured by ``radius_m`` and ``height_m`` is drawn as that cylinder about
    Z_B, centred on the hub centre of mass: top and bottom circles plus eight
    generators. A hub configured by an explicit ``inertia_kg_m2`` has no shape of
    its own; it is drawn as the homogeneous box of the same mass and inertia,
    aligned with the principal axes, with side ``a_k`` along principal axis ``k``
    from ``a_k^2 = 6 (J_1 + J_2 + J_3 - 2 J_k) / m`` (the top and bottom faces
    and the four vertical edges, "vertical" being the principal axis closest to
    Z_B).

    Parameters
    ----------
    plant : Plant
        The satellite.

    Returns
    -------
    HubOutline
    """
    hub = plant.config.hub
    if hub.inertia_kg_m2 is None:
        r, h2 = float(hub.radius_m), 0.5 * float(hub.height_m)
        ang = np.linspace(0.0, 2.0 * np.pi, _CIRCLE_POINTS)
        ring = np.column_stack([r * np.cos(ang), r * np.sin(ang), np.zeros_like(ang)])
        lines = [ring + np.array([0.0, 0.0, z]) for z in (h2, -h2)]
        for a in np.linspace(0.0, 2.0 * np.pi, _GENERATORS, endpoint=False):
            x, y = r * np.cos(a), r * np.sin(a)
            lines.append(np.array([[x, y, h2], [x, y, -h2]]))
        return HubOutline("cylinder", tuple(lines), max(r, h2), _radius=r, _half_height=h2)

    moments, axes = np.linalg.eigh(np.array(hub.inertia_kg_m2, dtype=float))
    sides2 = 6.0 * (moments.sum() - 2.0 * moments) / float(hub.mass_kg)
    half = 0.5 * np.sqrt(np.clip(sides2, 0.0, None))
    # Order the box axes so the last is the one closest to Z_B ("vertical").
    up = int(np.argmax(np.abs(axes[2, :])))
    order = [k for k in range(3) if k != up] + [up]
    axes, half = axes[:, order], half[order]
    square = np.array([[-1, -1], [1, -1], [1, 1], [-1, 1], [-1, -1]], dtype=float)
    lines = []
    for sz in (1.0, -1.0):
        local = np.column_stack([square * half[:2], np.full(5, sz * half[2])])
        lines.append(local @ axes.T)
    for sx, sy in square[:4]:
        local = np.array([[sx * half[0], sy * half[1], s * half[2]] for s in (1.0, -1.0)])
        lines.append(local @ axes.T)
    return HubOutline("box", tuple(lines), float(half.max()), _principal=axes, _half_extent=half)


@dataclass(frozen=True)
class SatelliteGeometry:
    """Drawable geometry of the satellite in the inertial frame N (all in metres).

    Attributes
    ----------
    centre : ndarray, shape (3,)
        Hub centre of mass, q[0:3] [m].
    R_NB : ndarray, shape (3, 3)
        Hub attitude, hub frame B -> N [-].
    hub_kind : {"cylinder", "box"}
        How the hub is drawn (see :func:`hub_outline`).
    hub_lines : tuple of ndarray, each shape (k, 3)
        Hub wireframe polylines [m].
    arms : ndarray, shape (n, 2, 3)
        Massless arm of each appendage: from the hub surface (where the ray from
        the hub centre to the mount point leaves the hub) to the displaced root [m].
    roots : ndarray, shape (n, 3)
        Panel roots (origin of P_i) [m].
    panels : ndarray, shape (k, 4, 3)
        Drawn quadrilaterals, each appendage's in config order (one per thesis plate,
        one per segment of a chain: the model's ``outlines``). For the thesis plate:
        root at -W/2, root at +W/2, tip at +W/2, tip at -W/2 (chord along X_P); a
        closed loop when the first is repeated [m].
    tips : ndarray, shape (n, 3)
        Panel tips (mid-chord of the free edge) [m].
    axes : ndarray, shape (3, 3)
        Row k is the hub body axis k (X_B, Y_B, Z_B) as a vector from ``centre``,
        scaled to a length proportional to the hub size [m].
    """

    centre: np.ndarray
    R_NB: np.ndarray
    hub_kind: str
    hub_lines: tuple[np.ndarray, ...]
    arms: np.ndarray
    roots: np.ndarray
    panels: np.ndarray
    tips: np.ndarray
    axes: np.ndarray

    @property
    def n_appendages(self) -> int:
        return int(self.roots.shape[0])

    def points(self) -> np.ndarray:
        """Every drawn point (hub, arms, panels, axis ends), shape (m, 3) [m]."""
        return np.concatenate(
            [
                *self.hub_lines,
                self.arms.reshape(-1, 3),
                self.panels.reshape(-1, 3),
                self.centre + self.axes,
                self.centre[None, :],
            ]
        )

    def bounds(self) -> tuple[np.ndarray, np.ndarray]:
        """Lower and upper corners of the axis-aligned bounding box, each (3,) [m]."""
        pts = self.points()
        return pts.min(axis=0), pts.max(axis=0)


def panel_corners_local(plant: Plant) -> np.ndarray:
    """Outline corners of each appendage, undeformed, hub frame B, shape (n, 4, 3) [m].

    Each model draws itself (``shape_points``); for the thesis plate the corners span
    0..L along +Y_P or -Y_P from its root and -W/2..W/2 along X_P (its mid-plane).

    Parameters
    ----------
    plant : Plant
        The satellite.

    Returns
    -------
    ndarray, shape (n, 4, 3)
        Corners of each appendage's outline, hub frame B [m].
    """
    return _shape_points(plant, np.zeros(plant.n_dof))[:, 0:4, :]


def _shape_points(plant: Plant, q: np.ndarray) -> np.ndarray:
    """Each appendage's drawable points at q, hub frame B, shape (n, 6, 3) [m]."""
    rows = zip(plant.config.appendages, plant.models, plant.params, plant.layout.blocks,
               strict=True)  # fmt: skip
    return np.stack([m.shape_points(app, p, q[b.slice]) for app, m, p, b in rows])


def _outlines(plant: Plant, q: np.ndarray) -> np.ndarray:
    """Every drawn quadrilateral at q, hub frame B, shape (k, 4, 3) [m]."""
    rows = zip(plant.config.appendages, plant.models, plant.params, plant.layout.blocks,
               strict=True)  # fmt: skip
    return np.concatenate([m.outlines(app, p, q[b.slice]) for app, m, p, b in rows])


def satellite_geometry(plant: Plant, q: np.ndarray | None = None) -> SatelliteGeometry:
    """Geometry of the satellite at generalized coordinates ``q``, frame N.

    Parameters
    ----------
    plant : Plant
        Any number of appendages.
    q : array_like, shape (plant.n_dof,), optional
        Generalized coordinates [m, rad] (layout of
        :mod:`flexsat.dynamics.kernels`); ``None`` is the undeformed satellite at
        the origin, q = 0.

    Returns
    -------
    SatelliteGeometry
    """
    q = np.zeros(plant.n_dof) if q is None else np.asarray(q, dtype=float)
    if q.shape != (plant.n_dof,):
        raise ValueError(f"expected q of shape ({plant.n_dof},), got {q.shape}")
    n = plant.n_appendages
    centre = q[0:3].copy()
    R_NB = rot_zyx(q[3:6])

    def to_n(points_b: np.ndarray) -> np.ndarray:  # (..., 3) in B -> N
        return centre + points_b @ R_NB.T

    pts = to_n(_shape_points(plant, q))  # corners, root, tip of each appendage
    outline = hub_outline(plant)
    rest_roots = _shape_points(plant, np.zeros(plant.n_dof))[:, 4, :]
    anchors = np.array([outline.clip_ray(p) for p in rest_roots]).reshape(n, 3)
    arms = np.stack([to_n(anchors), pts[:, 4, :]], axis=1)
    return SatelliteGeometry(
        centre=centre,
        R_NB=R_NB,
        hub_kind=outline.kind,
        hub_lines=tuple(to_n(line) for line in outline.lines),
        arms=arms,
        roots=pts[:, 4, :].copy(),
        panels=to_n(_outlines(plant, q)),
        tips=pts[:, 5, :].copy(),
        axes=_AXIS_SCALE * outline.half_size * R_NB.T,
    )
