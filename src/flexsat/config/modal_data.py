"""The modal-appendage data format: an interface-clamped structure's modes, versioned.

One file describes one appendage as the hybrid-coordinate model needs it
(docs/modal_format.md): its rigid mass properties about the interface point, in the
interface (mount) frame M, and n flexible modes of the structure clamped at that
point, mass-normalized (phi^T M phi = 1), each with its frequency, damping ratio and
six participation factors at the interface, plus optional output points with their
mode-shape rows. TOML suits a handful of modes, NPZ many; both carry the same keys and
``format_version``. Files are validated at load; NPZ files are read with
``allow_pickle=False``.
"""

from __future__ import annotations

import tomllib
import zipfile
import zlib
from pathlib import Path
from typing import Annotated, Any, Literal

import numpy as np
from pydantic import AllowInfNan, BaseModel, ConfigDict, Field, Strict, model_validator

from flexsat.errors import ConfigError
from flexsat.files import check_user_file, read_user_file, replacing, write_text

__all__ = [
    "FORMAT_VERSION",
    "ModalData",
    "OutputPoint",
    "load_modal_data",
    "modal_data_from_dict",
    "save_modal_data",
]

FORMAT_VERSION = 1

# Every number is bounded, so that nothing downstream overflows (L^T L of 2000 modes,
# omega^2, the eigenproblem of the hub and its appendages): the ranges span far beyond
# any spacecraft structure.
Real = Annotated[float, Strict(), AllowInfNan(False), Field(ge=-1e12, le=1e12)]
Length = Annotated[float, Strict(), AllowInfNan(False), Field(ge=-1e3, le=1e3)]  # [m]
Finite = Annotated[float, Strict(), AllowInfNan(False)]
# Checked with the ordering, by :class:`ModalData`. The top is far above any structural
# mode (a Craig-Bampton model keeping every mode of a coarse solid mesh reaches 1e5 Hz)
# and keeps (2 pi f)^2 and its products finite in the eigenproblems.
_FREQUENCY_RANGE_HZ = (1e-3, 1e8)
Vector3 = tuple[Real, Real, Real]
Point3 = tuple[Length, Length, Length]
Vector6 = tuple[Real, Real, Real, Real, Real, Real]
Matrix3 = tuple[Vector3, Vector3, Vector3]
_MAX_MODES = 2000
_MAX_OUTPUT_POINTS = 1000
# The most numbers one NPZ array may hold: output_mode_shapes at the largest counts.
_MAX_NUMBERS = _MAX_OUTPUT_POINTS * _MAX_MODES * 3
# Deflate compresses at most 1032:1: a member declaring more is not a deflated array.
_DEFLATE_MAX_RATIO = 1032
_NPZ_KEYS = ("format_version", "mass_kg", "center_of_mass_m", "inertia_interface_kg_m2",
             "frequencies_hz", "damping_ratios", "participation", "inertia_derivatives",
             "output_names", "output_positions_m", "output_mode_shapes", "damping_matrix",
             "first_moment_hessian", "coupling_gradient", "inertia_hessian")  # fmt: skip
# The second-order (large-motion) invariants hold n^2 entries per mode pair: they are
# accepted up to this many modes (9 n^2 = 810 000 numbers for the inertia's).
_MAX_SECOND_ORDER_MODES = 300
_SECOND_ORDER = ("first_moment_hessian", "coupling_gradient", "inertia_hessian")
# Relative slack of the positive-semidefiniteness tests (round-off of the file's own
# digits: a reduction written with 16 significant digits is exact to ~1e-15).
_PSD_RTOL = 1e-9


class _Frozen(BaseModel):
    model_config = ConfigDict(frozen=True, extra="forbid")


class OutputPoint(_Frozen):
    """A point of the structure whose motion is reported (e.g. the tip)."""

    name: Annotated[str, Field(min_length=1, max_length=64, description="the point's name")]
    position_m: Point3 = Field(description="undeformed position from the interface, frame M [m]")
    mode_shapes: list[Vector3] = Field(
        description="per mode, the point's translation per unit modal coordinate, frame M "
        "[m/(sqrt(kg) m)]"
    )


