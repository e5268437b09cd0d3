"""A driven mount coordinate: an appendage on a solar-array drive (SADM).

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
status names the gimbal lock otherwise). :func:`driven_chain` puts a chain on a
drive the same way: the rotor becomes its segment 0, on a joint that frees the
rotation about the chain's span axis, and its segments follow. A satellite TOML
puts an appendage on a drive with its ``drive`` key
(:class:`~flexsat.config.models.DriveConfig`); the plant builds it through
:func:`expand_drives`, which asks each model's ``on_drive`` hook (a model without
one refuses the key); a model that holds the drive in its own kernels (``holds_drive``,
the modal model) is left as it is. docs/model.md, 'Driven mount coordinate (SADM)'.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np
from pydantic import ValidationError

from flexsat.config.models import SatelliteConfig
from flexsat.dynamics.appendages.chain_config import DOF_NAMES, ChainConfig
from flexsat.dynamics.appendages.plate_config import PlateConfig
from flexsat.dynamics.appendages.registry import appendage_model
from flexsat.errors import ConfigError

__all__ = ["DRIVE_COORDINATE", "driven_chain", "driven_plate", "expand_drives", "with_sadm"]

DRIVE_COORDINATE = "eta_ry_0"
"""Name of the drive angle alpha_sadm in a driven plate's coordinates [rad]."""


