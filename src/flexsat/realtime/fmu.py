"""The plant as an FMI 2.0 co-simulation FMU: body torque in, attitude, rate, tip deflection out.

:class:`OpenLoopStepper` is the open-loop plant stepped from outside (the compiled
RK4 of :func:`flexsat.simulate.run_openloop` at a fixed ``dt``, the torque held over
each step), :func:`fmu_variables` its FMI interface, and :func:`export_fmu` packs it
with a satellite config into an FMU with pythonfmu (the optional extra ``fmu``;
:mod:`flexsat.realtime.fmu_slave` is the FMU's slave class). docs/realtime.md,
'The plant as an FMU' says why FMI 2.0 and what the FMU needs to run.
"""

from __future__ import annotations

import json
import re
import shutil
import sys
import tempfile
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from flexsat.config.load import validate_config
from flexsat.config.models import SatelliteConfig
from flexsat.dynamics.attitude import identity_frame
from flexsat.dynamics.initial import initial_state
from flexsat.dynamics.integrators import rk4_open_loop
from flexsat.dynamics.plant import Plant
from flexsat.errors import ConfigError
from flexsat.simulate.result import build_dataset
from flexsat.simulate.scenario import OpenLoopScenario

__all__ = [
    "CONFIG_RESOURCE",
    "MODEL_NAME",
    "UNITS",
    "FmuVariable",
    "OpenLoopStepper",
    "export_fmu",
    "fmu_variables",
    "load_resources",
]

MODEL_NAME = "FlexsatPlant"
"""The FMU's model name and model identifier (its binary is ``FlexsatPlant.so``)."""
CONFIG_RESOURCE = "satellite.json"
"""The satellite config inside the FMU's resources folder (JSON of the validated config)."""
SETTINGS_RESOURCE = "flexsat_fmu.json"
"""The export's settings inside the resources folder: the default ``dt`` [s]."""

UNITS: dict[str, tuple[dict[str, int], float]] = {
    "1": ({}, 1.0),
    "s": ({"s": 1}, 1.0),
    "m": ({"m": 1}, 1.0),
    "rad": ({"rad": 1}, 1.0),
    "deg": ({"rad": 1}, float(np.pi / 180.0)),
    "rad/s": ({"rad": 1, "s": -1}, 1.0),
    "deg/s": ({"rad": 1, "s": -1}, float(np.pi / 180.0)),
    "N.m": ({"kg": 1, "m": 2, "s": -2}, 1.0),
}
"""The FMU's units: SI base-unit exponents and the factor to SI of each (FMI 2.0
``UnitDefinitions``)."""

_AXES = ("x", "y", "z")
_EULER = ("roll", "pitch", "yaw")


@dataclass(frozen=True)
class FmuVariable:
    """One scalar variable of the FMU.

    Attributes
    ----------
    name : str
        FMI name (structured: ``tip.panel_1.z``).
    causality : str
        ``input``, ``output`` or ``parameter``.
    unit : str
        A key of :data:`UNITS`.
    description : str
        What it is, its frame.
    start : float
        Start value of an input or parameter [its unit]; 0 for an output.
    """

    name: str
    causality: str
    unit: str
    description: str
    start: float = 0.0


def fmu_variables(config: SatelliteConfig, dt_s: float = 1e-3) -> list[FmuVariable]:
    """The FMU's inputs, parameters and outputs for a satellite.

    Parameters
    ----------
    config : SatelliteConfig
        The satellite: one tip-deflection triple per appendage.
    dt_s : float
        Start value of the ``dt`` parameter, the RK4 step [s].

    Returns
    -------
    list of FmuVariable
        Inputs ``tau_x, tau_y, tau_z`` [N m]; parameters ``dt`` [s],
        ``initial_roll, initial_pitch, initial_yaw`` [deg], ``initial_rate_x, _y, _z``
        [deg/s]; outputs ``q0 .. q3`` [1], ``omega_x, _y, _z`` [rad/s],
        ``roll, pitch, yaw`` [rad] and ``tip.<appendage>.x, .y, .z`` [m], in this order.
    """
    out = [FmuVariable(f"tau_{a}", "input", "N.m",
                       f"body torque on the hub about {a}, frame B, held over each step")
           for a in _AXES]  # fmt: skip
    out.append(FmuVariable("dt", "parameter", "s", "RK4 step; every step size a multiple", dt_s))
    out += [FmuVariable(f"initial_{e}", "parameter", "deg", f"hub {e} at t = 0 (ZYX Euler)")
            for e in _EULER]  # fmt: skip
    out += [FmuVariable(f"initial_rate_{a}", "parameter", "deg/s",
                        f"hub body rate about {a} at t = 0, frame B") for a in _AXES]  # fmt: skip
    out += [FmuVariable(f"q{k}", "output", "1",
                        "hub attitude quaternion, B relative to N, scalar first (q0)")
            for k in range(4)]  # fmt: skip
    out += [FmuVariable(f"omega_{a}", "output", "rad/s", f"hub body rate about {a}, frame B")
            for a in _AXES]  # fmt: skip
    out += [FmuVariable(e, "output", "rad", f"hub {e}, ZYX Euler angle relative to N")
            for e in _EULER]  # fmt: skip
    for name in _tip_names(config):
        out += [FmuVariable(f"tip.{name}.{a}", "output", "m",
                            f"tip displacement of {name} along {a}, its mount frame")
                for a in _AXES]  # fmt: skip
    return out


