"""Simulation results: an ``xarray.Dataset`` with units, the configs that made it, a status.

Every variable carries the CF attributes ``units`` and ``long_name``; the dataset's
attributes hold the satellite config and the scenario as JSON, the flexsat version,
the solver, the wall time (of the integration alone, compilation excluded) and the
run's status. A run that stopped early (diverged) keeps its history up to the
failure, with ``status = "failed"`` and the message.

:class:`Result` works the way python-control's ``TimeResponseData`` does: it plots
itself (:meth:`Result.plot`, every figure of its run's kind), gives a tidy table
(:meth:`Result.to_pandas`), computes its metrics from the scenario it stores
(:meth:`Result.metrics`) and summarizes itself (:meth:`Result.summary`, and an HTML
table in a notebook). Figures and metrics are imported when first used, so reading
a result needs neither matplotlib nor the analysis modules.
"""

from __future__ import annotations

import importlib
import shutil
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from flexsat.analysis.run_records import Record, RunRecords
from flexsat.dynamics.attitude import inertial_records, vectors_to_inertial
from flexsat.dynamics.plant import Plant
from flexsat.dynamics.records import derive_records
from flexsat.errors import SimulationError

if TYPE_CHECKING:  # xarray and pandas (0.4 s) load when a dataset is built or read
    import xarray as xr

__all__ = ["FIGURE_PROVIDER", "Result", "ResultFigures", "build_dataset", "build_records",
           "dataset_of", "register_result_figures", "result_figures"]  # fmt: skip

AXES = ("x", "y", "z")

FIGURE_PROVIDER = "flexsat.plots"
"""The package that draws a result's figures unless one has registered: imported by name
when :meth:`Result.plot` is first called (it registers itself on import)."""


@dataclass(frozen=True)
class ResultFigures:
    """What draws a run's figures: the registry entry :meth:`Result.plot` looks up.

    Parameters
    ----------
    names : callable
        ``names(dataset) -> tuple of str``: the figures a run can draw, in the order
        they are written.
    plot : callable
        ``plot(dataset, kind, analysis) -> matplotlib.figure.Figure``: one figure by
        name (``analysis``: a :class:`~flexsat.analysis.modal.ModalAnalysis` or None).
    """

    names: Callable[[xr.Dataset], tuple[str, ...]]
    plot: Callable


_FIGURES: list[ResultFigures] = []


def register_result_figures(figures: ResultFigures) -> None:
    """Make :meth:`Result.plot` and :meth:`Result.figure_kinds` draw with ``figures``.

    :mod:`flexsat.plots` registers its figure sets when it is imported; a later
    registration replaces it (a package of one's own figures).

    Parameters
    ----------
    figures : ResultFigures
        The figure names and the drawing function.
    """
    _FIGURES[:] = [figures]


def result_figures() -> ResultFigures:
    """The registered figures, the figure package (:data:`FIGURE_PROVIDER`) imported by
    name first if none has registered: a plug-in lookup, so that the simulation layer
    names nothing of the figures layer above it and reading a result needs no
    matplotlib.

    Returns
    -------
    ResultFigures
        What :meth:`Result.plot` draws with.
    """
    if not _FIGURES:
        importlib.import_module(FIGURE_PROVIDER)
    return _FIGURES[0]


