"""Any discrete state-space controller in the loop: x+ = A x + B y, tau = C x + D y.

The controller is read from a file (NPZ or MATLAB ``.mat``) holding ``A`` (n, n),
``B`` (n, 6), ``C`` (3, n), ``D`` (3, 6) and ``dt`` (the period it was discretized
at [s], which must equal the loop's ``control_dt_s``). Its input, per call, is

    y = [theta_x, theta_y, theta_z, omega_e,x, omega_e,y, omega_e,z]

theta the attitude error as a rotation vector in the hub frame B [rad]
(theta_err q_v,e / ‖q_v,e‖, q_e = q_d^-1 (x) q with q_e0 >= 0; to first order the
small ZYX angles phi, theta, psi of :func:`flexsat.linear.linearize`), omega_e the
body-rate error [rad/s]. Its output is the body torque command [N m], clipped to
RF T_max per axis like every law's. Sign convention: the controller is
tau = K(z) y (the minus sign of negative feedback is inside D and C), the
convention :func:`flexsat.linear.hinf.synthesize` writes. The compiled step is the
difference equation itself, dense, with no allocation (``docs/control.md``,
"A state-space controller").
"""

from __future__ import annotations

import io
from dataclasses import dataclass
from pathlib import Path
from typing import Literal

import numpy as np
from numba import njit
from pydantic import Field, PrivateAttr, model_validator

from flexsat.control.laws._sliding import errors
from flexsat.control.laws.registry import LawConfig, LawSpec
from flexsat.control.registry import Channel

__all__ = [
    "CONTROLLER_INPUTS",
    "MAX_ORDER",
    "STATESPACE",
    "ControllerFileConfig",
    "DiscreteController",
    "StateSpaceConfig",
    "load_controller",
    "pack_controller",
    "save_controller",
]

MAX_ORDER = 64
"""Largest controller order the law runs (its state vector is allocated at this size)."""

CONTROLLER_INPUTS = ("theta_x", "theta_y", "theta_z", "omega_x", "omega_y", "omega_z")
"""The controller's inputs, in order: attitude error [rad], body-rate error [rad/s]."""

N_IN, N_OUT = 6, 3
_DT_RTOL = 1e-9  # the file's dt and the loop's control period agree to this relative tolerance
_MAX_ENTRY = 1e12  # |entries| above this are refused (no controller of flexsat's plants needs them)

# header of the packed gains: T_max, RF, n, dt, then A, B, C, D row-major
_T_MAX, _RF, _N, _DT, _HEADER = 0, 1, 2, 3, 4


@dataclass(frozen=True, eq=False)
class DiscreteController:
    """A discrete-time controller x[k+1] = A x[k] + B y[k], tau[k] = C x[k] + D y[k].

    Attributes
    ----------
    A : ndarray, shape (n, n)
        State matrix [-].
    B : ndarray, shape (n, 6)
        Input matrix, columns :data:`CONTROLLER_INPUTS` [1/rad, s/rad].
    C : ndarray, shape (3, n)
        Output matrix, rows the body torque x, y, z [N m].
    D : ndarray, shape (3, 6)
        Feedthrough [N m/rad, N m s/rad].
    dt : float
        Sample period it was discretized at [s].
    """

    A: np.ndarray
    B: np.ndarray
    C: np.ndarray
    D: np.ndarray
    dt: float

    @property
    def order(self) -> int:
        return int(self.A.shape[0])

    def to_statespace(self):
        """The controller as a discrete ``control.StateSpace`` (sample time ``dt``)."""
        import control

        outputs = ["tau_x", "tau_y", "tau_z"]
        return control.ss(self.A, self.B, self.C, self.D, self.dt,
                          inputs=list(CONTROLLER_INPUTS), outputs=outputs)  # fmt: skip


