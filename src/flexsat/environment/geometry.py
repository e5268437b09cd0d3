"""The satellite as the environment sees it: mass elements, surfaces, and how their loads
reach each appendage's coordinates.

Built once per run from the plant, undeformed (docs/environment.md, 'Appendage loads'):

- the hub: its inertia (the gravity gradient's hub term) and, for a cylinder hub
  (``radius_m``, ``height_m``), its two end discs and ``hub_facets`` flat faces
  around its side;
- each appendage: every quadrilateral its model draws (``AppendageModel.outlines``:
  the plate's panel, each segment of a chain) cut into ``cells_per_side`` x
  ``cells_per_side`` cells; each cell is a mass element (the appendage's mass spread
  uniformly over its area, placed so the cells keep the quadrilateral's first and
  second moments of area) and a surface on each side (front: the outline's winding
  normal; back: the opposite);
- a model whose outline has no area (a modal appendage drawn as a segment) is one mass
  element at its centre of mass, carried by the hub (its loads act on the hub as on a
  rigid attachment, its modes take none).

A load point of an appendage carries G_k (3 x count), the derivative of its position
(frame B) with respect to the appendage's coordinates at rest, so that a force F_k on
it is the generalized force G_k^T F_k on those coordinates (virtual work). It is
evaluated by central differences of the model's own outline: every model, built-in
or a user's, gets its loads mapped without code of its own.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from flexsat.environment.registry import (
    SURF_AREA,
    SURF_CENTRE,
    SURF_DIFFUSE,
    SURF_DRAG,
    SURF_NORMAL,
    SURF_SPECULAR,
    SURFACE_SIZE,
)

__all__ = ["LoadGeometry", "load_geometry"]

_STEP = 1e-6  # central-difference step of G_k [m, rad or the coordinate's unit]


@dataclass(frozen=True)
class LoadGeometry:
    """Load points of the satellite, hub frame B (module docstring).

    Attributes
    ----------
    points : ndarray, shape (k, 4)
        Mass elements: position from the hub centre of mass [m], mass [kg].
    surfaces : ndarray, shape (s, SURFACE_SIZE)
        Surfaces (``SURF_*`` slots of :mod:`flexsat.environment.registry`): centre [m],
        unit normal [-], area [m^2], optical fractions and drag coefficient [-].
    positions : ndarray, shape (k + s, 3)
        Where each load acts: the mass elements, then the surfaces' centres [m].
    owner : ndarray, shape (k + s, 2), int64
        Per load point, the offset in q of its appendage's first coordinate and their
        count; (-1, 0) for a point carried by the hub [-].
    jacobian : ndarray, shape (k + s, 3, c)
        G_k, c the largest coordinate count [m per coordinate unit].
    hub_inertia : ndarray, shape (3, 3)
        The hub's inertia about its centre of mass, frame B [kg m^2].
    appendage : ndarray, shape (k + s,), int64
        The appendage index of each load point, -1 for the hub [-].
    """

    points: np.ndarray
    surfaces: np.ndarray
    positions: np.ndarray
    owner: np.ndarray
    jacobian: np.ndarray
    hub_inertia: np.ndarray
    appendage: np.ndarray


def _surface(centre, normal, area, optics) -> np.ndarray:
    row = np.zeros(SURFACE_SIZE)
    row[SURF_CENTRE : SURF_CENTRE + 3] = centre
    row[SURF_NORMAL : SURF_NORMAL + 3] = normal
    row[SURF_AREA] = area
    row[SURF_SPECULAR], row[SURF_DIFFUSE] = optics.specular, optics.diffuse
    row[SURF_DRAG] = optics.drag_coefficient
    return row


def _hub_surfaces(hub, facets: int, optics) -> list[np.ndarray]:
    """The cylinder's end discs and side faces (none for a hub given by its inertia)."""
    if hub.radius_m is None or hub.height_m is None:
        return []
    r, h = hub.radius_m, hub.height_m
    rows = [_surface((0, 0, 0.5 * h), (0, 0, 1), np.pi * r * r, optics),
            _surface((0, 0, -0.5 * h), (0, 0, -1), np.pi * r * r, optics)]  # fmt: skip
    half = np.pi / facets
    for i in range(facets):
        phi = 2.0 * half * i
        n = np.array([np.cos(phi), np.sin(phi), 0.0])
        rows.append(_surface(r * np.cos(half) * n, n, 2.0 * r * np.sin(half) * h, optics))
    return rows


def _cells(quad: np.ndarray, n: int) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Cell parameters (u, v) of an n x n cut, the mass-element parameters (moments kept),
    and the cells' areas and front normals for a quadrilateral (4, 3)."""
    centres = (np.arange(n) + 0.5) / n
    spread = 0.5 + (centres - 0.5) / np.sqrt(1.0 - 1.0 / n**2) if n > 1 else centres
    u, v = np.meshgrid(centres, centres, indexing="ij")
    um, vm = np.meshgrid(spread, spread, indexing="ij")
    du = (1 - v)[..., None] * (quad[1] - quad[0]) + v[..., None] * (quad[2] - quad[3])
    dv = (1 - u)[..., None] * (quad[3] - quad[0]) + u[..., None] * (quad[2] - quad[1])
    cross = np.cross(du, dv) / n**2
    area = np.linalg.norm(cross, axis=-1)
    normal = cross / np.where(area > 0, area, 1.0)[..., None]
    uv = np.stack([u.ravel(), v.ravel()], axis=1)
    uvm = np.stack([um.ravel(), vm.ravel()], axis=1)
    return uv, uvm, area.ravel(), normal.reshape(-1, 3)