def _tip_names(config: SatelliteConfig) -> list[str]:
    """Each appendage's name as one segment of a structured FMI name."""
    names = [re.sub(r"\W", "_", a.name) for a in config.appendages]
    names = [f"_{n}" if n[:1].isdigit() else n for n in names]
    if len(set(names)) != len(names):
        raise ConfigError(f"appendages: names {names} collide as FMU variable names")
    return names


class OpenLoopStepper:
    """The open-loop plant stepped from outside: RK4 at ``dt_s``, a body torque held.

    The same compiled step as :func:`flexsat.simulate.run_openloop`
    (:func:`~flexsat.dynamics.integrators.rk4_open_loop`), its outputs derived as a
    run's records are (:func:`flexsat.simulate.result.build_dataset`): a native run
    and this stepper under the same torque profile agree to round-off.

    Parameters
    ----------
    plant : Plant
        The satellite.
    dt_s : float
        RK4 step [s], in (0, 0.1].
    attitude_deg : tuple of 3 float
        Hub ZYX Euler angles (roll, pitch, yaw) at t = 0 [deg].
    rate_deg_s : tuple of 3 float
        Hub body rate at t = 0, frame B [deg/s].

    Attributes
    ----------
    x : ndarray, shape (2 n_dof + 2,)
        The augmented state [q, q_dot, W_in, W_diss] (SI).
    frame : ndarray, shape (9,)
        Its attitude reference R_NF, row-major [-].
    time_s : float
        Simulated time of ``x`` [s].
    """

    def __init__(self, plant: Plant, dt_s: float, attitude_deg=(0.0, 0.0, 0.0),
                 rate_deg_s=(0.0, 0.0, 0.0)) -> None:  # fmt: skip
        scenario = validate_config(
            {"dt_s": dt_s, "duration_s": dt_s, "record_dt_s": dt_s, "torque": [],
             "initial": {"attitude_deg": list(attitude_deg), "rate_deg_s": list(rate_deg_s)}},
            "FMU parameters", OpenLoopScenario,
        )  # fmt: skip
        self.plant, self.dt_s = plant, scenario.dt_s
        q0, qd0 = initial_state(plant, scenario)
        self.x = np.concatenate([q0, qd0, [0.0, 0.0]])
        self.frame = identity_frame()
        self.time_s = 0.0
        self.torque = np.zeros(3)
        self._none = np.zeros(0)
        self._rec = (np.zeros(1), np.zeros((1, self.x.size)), np.zeros((1, 3)), np.zeros((1, 9)))

    def steps_in(self, step_s: float) -> int:
        """How many RK4 steps make ``step_s`` [s]; a ConfigError if it is not a whole number.

        Parameters
        ----------
        step_s : float
            A communication step [s].

        Returns
        -------
        int
            step_s / dt_s [-], at least 1.
        """
        n = round(step_s / self.dt_s)
        if n < 1 or abs(n * self.dt_s - step_s) > 1e-9 * step_s:
            raise ConfigError(f"step size {step_s:g} s: must be a whole multiple of dt "
                              f"({self.dt_s:g} s)")  # fmt: skip
        return n

    def step(self, torque_nm: np.ndarray, step_s: float) -> int:
        """Advance ``step_s`` [s] under the body torque ``torque_nm`` [N m], held.

        Parameters
        ----------
        torque_nm : ndarray, shape (3,)
            Body torque on the hub, frame B [N m].
        step_s : float
            Duration, a whole multiple of ``dt_s`` [s].

        Returns
        -------
        int
            0, or the kernel's status of a diverging step (the state stops before it).
        """
        n = self.steps_in(step_s)
        self.torque = np.array(torque_nm, dtype=float)
        # the torque as the held disturbance, no segments: 0.0 + tau of a native run's
        # single active segment is tau, so the arithmetic is the native run's
        status, done = rk4_open_loop(self.x, self.time_s, self.dt_s, n, n + 1, self._none,
                                     self._none, np.zeros((0, 3)), self.torque,
                                     self.plant.packed, self.frame, *self._rec, 0)  # fmt: skip
        self.time_s += done * self.dt_s
        return status

    def outputs(self) -> dict[str, float]:
        """The outputs of :func:`fmu_variables` now, by name.

        Returns
        -------
        dict
            ``q0 .. q3`` [-], ``omega_x ..`` [rad/s], ``roll, pitch, yaw`` [rad],
            ``tip.<appendage>.<axis>`` [m].
        """
        lay = self.plant.layout
        x = self.x[None, :]
        ds = build_dataset(self.plant, np.array([self.time_s]), x[:, lay.q], x[:, lay.qd],
                           x[:, lay.work_in], x[:, lay.dissipated], self.torque[None, :],
                           self.torque[None, :], {}, frames=self.frame[None, :])  # fmt: skip
        out = {f"q{k}": float(v) for k, v in enumerate(ds["quaternion"].values[0])}
        out |= {f"omega_{a}": float(v) for a, v in zip(_AXES, ds["omega"].values[0], strict=True)}
        euler = np.radians(ds["euler_deg"].values[0])
        out |= {e: float(v) for e, v in zip(_EULER, euler, strict=True)}
        tips = ds["tip_displacement"].values[0]
        for name, tip in zip(_tip_names(self.plant.config), tips, strict=True):
            out |= {f"tip.{name}.{a}": float(v) for a, v in zip(_AXES, tip, strict=True)}
        return out


