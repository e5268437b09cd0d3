"""Chain-built satellites shared by the chain tests: the thesis plates as chains."""

from __future__ import annotations

import copy

from flexsat.config import SatelliteConfig, validate_config
from tests.conftest import nominal_dict

SIX_DOFS = ["x", "y", "z", "rx", "ry", "rz"]


def plate_as_chain(app: dict, segments: int = 1) -> dict:
    """The nominal plate table as a chain of ``segments`` segments on 6-DOF joints, tuned
    to the plate's target frequencies (the joint DOFs name the plate's eta_* order)."""
    tf = app["target_frequencies_hz"]
    return {
        "name": app["name"], "model": "chain", "mount_point_m": app["mount_point_m"],
        "mount_yaw_deg": app["mount_yaw_deg"], "sadm_angle_deg": app["sadm_angle_deg"],
        "span_direction": app["span_direction"], "segments": segments,
        "length_m": app["length_m"], "width_m": app["width_m"],
        "thickness_m": app["thickness_m"], "surface_density_kg_m2": app["surface_density_kg_m2"],
        "joint": {
            "dofs": SIX_DOFS, "damping_ratio": app["damping_ratio"],
            "target_frequencies_hz": {
                "x": tf["translation_x"], "y": tf["translation_y"], "z": tf["translation_z"],
                "rx": tf["flapping"], "ry": tf["torsion"], "rz": tf["in_plane"],
            },
        },
    }  # fmt: skip


def thesis_chain_dict() -> dict:
    """The nominal satellite with each thesis plate as a one-segment 6-DOF chain."""
    data = copy.deepcopy(nominal_dict())
    data["appendages"] = [plate_as_chain(a) for a in data["appendages"]]
    return data


def thesis_chain_config() -> SatelliteConfig:
    return validate_config(thesis_chain_dict())


# A uniform cantilever (a slender steel-like bar, numbers chosen round): span L along
# +Y, flapwise bending about X. Euler-Bernoulli: omega_n = (beta_n L)^2 sqrt(EI / (rho A L^4)).
BEAM_LENGTH_M = 2.0
BEAM_MASS_KG = 4.0
BEAM_EI_N_M2 = 500.0
BEAM_GJ_N_M2 = 400.0
BETA_L = (1.875104, 4.694091, 7.854757)  # Euler-Bernoulli cantilever, beta_n L


def beam_frequency_hz(n: int, length_m: float = BEAM_LENGTH_M, mass_kg: float = BEAM_MASS_KG,
                      ei: float = BEAM_EI_N_M2) -> float:  # fmt: skip
    """Euler-Bernoulli cantilever frequency of mode n (1-based) [Hz]."""
    import math

    rho_a = mass_kg / length_m
    return BETA_L[n - 1] ** 2 * math.sqrt(ei / (rho_a * length_m**4)) / (2.0 * math.pi)


def cantilever_chain(segments: int, dofs=("rx",), hub_scale: float = 1.0,
                     mount=(0.0, 0.0, 0.0)) -> dict:  # fmt: skip
    """A satellite whose one appendage is the uniform cantilever as a chain of
    ``segments`` segments, springs from the beam's EI (and GJ); a thin bar (width and
    thickness 1 mm, so rotary inertia is negligible as Euler-Bernoulli assumes)."""
    return {
        "name": f"cantilever-{segments}",
        "hub": {"mass_kg": 100.0 * hub_scale,
                "inertia_kg_m2": [[50.0 * hub_scale, 0, 0], [0, 50.0 * hub_scale, 0],
                                  [0, 0, 50.0 * hub_scale]]},
        "appendages": [{
            "name": "beam", "model": "chain", "mount_point_m": list(mount),
            "span_direction": "+y", "segments": segments, "length_m": BEAM_LENGTH_M,
            "width_m": 1e-3, "thickness_m": 1e-6, "mass_kg": BEAM_MASS_KG,
            "joint": {"dofs": list(dofs)},
            "beam": {"EI_flap_N_m2": BEAM_EI_N_M2, "EI_in_plane_N_m2": BEAM_EI_N_M2,
                     "GJ_N_m2": BEAM_GJ_N_M2},
        }],
    }  # fmt: skip
