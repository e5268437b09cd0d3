"""Configuration of a chain appendage: N rigid segments in series on elastic joints.

Validated at the boundary (frozen pydantic, field-path errors) and resolved into one
:class:`Segment` per body by :meth:`ChainConfig.resolved_segments`, which is all the
packing in :mod:`flexsat.dynamics.appendages.chain` reads. See docs/model.md,
'Chain appendages'.

Frames: the mount frame M is named as every appendage model names it: the hub frame
B rotated by ``mount_yaw_deg`` about Z_B, then by ``sadm_angle_deg`` about the span
axis (Y_M for the default span, as the plate's SADM angle), or given as
``mount_matrix`` (any R_BM; the SADM angle then turns from it), its origin at
``mount_point_m``. The former ``mount_zyx_deg`` = (a, b, c), R_BM = Rz(a) Ry(b) Rx(c),
is still read, with a deprecation warning (:func:`renamed_mount`).
Joint 0 sits at the mount; joint k > 0 at the previous segment's ``next_joint_m``,
its axes those of the previous segment's frame. Each joint frees a subset of the six
relative DOFs ``x, y, z`` (translation of the segment's origin along the joint's axes
[m]) and ``rx, ry, rz`` (ZYX angles: R = Rz(rz) Ry(ry) Rx(rx) [rad]), the plate's
``eta_*`` convention.
"""

from __future__ import annotations

from typing import Annotated, Literal

import numpy as np
from pydantic import AllowInfNan, Field, Strict, model_validator

from flexsat.config.models import (
    Angle,
    Density,
    DriveConfig,
    Frequency,
    Mass,
    Matrix3,
    Name,
    Point3,
    Real,
    Size,
    Thickness,
    _check_inertia,
    _Frozen,
)

__all__ = [
    "AXES",
    "CHORD_THICKNESS",
    "DOF_NAMES",
    "BeamConfig",
    "ChainConfig",
    "JointConfig",
    "Segment",
    "SegmentConfig",
    "dof_kind",
]

DOF_NAMES = ("x", "y", "z", "rx", "ry", "rz")
"""The six relative DOFs of a joint, in coordinate order (translations, then ZYX angles)."""

Dof = Literal["x", "y", "z", "rx", "ry", "rz"]
NonNegative = Annotated[float, Strict(), AllowInfNan(False), Field(ge=0.0, le=1e12)]
Ratio = Annotated[float, Strict(), AllowInfNan(False), Field(ge=0.0, lt=1.0)]
Modulus = Annotated[float, Strict(), AllowInfNan(False), Field(gt=0.0, le=1e15)]
# Initial joint states, bounded as the scenario's initial states are (docs/model.md,
# 'Allowed ranges of the physical inputs').
_MAX_DEFLECTION_M, _MAX_RATE_M_S, _MAX_RATE_DEG_S = 10.0, 1e3, 1e4
AXES = {"x": 0, "y": 1, "z": 2}
"""Index of each segment-frame axis."""


def _is_rotation(dof: str) -> bool:
    return dof.startswith("r")


def _angle_in(dof: str, value: float) -> float:
    """A joint value at the boundary (deg for rotations, m for translations) in SI."""
    return float(np.radians(value)) if _is_rotation(dof) else float(value)