class ModalData(_Frozen):
    """One interface-clamped appendage: rigid mass properties and flexible modes.

    Frame M is the appendage's interface (mount) frame; the interface point is its
    origin. Participation factors are L_k = phi_k^T M_fr: the first three the
    translational ones [sqrt(kg)], the last three the rotational ones about the
    interface point [sqrt(kg) m]; the effective mass of mode k is L_k^T L_k (6 x 6).
    """

    format_version: Literal[1] = Field(description="version of this format")
    mass_kg: Annotated[
        float, Strict(), AllowInfNan(False), Field(gt=0.0, le=1e7, description="mass [kg]")
    ]
    center_of_mass_m: Point3 = Field(description="interface -> centre of mass, frame M [m]")
    inertia_interface_kg_m2: Matrix3 = Field(
        description="inertia about the interface point, frame M [kg m^2]"
    )
    frequencies_hz: Annotated[list[Finite], Field(max_length=_MAX_MODES)] = Field(
        description="interface-clamped natural frequencies, ascending, each within "
        "[1e-3, 1e8] Hz [Hz]"
    )
    damping_ratios: list[Real] = Field(description="modal damping ratio zeta_k, in [0, 1) [-]")
    participation: list[Vector6] = Field(
        description="L_k per mode: translation [sqrt(kg)], rotation about the interface "
        "[sqrt(kg) m], frame M"
    )
    inertia_derivatives: list[Matrix3] = Field(
        default_factory=list,
        description="optional: J'_k = dJ_I/d eta_k per mode, about the interface, frame M "
        "[sqrt(kg) m]; none: the inertia does not change with the modes",
    )
    output_points: Annotated[list[OutputPoint], Field(max_length=_MAX_OUTPUT_POINTS)] = Field(
        default_factory=list, description="points whose motion is reported (e.g. the tip)"
    )
    damping_matrix: list[list[Real]] = Field(
        default_factory=list,
        description="optional: the full modal damping matrix phi^T C phi (n x n, symmetric, "
        "positive semi-definite, its diagonal 2 zeta_k omega_k) [1/s]; none: diagonal",
    )
    first_moment_hessian: list[list[Vector3]] = Field(
        default_factory=list,
        description="optional, large motion: C_kl = d^2 c~/d eta_k d eta_l (n x n x 3, "
        "symmetric in k, l), about the interface, frame M [1/m]",
    )
    coupling_gradient: list[list[Vector3]] = Field(
        default_factory=list,
        description="optional, large motion: E_kl = d h_k/d eta_l, the rotational coupling "
        "of mode k, sum_p m_p x_p x dx_p/d eta_k, along mode l (n x n x 3), frame M [-]",
    )
    inertia_hessian: list[list[Matrix3]] = Field(
        default_factory=list,
        description="optional, large motion: J''_kl = d^2 J_I/d eta_k d eta_l (n x n x 3 x "
        "3, symmetric in k, l and as matrices), about the interface, frame M [-]",
    )

    @model_validator(mode="after")
    def _consistent(self) -> ModalData:
        n = len(self.frequencies_hz)
        for field in ("damping_ratios", "participation"):
            got = len(getattr(self, field))
            if got != n:
                raise ValueError(f"{field}: expected one entry per mode ({n}), got {got}")
        f = np.asarray(self.frequencies_hz, dtype=float)
        if n and f.min() <= 0.0:
            raise ValueError(f"frequencies_hz: must be > 0 Hz, got {f.min():.6g}")
        low, high = _FREQUENCY_RANGE_HZ
        outside = np.flatnonzero((f < low) | (f > high))
        if outside.size:
            k = int(outside[0])
            raise ValueError(f"frequencies_hz: each must be within [{low:g}, {high:g}] Hz, "
                             f"mode {k + 1} is {f[k]:.6g} Hz")  # fmt: skip
        if np.any(np.diff(f) < 0.0):
            k = int(np.argmax(np.diff(f) < 0.0))
            raise ValueError(
                f"frequencies_hz: must be sorted ascending, mode {k + 2} ({f[k + 1]:.6g} Hz) "
                f"is below mode {k + 1} ({f[k]:.6g} Hz)"
            )
        if self.inertia_derivatives and len(self.inertia_derivatives) != n:
            raise ValueError(
                f"inertia_derivatives: expected one 3 x 3 matrix per mode ({n}) or none, "
                f"got {len(self.inertia_derivatives)}"
            )
        dJ = self.inertia_derivative_array()
        if np.abs(dJ - dJ.transpose(0, 2, 1)).max(initial=0.0) > _PSD_RTOL * max(
                np.abs(dJ).max(initial=0.0), 1e-300):  # fmt: skip
            raise ValueError("inertia_derivatives: each matrix must be symmetric")
        zeta = np.asarray(self.damping_ratios, dtype=float)
        if n and (zeta.min() < 0.0 or zeta.max() >= 1.0):
            raise ValueError("damping_ratios: each must be in [0, 1)")
        self._check_damping_matrix(f, zeta)
        self._check_second_order()
        J = np.asarray(self.inertia_interface_kg_m2, dtype=float)
        if np.max(np.abs(J - J.T)) > _PSD_RTOL * np.max(np.abs(J)):
            raise ValueError("inertia_interface_kg_m2: must be symmetric (J == J^T)")
        rigid = self.rigid_mass_matrix()
        scale = float(np.max(np.abs(rigid)))
        if np.linalg.eigvalsh(rigid)[0] <= _PSD_RTOL * scale:
            raise ValueError(
                "inertia_interface_kg_m2: the rigid mass matrix about the interface "
                "[[m I, -m [c]x], [m [c]x, J]] must be positive definite (the inertia about "
                "the centre of mass J - m [c]x^T [c]x must be positive definite)"
            )
        for p, point in enumerate(self.output_points):
            if len(point.mode_shapes) != n:
                raise ValueError(
                    f"output_points[{p}].mode_shapes: expected one row per mode ({n}), "
                    f"got {len(point.mode_shapes)}"
                )
        residual = rigid - self.effective_mass()
        worst = float(np.linalg.eigvalsh(residual)[0])
        if worst < -_PSD_RTOL * scale:
            axis = int(np.argmin(np.diag(residual)))
            names = ("translation x", "translation y", "translation z",
                     "rotation x", "rotation y", "rotation z")  # fmt: skip
            raise ValueError(
                "participation: the modal effective masses exceed the rigid mass (sum_k "
                "L_k^T L_k must not exceed the rigid mass matrix about the interface; "
                f"worst direction {names[axis]}: effective {self.effective_mass()[axis, axis]:.6g}"
                f" > rigid {rigid[axis, axis]:.6g}); check the participation factors' units "
                "(mass-normalized modes)"
            )
        return self

    def _check_damping_matrix(self, f: np.ndarray, zeta: np.ndarray) -> None:
        if not self.damping_matrix:
            return
        n = self.n_modes
        rows = [len(r) for r in self.damping_matrix]
        if len(rows) != n or any(r != n for r in rows):
            raise ValueError(f"damping_matrix: expected {n} x {n} (one row and column per "
                             f"mode), got {len(rows)} rows of lengths "
                             f"{sorted(set(rows))}")  # fmt: skip
        D = np.asarray(self.damping_matrix, dtype=float)
        top = max(np.abs(D).max(initial=0.0), 1e-300)
        if np.abs(D - D.T).max() > _PSD_RTOL * top:
            raise ValueError("damping_matrix: must be symmetric")
        if np.linalg.eigvalsh(D)[0] < -_PSD_RTOL * top:
            raise ValueError("damping_matrix: must be positive semi-definite (no mode "
                             "combination may gain energy from the dampers)")  # fmt: skip
        diagonal = 4.0 * np.pi * zeta * f
        worst = np.abs(np.diag(D) - diagonal).max()
        if worst > _PSD_RTOL * max(top, np.abs(diagonal).max()):
            raise ValueError("damping_matrix: its diagonal must be 2 zeta_k omega_k of "
                             "damping_ratios and frequencies_hz (off by "
                             f"{worst:.3g} 1/s)")  # fmt: skip

    def _check_second_order(self) -> None:
        given = [name for name in _SECOND_ORDER if getattr(self, name)]
        if not given:
            return
        n = self.n_modes
        if len(given) != len(_SECOND_ORDER):
            missing = [name for name in _SECOND_ORDER if name not in given]
            raise ValueError(f"{missing[0]}: the large-motion invariants come together "
                             f"({', '.join(_SECOND_ORDER)}); {', '.join(given)} given "
                             "without it")  # fmt: skip
        if n > _MAX_SECOND_ORDER_MODES:
            raise ValueError(f"{given[0]}: the large-motion invariants are accepted up to "
                             f"{_MAX_SECOND_ORDER_MODES} modes, the data has {n}")  # fmt: skip
        for name in _SECOND_ORDER:
            rows = [len(r) for r in getattr(self, name)]
            if len(rows) != n or any(r != n for r in rows):
                raise ValueError(f"{name}: expected {n} x {n} entries (one per pair of "
                                 f"modes), got {len(rows)} rows of lengths "
                                 f"{sorted(set(rows))}")  # fmt: skip
        C, H = self.first_moment_hessian_array(), self.inertia_hessian_array()
        for name, x, swapped in (
            ("first_moment_hessian", C, C.transpose(1, 0, 2)),
            ("inertia_hessian", H, H.transpose(1, 0, 2, 3)),
            ("inertia_hessian", H, H.transpose(0, 1, 3, 2)),
        ):
            if np.abs(x - swapped).max() > _PSD_RTOL * max(np.abs(x).max(), 1e-300):
                raise ValueError(f"{name}: must be symmetric (in the mode pair k, l; the "
                                 "inertia's 3 x 3 matrices too)")  # fmt: skip

    @property
    def second_order(self) -> bool:
        """True when the data carries the large-motion invariants."""
        return bool(self.first_moment_hessian)

    def first_moment_hessian_array(self) -> np.ndarray:
        """C_kl, shape (n, n, 3) [1/m] (zeros when the data gives none)."""
        if not self.first_moment_hessian:
            return np.zeros((self.n_modes, self.n_modes, 3))
        return np.asarray(self.first_moment_hessian, dtype=float).reshape(
            self.n_modes, self.n_modes, 3
        )

    def coupling_gradient_array(self) -> np.ndarray:
        """E_kl, shape (n, n, 3) [-] (zeros when the data gives none)."""
        if not self.coupling_gradient:
            return np.zeros((self.n_modes, self.n_modes, 3))
        return np.asarray(self.coupling_gradient, dtype=float).reshape(
            self.n_modes, self.n_modes, 3
        )

    def inertia_hessian_array(self) -> np.ndarray:
        """J''_kl, shape (n, n, 3, 3) [-] (zeros when the data gives none)."""
        if not self.inertia_hessian:
            return np.zeros((self.n_modes, self.n_modes, 3, 3))
        return np.asarray(self.inertia_hessian, dtype=float).reshape(
            self.n_modes, self.n_modes, 3, 3
        )

    def damping_matrix_array(self) -> np.ndarray:
        """The modal damping matrix, shape (n, n) [1/s]: the file's, else diagonal."""
        if self.damping_matrix:
            return np.asarray(self.damping_matrix, dtype=float).reshape(self.n_modes, self.n_modes)
        omega = 2.0 * np.pi * np.asarray(self.frequencies_hz, dtype=float)
        return np.diag(2.0 * np.asarray(self.damping_ratios, dtype=float) * omega)

    @property
    def n_modes(self) -> int:
        return len(self.frequencies_hz)

    def rigid_mass_matrix(self) -> np.ndarray:
        """M_rr about the interface point, frame M, ordered [translation; rotation], (6, 6)."""
        m = self.mass_kg
        c = np.asarray(self.center_of_mass_m, dtype=float)
        C = np.array([[0.0, -c[2], c[1]], [c[2], 0.0, -c[0]], [-c[1], c[0], 0.0]])
        out = np.zeros((6, 6))
        out[:3, :3] = m * np.eye(3)
        out[:3, 3:] = -m * C
        out[3:, :3] = m * C
        out[3:, 3:] = np.asarray(self.inertia_interface_kg_m2, dtype=float)
        return out

    def participation_matrix(self) -> np.ndarray:
        """L, shape (n, 6): row k is mode k's participation factors."""
        return np.asarray(self.participation, dtype=float).reshape(self.n_modes, 6)

    def inertia_derivative_array(self) -> np.ndarray:
        """J'_k per mode, shape (n, 3, 3) (zeros when the file gives none)."""
        if not self.inertia_derivatives:
            return np.zeros((self.n_modes, 3, 3))
        return np.asarray(self.inertia_derivatives, dtype=float).reshape(self.n_modes, 3, 3)

    def effective_mass(self) -> np.ndarray:
        """Sum of the modal effective masses L^T L about the interface, frame M, (6, 6)."""
        L = self.participation_matrix()
        return L.T @ L

    def to_arrays(self) -> dict[str, np.ndarray]:
        """The format's keys as arrays (the NPZ layout)."""
        n = self.n_modes
        return {
            "format_version": np.array(FORMAT_VERSION),
            "mass_kg": np.array(self.mass_kg),
            "center_of_mass_m": np.array(self.center_of_mass_m),
            "inertia_interface_kg_m2": np.array(self.inertia_interface_kg_m2),
            "frequencies_hz": np.array(self.frequencies_hz, dtype=float),
            "damping_ratios": np.array(self.damping_ratios, dtype=float),
            "participation": self.participation_matrix(),
            "inertia_derivatives": np.array(self.inertia_derivatives,
                                            dtype=float).reshape(-1, 3, 3),
            "output_names": np.array([p.name for p in self.output_points], dtype=str),
            "output_positions_m": np.array([p.position_m for p in self.output_points],
                                           dtype=float).reshape(-1, 3),
            "output_mode_shapes": np.array([p.mode_shapes for p in self.output_points],
                                           dtype=float).reshape(-1, n, 3),
            "damping_matrix": np.array(self.damping_matrix, dtype=float).reshape(
                (n, n) if self.damping_matrix else (0,)),
            **{name: np.array(getattr(self, name), dtype=float).reshape(
                (n, n, *(3, 3)[: 2 if name == "inertia_hessian" else 1])
                if self.second_order else (0,)) for name in _SECOND_ORDER},
        }  # fmt: skip