def _check(name: str, A, B, C, D, dt) -> DiscreteController:
    """The matrices as float arrays, their shapes, finiteness and dt checked (ValueError)."""
    arrays = {}
    for key, value in (("A", A), ("B", B), ("C", C), ("D", D)):
        try:
            arr = np.atleast_2d(np.asarray(value, dtype=float))
        except (TypeError, ValueError):
            raise ValueError(f"{name}: {key} is not a numeric matrix") from None
        if arr.ndim != 2:
            raise ValueError(f"{name}: {key} must be a matrix, got {arr.ndim} dimensions")
        if not np.all(np.isfinite(arr)) or np.abs(arr).max(initial=0.0) > _MAX_ENTRY:
            raise ValueError(f"{name}: {key} must hold finite entries within +-{_MAX_ENTRY:g}")
        arrays[key] = arr
    n = arrays["A"].shape[0]
    expected = {"A": (n, n), "B": (n, N_IN), "C": (N_OUT, n), "D": (N_OUT, N_IN)}
    if not 1 <= n <= MAX_ORDER:
        raise ValueError(f"{name}: the order (rows of A) must be in 1..{MAX_ORDER}, got {n}")
    for key, shape in expected.items():
        if arrays[key].shape != shape:
            raise ValueError(
                f"{name}: {key} must have shape {shape} (n = {n} states, 6 inputs "
                f"{', '.join(CONTROLLER_INPUTS)}, 3 torque outputs), got {arrays[key].shape}"
            )
    try:
        dt_value = float(np.asarray(dt, dtype=float).reshape(-1)[0]) if np.size(dt) == 1 else None
    except (TypeError, ValueError):
        dt_value = None
    if dt_value is None or not np.isfinite(dt_value) or not 0.0 < dt_value <= 10.0:
        raise ValueError(f"{name}: dt must be one number in (0, 10] s, got {dt!r}")
    return DiscreteController(arrays["A"], arrays["B"], arrays["C"], arrays["D"], dt_value)


def load_controller(path: str | Path) -> DiscreteController:
    """Read and check a controller file (NPZ or MATLAB ``.mat``; module docstring).

    Parameters
    ----------
    path : str or Path
        The file; its suffix (``.npz`` or ``.mat``) says the format.

    Returns
    -------
    DiscreteController

    Raises
    ------
    ConfigError
        Unreadable or not a regular file, an unknown suffix, a missing variable, a
        matrix of the wrong shape, a non-finite entry, an order above
        :data:`MAX_ORDER`, a dt outside (0, 10] s; the message names the file.
    """
    from flexsat.errors import ConfigError
    from flexsat.files import read_user_file

    path = Path(path)
    name = f"controller file {path}"
    suffix = path.suffix.lower()
    if suffix not in (".npz", ".mat"):
        raise ConfigError(f"{name}: the suffix must be .npz or .mat, got {suffix or 'none'!r}")
    data = read_user_file(path, "controller")
    try:
        if suffix == ".npz":
            with np.load(io.BytesIO(data), allow_pickle=False) as npz:
                variables = {k: npz[k] for k in npz.files}
        else:
            from scipy.io import loadmat

            variables = loadmat(io.BytesIO(data))
    except Exception as exc:  # any parse failure of a user's file is one message
        raise ConfigError(f"{name}: not a readable {suffix} file ({type(exc).__name__})") from None
    missing = [k for k in ("A", "B", "C", "D", "dt") if k not in variables]
    if missing:
        raise ConfigError(
            f"{name}: missing variable(s) {', '.join(missing)} (needs A, B, C, D, dt)"
        )
    try:
        return _check(name, *(variables[k] for k in ("A", "B", "C", "D", "dt")))
    except ValueError as exc:
        raise ConfigError(str(exc)) from None


def save_controller(controller: DiscreteController, path: str | Path) -> Path:
    """Write a controller in the format :func:`load_controller` reads.

    Parameters
    ----------
    controller : DiscreteController
        The controller.
    path : str or Path
        Ends in ``.npz`` or ``.mat`` (the format).

    Returns
    -------
    Path
        ``path``.
    """
    from flexsat.errors import ConfigError
    from flexsat.files import replacing

    path = Path(path)
    arrays = {"A": controller.A, "B": controller.B, "C": controller.C, "D": controller.D,
              "dt": np.array(controller.dt)}  # fmt: skip
    if path.suffix.lower() == ".npz":
        with replacing(path) as handle:
            np.savez(handle, **arrays)
    elif path.suffix.lower() == ".mat":
        from scipy.io import savemat

        with replacing(path) as handle:
            savemat(handle, arrays)
    else:
        raise ConfigError(f"controller file {path}: the suffix must be .npz or .mat")
    return path


def pack_controller(controller: DiscreteController, t_max: float, rf: float) -> np.ndarray:
    """The law's packed gains: T_max, RF, n, dt, then A, B, C, D row-major.

    Parameters
    ----------
    controller : DiscreteController
        The controller.
    t_max : float
        T_max per axis [N m].
    rf : float
        Reduction factor RF of the software limit RF T_max [-].

    Returns
    -------
    ndarray, shape (4 + n^2 + 6 n + 3 n + 18,)
        The gains :func:`statespace_step` reads [SI].
    """
    head = np.array([t_max, rf, controller.order, controller.dt])
    return np.concatenate([head, *(m.ravel() for m in (controller.A, controller.B,
                                                       controller.C, controller.D))])  # fmt: skip


