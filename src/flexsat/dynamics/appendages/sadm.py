"""A driven mount coordinate: the thesis plate on a solar-array drive (SADM).

The thesis plate holds its SADM angle in its fixed mount rotation R_BM = Rz(yaw)
Ry(alpha_sadm). A moving array needs that angle as a generalized coordinate with its
own inertia (the drive rotor and the array) driven by a motor torque. The chain
model (:mod:`flexsat.dynamics.appendages.chain`) already has it: a joint that frees
one rotation, with zero stiffness and damping, is a revolute drive axis; the
generalized force a joint actuator puts on it (``[joint_actuator] kind =
"sadm_drive"``, :mod:`flexsat.control.stages.sadm_drive`) is the motor torque, and
its reaction on the hub is the joint equations' own. :func:`driven_plate` writes a
thesis plate as that two-segment chain:

- segment 0, the drive rotor: mass ``rotor_mass_kg`` on the axis at the root,
  inertia ``rotor_inertia_kg_m2`` about the axis, on joint 0 that frees ``ry``
  (Y_M, the plate's SADM axis) alone: coordinate ``eta_ry_0`` = alpha_sadm, its
  initial value the plate's ``sadm_angle_deg``;
- segment 1, the panel: the plate's mass, inertia (eqs. 2.9-2.11) and centre of mass,
  on the plate's 6-DOF elastic root joint (``eta_x_1`` ... ``eta_rz_1``) with the
  plate's tuned stiffness and damping (eqs. 2.14-2.15).

With the drive angle held, the panel's kinematics are the plate's exactly
(R_BP = Rz(yaw) Ry(alpha_sadm) R_MP(rho), the root at the mount point). The drive
axis is a ZYX joint angle: it must stay within +-90 deg of the mount frame (a
status names the gimbal lock otherwise). A satellite TOML puts a plate on a drive
with its ``drive`` key (:class:`~flexsat.config.models.DriveConfig`); the plant
builds it through :func:`expand_drives`. docs/model.md, 'Driven mount coordinate
(SADM)'.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np
from pydantic import ValidationError

from flexsat.config.models import AppendageConfig, SatelliteConfig
from flexsat.dynamics.appendages.chain_config import DOF_NAMES, ChainConfig
from flexsat.errors import ConfigError

__all__ = ["DRIVE_COORDINATE", "driven_plate", "expand_drives", "with_sadm"]

DRIVE_COORDINATE = "eta_ry_0"
"""Name of the drive angle alpha_sadm in a driven plate's coordinates [rad]."""


def driven_plate(plate: AppendageConfig, stiffness: np.ndarray, damping: np.ndarray,
                 rotor_inertia_kg_m2: float, rotor_mass_kg: float) -> ChainConfig:  # fmt: skip
    """The thesis plate ``plate`` on a SADM: a two-segment chain (module docstring).

    Parameters
    ----------
    plate : AppendageConfig
        The plate; its ``sadm_angle_deg`` becomes the drive's initial angle (within ±45 deg).
    stiffness, damping : ndarray, shape (6,)
        Its tuned root-joint stiffness [N/m, N m/rad] and damping [N s/m, N m s/rad], in
        the order eta_x, eta_y, eta_z, eta_rx, eta_ry, eta_rz.
    rotor_inertia_kg_m2 : float
        Drive rotor inertia about the drive axis, as seen at the array [kg m^2] (> 0).
    rotor_mass_kg : float
        Rotor mass, on the axis at the root [kg] (> 0).

    Returns
    -------
    ChainConfig
        Named as the plate; coordinates ``eta_ry_0`` (the drive) and ``eta_*_1``.
    """
    if plate.locked_dofs:
        raise ValueError(f"appendages: {plate.name!r} locks {plate.locked_dofs}; a driven "
                         "plate takes no locked DOFs")  # fmt: skip
    sign = plate.span_sign()
    rotor = {
        "mass_kg": rotor_mass_kg,
        # The rotor's transverse inertia equals its axial one: any value that keeps the
        # inertia physical serves, the rotor's centre of mass being on the axis.
        "inertia_kg_m2": np.diag([rotor_inertia_kg_m2] * 3).tolist(),
        "com_m": (0.0, 0.0, 0.0),
        "next_joint_m": (0.0, 0.0, 0.0),
        "joint": {"dofs": ["ry"], "stiffness": {"ry": 0.0}, "damping": {"ry": 0.0},
                  "initial": {"ry": plate.sadm_angle_deg}},
    }  # fmt: skip
    panel = {
        "mass_kg": plate.mass,
        "inertia_kg_m2": plate.centroidal_inertia().tolist(),
        "com_m": (0.0, 0.5 * sign * plate.length_m, 0.0),
        "next_joint_m": (0.0, sign * plate.length_m, 0.0),
        "joint": {"dofs": list(DOF_NAMES),
                  "stiffness": dict(zip(DOF_NAMES, map(float, stiffness), strict=True)),
                  "damping": dict(zip(DOF_NAMES, map(float, damping), strict=True))},
    }  # fmt: skip
    return ChainConfig.model_validate({
        "name": plate.name, "model": "chain", "mount_point_m": plate.mount_point_m,
        "mount_yaw_deg": plate.mount_yaw_deg, "span_direction": plate.span_direction,
        "segment_list": [rotor, panel],
    })  # fmt: skip