def load_resources(resources: str | Path) -> tuple[SatelliteConfig, float]:
    """The satellite config and default ``dt`` [s] an FMU carries in its resources folder.

    Parameters
    ----------
    resources : str or Path
        The unpacked FMU's ``resources`` folder.

    Returns
    -------
    config : SatelliteConfig
    dt_s : float
        The export's RK4 step [s].
    """
    folder = Path(resources)
    data = json.loads((folder / CONFIG_RESOURCE).read_text(encoding="utf-8"))
    for table in data.get("appendages", []):  # data files travel in the resources
        if isinstance(table.get("file"), str):
            table["file"] = str(folder / table["file"])
    settings = json.loads((folder / SETTINGS_RESOURCE).read_text(encoding="utf-8"))
    return validate_config(data, CONFIG_RESOURCE), float(settings["dt_s"])


def export_fmu(config: SatelliteConfig, path: str | Path, dt_s: float = 1e-3) -> Path:
    """Write the open-loop plant of ``config`` as an FMI 2.0 co-simulation FMU.

    Parameters
    ----------
    config : SatelliteConfig
        The satellite; an appendage's data file is copied into the FMU.
    path : str or Path
        The FMU to write (suffix ``.fmu``).
    dt_s : float
        Default of the FMU's ``dt`` parameter, the RK4 step [s], in (0, 0.1].

    Returns
    -------
    Path
        ``path``.

    Raises
    ------
    ConfigError
        A suffix other than ``.fmu``, a ``dt_s`` out of range, or pythonfmu missing
        (the extra ``fmu``).
    """
    path = Path(path)
    if path.suffix.lower() != ".fmu":
        raise ConfigError(f"--output: the suffix must be .fmu, got {path.name!r}")
    if not 0.0 < dt_s <= 0.1:
        raise ConfigError(f"--dt: must be in (0, 0.1] s, got {dt_s:g}")
    try:
        from pythonfmu import FmuBuilder
    except ImportError:
        raise ConfigError(
            "flexsat fmu export needs pythonfmu: pip install 'flexsat[fmu]'"
        ) from None
    slave = Path(__file__).with_name("fmu_slave.py")  # the slave's script, not imported here
    data = config.model_dump(mode="json")
    with tempfile.TemporaryDirectory(prefix="flexsat-fmu-") as folder:
        # the script alone in its folder: the builder puts that folder on sys.path
        script = Path(folder) / "script" / slave.name
        resources = Path(folder) / "resources"
        script.parent.mkdir()
        resources.mkdir()
        shutil.copyfile(slave, script)
        for k, table in enumerate(data.get("appendages", [])):
            if isinstance(table.get("file"), str):
                source = Path(table["file"])
                table["file"] = f"appendage_{k}_{source.name}"
                shutil.copyfile(source, resources / table["file"])
        (resources / CONFIG_RESOURCE).write_text(json.dumps(data), encoding="utf-8")
        (resources / SETTINGS_RESOURCE).write_text(json.dumps({"dt_s": dt_s}), encoding="utf-8")
        path.parent.mkdir(parents=True, exist_ok=True)
        try:
            FmuBuilder.build_FMU(script, dest=path, project_files=sorted(resources.iterdir()))
        finally:
            if str(script.parent) in sys.path:
                sys.path.remove(str(script.parent))
            sys.modules.pop(script.stem, None)
    return path