def _bilinear(quads: np.ndarray, seg: np.ndarray, uv: np.ndarray) -> np.ndarray:
    """Points of the quadrilaterals ``quads[seg]`` at parameters ``uv`` (m, 2)."""
    q = quads[seg]
    u, v = uv[:, :1], uv[:, 1:]
    return (1 - u) * (1 - v) * q[:, 0] + u * (1 - v) * q[:, 1] + u * v * q[:, 2] + (
        (1 - u) * v * q[:, 3])  # fmt: skip


def load_geometry(plant, config) -> LoadGeometry:
    """The load points of a plant (module docstring).

    Parameters
    ----------
    plant : flexsat.dynamics.plant.Plant
        The satellite.
    config : flexsat.environment.config.EnvironmentConfig
        The surfaces' optics, the cells per panel side and the hub's facets.

    Returns
    -------
    LoadGeometry
        Mass elements, surfaces and their maps onto the coordinates, frame B.
    """
    n = config.cells_per_side
    optics = config.surfaces
    points, p_owner, p_jac, p_app = [], [], [], []
    surfaces = _hub_surfaces(plant.config.hub, config.hub_facets, optics.hub)
    s_owner = [(-1, 0)] * len(surfaces)
    s_jac = [np.zeros((3, 0))] * len(surfaces)
    s_app = [-1] * len(surfaces)
    rows = zip(plant.config.appendages, plant.models, plant.params, plant.layout.blocks,
               strict=True)  # fmt: skip
    for index, (app, model, params, block) in enumerate(rows):
        count = block.count
        quads = model.outlines(app, params, np.zeros(count))
        cut = [_cells(quad, n) for quad in quads]
        total = sum(float(c[2].sum()) for c in cut)
        body = model.rigid_body(params)
        if total <= 0.0:  # drawn without area: one element on the hub
            points.append([*body.r_B, body.mass])
            p_owner.append((-1, 0))
            p_jac.append(np.zeros((3, 0)))
            p_app.append(index)
            continue
        seg = np.concatenate([np.full(len(c[0]), k) for k, c in enumerate(cut)])
        uv = np.concatenate([c[0] for c in cut])
        uvm = np.concatenate([c[1] for c in cut])
        area = np.concatenate([c[2] for c in cut])
        normal = np.concatenate([c[3] for c in cut])

        def jacobian(at: np.ndarray, model=model, app=app, params=params, count=count,
                     seg=seg) -> np.ndarray:  # fmt: skip
            G = np.zeros((len(at), 3, count))
            for j in range(count):
                dq = np.zeros(count)
                dq[j] = _STEP
                plus = _bilinear(model.outlines(app, params, dq), seg, at)
                minus = _bilinear(model.outlines(app, params, -dq), seg, at)
                G[:, :, j] = (plus - minus) / (2.0 * _STEP)
            return G

        mass_points = _bilinear(quads, seg, uvm)
        centres = _bilinear(quads, seg, uv)
        G_mass, G_cell = jacobian(uvm), jacobian(uv)
        for i in range(len(area)):
            points.append([*mass_points[i], body.mass * area[i] / total])
            p_owner.append((block.offset, count))
            p_jac.append(G_mass[i])
            p_app.append(index)
            for side, sign in ((optics.front, 1.0), (optics.back, -1.0)):
                surfaces.append(_surface(centres[i], sign * normal[i], area[i], side))
                s_owner.append((block.offset, count))
                s_jac.append(G_cell[i])
                s_app.append(index)
    pts = np.array(points, dtype=float).reshape(-1, 4)
    surf = np.array(surfaces, dtype=float).reshape(-1, SURFACE_SIZE)
    jac = p_jac + s_jac
    width = max([g.shape[1] for g in jac], default=0)
    G = np.zeros((len(jac), 3, max(width, 1)))
    for i, g in enumerate(jac):
        G[i, :, : g.shape[1]] = g
    positions = np.concatenate([pts[:, :3], surf[:, SURF_CENTRE : SURF_CENTRE + 3]])
    return LoadGeometry(
        points=np.ascontiguousarray(pts), surfaces=np.ascontiguousarray(surf),
        positions=np.ascontiguousarray(positions),
        owner=np.array(p_owner + s_owner, dtype=np.int64).reshape(-1, 2), jacobian=G,
        hub_inertia=np.ascontiguousarray(plant.config.hub.inertia()),
        appendage=np.array(p_app + s_app, dtype=np.int64),
    )  # fmt: skip