def _from_arrays(arrays: dict[str, np.ndarray]) -> dict[str, Any]:
    """NPZ arrays -> the plain dict of the format (validated by :class:`ModalData`)."""
    data: dict[str, Any] = {}
    for key, value in arrays.items():
        if key.startswith("output_"):
            continue
        data[key] = value.item() if value.ndim == 0 else value.tolist()
    names = arrays.get("output_names", np.zeros(0, dtype=str))
    positions = arrays.get("output_positions_m", np.zeros((0, 3)))
    shapes = arrays.get("output_mode_shapes", np.zeros((0, 0, 3)))
    for key, value, ndim, shape in (("output_names", names, 1, "(k,)"),
                                    ("output_positions_m", positions, 2, "(k, 3)"),
                                    ("output_mode_shapes", shapes, 3, "(k, n, 3)")):  # fmt: skip
        if value.ndim != ndim:
            raise ValueError(f"{key}: expected an array of shape {shape}, got shape "
                             f"{value.shape}")  # fmt: skip
    if not len(names) == len(positions) == len(shapes):
        raise ValueError(
            "output_names, output_positions_m and output_mode_shapes: expected one entry "
            f"per output point, got {len(names)}, {len(positions)} and {len(shapes)}"
        )
    data["output_points"] = [
        {"name": str(n), "position_m": p.tolist(), "mode_shapes": s.tolist()}
        for n, p, s in zip(names, positions, shapes, strict=True)
    ]
    return data


