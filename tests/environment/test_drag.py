"""Aerodynamic drag on a flat plate, and the exponential atmosphere."""

from __future__ import annotations

import numpy as np
import pytest

from flexsat.environment.drag import (
    EARTH_RADIUS,
    EARTH_ROTATION,
    VALLADO_ATMOSPHERE,
    DragConfig,
    drag_load,
    exponential_density,
)
from flexsat.environment.registry import SURFACE_SIZE


def _packed() -> np.ndarray:
    return DragConfig().packed(None)


@pytest.mark.parametrize("band", [0, 10, 17, 20, 22, 27])
def test_exponential_atmosphere_at_its_base_altitudes(band: int) -> None:
    """At each band's base altitude the density is the table's rho_0 (exp(0) = 1);
    halfway to the next, rho_0 exp(-dh/H): 1e-14 relative, round-off only."""
    h0, rho0, scale = VALLADO_ATMOSPHERE[band]
    params = _packed()
    assert exponential_density(params, h0 * 1e3) == pytest.approx(rho0, rel=1e-14)
    assert exponential_density(params, h0 * 1e3 + 2e3) == pytest.approx(
        rho0 * np.exp(-2.0 / scale), rel=1e-13
    )


def test_plate_normal_to_the_flow_takes_half_rho_v2_cd_a() -> None:
    """A plate facing the relative wind: |F| = 1/2 rho v_rel^2 C_D A, against the flow,
    v_rel = v - omega_E x r (co-rotating atmosphere). 1e-12 relative: the same
    expression computed in another order."""
    altitude, cd, area = 450e3, 2.2, 1.7
    r = np.array([EARTH_RADIUS + altitude, 0.0, 0.0])
    v = np.array([0.0, 7600.0, 1200.0])
    v_rel = v - np.cross([0.0, 0.0, EARTH_ROTATION], r)
    u = v_rel / np.linalg.norm(v_rel)
    eph = np.zeros(13)
    eph[1:4], eph[4:7] = r, v
    surface = np.zeros((1, SURFACE_SIZE))
    surface[0, 3:6], surface[0, 6], surface[0, 9] = u, area, cd
    force = np.zeros((1, 3))
    params = _packed()
    drag_load(eph, np.eye(3), np.zeros((0, 4)), surface, params, force, np.zeros(3))
    rho = exponential_density(params, altitude)
    assert rho == pytest.approx(1.585e-12, rel=1e-14)  # Table 8-4: the 450 km band's base
    expected = -0.5 * rho * (v_rel @ v_rel) * cd * area * u
    assert force[0] == pytest.approx(expected, rel=1e-12, abs=1e-12 * np.abs(expected).max())
    # a plate edge-on to the flow or in the wake takes none
    for normal in (np.cross(u, [0.0, 0.0, 1.0]) / np.linalg.norm(np.cross(u, [0, 0, 1.0])), -u):
        surface[0, 3:6] = normal
        force[:] = 0.0
        drag_load(eph, np.eye(3), np.zeros((0, 4)), surface, params, force, np.zeros(3))
        assert np.all(np.abs(force) < 1e-12 * np.abs(expected).max())


def test_nrlmsis_density_is_of_the_exponential_tables_order() -> None:
    """NRLMSIS 2.1 (pymsis) at 450 km, moderate activity, against the exponential
    table: the two models differ with solar activity, local time and latitude, so only
    within a factor of 5 (the table is a mean atmosphere)."""
    pytest.importorskip("pymsis")
    from flexsat.environment.drag import nrlmsis_density
    from tests.environment.orbits import circular_ephemeris

    eph = circular_ephemeris(450e3, 51.6, 600.0, 60.0)
    rho = nrlmsis_density(eph, "2026-01-01T00:00:00Z", 150.0, 4.0)
    assert np.all(rho > 1.585e-12 / 5.0) and np.all(rho < 1.585e-12 * 5.0)