class ControllerFileConfig(LawConfig):
    """What a law flying a discrete controller from a file holds: the file, read and
    checked once, and its discretization period against the loop's."""

    file: str = Field(description="the controller file (.npz or .mat: A, B, C, D, dt)")
    _controller: DiscreteController | None = PrivateAttr(None)

    @model_validator(mode="after")
    def _read(self) -> ControllerFileConfig:
        self._controller = load_controller(self.file)  # ConfigError is a ValueError: names file
        return self

    @property
    def controller(self) -> DiscreteController:
        """The controller the file holds."""
        return self._controller

    def check(self, scenario) -> None:
        dt = self.controller.dt
        if abs(dt - scenario.control_dt_s) > _DT_RTOL * scenario.control_dt_s:
            raise ValueError(
                f"file: the controller was discretized at dt = {dt:g} s, the loop runs at "
                f"control_dt_s = {scenario.control_dt_s:g} s; they must be equal"
            )


class StateSpaceConfig(ControllerFileConfig):
    """A discrete state-space controller read from a file (module docstring)."""

    kind: Literal["statespace"] = Field("statespace", description="the law's registered name")

    def gains(self, actuator) -> np.ndarray:
        return pack_controller(self.controller, actuator.t_max_nm, actuator.reduction_factor)


@njit(cache=True)
def controller_input(q_d, omega_d, omega_dot_d, q, omega_B):
    """y = (rotation-vector attitude error [rad], body-rate error [rad/s]) (module docstring)."""
    qv, _, omega_e, theta_err, _ = errors(q_d, omega_d, omega_dot_d, q, omega_B)
    norm = np.sqrt(qv[0] ** 2 + qv[1] ** 2 + qv[2] ** 2)
    k = theta_err / norm if norm > 0.0 else 2.0
    return (k * qv[0], k * qv[1], k * qv[2], omega_e[0], omega_e[1], omega_e[2])


@njit(cache=True)
def ss_output(gains, off, n, x, y, tau):
    """tau = C x + D y from the packed matrices starting at ``gains[off]`` (A first)."""
    c = off + n * n + n * N_IN
    d = c + N_OUT * n
    for i in range(N_OUT):
        acc = 0.0
        for j in range(n):
            acc += gains[c + i * n + j] * x[j]
        for j in range(N_IN):
            acc += gains[d + i * N_IN + j] * y[j]
        tau[i] = acc


@njit(cache=True)
def ss_update(gains, off, n, x, y, scratch):
    """x <- A x + B y in place (``scratch`` of length >= n holds the new state)."""
    b = off + n * n
    for i in range(n):
        acc = 0.0
        row = off + i * n
        for j in range(n):
            acc += gains[row + j] * x[j]
        brow = b + i * N_IN
        for j in range(N_IN):
            acc += gains[brow + j] * y[j]
        scratch[i] = acc
    for i in range(n):
        x[i] = scratch[i]


@njit(cache=True)  # compiled with LAW_SIGNATURE on first use
def statespace_step(q_d, omega_d, omega_dot_d, q, omega_B, J, gains, state, t, dt, tau_cmd, diag):
    """The state-space controller's command (law contract in
    :mod:`flexsat.control.laws.registry`).

    ``state``: x (first n of :data:`MAX_ORDER`), then scratch for the update.
    """
    limit = gains[_RF] * gains[_T_MAX]
    n = int(gains[_N])
    y = controller_input(q_d, omega_d, omega_dot_d, q, omega_B)
    ss_output(gains, _HEADER, n, state, y, diag)  # unclipped tau, diag[0:3]
    ss_update(gains, _HEADER, n, state, y, state[MAX_ORDER:])
    for a in range(3):
        tau_cmd[a] = min(limit, max(-limit, diag[a]))
    return 0


STATESPACE = LawSpec(
    name="statespace", label="SS", config=StateSpaceConfig, step=statespace_step,
    state_size=2 * MAX_ORDER,
    diagnostics=(Channel("tau_linear", "N m", "C x + D y before the clip", per_axis=True),),
    description="a discrete state-space controller read from a file (NPZ or .mat)",
)  # fmt: skip