def _read_npz(path: Path) -> dict[str, np.ndarray]:
    """The arrays of an NPZ file, each header checked before its array is allocated.

    A header's shape is not trusted: before reading, each member must be one of the
    format's keys, hold no Python objects (nothing is unpickled), declare at most
    ``_MAX_NUMBERS`` numbers, and declare exactly as many bytes as the member holds,
    which in turn must fit its compressed size (stored: equal; deflated: at most
    1032 times). A truncated or forged file is refused before any large allocation.
    """
    from numpy.lib import format as npy

    arrays: dict[str, np.ndarray] = {}
    with zipfile.ZipFile(path) as archive:
        for info in archive.infolist():
            key = info.filename.removesuffix(".npy")
            if key not in _NPZ_KEYS or not info.filename.endswith(".npy"):
                raise ValueError(f"unknown member {info.filename[:80]!r} (allowed: "
                                 f"{', '.join(k + '.npy' for k in _NPZ_KEYS)})")  # fmt: skip
            ratio = 1 if info.compress_type == zipfile.ZIP_STORED else _DEFLATE_MAX_RATIO
            if info.file_size > ratio * info.compress_size + 64:
                raise ValueError(f"{key}: the member declares {info.file_size} bytes in "
                                 f"{info.compress_size} compressed bytes (damaged or "
                                 "forged)")  # fmt: skip
            with archive.open(info) as member:
                version = npy.read_magic(member)
                if version == (1, 0):
                    shape, _, dtype = npy.read_array_header_1_0(member)
                elif version == (2, 0):
                    shape, _, dtype = npy.read_array_header_2_0(member)
                else:
                    raise ValueError(f"{key}: .npy format version {version} is not read "
                                     "(1.0 and 2.0 are)")  # fmt: skip
                if dtype.hasobject:
                    raise ValueError(f"{key}: holds Python objects (refused: nothing is "
                                     "unpickled)")  # fmt: skip
                count = float(np.prod(shape, dtype=np.float64))
                if count > _MAX_NUMBERS:
                    raise ValueError(f"{key}: shape {shape} holds more than the "
                                     f"{_MAX_NUMBERS} numbers the format allows")  # fmt: skip
                declared, held = int(count) * dtype.itemsize, info.file_size - member.tell()
                if declared != held:
                    raise ValueError(f"{key}: the header's shape {shape} of {dtype} needs "
                                     f"{declared} bytes, the file holds {held}")  # fmt: skip
                member.seek(0)  # read_array reads the header again
                arrays[key] = npy.read_array(member, allow_pickle=False)
    return arrays


