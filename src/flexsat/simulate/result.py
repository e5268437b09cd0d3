"""Simulation results: an ``xarray.Dataset`` with units, the configs that made it, a status.

Every variable carries a ``units`` attribute; the dataset's attributes hold the
satellite config and the scenario as JSON, the flexsat version, the solver, the
wall time and the run's status. A run that stopped early (diverged) keeps its
history up to the failure, with ``status = "failed"`` and the message.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np
import xarray as xr
from scipy.spatial.transform import Rotation

from flexsat.dynamics.attitude import inertial_records, vectors_to_inertial
from flexsat.dynamics.plant import Plant
from flexsat.dynamics.records import derive_records
from flexsat.errors import SimulationError

__all__ = ["Result", "build_dataset"]

AXES = ("x", "y", "z")


@dataclass(frozen=True)
class Result:
    """A simulation result wrapping its dataset (``result.dataset``).

    Parameters
    ----------
    dataset : xarray.Dataset
        The recorded run: every variable with its ``units``, the config and the
        scenario in the attributes.
    """

    dataset: xr.Dataset

    @property
    def ok(self) -> bool:
        return self.dataset.attrs["status"] == "ok"

    @property
    def message(self) -> str:
        return str(self.dataset.attrs.get("message", ""))

    @property
    def time(self) -> np.ndarray:
        return self.dataset["time"].values

    def raise_for_status(self) -> None:
        """Raise the run's :class:`SimulationError` if it failed."""
        if not self.ok:
            raise SimulationError(self.message)

    def to_netcdf(self, path: str | Path) -> Path:
        """Write the dataset to NetCDF (written to a temporary name, then moved)."""
        path = Path(path)
        path.parent.mkdir(parents=True, exist_ok=True)
        partial = path.with_suffix(path.suffix + ".partial")
        self.dataset.to_netcdf(partial)
        partial.replace(path)
        return path

    @classmethod
    def from_netcdf(cls, path: str | Path) -> Result:
        """Read a result written by :meth:`to_netcdf` (loaded into memory)."""
        with xr.open_dataset(path) as ds:
            return cls(ds.load())