class JointConfig(_Frozen):
    """One elastic joint: its free DOFs, their stiffness and damping, its initial state.

    Give the stiffness one way: ``stiffness`` (per free DOF [N/m, N m/rad]) or
    ``target_frequencies_hz`` (per free DOF, tuned as the thesis does, eqs.
    2.14-2.15) or, in a uniform chain, the chain's ``beam`` table. Damping:
    ``damping`` (per free DOF [N s/m, N m s/rad]) or ``damping_ratio`` (every free
    DOF, eq. 2.15). A DOF not in ``dofs`` is locked and may not be given a value.
    """

    dofs: Annotated[tuple[Dof, ...], Field(min_length=1, max_length=6)] = Field(
        description="free relative DOFs of the joint, any of x, y, z, rx, ry, rz"
    )
    stiffness: dict[Dof, NonNegative] | None = Field(
        None, description="stiffness per free DOF [N/m, N m/rad]"
    )
    target_frequencies_hz: dict[Dof, Frequency] | None = Field(
        None, description="clamped-root target frequency per free DOF [Hz] (eq. 2.14)"
    )
    damping: dict[Dof, NonNegative] | None = Field(
        None, description="damping per free DOF [N s/m, N m s/rad]"
    )
    damping_ratio: Ratio | None = Field(None, description="damping ratio of every free DOF [-]")
    initial: dict[Dof, Real] = Field(
        default_factory=dict, description="initial deflection per free DOF [m, deg]"
    )
    initial_rate: dict[Dof, Real] = Field(
        default_factory=dict, description="initial rate per free DOF [m/s, deg/s]"
    )

    @model_validator(mode="after")
    def _consistent(self) -> JointConfig:
        if len(set(self.dofs)) != len(self.dofs):
            raise ValueError(f"dofs: each DOF at most once, got {list(self.dofs)}")
        for field in ("stiffness", "target_frequencies_hz", "damping", "initial", "initial_rate"):
            given = getattr(self, field) or {}
            locked = sorted(set(given) - set(self.dofs))
            if locked:
                raise ValueError(
                    f"{field}: {locked} locked (not in dofs {list(self.dofs)}); a locked DOF "
                    "takes no value"
                )
        for field in ("stiffness", "target_frequencies_hz", "damping"):
            given = getattr(self, field)
            if given is not None and set(given) != set(self.dofs):
                missing = [d for d in self.dofs if d not in given]
                raise ValueError(f"{field}: give a value for every free DOF, missing {missing}")
        if self.stiffness is not None and self.target_frequencies_hz is not None:
            raise ValueError("give either stiffness or target_frequencies_hz, not both")
        if self.damping is not None and self.damping_ratio is not None:
            raise ValueError("give either damping or damping_ratio, not both")
        if self.target_frequencies_hz is not None and self.damping is not None:
            raise ValueError("target_frequencies_hz tunes the damping too: give damping_ratio")
        for dof, value in self.initial.items():
            if _is_rotation(dof) and abs(value) >= 45.0:
                raise ValueError(f"initial.{dof}: {value} deg, must stay below 45 deg")
            if not _is_rotation(dof) and abs(value) > _MAX_DEFLECTION_M:
                raise ValueError(f"initial.{dof}: {value:g} m, must be within "
                                 f"+-{_MAX_DEFLECTION_M:g} m")  # fmt: skip
        for dof, value in self.initial_rate.items():
            rotation = _is_rotation(dof)
            limit, unit = (_MAX_RATE_DEG_S, "deg/s") if rotation else (_MAX_RATE_M_S, "m/s")
            if abs(value) > limit:
                raise ValueError(f"initial_rate.{dof}: {value:g} {unit}, must be within "
                                 f"+-{limit:g} {unit}")  # fmt: skip
        return self

    def free_mask(self) -> np.ndarray:
        """1.0 for each free DOF in :data:`DOF_NAMES` order, else 0.0, shape (6,)."""
        return np.array([1.0 if d in self.dofs else 0.0 for d in DOF_NAMES])

    def ordered(self) -> tuple[str, ...]:
        """The free DOFs in coordinate order (:data:`DOF_NAMES`)."""
        return tuple(d for d in DOF_NAMES if d in self.dofs)


class BeamConfig(_Frozen):
    """Uniform-beam properties the joints of a uniform chain take their stiffness from.

    A chain of N rigid segments of length l = L/N: the interior joints carry the
    flexibility of one segment length, k = EI/l (GJ/l, EA/l); the root joint only
    of half a segment (the clamp to the first segment's mid-point), k = 2 EI/l. The
    flapwise bending is about the chord axis, in-plane bending about the thickness
    axis, torsion and the axial DOF about and along the span (docs/model.md, 'Chain
    appendages').
    """

    EI_flap_N_m2: Modulus | None = Field(None, description="flapwise bending stiffness [N m^2]")
    EI_in_plane_N_m2: Modulus | None = Field(None, description="in-plane bending stiffness [N m^2]")
    GJ_N_m2: Modulus | None = Field(None, description="torsional stiffness [N m^2]")
    EA_N: Modulus | None = Field(None, description="axial stiffness [N]")


