"""Drawable satellite geometry: exact positions for known coordinates, any N."""

from __future__ import annotations

import numpy as np
import pytest

import flexsat.config
from flexsat.compiled import linalg3
from flexsat.config import validate_config
from flexsat.dynamics.plant import Plant
from flexsat.plots import hub_outline, rot_zyx, satellite_geometry

L, W, R_MOUNT = 4.5, 1.5, 0.8
TIP = R_MOUNT + L  # 5.3 m from the hub centre


@pytest.fixture(scope="module")
def plant() -> Plant:
    return Plant.from_config(flexsat.config.nominal())


def _q(plant: Plant, **entries: float) -> np.ndarray:
    """q with named entries: hub 'x'..'psi', or 'p<i>_<k>' for joint DOF k of appendage i."""
    names = ["x", "y", "z", "phi", "theta", "psi"]
    q = plant.zeros()
    for key, value in entries.items():
        if key in names:
            q[names.index(key)] = value
        else:
            i, k = key[1:].split("_")
            q[6 + 6 * (int(i) - 1) + int(k)] = value
    return q


def test_undeformed_tips_and_corners(plant: Plant) -> None:
    g = satellite_geometry(plant, plant.zeros())
    np.testing.assert_allclose(g.tips[0], [0.0, TIP, 0.0], rtol=0, atol=1e-12)
    np.testing.assert_allclose(g.tips[1], [0.0, -TIP, 0.0], rtol=0, atol=1e-12)
    np.testing.assert_allclose(g.roots, [[0.0, R_MOUNT, 0.0], [0.0, -R_MOUNT, 0.0]], atol=1e-12)
    # Corners: root -W/2, root +W/2, tip +W/2, tip -W/2 (chord along X_P = X_B here).
    for i, sign in enumerate((1.0, -1.0)):
        expected = [
            [-W / 2, sign * R_MOUNT, 0.0],
            [W / 2, sign * R_MOUNT, 0.0],
            [W / 2, sign * TIP, 0.0],
            [-W / 2, sign * TIP, 0.0],
        ]
        np.testing.assert_allclose(g.panels[i], expected, rtol=0, atol=1e-12)
    assert set(np.round(np.abs(g.panels[..., 0]), 12).ravel()) == {0.75}
    assert g.n_appendages == 2
    assert satellite_geometry(plant).tips.tolist() == g.tips.tolist()  # q=None is q=0


def test_hub_yaw_90_deg_turns_panel_1_tip_to_minus_x(plant: Plant) -> None:
    q = _q(plant, psi=np.pi / 2)
    g = satellite_geometry(plant, q)
    np.testing.assert_allclose(g.tips[0], [-TIP, 0.0, 0.0], atol=1e-12)
    np.testing.assert_allclose(g.tips[1], [TIP, 0.0, 0.0], atol=1e-12)
    # Same as R_NB = Rz(psi) Ry(theta) Rx(phi) of the kernels applied to the tip in B.
    R_NB = np.array(linalg3.rot_zyx(*q[3:6]))
    np.testing.assert_allclose(g.tips[0], R_NB @ [0.0, TIP, 0.0], atol=1e-12)
    np.testing.assert_allclose(g.R_NB, R_NB, atol=1e-15)
    np.testing.assert_allclose(g.axes[0] / np.linalg.norm(g.axes[0]), [0.0, 1.0, 0.0], atol=1e-12)


def test_in_plane_root_rotation_moves_tip_along_minus_x(plant: Plant) -> None:
    rho_z = 0.3
    g = satellite_geometry(plant, _q(plant, p1_5=rho_z))
    # R_MP = Rz(rho_z): the tip (0, L, 0)_P goes to (-L sin rho_z, L cos rho_z, 0)_M.
    np.testing.assert_allclose(
        g.tips[0], [-L * np.sin(rho_z), R_MOUNT + L * np.cos(rho_z), 0.0], atol=1e-12
    )
    assert g.tips[0, 0] < 0.0
    np.testing.assert_allclose(g.tips[1], [0.0, -TIP, 0.0], atol=1e-12)  # panel 2 untouched


def test_flapping_and_root_translation(plant: Plant) -> None:
    rho_x, eta_z = 0.2, 0.05
    g = satellite_geometry(plant, _q(plant, p1_3=rho_x, p2_2=eta_z))
    # Rx(rho_x) lifts the +Y tip: (0, L cos, L sin).
    np.testing.assert_allclose(
        g.tips[0], [0.0, R_MOUNT + L * np.cos(rho_x), L * np.sin(rho_x)], atol=1e-12
    )
    np.testing.assert_allclose(g.roots[1], [0.0, -R_MOUNT, eta_z], atol=1e-12)
    np.testing.assert_allclose(g.arms[1, 1], g.roots[1], atol=0)


def test_matches_kernel_tip_displacement(plant: Plant) -> None:
    rng = np.random.default_rng(3)
    q = plant.zeros()
    q[6:] = rng.normal(scale=0.2, size=plant.n_dof - 6)
    moved = satellite_geometry(plant, q).tips - satellite_geometry(plant).tips
    R_BM = np.stack([m.mount_rotation(p) for m, p in zip(plant.models, plant.params, strict=True)])
    in_hub = np.einsum("nij,nj->ni", R_BM, plant.tip_displacement(q))
    np.testing.assert_allclose(moved, in_hub, atol=1e-12)