def with_sadm(config: SatelliteConfig, rotor_inertia_kg_m2: float, rotor_mass_kg: float,
              names: tuple[str, ...] | None = None) -> SatelliteConfig:  # fmt: skip
    """``config`` with its plates (all, or those named) on a SADM: their ``drive`` key set.

    The plant builds each such plate as :func:`driven_plate` (:func:`expand_drives`):
    the joints keep the stiffness and damping the plant tunes them to (eqs.
    2.14-2.15), so the driven satellite is the same satellite with one more
    coordinate per plate.

    Parameters
    ----------
    config : SatelliteConfig
        The satellite.
    rotor_inertia_kg_m2 : float
        Each drive rotor's inertia about the SADM axis [kg m^2].
    rotor_mass_kg : float
        Each drive rotor's mass [kg].
    names : tuple of str, optional
        The plates to put on a drive [-]; default every plate.

    Returns
    -------
    SatelliteConfig
        The satellite, each chosen plate with ``drive = {rotor_inertia_kg_m2,
        rotor_mass_kg}`` [-].

    Raises
    ------
    pydantic.ValidationError
        A plate that cannot go on a drive (its ``drive`` validation message).
    """
    drive = {"rotor_inertia_kg_m2": rotor_inertia_kg_m2, "rotor_mass_kg": rotor_mass_kg}
    appendages = [
        AppendageConfig.model_validate({**dict(app), "drive": drive})
        if isinstance(app, AppendageConfig) and (names is None or app.name in names) else app
        for app in config.appendages
    ]  # fmt: skip
    return config.model_copy(update={"appendages": appendages})


def expand_drives(config: SatelliteConfig,
                  build: Callable[[SatelliteConfig], Any]) -> SatelliteConfig:  # fmt: skip
    """``config`` with each plate on a drive (its ``drive`` key) written as its chain.

    The joints take the stiffness and damping the plant tunes the undriven plates to
    (eqs. 2.14-2.15, on the satellite with every drive removed), then
    :func:`driven_plate` builds each driven plate's two-segment chain.

    Parameters
    ----------
    config : SatelliteConfig
        The satellite.
    build : callable
        The plant of a satellite with no drive, tuned
        (:meth:`flexsat.dynamics.plant.Plant.from_config`, which calls this function:
        the plant is passed in so that this module needs no import of it).

    Returns
    -------
    SatelliteConfig
        ``config`` itself when no plate has a drive; else a copy whose driven plates
        are chains [-].

    Raises
    ------
    ConfigError
        Naming the plate's ``drive`` when its chain is refused.
    """
    driven = [isinstance(app, AppendageConfig) and app.drive is not None
              for app in config.appendages]  # fmt: skip
    if not any(driven):
        return config
    fixed = [app.model_copy(update={"drive": None}) if d else app
             for app, d in zip(config.appendages, driven, strict=True)]  # fmt: skip
    plant = build(config.model_copy(update={"appendages": fixed}))
    appendages = list(config.appendages)
    for k, (app, model, params) in enumerate(zip(config.appendages, plant.models, plant.params,
                                                 strict=True)):  # fmt: skip
        if driven[k]:
            appendages[k] = _chain(k, app, model.stiffness(params), model.damping(params))
    return config.model_copy(update={"appendages": appendages})


def _chain(k: int, plate: AppendageConfig, stiffness: np.ndarray,
           damping: np.ndarray) -> ChainConfig:  # fmt: skip
    """:func:`driven_plate` of appendage ``k``, a refusal as a ConfigError naming its drive."""
    try:
        return driven_plate(plate, stiffness, damping, plate.drive.rotor_inertia_kg_m2,
                            plate.drive.rotor_mass_kg)  # fmt: skip
    except ValidationError as exc:
        first = exc.errors()[0]
        raise ConfigError(f"appendages[{k}].drive: {plate.name!r} cannot be built on a drive: "
                          f"{first['msg'].removeprefix('Value error, ')}") from None  # fmt: skip