class SegmentConfig(_Frozen):
    """One rigid segment of a listed chain, in its own frame (origin at its joint).

    Give the inertia about its centre of mass either as ``inertia_kg_m2`` or as a
    solid box ``box_m`` (edge lengths along the segment's x, y, z; a thin plate or a
    bar is a box with one or two small edges).
    """

    mass_kg: Mass = Field(description="segment mass [kg]")
    inertia_kg_m2: Matrix3 | None = Field(
        None, description="inertia about the segment centre of mass, segment frame [kg m^2]"
    )
    box_m: tuple[Size | Thickness, Size | Thickness, Size | Thickness] | None = Field(
        None, description="solid-box edge lengths along the segment axes [m]"
    )
    com_m: Point3 = Field(description="joint -> segment centre of mass, segment frame [m]")
    next_joint_m: Point3 = Field(description="joint -> next joint (or the tip), segment frame [m]")
    joint: JointConfig = Field(description="the joint at the segment's origin")

    @model_validator(mode="after")
    def _one_inertia(self) -> SegmentConfig:
        if (self.inertia_kg_m2 is None) == (self.box_m is None):
            raise ValueError("give exactly one of inertia_kg_m2 and box_m")
        if self.inertia_kg_m2 is not None:
            _check_inertia(np.array(self.inertia_kg_m2, dtype=float))
        if self.joint.stiffness is None and self.joint.target_frequencies_hz is None:
            raise ValueError("joint: give stiffness or target_frequencies_hz")
        return self

    def centroidal_inertia(self) -> np.ndarray:
        """Inertia about the centre of mass, segment frame, shape (3, 3) [kg m^2]."""
        if self.inertia_kg_m2 is not None:
            return np.array(self.inertia_kg_m2, dtype=float)
        return _box_inertia(self.mass_kg, np.array(self.box_m, dtype=float))


def _box_inertia(mass: float, edges: np.ndarray) -> np.ndarray:
    """Solid box about its centre (the thin plate of eqs. 2.9-2.11 is one)."""
    a2 = edges**2
    return mass / 12.0 * np.diag([a2[1] + a2[2], a2[0] + a2[2], a2[0] + a2[1]])


class Segment:
    """One resolved segment: SI numbers only (what the packing reads).

    Parameters
    ----------
    mass : float
        Segment mass [kg].
    inertia : array_like, shape (3, 3)
        Inertia about its centre of mass, segment frame [kg m^2].
    com : array_like, shape (3,)
        Joint -> centre of mass, segment frame [m].
    next_joint : array_like, shape (3,)
        Joint -> next joint (or the tip), segment frame [m].
    joint : JointConfig
        Its joint (coordinates, initial state, damping).
    stiffness : dict, optional
        Stiffness per joint coordinate [N/m or N m/rad], overriding the joint's.
    """

    __slots__ = ("com", "damping", "damping_ratio", "dofs", "frequencies", "inertia", "mass",
                 "next_joint", "q0", "qd0", "stiffness")  # fmt: skip

    def __init__(self, mass, inertia, com, next_joint, joint: JointConfig,
                 stiffness: dict | None = None) -> None:  # fmt: skip
        self.mass = float(mass)
        self.inertia = np.asarray(inertia, dtype=float)
        self.com = np.asarray(com, dtype=float)
        self.next_joint = np.asarray(next_joint, dtype=float)
        self.dofs = joint.ordered()
        given = stiffness if stiffness is not None else joint.stiffness
        self.stiffness = None if given is None else np.array([given[d] for d in self.dofs])
        freq = joint.target_frequencies_hz
        self.frequencies = None if freq is None else np.array([freq[d] for d in self.dofs])
        self.damping = (None if joint.damping is None
                        else np.array([joint.damping[d] for d in self.dofs]))  # fmt: skip
        self.damping_ratio = joint.damping_ratio or 0.0
        self.q0 = np.array([_angle_in(d, joint.initial.get(d, 0.0)) for d in self.dofs])
        self.qd0 = np.array([_angle_in(d, joint.initial_rate.get(d, 0.0)) for d in self.dofs])


