"""A chain of N rigid segments in series on elastic joints (``model = "chain"``).

The thesis's own recommendation for higher modes (section 6.2): discretize each
appendage into "a kinematic chain of N rigid segments connected in series". Each
joint frees any subset of the six relative DOFs; the thesis plate is the chain of one
segment on a full 6-DOF joint and gives the same results as
:mod:`flexsat.dynamics.appendages.plate`.

Coordinates: per joint, root first, its free DOFs in the order ``x, y, z, rx, ry,
rz`` (:data:`~flexsat.dynamics.appendages.chain_config.DOF_NAMES`), named
``eta_<dof>_<joint>`` (``eta_rx_0``: the root joint's rotation about its x axis).
The configuration is :class:`~flexsat.dynamics.appendages.chain_config.ChainConfig`,
the kernels are in :mod:`~flexsat.dynamics.appendages.chain_kernels`; see
docs/model.md, 'Chain appendages'.
"""

from __future__ import annotations

from typing import ClassVar

import numpy as np

from flexsat.dynamics.appendages.chain_config import (
    AXES,
    CHORD_THICKNESS,
    DOF_NAMES,
    ChainConfig,
    dof_kind,
)
from flexsat.dynamics.appendages.chain_kernels import (
    G_C,
    G_COM,
    G_FREE,
    G_J,
    G_K,
    G_KIND,
    G_MASS,
    G_NEXT,
    G_NF,
    G_OFF,
    H_MOUNT,
    H_N,
    H_R_BM,
    H_TIP,
    H_TIP0,
    HEADER,
    JOINT_GENERAL,
    JOINT_HINGE_X,
    SEG,
    WSEG,
    bias_forces,
    joint_wrench,
    mass_matrix,
    observe,
    pass1,
    pass2,
    tips,
)
from flexsat.dynamics.appendages.contract import (
    AppendageKernels,
    AppendageModel,
    Coordinate,
    DerivedPath,
    RigidBody,
)
from flexsat.dynamics.appendages.sadm import driven_chain

__all__ = ["ChainModel"]


def _rotation(angles_xyz: np.ndarray) -> np.ndarray:
    """Rz(rz) Ry(ry) Rx(rx) of a joint's (rx, ry, rz) [rad]."""
    from scipy.spatial.transform import Rotation  # here: scipy.spatial costs 0.25 s to import

    return Rotation.from_euler("ZYX", angles_xyz[::-1]).as_matrix()


def _scale_mass(table: dict, factor: float) -> None:
    """Campaign path ``appendages[*].inertia``: scale the chain's mass and so its inertia
    (every segment's of a listed chain; joints tuned to target frequencies keep them)."""
    if table.get("segment_list") is not None:
        for segment in table["segment_list"]:
            segment["mass_kg"] = segment["mass_kg"] * factor
            if segment.get("inertia_kg_m2") is not None:
                segment["inertia_kg_m2"] = (np.asarray(segment["inertia_kg_m2"]) * factor).tolist()
        return
    field = "mass_kg" if table.get("mass_kg") is not None else "surface_density_kg_m2"
    table[field] = table[field] * factor


def _joint_tables(table: dict) -> list[dict]:
    """Every joint table of a chain's plain-dict table: each listed segment's, or the
    uniform chain's ``joint`` and ``root_joint``."""
    if table.get("segment_list") is not None:
        return [segment["joint"] for segment in table["segment_list"]]
    return [table[field] for field in ("joint", "root_joint") if table.get(field) is not None]


def _set_damping_ratio(table: dict, ratio: float) -> None:
    """Campaign path ``appendages[*].damping_ratio`` on a chain: the damping ratio of
    every free DOF of every joint (eq. 2.15), in place of any damping given per DOF."""
    for joint in _joint_tables(table):
        joint["damping_ratio"] = ratio
        joint["damping"] = None


_BEAM_PROPERTY = {"flapping": "EI_flap_N_m2", "in_plane": "EI_in_plane_N_m2", "torsion": "GJ_N_m2"}