@dataclass(frozen=True)
class Result:
    """A simulation result wrapping its dataset (``result.dataset``).

    Parameters
    ----------
    dataset : xarray.Dataset
        The recorded run: every variable with its ``units``, the config and the
        scenario in the attributes.
    path : Path, optional
        The NetCDF file a streamed run's records were written to (the dataset reads
        it lazily; :mod:`flexsat.simulate.stream`); None for a run held in memory.
    """

    dataset: xr.Dataset
    path: Path | None = None

    @property
    def ok(self) -> bool:
        return self.dataset.attrs["status"] == "ok"

    @property
    def message(self) -> str:
        return str(self.dataset.attrs.get("message", ""))

    @property
    def time(self) -> np.ndarray:
        """Record times [s], shape (m,)."""
        return self.dataset["time"].values

    @property
    def kind(self) -> str:
        """``"slew"`` for a closed-loop run, ``"openloop"`` for an open-loop one."""
        return "slew" if "pointing_error_deg" in self.dataset else "openloop"

    def figure_kinds(self) -> tuple[str, ...]:
        """The figures :meth:`plot` can draw for this run, in the order they are written."""
        return result_figures().names(self.dataset)

    def plot(self, kind: str = "attitude", *, analysis=None):
        """Draw one of the run's figures.

        Parameters
        ----------
        kind : str
            A name of :meth:`figure_kinds` (open loop: ``attitude``, ``quaternion``,
            ``angular_acceleration``, ``torques``, ``root_deformation``,
            ``tip_displacement``, ``angular_momentum``, ``energy``, ``spectrogram``;
            slew: ``attitude``, ``quaternion``, ``pointing``, ``phase_plane``, the
            sliding-surface figures when the law has one, ``disturbances``,
            ``torque_limits``, ``torque_breakdown``, ``root_deformation``,
            ``tip_displacement``, ``flex_torque``, ``energy``, then one per loop
            stage that records something, named after it: ``mekf``, ``wheels``...).
        analysis : flexsat.analysis.modal.ModalAnalysis, optional
            For the modal lines of the open-loop figures; default: computed from
            the stored config when the figure needs it.

        Returns
        -------
        matplotlib.figure.Figure
            Created without pyplot (in a notebook it displays as the cell's value).

        Raises
        ------
        FlexsatError
            If ``kind`` is not a figure of this run (the message lists them).
        """
        return result_figures().plot(self.dataset, kind, analysis)

    def to_pandas(self):
        """The records as one tidy table: a row per time, variable and component.

        Returns
        -------
        pandas.DataFrame
            Columns ``time_s`` [s], ``variable`` (the dataset's name), ``component``
            (the non-time coordinates joined by ``.``, e.g. ``p1.z``; empty for a
            scalar), ``value`` (in ``units``), ``units`` and ``long_name``. Filter
            it like any long table: ``df[df.variable == "omega"]``.
        """
        import pandas as pd

        frames = []
        for name, var in self.dataset.data_vars.items():
            if "time" not in var.dims:
                continue
            other = [d for d in var.dims if d != "time"]
            values = var.transpose("time", *other).values.reshape(var.sizes["time"], -1)
            labels = [""]
            for dim in other:
                coords = [str(c) for c in self.dataset[dim].values]
                labels = [f"{a}.{b}" if a else b for a in labels for b in coords]
            frames.append(pd.DataFrame({
                "time_s": np.repeat(self.time, len(labels)),
                "variable": name,
                "component": np.tile(labels, var.sizes["time"]),
                "value": values.ravel(),
                "units": var.attrs.get("units", ""),
                "long_name": var.attrs.get("long_name", ""),
            }))  # fmt: skip
        table = pd.concat(frames, ignore_index=True)
        for column in ("variable", "component", "units", "long_name"):
            table[column] = table[column].astype("category")
        return table

    def metrics(self) -> dict:
        """The run's metrics, from the requirements and limits of its stored scenario.

        Returns
        -------
        dict
            A slew: :func:`flexsat.analysis.requirements.slew_metrics` (R1-R3 against
            the stored scenario's bands and T_max); an open-loop run:
            :func:`flexsat.analysis.openloop.openloop_metrics`. A failed run's
            metrics are those of its finite part (``finite_until_s`` where it
            applies). Keys end in their unit.
        """
        if self.kind == "slew":
            from flexsat.analysis.requirements import slew_metrics

            return slew_metrics(self.dataset)
        from flexsat.analysis.openloop import openloop_metrics

        return openloop_metrics(self.dataset)

    def summary(self):
        """A rich table of the run: what ran, its status and its metrics.

        Returns
        -------
        rich.table.Table
            Print it with ``rich.print(result.summary())``; in a notebook the
            result itself displays as the same table in HTML (``_repr_html_``).
        """
        from rich.table import Table

        table = Table(title=str(self.dataset.attrs.get("title", "flexsat run")))
        table.add_column("quantity", no_wrap=True)
        table.add_column("value", justify="right")
        for key, value in self._summary_rows():
            table.add_row(key, value)
        return table

    def _summary_rows(self) -> list[tuple[str, str]]:
        attrs = self.dataset.attrs
        rows = [
            ("status", str(attrs.get("status", ""))),
            ("records", str(self.dataset.sizes["time"])),
            ("simulated [s]", f"{float(self.time[-1]):.6g}"),
            ("wall time [s] (compilation excluded)", f"{float(attrs.get('wall_time_s', 0)):.3g}"),
        ]
        if self.message:
            rows.append(("message", self.message))
        skip = ("files", "status", "message", "steps", "wall_time_s")
        rows += [(k, _shown(v)) for k, v in self.metrics().items() if k not in skip]
        return rows

    def _repr_html_(self) -> str:
        import html

        body = "".join(
            f"<tr><th style='text-align:left'>{html.escape(k)}</th>"
            f"<td style='text-align:right'>{html.escape(v)}</td></tr>"
            for k, v in self._summary_rows()
        )
        title = html.escape(str(self.dataset.attrs.get("title", "flexsat run")))
        return f"<table><caption>{title}</caption><tbody>{body}</tbody></table>"

    def raise_for_status(self) -> None:
        """Raise the run's :class:`SimulationError` if it failed."""
        if not self.ok:
            raise SimulationError(self.message)

    def to_netcdf(self, path: str | Path) -> Path:
        """Write the dataset to NetCDF (written to a temporary name, then moved)."""
        from flexsat.files import ensure_dir, replacing_name

        path = Path(path)
        ensure_dir(path.parent)
        streamed = self.path is not None and not path.is_symlink()
        if streamed and path.resolve() == self.path.resolve():
            return path  # a streamed run already written there
        with replacing_name(path) as partial:  # a link at path is replaced, not followed
            if self.path is not None:  # a streamed run: copy its file, never load it whole
                shutil.copyfile(self.path, partial)
            else:
                self.dataset.to_netcdf(partial)
        return path

    @classmethod
    def from_netcdf(cls, path: str | Path) -> Result:
        """Read a result written by :meth:`to_netcdf` (loaded into memory)."""
        import xarray as xr

        with xr.open_dataset(path) as ds:
            return cls(ds.load())