def build_dataset(
    plant: Plant,
    t: np.ndarray,
    q: np.ndarray,
    qd: np.ndarray,
    work_in: np.ndarray,
    dissipated: np.ndarray,
    tau_cmd: np.ndarray,
    tau_applied: np.ndarray,
    attrs: dict,
    frames: np.ndarray | None = None,
) -> xr.Dataset:
    """Derive every recorded quantity from the recorded states.

    Parameters
    ----------
    t : ndarray, shape (m,)
        Record times [s].
    q, qd : ndarray, shape (m, n_dof)
    work_in, dissipated : ndarray, shape (m,)
        Cumulative work of the applied torque and damper dissipation [J].
    tau_cmd, tau_applied : ndarray, shape (m, 3)
        Commanded and applied body torque held from each record time [N m].
    attrs : dict
        Dataset attributes (configs as JSON, status...).
    frames : ndarray, shape (m, 9), optional
        The attitude reference R_NF of each record (:mod:`flexsat.dynamics.attitude`);
        the hub part of ``q`` and ``qd`` is relative to it. Default: the identity.
        The dataset holds every attitude, position and momentum relative to N.
    """
    m, n = q.shape
    names = [a.name for a in plant.config.appendages]
    n_app = len(names)
    omega = np.empty((m, 3))
    omega_dot = np.empty((m, 3))
    tau_flex = np.empty((m, 3))
    H = np.empty((m, 3))
    H_rigid = np.empty((m, 3))
    kinetic = np.empty(m)
    elastic = np.empty(m)
    tips = np.zeros((m, n_app, 3))
    # A diverged run keeps its last finite state, whose derived values may overflow.
    with np.errstate(over="ignore", invalid="ignore"):
        derive_records(
            np.ascontiguousarray(q), np.ascontiguousarray(qd), np.ascontiguousarray(tau_applied),
            plant.packed, omega, omega_dot, tau_flex, H, H_rigid, kinetic, elastic, tips,
        )  # fmt: skip
    if frames is not None:  # relative to N: H_N = R_NF H_F (docs/model.md)
        q, qd = inertial_records(q, qd, omega, frames)
        H = vectors_to_inertial(H, frames)
        H_rigid = vectors_to_inertial(H_rigid, frames)
    rotations = Rotation.from_euler("ZYX", q[:, 5:2:-1])  # R_NB = Rz(psi) Ry(theta) Rx(phi)
    total = kinetic + elastic
    quat_scalar_last = rotations.as_quat()
    quaternion = np.column_stack([quat_scalar_last[:, 3], quat_scalar_last[:, :3]])
    # Root motion per appendage, as its model defines it.
    blocks = list(zip(plant.models, plant.layout.blocks, strict=True))
    root = [model.root_motion(q[:, b.slice], b.names) for model, b in blocks]
    root_rate = [model.root_motion(qd[:, b.slice], b.names) for model, b in blocks]

    def var(dims, data, units, description):
        return (dims, data, {"units": units, "description": description})

    ta, tpa = ("time", "axis"), ("time", "appendage", "axis")
    data_vars = {
        "q": var(("time", "dof"), q, "SI (m, rad)", "generalized coordinates"),
        "qd": var(("time", "dof"), qd, "SI (m/s, rad/s)", "generalized velocities"),
        "euler_deg": var(("time", "euler"), np.degrees(q[:, 3:6]), "deg", "hub ZYX Euler angles"),
        "quaternion": var(
            ("time", "quat"), quaternion, "1", "hub attitude quaternion, scalar first"
        ),
        "omega": var(ta, omega, "rad/s", "hub body rate, frame B"),
        "omega_dot": var(ta, omega_dot, "rad/s^2", "hub angular acceleration, frame B"),
        "eta": var(tpa, _stack(root, 0, m), "m", "root translation, mount frame"),
        "rho": var(tpa, _stack(root, 1, m), "rad", "root rotation (ZYX angles), mount frame"),
        "eta_rate": var(tpa, _stack(root_rate, 0, m), "m/s", "root translation rate"),
        "rho_rate": var(tpa, _stack(root_rate, 1, m), "rad/s", "root rotation angle rates"),
        "tip_displacement": var(tpa, tips, "m", "panel tip displacement, mount frame"),
        "tau_cmd": var(ta, tau_cmd, "N m", "commanded body torque, frame B"),
        "tau_applied": var(ta, tau_applied, "N m", "applied body torque, frame B"),
        "tau_flex": var(ta, tau_flex, "N m", "torque of the joints on the hub about its CoM"),
        "tau_net": var(ta, tau_applied + tau_flex, "N m", "net torque on the hub, frame B"),
        "angular_momentum": var(ta, H, "N m s", "total angular momentum, inertial frame"),
        "rigid_angular_momentum": var(
            ta, H_rigid, "N m s", "rigid part J(eta) omega, inertial frame"
        ),
        "kinetic_energy": var("time", kinetic, "J", "kinetic energy T"),
        "elastic_energy": var("time", elastic, "J", "elastic energy U"),
        "total_energy": var("time", total, "J", "T + U"),
        "work_in": var("time", work_in, "J", "cumulative work of the applied torque"),
        "dissipated_energy": var("time", dissipated, "J", "cumulative damper dissipation"),
        "energy_balance_error": var(
            "time",
            total - total[0] - work_in + dissipated,
            "J",
            "E(t) - E(0) - W_in(t) + W_diss(t): numerical error of the integration",
        ),
    }
    coords = {
        "time": ("time", t, {"units": "s"}),
        "axis": list(AXES),
        "euler": ["roll", "pitch", "yaw"],
        "quat": ["q0", "q1", "q2", "q3"],
        "appendage": names,
        "dof": plant.dof_names(),
    }
    return xr.Dataset(data_vars, coords=coords, attrs=attrs)


def _stack(per_appendage: list[tuple[np.ndarray, np.ndarray]], k: int, m: int) -> np.ndarray:
    """Part k of each appendage's (eta, rho) pair as one (m, n, 3) array."""
    return np.stack([pair[k] for pair in per_appendage], axis=1).reshape(m, -1, 3)