def _frequency_scaler(kind: str):
    """Campaign path ``appendages[*].target_frequencies_hz.<kind>`` on a chain, a factor
    s on the frequencies of that kind: every joint stiffness of the kind (from the beam
    table, per DOF, or tuned to a per-joint target frequency) times s^2. The clamped
    chain's modes of that kind then all move by s exactly, as the plate's one mode of
    that kind does when its target is scaled: a straight chain's flapwise, in-plane and
    torsion motions do not couple at first order (docs/campaigns.md, 'Modifier paths on
    any appendage model')."""

    def scale(table: dict, factor: float) -> None:
        span = table.get("span_direction", "+y")
        if table.get("beam") is not None and table["beam"].get(_BEAM_PROPERTY[kind]) is not None:
            table["beam"][_BEAM_PROPERTY[kind]] *= factor**2
        for joint in _joint_tables(table):
            for field, power in (("stiffness", 2), ("target_frequencies_hz", 1)):
                for dof, value in (joint.get(field) or {}).items():
                    if dof_kind(span, dof) == kind:
                        joint[field][dof] = value * factor**power

    return scale


class ChainModel(AppendageModel):
    """Serial chain of rigid segments on elastic joints (:class:`ChainConfig`)."""

    name = "chain"
    config_class = ChainConfig
    kernels = AppendageKernels(pass1, pass2, mass_matrix, bias_forces, observe, joint_wrench, tips)
    transmits_inertia = True
    modifiers: ClassVar[dict] = {
        "inertia": DerivedPath(_scale_mass),
        "damping_ratio": DerivedPath(_set_damping_ratio, ops=("set",), factor=False),
        **{f"target_frequencies_hz.{kind}": DerivedPath(_frequency_scaler(kind), ops=("scale",))
           for kind in _BEAM_PROPERTY},
    }  # fmt: skip
    work_size = WSEG

    # -- layout ---------------------------------------------------------------------------

    def coordinates(self, config: ChainConfig) -> tuple[Coordinate, ...]:
        return tuple(
            Coordinate(f"eta_{dof}_{k}", "rad" if dof.startswith("r") else "m")
            for k, seg in enumerate(config.resolved_segments())
            for dof in seg.dofs
        )

    def work_columns(self, params: np.ndarray) -> int:
        return WSEG * self.segment_count(params)

    def pack(self, config: ChainConfig) -> np.ndarray:
        segments = config.resolved_segments()
        n = len(segments)
        row = np.zeros(HEADER + SEG * n)
        R_BM = config.mount_rotation()
        row[H_MOUNT : H_MOUNT + 3] = config.mount_point_m
        row[H_R_BM : H_R_BM + 9] = R_BM.ravel()
        row[H_N] = n
        last = segments[-1]
        row[H_TIP : H_TIP + 3] = last.next_joint
        row[H_TIP0 : H_TIP0 + 3] = sum(s.next_joint for s in segments)  # frames aligned at rest
        offset = 0
        for k, seg in enumerate(segments):
            g = HEADER + SEG * k
            mass, com, inertia = seg.mass, seg.com, seg.inertia
            if k == n - 1 and config.tip_mass_kg > 0.0:
                mass, com, inertia = _with_point_mass(seg, config.tip_mass_kg, last.next_joint)
            row[g + G_MASS] = mass
            row[g + G_J : g + G_J + 9] = inertia.ravel()
            row[g + G_COM : g + G_COM + 3] = com
            row[g + G_NEXT : g + G_NEXT + 3] = seg.next_joint
            free = [DOF_NAMES.index(d) for d in seg.dofs]
            row[g + G_FREE + np.array(free)] = 1.0
            if seg.stiffness is not None:
                row[g + G_K + np.array(free)] = seg.stiffness
            if seg.damping is not None:
                row[g + G_C + np.array(free)] = seg.damping
            row[g + G_OFF] = offset
            row[g + G_NF] = len(free)
            row[g + G_KIND] = _joint_kind(free)
            offset += len(free)
        return row

    def tune(self, config: ChainConfig, params: np.ndarray, inertia_diag: np.ndarray
             ) -> np.ndarray:  # fmt: skip
        # Per free DOF: target frequency -> k = J_eq w^2, c = 2 zeta w J_eq (eqs. 2.14-2.15);
        # a damping ratio on a given stiffness -> c = 2 zeta sqrt(k J_eq); else as given.
        stiffness, damping = self.stiffness(params), self.damping(params)
        start = 0
        for seg in config.resolved_segments():
            block = slice(start, start + len(seg.dofs))
            J_eq = inertia_diag[block]
            if seg.frequencies is not None:
                omega = 2.0 * np.pi * seg.frequencies
                stiffness[block] = J_eq * omega**2  # eq. 2.14
                damping[block] = 2.0 * seg.damping_ratio * omega * J_eq  # eq. 2.15
            elif seg.damping is None:
                damping[block] = 2.0 * seg.damping_ratio * np.sqrt(stiffness[block] * J_eq)
            start = block.stop
        return self.with_joints(params, stiffness, damping)

    def _free_columns(self, params: np.ndarray, base: int) -> np.ndarray:
        n = self.segment_count(params)
        cols = [HEADER + SEG * k + base + i for k in range(n) for i in range(6)
                if params[HEADER + SEG * k + G_FREE + i] != 0.0]  # fmt: skip
        return np.array(cols, dtype=int)

    def on_drive(self, config: ChainConfig, params: np.ndarray) -> ChainConfig | None:
        if config.drive is None:
            return None
        drive = config.drive
        return driven_chain(config, self.stiffness(params), self.damping(params),
                            drive.rotor_inertia_kg_m2, drive.rotor_mass_kg)  # fmt: skip

    def stiffness(self, params: np.ndarray) -> np.ndarray:
        return params[self._free_columns(params, G_K)].copy()

    def damping(self, params: np.ndarray) -> np.ndarray:
        return params[self._free_columns(params, G_C)].copy()

    def with_joints(self, params: np.ndarray, stiffness: np.ndarray, damping: np.ndarray
                    ) -> np.ndarray:  # fmt: skip
        row = params.copy()
        row[self._free_columns(params, G_K)] = stiffness
        row[self._free_columns(params, G_C)] = damping
        return row

    # -- geometry -------------------------------------------------------------------------

    @staticmethod
    def segment_count(params: np.ndarray) -> int:
        """N, the number of segments of a packed row."""
        return int(params[H_N])

    @staticmethod
    def mount_rotation(params: np.ndarray) -> np.ndarray:
        """R_BM of a packed row, shape (3, 3)."""
        return params[H_R_BM : H_R_BM + 9].reshape(3, 3)

    @staticmethod
    def mount_point(params: np.ndarray) -> np.ndarray:
        """r_m, the root joint position in B, shape (3,) [m]."""
        return params[H_MOUNT : H_MOUNT + 3]

    def segment_poses(self, params: np.ndarray, q_block: np.ndarray
                      ) -> tuple[np.ndarray, np.ndarray]:  # fmt: skip
        """Every segment's frame at coordinates ``q_block`` (count,), hub frame B.

        Returns R_BP (N, 3, 3) and the segment origins (N + 1, 3) [m] from the hub
        centre of mass: row N is the free end (the last segment's next joint).
        """
        n = self.segment_count(params)
        R = self.mount_rotation(params)
        origin = self.mount_point(params).copy()
        rotations, points = np.empty((n, 3, 3)), np.empty((n + 1, 3))
        for k in range(n):
            g = HEADER + SEG * k
            values = np.zeros(6)
            free = params[g + G_FREE : g + G_FREE + 6] != 0.0
            start = int(params[g + G_OFF])
            values[free] = q_block[start : start + int(params[g + G_NF])]
            origin = origin + R @ values[:3]
            R = R @ _rotation(values[3:])
            rotations[k], points[k] = R, origin
            origin = origin + R @ params[g + G_NEXT : g + G_NEXT + 3]
        points[n] = origin
        return rotations, points

    def rigid_body(self, params: np.ndarray) -> RigidBody:
        return self.rigid_body_at(params, np.zeros(self._coordinate_count(params)))

    def rigid_body_at(self, params: np.ndarray, q_block: np.ndarray) -> RigidBody:
        n = self.segment_count(params)
        rotations, points = self.segment_poses(params, q_block)
        rows = [HEADER + SEG * k for k in range(n)]
        masses = np.array([params[g + G_MASS] for g in rows])
        coms = np.array([points[k] + rotations[k] @ params[g + G_COM : g + G_COM + 3]
                         for k, g in enumerate(rows)])  # fmt: skip
        mass = float(masses.sum())
        r = masses @ coms / mass
        J = np.zeros((3, 3))
        for k in range(n):
            g = HEADER + SEG * k
            d = coms[k] - r
            J_k = params[g + G_J : g + G_J + 9].reshape(3, 3)
            J += rotations[k] @ J_k @ rotations[k].T
            J += masses[k] * (d @ d * np.eye(3) - np.outer(d, d))  # parallel axes
        return RigidBody(mass, r, J)

    def _coordinate_count(self, params: np.ndarray) -> int:
        n = self.segment_count(params)
        return int(sum(params[HEADER + SEG * k + G_NF] for k in range(n)))

    # -- initial state ----------------------------------------------------------------------

    def default_state(self, config: ChainConfig) -> tuple[np.ndarray, np.ndarray]:
        segments = config.resolved_segments()
        return (np.concatenate([s.q0 for s in segments]),
                np.concatenate([s.qd0 for s in segments]))  # fmt: skip

    def initial_state(self, config: ChainConfig, entry) -> tuple[np.ndarray, np.ndarray]:
        # A scenario's plate-form entry sets the root joint: eta_m on x, y, z, rho_deg on
        # rx, ry, rz (rates likewise); a non-zero value on a locked DOF is an error.
        q, qd = self.default_state(config)
        root = config.resolved_segments()[0]
        values = np.concatenate([entry.eta_m, np.radians(entry.rho_deg)])
        rates = np.concatenate([entry.eta_rate_m_s, np.radians(entry.rho_rate_deg_s)])
        for i, dof in enumerate(DOF_NAMES):
            if dof in root.dofs:
                a = root.dofs.index(dof)
                q[a], qd[a] = values[i], rates[i]
            elif values[i] != 0.0 or rates[i] != 0.0:
                raise ValueError(
                    f"initial.appendages: {config.name!r} root joint DOF {dof!r} is locked "
                    f"(free: {list(root.dofs)})"
                )
        return q, qd

    # -- reports, plots, classification -------------------------------------------------------

    def describe(self, config: ChainConfig, params: np.ndarray) -> dict:
        body = self.rigid_body(params)
        return {
            "segments": self.segment_count(params),
            "mass_kg": body.mass,
            "inertia_B_kg_m2": body.J_B.tolist(),
            "coordinates": [c.name for c in self.coordinates(config)],
            "stiffness": self.stiffness(params).tolist(),
            "damping": self.damping(params).tolist(),
        }

    def shape_points(self, config: ChainConfig, params: np.ndarray, q_block: np.ndarray
                     ) -> np.ndarray:  # fmt: skip
        # The outline joins the root edge (chord at the mount) to the free edge (chord of
        # the last segment); rows 4 and 5 are the root and the free end.
        rotations, points = self.segment_poses(params, q_block)
        chord = self._chord(config)
        R_first, R_last = rotations[0], rotations[-1]
        root, end = points[0], points[-1]
        out = np.empty((6, 3))
        out[0], out[1] = root - R_first @ chord, root + R_first @ chord
        out[2], out[3] = end + R_last @ chord, end - R_last @ chord
        out[4], out[5] = root, end
        return out

    def outlines(self, config: ChainConfig, params: np.ndarray, q_block: np.ndarray
                 ) -> np.ndarray:  # fmt: skip
        """Each segment's quadrilateral at ``q_block``, hub frame B [m], shape (N, 4, 3)."""
        rotations, points = self.segment_poses(params, q_block)
        chord = self._chord(config)
        n = len(rotations)
        out = np.empty((n, 4, 3))
        for k in range(n):
            half = rotations[k] @ chord
            out[k] = (points[k] - half, points[k] + half, points[k + 1] + half,
                      points[k + 1] - half)  # fmt: skip
        return out

    def mirror_block(self, params_i: np.ndarray, params_j: np.ndarray, reflect: np.ndarray,
                     rtol: float) -> np.ndarray | None:  # fmt: skip
        # At rest every segment frame has the mount's axes, so one map T = R_j^T reflect
        # R_i takes i's segment-frame vectors to j's; j mirrors i when T is diagonal of
        # signs, the geometry and joints map under it, and then each
        # joint's translations map by T and its rotations (axial) by -T, as the plate's.
        if len(params_i) != len(params_j):
            return None
        R_i, R_j = self.mount_rotation(params_i), self.mount_rotation(params_j)
        T = R_j.T @ reflect @ R_i
        if not np.allclose(np.abs(T), np.eye(3), atol=rtol):
            return None
        T = np.diag(np.round(np.diag(T)))
        mount_i, mount_j = self.mount_point(params_i), self.mount_point(params_j)
        scale_ = max(1.0, float(np.max(np.abs(mount_i))))
        if not np.allclose(mount_j, reflect @ mount_i, atol=rtol * scale_):
            return None
        signs = []
        for k in range(self.segment_count(params_i)):
            g = HEADER + SEG * k
            a, b = params_i[g : g + SEG], params_j[g : g + SEG]
            J_a, J_b = a[G_J : G_J + 9].reshape(3, 3), b[G_J : G_J + 9].reshape(3, 3)
            com, nxt = slice(G_COM, G_COM + 3), slice(G_NEXT, G_NEXT + 3)
            same = (
                np.isclose(b[G_MASS], a[G_MASS], rtol=rtol)
                and np.allclose(J_b, T @ J_a @ T, atol=rtol * np.abs(J_a).max())
                and np.allclose(b[com], T @ a[com], atol=rtol * scale_)
                and np.allclose(b[nxt], T @ a[nxt], atol=rtol * scale_)
                and np.array_equal(b[G_FREE : G_FREE + 6], a[G_FREE : G_FREE + 6])
                and np.allclose(b[G_K : G_C + 6], a[G_K : G_C + 6], rtol=rtol)
            )  # fmt: skip
            if not same:
                return None
            axis_signs = np.concatenate([np.diag(T), -np.diag(T)])
            signs += [axis_signs[i] for i in range(6) if a[G_FREE + i] != 0.0]
        return np.diag(signs)

    @staticmethod
    def _chord(config: ChainConfig) -> np.ndarray:
        """Half the chord, segment frame [m] (0 for a listed chain without width)."""
        half = np.zeros(3)
        if config.width_m is not None:
            half[AXES[CHORD_THICKNESS[config.span_direction[1]][0]]] = 0.5 * config.width_m
        return half

    def target_frequencies(self, config: ChainConfig) -> tuple[tuple[str, float], ...]:
        out = []
        for seg in config.resolved_segments():
            if seg.frequencies is None:
                continue
            for dof, value in zip(seg.dofs, seg.frequencies, strict=True):
                kind = config.dof_kind(dof)
                label = f"translation {dof}" if kind == "translation" else kind.replace("_", "-")
                if (label, value) not in out:
                    out.append((label, float(value)))
        return tuple(out)

    def extent(self, config: ChainConfig) -> float:
        return float(np.linalg.norm(sum(s.next_joint for s in config.resolved_segments())))

    def mode_kinds(self, config: ChainConfig) -> tuple[str, ...]:
        return tuple(config.dof_kind(d) for s in config.resolved_segments() for d in s.dofs)

    def root_motion(self, q_block: np.ndarray, names: tuple[str, ...] = ()
                    ) -> tuple[np.ndarray, np.ndarray]:  # fmt: skip
        # The root joint's DOFs (eta_<dof>_0) in eta = (x, y, z), rho = (rx, ry, rz);
        # a locked DOF stays zero.
        out = np.zeros((q_block.shape[0], 6))
        for a, name in enumerate(names):
            dof, _, joint = name.removeprefix("eta_").rpartition("_")
            if joint == "0":
                out[:, DOF_NAMES.index(dof)] = q_block[:, a]
        return out[:, :3], out[:, 3:]


def _joint_kind(free: list[int]) -> int:
    """The kernels' joint-kind code of a joint with these free DOFs (indices into
    ``DOF_NAMES``): a hinge about axis a (one free rotation, a = 0, 1, 2 for rx, ry, rz)
    takes the specialized recursion step, any other joint the general one."""
    if len(free) == 1 and free[0] >= 3:
        return JOINT_HINGE_X + free[0] - 3
    return JOINT_GENERAL


def _with_point_mass(seg, tip_mass: float, point: np.ndarray):
    """Mass, centre of mass and centroidal inertia of a segment with a point mass added."""
    mass = seg.mass + tip_mass
    com = (seg.mass * seg.com + tip_mass * point) / mass
    d1, d2 = seg.com - com, point - com
    inertia = (seg.inertia + seg.mass * (d1 @ d1 * np.eye(3) - np.outer(d1, d1))
               + tip_mass * (d2 @ d2 * np.eye(3) - np.outer(d2, d2)))  # fmt: skip
    return mass, com, inertia
