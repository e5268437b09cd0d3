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
        "mount_zyx_deg": [app["mount_yaw_deg"], app["sadm_angle_deg"], 0.0],
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