def driven_plate(plate: PlateConfig, stiffness: np.ndarray, damping: np.ndarray,
                 rotor_inertia_kg_m2: float, rotor_mass_kg: float) -> ChainConfig:  # fmt: skip
    """The thesis plate ``plate`` on a SADM: a two-segment chain (module docstring).

    Parameters
    ----------
    plate : PlateConfig
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
    rotor = _rotor("ry", plate.sadm_angle_deg, rotor_inertia_kg_m2, rotor_mass_kg)
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


def driven_chain(chain: ChainConfig, stiffness: np.ndarray, damping: np.ndarray,
                 rotor_inertia_kg_m2: float, rotor_mass_kg: float) -> ChainConfig:  # fmt: skip
    """The chain ``chain`` on a SADM turning it about its span axis: the same chain with
    the drive rotor as its segment 0.

    The rotor's joint frees the rotation about the span axis of the mount frame
    (``eta_ry_0`` for a chain spanning +-Y, ``eta_rx_0`` or ``eta_rz_0`` otherwise),
    starting at the chain's ``sadm_angle_deg``; the chain's segments follow, segment
    k becoming k + 1, each joint with the stiffness and damping it was tuned to. With
    the drive angle held, every segment's pose is the undriven chain's.

    Parameters
    ----------
    chain : ChainConfig
        The chain; its ``sadm_angle_deg`` becomes the drive's initial angle.
    stiffness, damping : ndarray, shape (n,)
        Its tuned joint stiffness [N/m, N m/rad] and damping [N s/m, N m s/rad], one per
        coordinate in the chain's coordinate order.
    rotor_inertia_kg_m2 : float
        Drive rotor inertia about the drive axis, as seen at the array [kg m^2] (> 0).
    rotor_mass_kg : float
        Rotor mass, on the axis at the root [kg] (> 0).

    Returns
    -------
    ChainConfig
        Named as the chain, given as a segment list, with no drive and no SADM angle.
    """
    spin = ("rx", "ry", "rz")[chain.span_axis()[0]]
    segments, first = [], 0
    for seg, joint in zip(chain.resolved_segments(), chain.joints(), strict=True):
        dofs, count = list(seg.dofs), len(seg.dofs)
        tuned = {"stiffness": dict(zip(dofs, map(float, stiffness[first : first + count]),
                                       strict=True)),
                 "damping": dict(zip(dofs, map(float, damping[first : first + count]),
                                     strict=True))}  # fmt: skip
        first += count
        segments.append({
            "mass_kg": seg.mass, "inertia_kg_m2": seg.inertia.tolist(),
            "com_m": tuple(seg.com), "next_joint_m": tuple(seg.next_joint),
            "joint": {"dofs": dofs, **tuned, "initial": dict(joint.initial),
                      "initial_rate": dict(joint.initial_rate)},
        })  # fmt: skip
    mount = ({"mount_matrix": chain.mount_matrix} if chain.mount_matrix is not None
             else {"mount_yaw_deg": chain.mount_yaw_deg})  # fmt: skip
    return ChainConfig.model_validate({
        "name": chain.name, "model": "chain", "mount_point_m": chain.mount_point_m, **mount,
        "span_direction": chain.span_direction, "tip_mass_kg": chain.tip_mass_kg,
        "segment_list": [_rotor(spin, chain.sadm_angle_deg, rotor_inertia_kg_m2,
                                rotor_mass_kg), *segments],
    })  # fmt: skip


def _rotor(spin: str, angle_deg: float, inertia: float, mass: float) -> dict:
    """Segment 0 of a driven appendage: the rotor, on a joint that frees ``spin`` alone."""
    return {
        "mass_kg": mass,
        # The rotor's transverse inertia equals its axial one: any value that keeps the
        # inertia physical serves, the rotor's centre of mass being on the axis.
        "inertia_kg_m2": np.diag([inertia] * 3).tolist(),
        "com_m": (0.0, 0.0, 0.0),
        "next_joint_m": (0.0, 0.0, 0.0),
        "joint": {"dofs": [spin], "stiffness": {spin: 0.0}, "damping": {spin: 0.0},
                  "initial": {spin: angle_deg}},
    }  # fmt: skip


def with_sadm(config: SatelliteConfig, rotor_inertia_kg_m2: float, rotor_mass_kg: float,
              names: tuple[str, ...] | None = None) -> SatelliteConfig:  # fmt: skip
    """``config`` with its appendages (all, or those named) on a SADM: their ``drive`` key set.

    Only appendages whose model takes a drive (a ``drive`` field in its config) are
    changed; with ``names`` not given, a modal appendage without its ``drive_axis`` is
    left alone (it names no axis to turn about). The plant builds each plate or chain
    as its model's chain on the drive (:func:`expand_drives`): the joints keep the
    stiffness and damping the plant tunes them to (eqs. 2.14-2.15), so the driven
    satellite is the same satellite with one more coordinate per driven appendage; a
    modal appendage holds its drive angle itself (docs/model.md, 'Modal appendage on a
    drive').

    Parameters
    ----------
    config : SatelliteConfig
        The satellite.
    rotor_inertia_kg_m2 : float
        Each drive rotor's inertia about the SADM axis [kg m^2].
    rotor_mass_kg : float
        Each drive rotor's mass [kg].
    names : tuple of str, optional
        The appendages to put on a drive [-]; default every one that takes a drive.

    Returns
    -------
    SatelliteConfig
        The satellite, each chosen appendage with ``drive = {rotor_inertia_kg_m2,
        rotor_mass_kg}`` [-].

    Raises
    ------
    pydantic.ValidationError
        An appendage that cannot go on a drive (its ``drive`` validation message).
    """
    drive = {"rotor_inertia_kg_m2": rotor_inertia_kg_m2, "rotor_mass_kg": rotor_mass_kg}
    appendages = [
        type(app).model_validate({**dict(app), "drive": drive})
        if "drive" in type(app).model_fields and (names is None or app.name in names)
        and (names is not None or getattr(app, "drive_axis", True) is not None) else app
        for app in config.appendages
    ]  # fmt: skip
    return config.model_copy(update={"appendages": appendages})


def expand_drives(config: SatelliteConfig,
                  build: Callable[[SatelliteConfig], Any]) -> SatelliteConfig:  # fmt: skip
    """``config`` with each appendage on a drive (its ``drive`` key) written by its
    model's :meth:`~flexsat.dynamics.appendages.contract.AppendageModel.on_drive` hook.

    The joints take the stiffness and damping the plant tunes the undriven
    appendages to (eqs. 2.14-2.15, on the satellite with every drive removed); the
    model then writes each driven appendage as a chain whose first segment is the
    drive rotor.

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
        ``config`` itself when no appendage has a drive; else a copy whose driven
        appendages are chains [-].

    Raises
    ------
    ConfigError
        Naming the appendage's ``drive`` when its model has no drive or refuses it.
    """
    driven = [
        getattr(app, "drive", None) is not None and not appendage_model(app.model).holds_drive
        for app in config.appendages
    ]
    if not any(driven):
        return config
    fixed = [app.model_copy(update={"drive": None}) if d else app
             for app, d in zip(config.appendages, driven, strict=True)]  # fmt: skip
    plant = build(config.model_copy(update={"appendages": fixed}))
    appendages = list(config.appendages)
    for k, (app, params) in enumerate(zip(config.appendages, plant.params, strict=True)):
        if driven[k]:
            appendages[k] = _on_drive(k, app, params)
    return config.model_copy(update={"appendages": appendages})


def _on_drive(k: int, app: Any, params: np.ndarray) -> ChainConfig:
    """Appendage ``k`` on its drive, a refusal as a ConfigError naming its drive."""
    model = appendage_model(app.model)
    try:
        chain = model.on_drive(app, params)
    except (ValidationError, ValueError) as exc:
        first = exc.errors()[0]["msg"] if isinstance(exc, ValidationError) else str(exc)
        raise ConfigError(f"appendages[{k}].drive: {app.name!r} cannot be built on a drive: "
                          f"{first.removeprefix('Value error, ')}") from None  # fmt: skip
    if chain is None:
        raise ConfigError(f"appendages[{k}].drive: the {app.model!r} model has no drive")
    return chain