_SPAN = Literal["+x", "-x", "+y", "-y", "+z", "-z"]
# Chord (width) and thickness axes for each span axis: flapwise bending is about the
# chord axis, in-plane bending about the thickness axis (the thesis: span Y, chord X,
# thickness Z, so flapping about X and in-plane about Z).
CHORD_THICKNESS = {"x": ("y", "z"), "y": ("x", "z"), "z": ("x", "y")}
"""(chord, thickness) axes of each span axis."""


def dof_kind(span_direction: str, dof: str) -> str:
    """The modal kind of a joint DOF of a chain whose span runs along ``span_direction``.

    Parameters
    ----------
    span_direction : str
        ``+x``, ``-x``, ``+y``, ``-y``, ``+z`` or ``-z`` [-].
    dof : str
        A joint DOF, one of :data:`DOF_NAMES` [-].

    Returns
    -------
    str
        ``flapping`` (rotation about the chord axis), ``in_plane`` (about the
        thickness axis), ``torsion`` (about the span) or ``translation`` [-].
    """
    if not _is_rotation(dof):
        return "translation"
    span = span_direction[1]
    chord, thickness = CHORD_THICKNESS[span]
    return {chord: "flapping", thickness: "in_plane", span: "torsion"}[dof[1]]


class ChainConfig(_Frozen):
    """A chain appendage: N rigid segments in series, each on an elastic joint.

    Uniform chain: ``segments`` (N), ``length_m`` (total span along
    ``span_direction``), ``width_m`` and ``thickness_m`` (plate geometry: chord and
    thickness axes), the mass as ``mass_kg`` or ``surface_density_kg_m2`` (total),
    ``joint`` (every joint; ``root_joint`` may differ) and optionally ``beam``.
    Listed chain: ``segment_list``, one table per segment. ``tip_mass_kg`` is a
    point mass at the last segment's ``next_joint_m`` (the free end).
    """

    name: Name = Field(description="unique name of the appendage")
    model: Literal["chain"] = Field(description="appendage model (registry key)")
    mount_point_m: Point3 = Field(description="root joint position from hub centre of mass, B [m]")
    mount_yaw_deg: Angle = Field(0.0, description="mount frame rotation about Z_B [deg]")
    sadm_angle_deg: Angle = Field(0.0, description="SADM angle about the span axis [deg]")
    mount_matrix: Matrix3 | None = Field(
        None, description="R_BM (mount -> hub) [-], instead of mount_yaw_deg"
    )
    span_direction: _SPAN = Field("+y", description="span axis of the segment frames")
    segments: Annotated[int, Strict(), Field(ge=1, le=512)] | None = Field(
        None, description="segment count N of a uniform chain"
    )
    length_m: Size | None = Field(None, description="total span L of a uniform chain [m]")
    width_m: Size | None = Field(None, description="chord of a uniform chain [m]")
    thickness_m: Thickness | None = Field(None, description="thickness of a uniform chain [m]")
    mass_kg: Mass | None = Field(None, description="total mass of a uniform chain [kg]")
    surface_density_kg_m2: Density | None = Field(None, description="rho_sup [kg/m^2]")
    joint: JointConfig | None = Field(None, description="every joint of a uniform chain")
    root_joint: JointConfig | None = Field(None, description="joint 0, if unlike the others")
    beam: BeamConfig | None = Field(None, description="uniform-beam stiffness of the joints")
    segment_list: Annotated[list[SegmentConfig], Field(min_length=1, max_length=512)] | None = (
        Field(None, description="the segments of a listed chain, root first")
    )
    tip_mass_kg: Annotated[float, Strict(), AllowInfNan(False), Field(ge=0.0, le=1e7)] = Field(
        0.0, description="point mass at the free end [kg]"
    )
    drive: DriveConfig | None = Field(
        None, description="put the chain on a solar-array drive turning it about its span "
        "axis: its SADM angle becomes a coordinate; default: the angle is fixed"
    )  # fmt: skip

    @model_validator(mode="before")
    @classmethod
    def _renamed_mount(cls, value):
        return renamed_mount(value)

    @model_validator(mode="after")
    def _one_form(self) -> ChainConfig:
        uniform = ("segments", "length_m", "width_m", "thickness_m", "joint")
        if self.mount_matrix is not None:
            if self.mount_yaw_deg:
                raise ValueError("give either mount_yaw_deg or mount_matrix, not both")
            R = np.array(self.mount_matrix, dtype=float)
            if not np.allclose(R @ R.T, np.eye(3), atol=1e-9) or np.linalg.det(R) < 0.0:
                raise ValueError("mount_matrix must be a rotation (orthonormal, det +1)")
        if self.segment_list is not None:
            given = [f for f in (*uniform, "mass_kg", "surface_density_kg_m2", "root_joint",
                                 "beam") if getattr(self, f) is not None]  # fmt: skip
            if given:
                raise ValueError(f"segment_list lists every segment: drop {given}")
            return self
        missing = [f for f in uniform if getattr(self, f) is None]
        if missing:
            raise ValueError(
                f"segments: a uniform chain needs {missing} (or give segment_list instead)"
            )
        if (self.mass_kg is None) == (self.surface_density_kg_m2 is None):
            raise ValueError("give exactly one of mass_kg and surface_density_kg_m2")
        for field in ("joint", "root_joint"):
            joint = getattr(self, field)
            if joint is None:
                continue
            tuned = joint.stiffness is not None or joint.target_frequencies_hz is not None
            if self.beam is None and not tuned:
                raise ValueError(f"{field}: give stiffness, target_frequencies_hz or a beam")
            if self.beam is not None and tuned:
                raise ValueError(f"{field}: the beam gives the stiffness; drop it here")
            if self.beam is not None:
                self._beam_stiffness(joint, 1.0)  # every free DOF has a beam property
        return self

    @property
    def total_mass(self) -> float:
        """Total segment mass of a uniform chain [kg] (tip mass excluded)."""
        if self.mass_kg is not None:
            return self.mass_kg
        return self.surface_density_kg_m2 * self.length_m * self.width_m  # eq. 2.6

    def span_axis(self) -> tuple[int, float]:
        """Index (0, 1, 2) and sign of the span axis in the segment frames."""
        return AXES[self.span_direction[1]], (1.0 if self.span_direction[0] == "+" else -1.0)

    def dof_kind(self, dof: str) -> str:
        """The modal kind of a joint DOF: flapping, in_plane, torsion or translation."""
        return dof_kind(self.span_direction, dof)

    def _beam_stiffness(self, joint: JointConfig, factor: float) -> dict:
        """Stiffness per free DOF from the beam table: factor * (EI, GJ, EA) / l."""
        seg_length = self.length_m / self.segments
        span = self.span_direction[1]
        prop = {"flapping": "EI_flap_N_m2", "in_plane": "EI_in_plane_N_m2", "torsion": "GJ_N_m2"}
        out = {}
        for dof in joint.dofs:
            kind = self.dof_kind(dof)
            field = prop.get(kind) if kind != "translation" else ("EA_N" if dof == span else None)
            value = None if field is None else getattr(self.beam, field)
            if value is None:
                raise ValueError(
                    f"beam: joint DOF {dof!r} ({kind}) has no beam property"
                    + (f"; give beam.{field}" if field else "; lock it or give its stiffness")
                )
            out[dof] = factor * value / seg_length
        return out

    def mount_rotation(self) -> np.ndarray:
        """R_BM (mount frame -> hub frame), shape (3, 3): ``mount_matrix`` or
        Rz(``mount_yaw_deg``), then turned by ``sadm_angle_deg`` about the span axis."""
        from scipy.spatial.transform import Rotation  # here: scipy.spatial costs 0.25 s to import

        if self.mount_matrix is not None:
            base = np.array(self.mount_matrix, dtype=float)
        else:
            base = Rotation.from_euler("Z", np.radians(self.mount_yaw_deg)).as_matrix()
        if not self.sadm_angle_deg:
            return base
        axis = np.zeros(3)
        axis[self.span_axis()[0]] = 1.0
        return base @ Rotation.from_rotvec(np.radians(self.sadm_angle_deg) * axis).as_matrix()

    def joints(self) -> list[JointConfig]:
        """The joint of each segment as configured, root first."""
        if self.segment_list is not None:
            return [s.joint for s in self.segment_list]
        return [self.root_joint if (k == 0 and self.root_joint is not None) else self.joint
                for k in range(self.segments)]  # fmt: skip

    def resolved_segments(self) -> list[Segment]:
        """One :class:`Segment` per body, root first (SI)."""
        if self.segment_list is not None:
            return [Segment(s.mass_kg, s.centroidal_inertia(), s.com_m, s.next_joint_m, s.joint)
                    for s in self.segment_list]  # fmt: skip
        n = self.segments
        axis, sign = self.span_axis()
        seg_length = self.length_m / n
        chord, thickness = CHORD_THICKNESS[self.span_direction[1]]
        edges = np.zeros(3)
        edges[axis] = seg_length
        edges[AXES[chord]] = self.width_m
        edges[AXES[thickness]] = self.thickness_m
        mass = self.total_mass / n
        inertia = _box_inertia(mass, edges)  # eqs. 2.9-2.11 per segment
        step = np.zeros(3)
        step[axis] = sign * seg_length
        out = []
        for k, joint in enumerate(self.joints()):
            stiffness = None
            if self.beam is not None:
                stiffness = self._beam_stiffness(joint, 2.0 if k == 0 else 1.0)
            out.append(Segment(mass, inertia, 0.5 * step, step, joint, stiffness))
        return out