def modal_data_from_dict(data: dict[str, Any], source: str = "modal data") -> ModalData:
    """Validate a plain dict of the format; one :class:`ConfigError` naming the field.

    Parameters
    ----------
    data : dict
        The format's keys and values.
    source : str
        Where the data came from, for the message.

    Returns
    -------
    ModalData
        The validated data.
    """
    from flexsat.config.load import validate_config

    return validate_config(data, source=source, model=ModalData)


def load_modal_data(path: str | Path) -> ModalData:
    """Read and validate a modal data file (``.toml`` or ``.npz``).

    Parameters
    ----------
    path : path
        The file.

    Returns
    -------
    ModalData
        The validated data.

    Raises
    ------
    ConfigError
        Missing or unreadable file, not a regular file or larger than
        :data:`flexsat.files.MAX_INPUT_BYTES`, unknown suffix, or any invalid field
        (the message names it).
    """
    path = Path(path)
    suffix = path.suffix.lower()
    if suffix == ".toml":
        try:
            data = tomllib.loads(read_user_file(path, "modal data").decode("utf-8"))
        except (OSError, UnicodeDecodeError, tomllib.TOMLDecodeError) as exc:
            raise ConfigError(f"cannot read modal data file {path}: {exc}") from None
    elif suffix == ".npz":
        check_user_file(path, "modal data")  # a FIFO or a device is refused, not read
        try:
            data = _from_arrays(_read_npz(path))
        except FileNotFoundError:
            raise ConfigError(f"modal data file not found: {path}") from None
        except (OSError, ValueError, EOFError, zipfile.BadZipFile, zlib.error,
                NotImplementedError) as exc:  # fmt: skip
            raise ConfigError(f"cannot read modal data file {path}: {exc}") from None
    else:
        raise ConfigError(f"modal data file {path}: the suffix must be .toml or .npz")
    return modal_data_from_dict(data, source=str(path))


