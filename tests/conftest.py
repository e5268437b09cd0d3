"""Shared fixtures: the nominal plant and config variants built from the nominal preset."""

from __future__ import annotations

import os

# One BLAS thread per test process. Two pytest-xdist workers on two cores, each running
# OpenBLAS's threads on the mu analyses' small matrices (69 x 69), oversubscribe the
# cores: under load the upper bound's optimiser slowed 15x or more (docs/performance.md,
# "The test suite"). The workers `make test` starts inherit these variables and load
# numpy after them; a single-process pytest has loaded numpy already (pytest imports
# numba for the warning filter of pyproject.toml), so set them by hand there. A
# variable already set is kept.
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
os.environ.setdefault("OMP_NUM_THREADS", "1")

import copy
import tomllib

import numpy as np
import pytest
from hypothesis import settings

from flexsat.config import SatelliteConfig, preset_path, validate_config
from flexsat.dynamics.plant import Plant

# Hypothesis runs derandomized by default (profile "ci"): the same examples on every
# run and machine, so the suite cannot fail at random. HYPOTHESIS_PROFILE=explore
# draws fresh examples (seeded from the clock) to look for new failures.
settings.register_profile("ci", derandomize=True, print_blob=True)
settings.register_profile("explore", derandomize=False, print_blob=True)
HYPOTHESIS_PROFILE = os.environ.get("HYPOTHESIS_PROFILE", "ci")
settings.load_profile(HYPOTHESIS_PROFILE)


def pytest_report_header(config) -> str:
    chosen = settings.get_profile(HYPOTHESIS_PROFILE)
    seed = "fixed, from each test's name" if chosen.derandomize else "random"
    return f"hypothesis profile: {HYPOTHESIS_PROFILE!r} (seed: {seed})"


def nominal_dict() -> dict:
    """The nominal preset as a plain dict, to derive variants from."""
    return tomllib.loads(preset_path("nominal").read_text())


def config_from(data: dict) -> SatelliteConfig:
    return validate_config(data)


def variant(**appendage_updates) -> dict:
    """Nominal dict with the same updates applied to every appendage."""
    data = nominal_dict()
    for app in data["appendages"]:
        app.update(copy.deepcopy(appendage_updates))
    return data


def two_different_panels() -> SatelliteConfig:
    """Two unlike panels at different SADM angles, one mounted off-axis."""
    data = nominal_dict()
    first, second = data["appendages"]
    first["sadm_angle_deg"] = 30.0
    second.update(
        sadm_angle_deg=-55.0,
        length_m=3.2,
        width_m=1.1,
        surface_density_kg_m2=1.7,
        mount_point_m=[0.1, -0.75, 0.2],
        damping_ratio=0.02,
    )
    second["target_frequencies_hz"].update(flapping=0.4, in_plane=0.9, torsion=1.3)
    data["hub"] = {
        "mass_kg": 150.0,
        "inertia_kg_m2": [[41.6, 1.2, -0.8], [1.2, 40.1, 0.5], [-0.8, 0.5, 27.0]],
    }
    return config_from(data)


def one_panel() -> SatelliteConfig:
    data = nominal_dict()
    data["appendages"] = data["appendages"][:1]
    return config_from(data)


def three_panels() -> SatelliteConfig:
    """Three panels 120 deg apart around the hub Z axis."""
    data = nominal_dict()
    base = data["appendages"][0]
    apps = []
    for k, yaw in enumerate((0.0, 120.0, 240.0)):
        app = copy.deepcopy(base)
        radius = 0.8
        app.update(
            name=f"panel_{k + 1}",
            mount_yaw_deg=yaw,
            mount_point_m=[
                -radius * np.sin(np.radians(yaw)),
                radius * np.cos(np.radians(yaw)),
                0.0,
            ],
            sadm_angle_deg=15.0 * k,
        )
        apps.append(app)
    data["appendages"] = apps
    return config_from(data)


@pytest.fixture(scope="session")
def nominal_plant() -> Plant:
    from flexsat.config import nominal

    return Plant.from_config(nominal())


TOPOLOGIES = {
    "nominal": lambda: config_from(nominal_dict()),
    "sadm_45": lambda: config_from(variant(sadm_angle_deg=45.0)),
    "two_different": two_different_panels,
    "one_panel": one_panel,
    "three_panels": three_panels,
}


@pytest.fixture(scope="session", params=sorted(TOPOLOGIES))
def any_plant(request) -> Plant:
    """Each topology the engine must handle without new code."""
    return Plant.from_config(TOPOLOGIES[request.param]())


def random_state(plant: Plant, rng: np.random.Generator, scale: float = 0.3):
    """Random q, q_dot with hub pitch and joint rho_y kept away from +-90 deg."""
    q = rng.normal(scale=scale, size=plant.n_dof)
    qd = rng.normal(scale=scale, size=plant.n_dof)
    return q, qd