def build_records(
    plant: Plant,
    t: np.ndarray,
    q: np.ndarray,
    qd: np.ndarray,
    work_in: np.ndarray,
    dissipated: np.ndarray,
    tau_cmd: np.ndarray,
    tau_applied: np.ndarray,
    attrs: dict,
    energy0: float | None = None,
    frames: np.ndarray | None = None,
    joint_force: np.ndarray | None = None,
    solved: np.ndarray | None = None,
    more: Callable[[dict], dict] | None = None,
) -> RunRecords:
    """Derive every recorded quantity from the recorded states, as plain arrays.

    What :func:`build_dataset` puts in a run's dataset, without building it: a
    campaign case's metrics and history read these (docs/performance.md, "Campaign
    cases").

    Parameters
    ----------
    plant : Plant
        The plant that flew the run.
    t : ndarray, shape (m,)
        Record times [s].
    q, qd : ndarray, shape (m, n_dof)
        Recorded generalized coordinates [m, rad] and rates [m/s, rad/s].
    work_in, dissipated : ndarray, shape (m,)
        Cumulative work of the applied torque and damper dissipation [J].
    tau_cmd, tau_applied : ndarray, shape (m, 3)
        Commanded and applied body torque held from each record time [N m].
    attrs : dict
        Dataset attributes (configs as JSON, status...).
    energy0 : float, optional
        E(0) of the run [J], for a block of records that does not start at t = 0
        (a streamed run); default: the first record's total energy.
    frames : ndarray, shape (m, 9), optional
        The attitude reference R_NF of each record, row-major [-]
        (:mod:`flexsat.dynamics.attitude`);
        the hub part of ``q`` and ``qd`` is relative to it. Default: the identity.
        The dataset holds every attitude, position and momentum relative to N.
    joint_force : ndarray, shape (m, n_dof), optional
        Generalized forces of the joint actuators held from each record, zero on the
        hub coordinates [N, N m per coordinate] (a slew's joint actuator): the
        accelerations and tau_flex are those of the plant under them, and the dataset
        holds them as ``joint_force``. Default: none (no variable).
    solved : ndarray, shape (m, 2, n_dof), optional
        q_ddot and the locked coordinates' constraint forces of the records the
        compiled loop has them for, rows of NaN elsewhere [m/s^2, rad/s^2; N, N m]
        (``PreparedSlew.rec_solved``); the missing rows are solved for and written
        into it. Default: all solved for.
    more : callable, optional
        Given the data variables (name -> (dims, values, attributes)), returns more
        of them, added to the records.

    Returns
    -------
    RunRecords
        Every variable (the dimension coordinates ``time`` [s], ``axis``, ``euler``,
        ``quat``, ``appendage`` and ``dof`` included) and ``attrs``.
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
    joints = np.zeros((m, n)) if joint_force is None else np.ascontiguousarray(joint_force)
    # the rows solved for are written into it (the run's own buffer, not copied)
    kept = np.full((m, 2, n), np.nan) if solved is None else np.ascontiguousarray(solved)
    # A diverged run keeps its last finite state, whose derived values may overflow.
    with np.errstate(over="ignore", invalid="ignore"):
        derive_records(
            np.ascontiguousarray(q), np.ascontiguousarray(qd), np.ascontiguousarray(tau_applied),
            joints, kept, plant.packed, omega, omega_dot, tau_flex, H, H_rigid, kinetic, elastic,
            tips,
        )  # fmt: skip
    if frames is not None:  # relative to N: H_N = R_NF H_F (docs/model.md)
        q, qd = inertial_records(q, qd, omega, frames)
        H = vectors_to_inertial(H, frames)
        H_rigid = vectors_to_inertial(H_rigid, frames)
    total = kinetic + elastic
    quaternion = _quaternions(q[:, 3:6])
    # Root motion per appendage, as its model defines it.
    blocks = list(zip(plant.models, plant.layout.blocks, strict=True))
    root = [model.root_motion(q[:, b.slice], b.names) for model, b in blocks]
    root_rate = [model.root_motion(qd[:, b.slice], b.names) for model, b in blocks]

    def var(dims, data, units, long_name):
        return (dims, data, {"units": units, "long_name": long_name})

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
            total - (total[0] if energy0 is None else energy0) - work_in + dissipated,
            "J",
            "E(t) - E(0) - W_in(t) + W_diss(t): numerical error of the integration",
        ),
    }
    if joint_force is not None:
        data_vars["joint_force"] = var(
            ("time", "dof"), joint_force, "SI (N, N m)",
            "generalized forces of the joint actuators, held from each record (zero on "
            "the hub coordinates)",
        )  # fmt: skip
    if more is not None:
        data_vars.update(more(data_vars))
    coords = {
        "time": (t, {"units": "s", "long_name": "time since the start of the run"}),
        "axis": (list(AXES), {}),
        "euler": (["roll", "pitch", "yaw"], {}),
        "quat": (["q0", "q1", "q2", "q3"], {}),
        "appendage": (names, {}),
        "dof": (plant.dof_names(), {}),
    }
    variables = {name: Record((dims,) if isinstance(dims, str) else tuple(dims), values, attributes)
                 for name, (dims, values, attributes) in data_vars.items()}  # fmt: skip
    for name, (values, attributes) in coords.items():
        variables[name] = Record((name,), np.asarray(values), attributes)
    return RunRecords(variables, attrs)


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
    energy0: float | None = None,
    frames: np.ndarray | None = None,
    joint_force: np.ndarray | None = None,
    solved: np.ndarray | None = None,
    more: Callable[[dict], dict] | None = None,
) -> xr.Dataset:
    """Derive every recorded quantity from the recorded states, as a run's dataset.

    Parameters
    ----------
    plant, t, q, qd, work_in, dissipated, tau_cmd, tau_applied, attrs : as in :func:`build_records`
        The plant, the records and the attributes.
    energy0, frames, joint_force, solved, more : as in :func:`build_records`
        The optional records.

    Returns
    -------
    xarray.Dataset
        :func:`build_records`' variables and attributes (:func:`dataset_of`).
    """
    return dataset_of(build_records(plant, t, q, qd, work_in, dissipated, tau_cmd, tau_applied,
                                    attrs, energy0, frames, joint_force, solved, more))  # fmt: skip


def dataset_of(records: RunRecords) -> xr.Dataset:
    """The ``xarray.Dataset`` of a run's records (the arrays themselves, not copies).

    Parameters
    ----------
    records : RunRecords
        The records (:func:`build_records`): each record whose only dimension bears
        its name becomes an index coordinate, every other one a data variable.

    Returns
    -------
    xarray.Dataset
        With the records' attributes.
    """
    data_vars, coords = {}, {}
    for name, var in records.variables.items():
        if var.dims == (name,):
            coords[name] = (var.values, var.attrs)
        else:
            data_vars[name] = (var.dims, var.values, var.attrs)
    return _dataset(data_vars, coords, dict(records.attrs))


def _dataset(data_vars: dict, coords: dict, attrs: dict) -> xr.Dataset:
    """``xr.Dataset(data_vars, coords=...)`` of numpy arrays, built from its parts.

    The same dataset (``identical``, coordinates of the same dtype) in less time:
    xarray's constructor inspects every array
    for a dask or other chunked array, and on its first use in a process that imports
    dask (0.4 s in each campaign worker). Here the arrays are numpy arrays by
    construction, so the variables take them as they are (``fastpath``) and each
    dimension coordinate gets its pandas index directly.

    Parameters
    ----------
    data_vars : dict
        Name -> (dims, ndarray, attributes).
    coords : dict
        Dimension name -> (values, attributes): one index coordinate per dimension.
    attrs : dict
        Dataset attributes.
    """
    import pandas as pd
    import xarray as xr
    from xarray.indexes import PandasIndex

    variables, indexes = {}, {}
    for name, (values, attributes) in coords.items():
        values = np.asarray(values)
        index = PandasIndex(pd.Index(values), name, coord_dtype=values.dtype)
        (variable,) = index.create_variables().values()
        variable.attrs.update(attributes)
        variables[name], indexes[name] = variable, index
    data = {name: xr.Variable(dims, values, attributes, fastpath=True)
            for name, (dims, values, attributes) in data_vars.items()}  # fmt: skip
    return xr.Dataset(data, coords=xr.Coordinates(variables, indexes=indexes), attrs=attrs)


def _quaternions(euler: np.ndarray) -> np.ndarray:
    """Scalar-first unit quaternions of R_NB = Rz(psi) Ry(theta) Rx(phi) (eq. 2.25).

    The product q_z(psi) q_y(theta) q_x(phi) of the elementary rotations' quaternions
    written out in half angles: scipy's ``Rotation.from_euler("ZYX", ...)`` composes the
    same product (to 2e-16, same sign) at ten times the cost for a run's records.

    Parameters
    ----------
    euler : ndarray, shape (m, 3)
        ZYX Euler angles (phi, theta, psi) [rad].

    Returns
    -------
    ndarray, shape (m, 4)
        (q0, q1, q2, q3), q0 the scalar part [-].
    """
    c1, c2, c3 = np.cos(0.5 * euler).T
    s1, s2, s3 = np.sin(0.5 * euler).T
    return np.column_stack([
        c1 * c2 * c3 + s1 * s2 * s3,
        s1 * c2 * c3 - c1 * s2 * s3,
        c1 * s2 * c3 + s1 * c2 * s3,
        c1 * c2 * s3 - s1 * s2 * c3,
    ])  # fmt: skip


def _shown(value) -> str:
    """A metric as text: 6 significant digits, vectors comma separated."""
    if isinstance(value, (list, tuple)):
        return ", ".join(_shown(v) for v in value)
    if isinstance(value, float):
        return f"{value:.6g}"
    return str(value)


def _stack(per_appendage: list[tuple[np.ndarray, np.ndarray]], k: int, m: int) -> np.ndarray:
    """Part k of each appendage's (eta, rho) pair as one (m, n, 3) array."""
    return np.stack([pair[k] for pair in per_appendage], axis=1).reshape(m, -1, 3)