def save_modal_data(data: ModalData, path: str | Path) -> Path:
    """Write ``data`` as ``.toml`` (every float with 17 significant digits: exact) or
    ``.npz``.

    Parameters
    ----------
    data : ModalData
        The appendage's modal data.
    path : path
        The file; its suffix picks the format.

    Returns
    -------
    Path
        ``path``.
    """
    path = Path(path)
    suffix = path.suffix.lower()
    if suffix == ".npz":
        with replacing(path) as handle:  # a link at path is replaced, never followed
            np.savez(handle, **data.to_arrays())
    elif suffix == ".toml":
        write_text(path, _toml(data.model_dump()))
    else:
        raise ConfigError(f"modal data file {path}: the suffix must be .toml or .npz")
    return path


def _value(v: Any) -> str:
    if isinstance(v, (list, tuple)):
        return "[" + ", ".join(_value(x) for x in v) + "]"
    if isinstance(v, str):
        return '"' + v.replace("\\", "\\\\").replace('"', '\\"') + '"'
    return repr(float(v)) if isinstance(v, float) else str(v)


def _toml(data: dict[str, Any]) -> str:
    """The few shapes of the format as TOML (floats by repr: they round-trip exactly)."""
    lines = [f"{k} = {_value(v)}" for k, v in data.items() if k != "output_points"]
    for point in data["output_points"]:
        lines += ["", "[[output_points]]"] + [f"{k} = {_value(v)}" for k, v in point.items()]
    return "\n".join(lines) + "\n"