def test_hub_pose_is_a_rigid_motion(plant: Plant) -> None:
    rng = np.random.default_rng(7)
    q = rng.normal(scale=0.3, size=plant.n_dof)
    g = satellite_geometry(plant, q)
    local = q.copy()
    local[:6] = 0.0
    g0 = satellite_geometry(plant, local)
    R = rot_zyx(q[3:6])
    for moved, rest in ((g.panels, g0.panels), (g.arms, g0.arms), (g.tips, g0.tips)):
        np.testing.assert_allclose(moved, q[0:3] + rest @ R.T, atol=1e-12)
    for moved, rest in zip(g.hub_lines, g0.hub_lines, strict=True):
        np.testing.assert_allclose(moved, q[0:3] + rest @ R.T, atol=1e-12)
    lo, hi = g.bounds()
    assert np.all(lo <= g.tips.min(axis=0)) and np.all(hi >= g.tips.max(axis=0))


def test_rot_zyx_matches_kernels() -> None:
    rng = np.random.default_rng(11)
    for angles in rng.uniform(-3.0, 3.0, size=(5, 3)):
        np.testing.assert_allclose(rot_zyx(angles), np.array(linalg3.rot_zyx(*angles)), atol=1e-15)
    assert rot_zyx(rng.normal(size=(4, 2, 3))).shape == (4, 2, 3, 3)


def test_cylinder_hub_and_arms(plant: Plant) -> None:
    g = satellite_geometry(plant)
    assert g.hub_kind == "cylinder"
    top, bottom = g.hub_lines[0], g.hub_lines[1]
    np.testing.assert_allclose(np.hypot(top[:, 0], top[:, 1]), 0.6, atol=1e-12)
    np.testing.assert_allclose(top[:, 2], 0.75, atol=1e-12)
    np.testing.assert_allclose(bottom[:, 2], -0.75, atol=1e-12)
    # Arms run from the hub surface (radius 0.6 m) to the roots (0.8 m).
    np.testing.assert_allclose(g.arms[0], [[0.0, 0.6, 0.0], [0.0, 0.8, 0.0]], atol=1e-12)
    np.testing.assert_allclose(g.arms[1], [[0.0, -0.6, 0.0], [0.0, -0.8, 0.0]], atol=1e-12)


def test_explicit_inertia_hub_is_drawn_as_the_equivalent_box() -> None:
    data = flexsat.config.nominal().model_dump()
    J = np.array([[60.0, 5.0, 0.0], [5.0, 41.6, 0.0], [0.0, 0.0, 27.0]])
    data["hub"] = {"mass_kg": 150.0, "inertia_kg_m2": J.tolist()}
    plant = Plant.from_config(validate_config(data))
    outline = hub_outline(plant)
    assert outline.kind == "box"
    corners = np.unique(np.round(np.concatenate(outline.lines), 12), axis=0)
    assert corners.shape == (8, 3)
    # A homogeneous box with these 8 corners has the hub's inertia: J = m/3 (diag sum
    # of half-extent squares - outer products) averaged over the corners.
    second = corners.T @ corners / 8.0  # = diag(h_k^2) in the box axes
    box_J = 150.0 / 3.0 * (np.trace(second) * np.eye(3) - second)
    np.testing.assert_allclose(box_J, J, rtol=1e-9, atol=1e-9)
    g = satellite_geometry(plant)
    assert g.hub_kind == "box"
    mounts = [m.mount_point(p) for m, p in zip(plant.models, plant.params, strict=True)]
    np.testing.assert_allclose(g.arms[:, 1], mounts, atol=1e-12)
    assert np.all(np.linalg.norm(g.arms[:, 0], axis=1) <= R_MOUNT + 1e-12)


def test_any_number_of_appendages() -> None:
    data = flexsat.config.nominal().model_dump()
    template = data["appendages"][0]
    apps = []
    for k in range(8):
        yaw = 45.0 * k
        mount = [-R_MOUNT * np.sin(np.radians(yaw)), R_MOUNT * np.cos(np.radians(yaw)), 0.0]
        apps.append(dict(template, name=f"p{k}", mount_yaw_deg=yaw, mount_point_m=mount))
    plant = Plant.from_config(validate_config(dict(data, appendages=apps)))
    g = satellite_geometry(plant)
    assert g.panels.shape == (8, 4, 3) and g.arms.shape == (8, 2, 3)
    np.testing.assert_allclose(np.linalg.norm(g.tips, axis=1), TIP, atol=1e-12)
    np.testing.assert_allclose(g.tips[2], [-TIP, 0.0, 0.0], atol=1e-12)  # yaw 90 deg


def test_rejects_wrong_shape(plant: Plant) -> None:
    with pytest.raises(ValueError, match="shape"):
        satellite_geometry(plant, np.zeros(plant.n_dof + 1))