_RENAMED_WARNED: set[str] = set()
"""Former keys already warned of in this process (each is warned of once)."""


def renamed_mount(value):
    """A chain table's former ``mount_zyx_deg`` = (a, b, c), R_BM = Rz(a) Ry(b) Rx(c), in
    the keys every appendage model names its mount with.

    (a, b, 0) on a chain spanning +-Y is ``mount_yaw_deg`` = a, ``sadm_angle_deg`` = b
    exactly (the plate's Rz(yaw) Ry(sadm)); (a, 0, 0) on any span, ``mount_yaw_deg`` =
    a; any other orientation, ``mount_matrix``. A :class:`FutureWarning` naming the old
    and the new key is issued once per process.

    Parameters
    ----------
    value : Any
        The table as given (a dict; anything else is returned as it is).

    Returns
    -------
    Any
        The table without ``mount_zyx_deg``.
    """
    import warnings

    from scipy.spatial.transform import Rotation  # here: scipy.spatial costs 0.25 s to import

    if not isinstance(value, dict) or "mount_zyx_deg" not in value:
        return value
    table = dict(value)
    old = table.pop("mount_zyx_deg")
    try:
        a, b, c = (float(x) for x in old)
    except (TypeError, ValueError):
        raise ValueError(f"mount_zyx_deg (deprecated): three angles [deg], got {old!r}") from None
    given = [key for key in ("mount_yaw_deg", "sadm_angle_deg", "mount_matrix") if key in table]
    if given:
        raise ValueError(f"give mount_zyx_deg (deprecated) or {', '.join(given)}, not both")
    span = str(table.get("span_direction", "+y"))[-1:]
    if c == 0.0 and (b == 0.0 or span == "y"):
        table["mount_yaw_deg"], table["sadm_angle_deg"] = a, b
        new = "mount_yaw_deg and sadm_angle_deg"
    else:
        R_BM = Rotation.from_euler("ZYX", np.radians([a, b, c])).as_matrix()
        table["mount_matrix"] = R_BM.tolist()
        new = "mount_matrix"
    if "mount_zyx_deg" not in _RENAMED_WARNED:
        _RENAMED_WARNED.add("mount_zyx_deg")
        warnings.warn(
            f"appendages: mount_zyx_deg is deprecated, read as {new} (the keys every "
            f"appendage model names its mount with: mount_yaw_deg, sadm_angle_deg or "
            f"mount_matrix); write {new} instead",
            FutureWarning,
            stacklevel=2,
        )
    return table
