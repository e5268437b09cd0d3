"""Formulas of their own for the independent check of the study report.

Written from the definitions (docs/control.md, 'How R1 and R2 are judged';
docs/results.md; docs/linear.md, 'Loop gains and margins'; the thesis *Multi-Body
Dynamic Modeling and Robust Sliding Mode Control of Flexible Satellites*, sections
2.1, 3.2, 3.3 and 5.1), not from flexsat's implementation: plain numpy for the run
metrics, rigid-body mechanics for M(0), ``scipy.linalg.eigh`` for the modes and
python-control for the loop margins. Nothing here imports flexsat's analysis code;
the runs it reads are the stored NetCDF files (``xarray``).

Also the reader of the report: :func:`report_tables` parses every ``<table>`` of the
HTML page back (caption, header, cells with their text and attributes) with the
standard library's ``html.parser``, and :func:`printed` turns a cell's text back into
the value it shows.
"""

from __future__ import annotations

import json
import math
import re
from dataclasses import dataclass, field
from html.parser import HTMLParser

import numpy as np
import scipy.signal
from scipy.linalg import eigh
from scipy.spatial.transform import Rotation

import control

# -- the report's tables --------------------------------------------------------------


@dataclass
class Table:
    """One ``<table>`` of the report: where it is, its caption, header and body cells."""

    section: str | None
    subheading: str | None
    caption: str
    header: list[str]
    rows: list[list[dict]] = field(default_factory=list)

    def columns(self) -> list[str]:
        """Column keys: the header, a repeated header prefixed by the last distinct one
        before it (the margins table has three 'at [Hz]')."""
        keys, last = [], ""
        for text in self.header:
            if text in self.header[: len(keys)] or self.header.count(text) > 1:
                keys.append(f"{last} / {text}")
            else:
                keys.append(text)
                last = text
        return keys

    @property
    def name(self) -> str:
        where = self.section or "page"
        if self.subheading:
            where += f"/{self.subheading}"
        return f"{where}: {self.caption!r}"


class _Tables(HTMLParser):
    def __init__(self) -> None:
        super().__init__()
        self.tables: list[Table] = []
        self._section = None
        self._sub = None
        self._table: Table | None = None
        self._text_of: str | None = None  # "h3" or "caption" while inside one
        self._row: list[dict] | None = None
        self._cell: dict | None = None
        self._in_head = False

    def handle_starttag(self, tag, attrs):
        attrs = dict(attrs)
        if tag == "section":
            self._section, self._sub = attrs.get("id"), None
        elif tag == "h3":
            self._text_of, self._sub = "h3", ""
        elif tag == "table":
            self._table = Table(self._section, self._sub, "", [])
        elif self._table is None:
            return
        elif tag == "caption":
            self._text_of = "caption"
        elif tag == "thead":
            self._in_head = True
        elif tag == "tr":
            self._row = []
        elif tag in ("td", "th"):
            self._cell = {"text": "", "tag": tag, **attrs}

    def handle_data(self, data):
        if self._cell is not None:
            self._cell["text"] += data
        elif self._text_of == "h3":
            self._sub += data
        elif self._text_of == "caption" and self._table is not None:
            self._table.caption += data

    def handle_endtag(self, tag):
        if tag in ("h3", "caption"):
            self._text_of = None
        if self._table is None:
            return
        if tag in ("td", "th") and self._cell is not None:
            self._cell["text"] = self._cell["text"].strip()
            self._row.append(self._cell)
            self._cell = None
        elif tag == "tr" and self._row is not None:
            if self._in_head:
                self._table.header = [c["text"] for c in self._row]
            else:
                self._table.rows.append(self._row)
            self._row = None
        elif tag == "thead":
            self._in_head = False
        elif tag == "table":
            self.tables.append(self._table)
            self._table = None


def report_tables(html_text: str) -> list[Table]:
    """Every table of the report, in page order."""
    parser = _Tables()
    parser.feed(html_text)
    return parser.tables


_NUMBER = re.compile(r"^[-+]?(\d+(\.\d*)?|\.\d+)([eE][-+]?\d+)?$")


def printed(text: str):
    """The value a cell's text shows: None for '—', True/False for pass/fail, a float,
    a list of floats ('a, b, c'), a list of rows ('[a, b; c, d]'), else the text."""
    text = text.strip()
    if text in ("—", ""):
        return None if text == "—" else ""
    if text in ("pass", "fail"):
        return text == "pass"
    if text.startswith("[") and text.endswith("]") and ";" in text:
        return [printed(row) for row in text[1:-1].split(";")]
    if "," in text:
        parts = [printed(p) for p in text.split(",")]
        return parts if all(isinstance(p, float) or p is None for p in parts) else text
    if _NUMBER.match(text):
        return float(text)
    return text


def half_unit(text: str) -> float:
    """Half a unit in the last printed digit of a number's text: the rounding the
    report's 4 significant digits leave (``1.231`` -> 5e-4, ``3.243e-05`` -> 5e-9,
    ``120`` -> 0.5 only when the text was rounded: an integer text is exact to 0.5)."""
    mantissa, _, exponent = text.strip().lower().partition("e")
    decimals = len(mantissa.split(".")[1]) if "." in mantissa else 0
    return 0.5 * 10.0 ** (-decimals + (int(exponent) if exponent else 0))


# -- configuration: eqs. 2.3-2.6 and the joint tuning 2.14-2.15 ---------------------------


def cylinder_inertia(mass: float, radius: float, height: float) -> np.ndarray:
    """Solid cylinder about its centre, axis Z [kg m^2] (thesis eqs. 2.3-2.4)."""
    lateral = mass * (3.0 * radius**2 + height**2) / 12.0
    return np.diag([lateral, lateral, 0.5 * mass * radius**2])


_AXIS = {"+x": (0, 1.0), "-x": (0, -1.0), "+y": (1, 1.0), "-y": (1, -1.0)}


def span_vector(direction: str) -> np.ndarray:
    """Unit vector of a plate's span in the hub frame."""
    axis, sign = _AXIS[direction]
    out = np.zeros(3)
    out[axis] = sign
    return out


def plate(app: dict) -> dict:
    """A thesis plate from its config: mass, centroidal inertia in its span frame
    (span along Y, width along X, thickness along Z), root-to-centre distance, the
    six joint stiffnesses and dampings [eta_x, eta_y, eta_z, rho_x, rho_y, rho_z].

    Each joint DOF is tuned so that the plate clamped at its root alone, on that DOF,
    has the target frequency: k = I_root (2 pi f)^2 with I_root the plate's mass
    (translations) or its inertia about the root axis (rotations, parallel axis
    theorem); c = 2 zeta sqrt(k I_root) (thesis eqs. 2.14-2.15).
    """
    L, W, t = app["length_m"], app["width_m"], app["thickness_m"]
    m = app["mass_kg"] if app.get("mass_kg") is not None else app["surface_density_kg_m2"] * L * W
    centroid = np.diag([m * (L**2 + t**2) / 12.0, m * (W**2 + t**2) / 12.0,
                        m * (L**2 + W**2) / 12.0])  # fmt: skip
    arm = L / 2.0
    about_root = [m, m, m, centroid[0, 0] + m * arm**2, centroid[1, 1],
                  centroid[2, 2] + m * arm**2]  # fmt: skip
    f = app["target_frequencies_hz"]
    targets = [f["translation_x"], f["translation_y"], f["translation_z"], f["flapping"],
               f["torsion"], f["in_plane"]]  # fmt: skip
    k = [i * (2.0 * math.pi * fr) ** 2 for i, fr in zip(about_root, targets, strict=True)]
    c = [
        2.0 * app["damping_ratio"] * math.sqrt(ki * i) for ki, i in zip(k, about_root, strict=True)
    ]
    return {"mass": m, "centroid": centroid, "arm": arm, "stiffness": k, "damping": c}


def _skew(v) -> np.ndarray:
    return np.array([[0.0, -v[2], v[1]], [v[2], 0.0, -v[0]], [-v[1], v[0], 0.0]])


def span_frame(direction: str) -> np.ndarray:
    """Rotation taking the plate's own frame (span along +Y) to the hub frame: a plate
    spanning -Y is the +Y one turned by pi about Z."""
    axis, sign = _AXIS[direction]
    if axis == 1:
        return np.eye(3) if sign > 0 else np.diag([-1.0, -1.0, 1.0])
    turn = -math.pi / 2 if sign > 0 else math.pi / 2  # +x: +Y turned by -90 deg about Z
    return Rotation.from_euler("z", turn).as_matrix()


def mass_matrix_at_rest(config: dict) -> np.ndarray:
    """M(0) of a hub with thesis plates, from rigid-body mechanics [SI].

    Generalized velocities: hub translation rate (B), hub Euler rates (= the body
    rate at q = 0), and per plate the root translation rates and root rotation rates,
    both along the hub axes at q = 0 (mount yaw and SADM angle zero: checked). The
    kinetic energy of each body is 1/2 m |v_c|^2 + 1/2 w^T I_c w; its Jacobians at
    q = 0: v_c = v + w x r_c + eta_dot + rho_dot x (arm s), w_plate = w + rho_dot.
    """
    hub = config["hub"]
    J_hub = (np.asarray(hub["inertia_kg_m2"]) if hub.get("inertia_kg_m2") is not None
             else cylinder_inertia(hub["mass_kg"], hub["radius_m"], hub["height_m"]))  # fmt: skip
    apps = config["appendages"]
    n = 6 + 6 * len(apps)
    M = np.zeros((n, n))
    M[:3, :3] = hub["mass_kg"] * np.eye(3)
    M[3:6, 3:6] = J_hub
    for k, app in enumerate(apps):
        assert app["mount_yaw_deg"] == 0.0 and app["sadm_angle_deg"] == 0.0, app["name"]
        p = plate(app)
        s = span_vector(app["span_direction"])
        r_c = np.asarray(app["mount_point_m"]) + p["arm"] * s
        R = span_frame(app["span_direction"])
        I_c = R @ p["centroid"] @ R.T
        Jv = np.zeros((3, n))  # centre-of-mass velocity
        Jw = np.zeros((3, n))  # angular velocity
        j = 6 + 6 * k
        Jv[:, 0:3] = np.eye(3)
        Jv[:, 3:6] = -_skew(r_c)
        Jv[:, j : j + 3] = np.eye(3)
        Jv[:, j + 3 : j + 6] = -_skew(p["arm"] * s)
        Jw[:, 3:6] = np.eye(3)
        Jw[:, j + 3 : j + 6] = np.eye(3)
        M += p["mass"] * Jv.T @ Jv + Jw.T @ I_c @ Jw
    return M


def stiffness_damping(config: dict) -> tuple[np.ndarray, np.ndarray]:
    """K_sys and C_damp (diagonal; zero on the hub's six DOFs)."""
    k, c = [0.0] * 6, [0.0] * 6
    for app in config["appendages"]:
        p = plate(app)
        k += p["stiffness"]
        c += p["damping"]
    return np.diag(k), np.diag(c)


# -- modes: K phi = w^2 M phi (eq. 3.3) --------------------------------------------------

HUB_DOFS = ("x", "y", "z", "phi", "theta", "psi")
_HUB = HUB_DOFS
_KIND = ("translation", "translation", "translation", "flapping", "torsion", "in_plane")


def modes(config: dict) -> list[dict]:
    """Every mode: frequency [Hz], kind, symmetry, hub DOF, in ascending frequency.

    - kind: the joint DOF type holding most of the mode's strain energy k_j phi_j^2
      (rotation about X: flapping, about Y: torsion, about Z: in-plane, any
      translation);
    - symmetry: the parity under the reflection through the hub XZ plane (y -> -y on
      positions and translations, rotations as axial vectors: x, z rotations flip;
      the two plates swap), by the M-weighted overlap <phi, P phi>_M / <phi, phi>_M;
      above 0.9 in size a definite parity, else "none";
    - hub DOF: the hub coordinate of largest mass-weighted amplitude sqrt(M_jj)|phi_j|
      when it reaches 10 % of the largest over all coordinates.
    """
    M = mass_matrix_at_rest(config)
    K, _ = stiffness_damping(config)
    w2, phi = eigh(K, M)
    n = M.shape[0]
    P = _mirror(config, n)
    out = []
    for i in range(n):
        v = phi[:, i]
        rigid = w2[i] < 1e-6 * w2.max()
        freq = 0.0 if rigid else math.sqrt(w2[i]) / (2 * math.pi)
        entry = {"index": i + 1, "frequency_hz": freq}
        if not rigid:
            strain = np.diag(K) * v**2
            by_kind = {}
            for j in range(6, n):
                kind = _KIND[(j - 6) % 6]
                by_kind[kind] = by_kind.get(kind, 0.0) + strain[j]
            entry["kind"] = max(by_kind, key=by_kind.get)
            overlap = (v @ M @ (P @ v)) / (v @ M @ v) if P is not None else 0.0
            entry["symmetry"] = ("symmetric" if overlap > 0.9 else
                                 "antisymmetric" if overlap < -0.9 else "none")  # fmt: skip
            amplitude = np.sqrt(np.diag(M)) * np.abs(v)
            hub = int(np.argmax(amplitude[:6]))
            entry["hub_dof"] = _HUB[hub] if amplitude[hub] >= 0.1 * amplitude.max() else None
        out.append(entry)
    return out


def _mirror(config: dict, n: int) -> np.ndarray | None:
    """The reflection y -> -y in generalized coordinates, for two mirror-image plates."""
    apps = config["appendages"]
    if len(apps) != 2:
        return None
    a, b = apps

    def image(app):
        point = np.asarray(app["mount_point_m"]) * [1, -1, 1]
        return point.tolist(), {"+y": "-y", "-y": "+y"}.get(app["span_direction"])

    same = {k: v for k, v in a.items() if k not in ("name", "mount_point_m", "span_direction")}
    other = {k: v for k, v in b.items() if k not in ("name", "mount_point_m", "span_direction")}
    if same != other or image(a) != (list(b["mount_point_m"]), b["span_direction"]):
        return None
    translation = np.diag([1.0, -1.0, 1.0])
    rotation = np.diag([-1.0, 1.0, -1.0])  # axial vector: det(reflection) * reflection
    P = np.zeros((n, n))
    P[0:3, 0:3], P[3:6, 3:6] = translation, rotation
    # joint coordinates along the hub axes at q = 0: the plates swap
    for src, dst in ((6, 12), (12, 6)):
        P[dst : dst + 3, src : src + 3] = translation
        P[dst + 3 : dst + 6, src + 3 : src + 6] = rotation
    return P


def mode_entry(mode: dict, M: np.ndarray, v: np.ndarray, names: list[str]) -> dict:
    """A mode as ``flexsat modal --json`` lists it: index, frequency, kind ("rigid" for a
    rigid-body mode), symmetry ("none" for one), its dominant DOFs (mass-weighted
    amplitude sqrt(M_jj)|phi_j| at least half the largest, largest first) and hub DOF."""
    amplitude = np.sqrt(np.diag(M)) * np.abs(v)
    amplitude = amplitude / amplitude.max()
    order = np.argsort(-amplitude, kind="stable")
    rigid = mode["frequency_hz"] == 0.0
    return {
        "index": mode["index"],
        "frequency_hz": mode["frequency_hz"],
        "kind": "rigid" if rigid else mode["kind"],
        "symmetry": "none" if rigid else mode["symmetry"],
        "dominant_dofs": [names[j] for j in order if amplitude[j] >= 0.5],
        "hub_dof": None if rigid else mode["hub_dof"],
    }


def effective_masses(config: dict) -> dict:
    """Modal effective masses and inertias of the hub-fixed appendage modes
    (docs/linear.md, 'Frequency-domain views'): phi mass-normalized on the joint block
    of M(0), L = phi^T M_fh, effective = L^2 per hub direction; the residual
    M_hh - M_hf M_ff^-1 M_fh adds up with them to M_hh (the total); the cumulative
    fraction of the total, mode by mode."""
    M = mass_matrix_at_rest(config)
    K, _ = stiffness_damping(config)
    w2, phi = eigh(K[6:, 6:], M[6:, 6:])
    L = phi.T @ M[6:, :6]
    effective = L**2
    total = np.diag(M[:6, :6])
    residual = np.diag(M[:6, :6] - M[:6, 6:] @ np.linalg.solve(M[6:, 6:], M[6:, :6]))
    return {
        "directions": ["x", "y", "z", "rx", "ry", "rz"],
        "units": ["kg", "kg", "kg", "kg m^2", "kg m^2", "kg m^2"],
        "frequencies_hz": (np.sqrt(w2) / (2 * math.pi)).tolist(),
        "effective": effective.tolist(),
        "cumulative_fraction": (np.cumsum(effective, axis=0) / total).tolist(),
        "residual": residual.tolist(),
        "total": total.tolist(),
    }


def flexible_peaks(config: dict, plant: control.StateSpace, loop, axis: int) -> list[dict]:
    """The loop gain's peak at each flexible mode that drives this axis's rotation (hub
    DOF phi, theta, psi): the mode's natural frequency |lambda| / 2 pi from the
    eigenvalues of A, the largest |L(jw)| within +-10 % of it (bounded search on a
    fine grid, refined by scipy), in dB, and how the loop copes with it: "gain"
    when the peak stays below 0 dB, else "phase"."""
    from scipy.optimize import minimize_scalar

    lam = np.linalg.eigvals(plant.A)
    lam = lam[lam.imag > 0]
    out = []
    for mode in modes(config):
        if mode["frequency_hz"] == 0.0 or mode["hub_dof"] != HUB_DOFS[3 + axis]:
            continue
        w0 = 2 * math.pi * mode["frequency_hz"]
        natural = abs(lam[np.argmin(np.abs(np.abs(lam) - w0))])
        grid = np.linspace(0.9 * natural, 1.1 * natural, 4001)
        gain = np.abs(loop(1j * grid)).ravel()
        k = int(np.argmax(gain))
        lo, hi = grid[max(k - 1, 0)], grid[min(k + 1, grid.size - 1)]
        best = minimize_scalar(lambda w: -abs(complex(loop(1j * w))), bounds=(lo, hi),
                               method="bounded", options={"xatol": 1e-12 * natural})  # fmt: skip
        peak_db = 20 * math.log10(-best.fun)
        out.append({"mode_hz": natural / (2 * math.pi), "peak_hz": best.x / (2 * math.pi),
                    "peak_gain_db": peak_db,
                    "stabilized": "gain" if peak_db < 0 else "phase"})  # fmt: skip
    return out


# -- a run's records -----------------------------------------------------------------


def stored(ds, name: str) -> np.ndarray:
    return np.asarray(ds[name].values, dtype=float)


def scenario_of(ds) -> dict:
    return json.loads(ds.attrs["scenario"])


def config_of(ds) -> dict:
    return json.loads(ds.attrs["config"])


def quat_scalar_last(q: np.ndarray) -> np.ndarray:
    return np.concatenate([q[..., 1:], q[..., :1]], axis=-1)


def error_vectors(ds) -> np.ndarray:
    """Rotation vector of q_e = q_d^-1 (x) q per record [deg] (eq. 4.1; its components
    are the same in the target and the hub frame), the target from the scenario's
    ZYX Euler angles."""
    roll, pitch, yaw = scenario_of(ds)["target_euler_deg"]
    target = Rotation.from_euler("ZYX", [yaw, pitch, roll], degrees=True)
    attitude = Rotation.from_quat(quat_scalar_last(stored(ds, "quaternion")))
    return np.degrees((target.inv() * attitude).as_rotvec())


def settle(t: np.ndarray, values: np.ndarray, bound: float) -> float | None:
    """The time from which ``values`` stay below ``bound`` to the end (None: never)."""
    above = np.nonzero(~(values < bound))[0]
    if above.size == 0:
        return float(t[0])
    if above[-1] == t.size - 1:
        return None
    return float(t[above[-1] + 1])


def _time_eps(t: np.ndarray) -> float:
    return 1e-6 * float(t[1] - t[0])


def slew_metrics(ds, plates: bool = True) -> dict:
    """A slew's metrics from its records and stored scenario (docs/control.md, 'How R1
    and R2 are judged'; docs/results.md). Without ``plates`` (a satellite whose
    appendages are not plain thesis plates), no tip displacement nor elastic energy."""
    sc = scenario_of(ds)
    req = sc["requirements"]
    t = stored(ds, "time")
    eps = _time_eps(t)
    e = error_vectors(ds)
    pointing = np.linalg.norm(e, axis=1)
    rate = np.degrees(np.linalg.norm(stored(ds, "omega"), axis=1))  # step: omega_d = 0
    assert sc["reference"]["kind"] == "step", "omega_d = 0 holds for a step reference only"
    start = req["settling_deadline_s"]
    end = req["window_end_s"] if req["window_end_s"] is not None else sc["duration_s"]
    # judged only when the planned run covers the window; a run planned to end before
    # it is "not judged" (None), one that stopped early fails
    judged = start < end <= sc["duration_s"] + eps
    inside = (t >= start - eps) & (t <= end + eps) & judged
    covered = t[-1] >= end - eps
    ape = float(pointing[inside].max()) if inside.any() else None
    max_rate = float(rate[inside].max()) if inside.any() else None
    # RPE: consecutive sub-windows of rpe_window_s from the window's start
    window = req["rpe_window_s"]
    bins = np.floor((t[inside] - start) / window + 1e-9).astype(int)
    ew = e[inside]
    rpe = 0.0
    for b in np.unique(bins):
        chunk = ew[bins == b]
        rpe = max(rpe, float(np.linalg.norm(chunk - chunk.mean(axis=0), axis=1).max()))
    if bins.size and np.bincount(bins - bins.min()).max() < 2:
        rpe = float("nan")  # every window a lone record: not measured
    applied = np.abs(stored(ds, "tau_applied"))
    t_max = sc["actuator"]["t_max_nm"]
    lam = stored(ds, "lambda_act") if "lambda_act" in ds else None
    switch = None
    if lam is not None:
        moved = np.nonzero(np.abs(lam - lam[0]) > 1e-9 * abs(lam[0]))[0]
        switch = float(t[moved[0]]) if moved.size else None
    roll, pitch, yaw = np.nan, np.nan, np.nan
    zyx = Rotation.from_quat(quat_scalar_last(stored(ds, "quaternion")[-1])).as_euler(
        "ZYX", degrees=True
    )
    yaw, pitch, roll = zyx
    dt = sc["dt_s"]
    return {
        "final_pointing_error_deg": float(pointing[-1]),
        "final_rate_error_deg_s": float(rate[-1]),
        "settling_time_s": settle(t, pointing, req["pointing_deg"]),
        "r2_settling_time_s": settle(t, rate, req["jitter_deg_s"]),
        "observation_window_s": [start, end],
        "r1_pass": bool(covered and ape < req["pointing_deg"]) if judged else None,
        "r2_pass": bool(covered and max_rate < req["jitter_deg_s"]) if judged else None,
        # the reason's wording is flexsat's; here only whether there is one (the runs
        # this module rebuilds are all judged, so a non-empty text would not match)
        "not_judged_reason": "" if judged else "not judged",
        "ape_deg": ape,
        "rpe_deg": rpe,
        "rpe_window_s": window,
        "max_rate_error_deg_s": max_rate,
        "max_abs_torque_nm": applied.max(axis=0).tolist(),
        "max_commanded_torque_nm": np.abs(stored(ds, "tau_cmd")).max(axis=0).tolist(),
        "r3_pass": r3_pass(ds, applied, t_max),
        "lambda_switch_time_s": switch,
        "final_euler_deg": [roll, pitch, yaw],
        "peak_flex_torque_nm": np.abs(stored(ds, "tau_flex")).max(axis=0).tolist(),
        "peak_tip_displacement_m": peak_tip(ds) if plates else None,
        "finite_until_s": finite_until(ds),
        "steps": round(sc["duration_s"] / dt),
        "status": "ok" if finite_until(ds) >= sc["duration_s"] - eps else "failed",
        "control_energy_j": float(
            np.trapezoid(np.abs(np.sum(stored(ds, "tau_applied") * stored(ds, "omega"), axis=1)), t)
        ),
        "residual_elastic_energy_j": (
            float(elastic_energy(ds)[t >= t[-1] - 10.0 - eps].max()) if plates else None
        ),
    }


def r3_pass(ds, applied: np.ndarray, t_max: float) -> bool:
    """R3 (docs/control.md, 'R3 with an actuator of units'): an actuator of units (one
    that records ``actuator_torque_ratio``, the largest motor torque asked of a unit
    over its limit) passes when that ratio stays at most 1 and no unit reached its
    momentum limit (``actuator_saturated`` nonzero); any other actuator when the hub
    torque stays within T_max per axis at every record."""
    saturated = "actuator_saturated" in ds and bool(np.any(stored(ds, "actuator_saturated")))
    if "actuator_torque_ratio" in ds:
        ratio = stored(ds, "actuator_torque_ratio")
        return bool(np.all(ratio[np.isfinite(ratio)] <= 1.0)) and not saturated
    return bool(np.all(applied <= t_max)) and not saturated


def residual_rate_verdict(ds) -> dict:
    """The delay sweep's stability verdict (docs/control.md, 'Stability verdict of the
    delay sweep'): the observation window cut in two halves, the envelope of a half
    its peak residual rate, the ratio the second half's over the first's; diverges
    (stopped, or ratio >= 2), stable (second half inside R2's band, or ratio <= 0.5),
    else a limit cycle."""
    sc = scenario_of(ds)
    req = sc["requirements"]
    t = stored(ds, "time")
    eps = _time_eps(t)
    rate = np.degrees(np.linalg.norm(stored(ds, "omega"), axis=1))
    start = req["settling_deadline_s"]
    end = req["window_end_s"] if req["window_end_s"] is not None else sc["duration_s"]
    mid = 0.5 * (start + end)
    first = rate[(t >= start - eps) & (t < mid - eps)].max()
    last = rate[(t >= mid - eps) & (t <= end + eps)].max()
    ratio = float(last / first)
    stopped = finite_until(ds) < sc["duration_s"] - eps
    if stopped:
        verdict = "diverges"
    elif last < req["jitter_deg_s"]:
        verdict = "stable"
    elif ratio >= 2.0:
        verdict = "diverges"
    elif ratio <= 0.5:
        verdict = "stable"
    else:
        verdict = "limit cycle"
    return {"verdict": verdict, "envelope_last_deg_s": float(last), "envelope_ratio": ratio}


def finite_until(ds) -> float:
    t = stored(ds, "time")
    ok = np.ones(t.size, bool)
    for name in ("q", "qd", "quaternion", "omega"):  # the plant's state
        ok &= np.isfinite(stored(ds, name).reshape(t.size, -1)).all(axis=1)
    bad = np.nonzero(~ok)[0]
    return float(t[-1] if bad.size == 0 else t[max(bad[0] - 1, 0)])


def joint_coordinates(ds) -> tuple[np.ndarray, np.ndarray]:
    """Joint coordinates and rates per record, (time, appendage, 6) each."""
    q, qd = stored(ds, "q"), stored(ds, "qd")
    n = (q.shape[1] - 6) // 6
    return q[:, 6:].reshape(-1, n, 6), qd[:, 6:].reshape(-1, n, 6)


def elastic_energy(ds) -> np.ndarray:
    """U = 1/2 sum k_j q_j^2 per record [J], k from the tuning of the stored config."""
    K, _ = stiffness_damping(config_of(ds))
    q = stored(ds, "q")
    return 0.5 * np.sum(np.diag(K) * q**2, axis=1)


def peak_tip(ds) -> float:
    """Largest tip displacement over the run [m]: the root translation plus the span
    vector turned by the root's ZYX rotation, less the span vector, in the mount frame
    (the hub axes at zero mount yaw and SADM angle)."""
    cfg = config_of(ds)
    eta, _ = joint_coordinates(ds)
    peak = 0.0
    for k, app in enumerate(cfg["appendages"]):
        span = app["length_m"] * span_vector(app["span_direction"])
        rot = Rotation.from_euler("ZYX", eta[:, k, [5, 4, 3]]).as_matrix()
        tip = eta[:, k, :3] + rot @ span - span
        peak = max(peak, float(np.linalg.norm(tip, axis=1).max()))
    return peak


def openloop_metrics(ds) -> dict:
    """The open-loop run's numbers (thesis section 3.3) from its records and physics.

    The angular momentum of the free satellite is the torque's impulse; the final
    rate and energy are those of the locked body spinning with it (the elastic motion
    has decayed); U = 1/2 sum k q^2; the dissipation the integral of sum c qd^2; the
    ripple frequency the peak of the yaw acceleration's spectrum after the torque
    ends (Hann window, zero-padded FFT, 0.05 Hz and up).
    """
    sc = scenario_of(ds)
    cfg = config_of(ds)
    t = stored(ds, "time")
    eps = _time_eps(t)
    impulse = np.zeros(3)
    ends = 0.0
    for seg in sc["torque"]:
        impulse += np.asarray(seg["torque_nm"]) * (seg["end_s"] - seg["start_s"])
        ends = max(ends, seg["end_s"])
    J_locked = mass_matrix_at_rest(cfg)[3:6, 3:6]
    spin = np.linalg.solve(J_locked, impulse)  # final body rate (rest attitude: yaw spin)
    K, C = stiffness_damping(cfg)
    U = 0.5 * np.sum(np.diag(K) * stored(ds, "q") ** 2, axis=1)
    power = np.sum(np.diag(C) * stored(ds, "qd") ** 2, axis=1)
    free = t >= ends - eps
    yaw_acc = stored(ds, "omega_dot")[free, 2]
    yaw_acc = (yaw_acc - yaw_acc.mean()) * np.hanning(yaw_acc.size)
    n_fft = 1 << 20
    spectrum = np.abs(np.fft.rfft(yaw_acc, n_fft))
    freqs = np.fft.rfftfreq(n_fft, float(t[1] - t[0]))
    spectrum[freqs < 0.05] = 0.0
    q = stored(ds, "q")
    rho = q[:, 6:].reshape(q.shape[0], -1, 6)[:, :, 3:]
    balance = (stored(ds, "total_energy") - stored(ds, "total_energy")[0]
               - stored(ds, "work_in") + stored(ds, "dissipated_energy"))  # fmt: skip
    return {
        "final_angular_momentum_nms": impulse.tolist(),
        "final_rate_deg_s": np.degrees(spin).tolist(),
        "total_energy_j": float(0.5 * spin @ J_locked @ spin),
        "peak_elastic_energy_j": float(U.max()),
        "dissipated_energy_j": float(np.trapezoid(power, t)),
        "peak_flex_torque_nm": np.abs(stored(ds, "tau_flex")).max(axis=0).tolist(),
        "peak_tip_displacement_m": peak_tip(ds),
        "peak_root_rotation_deg": float(np.degrees(np.abs(rho).max())),
        "dominant_frequency_hz": float(freqs[np.argmax(spectrum)]),
        "energy_balance_error_j": float(np.abs(balance).max()),
        "finite_until_s": finite_until(ds),
        "steps": round(sc["duration_s"] / sc["dt_s"]),
        "status": "ok" if finite_until(ds) >= sc["duration_s"] - eps else "failed",
    }


# -- statistics over a campaign's cases ---------------------------------------------------


def statistics(rows: list[dict]) -> dict:
    """One variant's figures over its cases' metrics (docs/control.md, 'Comparing the
    laws over the campaigns'): pass rates, settling-time quantiles (linear
    interpolation between order statistics) and the count that never settle, the
    largest peaks, and the median and largest energies."""
    n = len(rows)
    ok = [r for r in rows if r["status"] == "ok"]

    def quantiles(key):
        values = sorted(r[key] for r in ok if r[key] is not None)
        out = {"never": n - len(values)}
        for name, p in (("min", 0.0), ("median", 0.5), ("p90", 0.9), ("max", 1.0)):
            if not values:
                out[name] = None
                continue
            pos = p * (len(values) - 1)
            lo = math.floor(pos)
            hi = min(lo + 1, len(values) - 1)
            out[name] = values[lo] + (pos - lo) * (values[hi] - values[lo])
        return out

    return {
        "cases": n,
        "failed": n - len(ok),
        **{f"r{i}_pass_rate": sum(r[f"r{i}_pass"] for r in ok) / n for i in (1, 2, 3)},
        "settling_time_s": quantiles("settling_time_s"),
        "r2_settling_time_s": quantiles("r2_settling_time_s"),
        "peak_flex_torque_nm": max(max(r["peak_flex_torque_nm"]) for r in ok),
        "peak_tip_displacement_m": max(r["peak_tip_displacement_m"] for r in ok),
        "control_energy_j": {"median": float(np.median([r["control_energy_j"] for r in ok])),
                             "max": max(r["control_energy_j"] for r in ok)},
        "residual_elastic_energy_j": {
            "median": float(np.median([r["residual_elastic_energy_j"] for r in ok])),
            "max": max(r["residual_elastic_energy_j"] for r in ok)},
    }  # fmt: skip


# -- loop margins (docs/linear.md, 'Loop gains and margins') -----------------------------


def state_space(config: dict) -> control.StateSpace:
    """The satellite about rest: x = (q, qd), u = body torque, y = (attitude, rate):
    A = [[0, I], [-M^-1 K, -M^-1 C]], B = [0; M^-1 [0; I3; 0]] (eqs. 2.50, 3.4)."""
    M = mass_matrix_at_rest(config)
    K, C = stiffness_damping(config)
    n = M.shape[0]
    Minv = np.linalg.inv(M)
    A = np.block([[np.zeros((n, n)), np.eye(n)], [-Minv @ K, -Minv @ C]])
    E = np.zeros((n, 3))
    E[3:6] = np.eye(3)
    B = np.vstack([np.zeros((n, 3)), Minv @ E])
    Cy = np.zeros((6, 2 * n))
    Cy[0:3, 3:6] = np.eye(3)
    Cy[3:6, n + 3 : n + 6] = np.eye(3)
    return control.ss(A, B, Cy, np.zeros((6, 3)))


def sliding_gains(law: dict, J: np.ndarray) -> np.ndarray:
    """tau = -K (theta, omega) of an SMC/ASMC inside its boundary layer about rest
    (docs/linear.md, 'Sliding-mode laws inside their boundary layer'): with
    q_v,e = theta/2 and s = omega + Lambda q_v,e, tau = -Lambda J omega / 2 -
    JK s / Phi, Lambda = lambda_max and JK = jk_min for the ASMC at the target."""
    lam = law["lambda_max"] if law["kind"] == "asmc" else law["lambda"]
    jk = law["jk_min_nm"] if law["kind"] == "asmc" else law["jk_nm"]
    phi = law["phi"]
    K_theta = jk * lam / (2.0 * phi) * np.eye(3)
    K_omega = lam * J / 2.0 + jk / phi * np.eye(3)
    return np.hstack([K_theta, K_omega])


def loop_margins(plant: control.StateSpace, K: np.ndarray, axis: int) -> dict:
    """Margins of the loop broken at one axis's torque, the other two closed.

    The loop gain L(s) = K_a C (sI - A_cl)^-1 B_a, A_cl = A - B_o K_o C. python-control
    gives the margins (``stability_margins``: the phase margin of least size over the
    gain crossovers, the gain margin, infinite when the phase never crosses -180 deg)
    and every gain crossover with its phase margin (``returnall=True``); the delay
    margin is the least (phase margin mod 360 deg) / w_c over the crossovers.
    """
    import warnings

    A, B, C = plant.A, plant.B, plant.C
    others = [i for i in range(3) if i != axis]
    A_cl = A - B[:, others] @ K[others] @ C
    L = control.ss(A_cl, B[:, [axis]], K[[axis]] @ C, 0.0)
    # The polynomial form from scipy whether or not slycot is installed: python-control
    # converts with slycot's tb04ad when it can, whose polynomials of this stiff loop
    # give spurious phase crossings near 0 Hz.
    num, den = scipy.signal.ss2tf(A_cl, B[:, [axis]], K[[axis]] @ C, np.zeros((1, 1)))
    polynomial = control.tf(num[0], den)
    with warnings.catch_warnings():  # python-control's polynomial pass overflows harmlessly
        warnings.simplefilter("ignore", RuntimeWarning)
        gm, pm, _, wpc, wgc, _ = control.stability_margins(polynomial)
        _, pms, _, _, wgcs, _ = control.stability_margins(polynomial, returnall=True)
    crossings = sorted(zip(np.atleast_1d(wgcs), np.atleast_1d(pms), strict=True))
    delays = [math.radians(p % 360.0) / w for w, p in crossings]
    k_dm = int(np.argmin(delays))
    infinite = not np.isfinite(gm)
    return {
        "phase_margin_deg": float(pm),
        "gain_crossover_hz": float(wgc) / (2 * math.pi),
        "gain_margin": None if infinite else float(gm),
        "phase_crossover_hz": None if infinite else float(wpc) / (2 * math.pi),
        "delay_margin_s": delays[k_dm],
        "delay_crossover_hz": float(crossings[k_dm][0]) / (2 * math.pi),
        "crossovers_hz": [float(w) / (2 * math.pi) for w, _ in crossings],
        "crossovers": [
            {
                "frequency_hz": float(w) / (2 * math.pi),
                "phase_margin_deg": float(p),
                "delay_margin_s": d,
            }
            for (w, p), d in zip(crossings, delays, strict=True)
        ],
        "loop": L,
    }


# -- robust stability: the thesis's parameter box, transcribed a second time ---------------

THESIS_BOX = {  # factor on the nominal value at delta = -1 and +1 (thesis section 5.2.2)
    "frequency": (0.8, 1.2),  # the rotation joints' target frequencies +-20 %
    "damping": (0.0, 1.0),  # the damping ratio from 0 to the nominal
    "hub_inertia": (0.8, 1.2),
    "panel_inertia": (0.8, 1.2),  # the panel mass, so its inertia
}
_ROTATION_TARGETS = ("flapping", "in_plane", "torsion")


def perturbed(config: dict, factors: dict) -> dict:
    """The satellite with each factor applied to its nominal value: the rotation joints'
    target frequencies, the damping ratio, the hub's inertia tensor, the plates' mass."""
    out = json.loads(json.dumps(config))
    hub = out["hub"]
    J = (np.asarray(hub["inertia_kg_m2"]) if hub.get("inertia_kg_m2") is not None
         else cylinder_inertia(hub["mass_kg"], hub["radius_m"], hub["height_m"]))  # fmt: skip
    hub["inertia_kg_m2"] = (factors.get("hub_inertia", 1.0) * J).tolist()
    for app in out["appendages"]:
        for axis in _ROTATION_TARGETS:
            app["target_frequencies_hz"][axis] *= factors.get("frequency", 1.0)
        app["damping_ratio"] *= factors.get("damping", 1.0)
        key = "mass_kg" if app.get("mass_kg") is not None else "surface_density_kg_m2"
        app[key] *= factors.get("panel_inertia", 1.0)
    return out


def box_factors(config: dict, nominal: dict) -> dict:
    """The factors that make ``config`` from ``nominal`` (one per parameter; asserted
    the same on every plate and rotation joint)."""

    def hub_J(c):
        h = c["hub"]
        return (np.asarray(h["inertia_kg_m2"]) if h.get("inertia_kg_m2") is not None
                else cylinder_inertia(h["mass_kg"], h["radius_m"], h["height_m"]))  # fmt: skip

    found = {name: [] for name in THESIS_BOX}
    for app, ref in zip(config["appendages"], nominal["appendages"], strict=True):
        for axis in _ROTATION_TARGETS:
            found["frequency"].append(app["target_frequencies_hz"][axis]
                                      / ref["target_frequencies_hz"][axis])  # fmt: skip
        found["damping"].append(app["damping_ratio"] / ref["damping_ratio"])
        found["panel_inertia"].append(plate(app)["mass"] / plate(ref)["mass"])
    Jc, Jn = hub_J(config), hub_J(nominal)
    found["hub_inertia"] = list(np.diag(Jc) / np.diag(Jn))
    out = {}
    for name, values in found.items():
        assert np.ptp(values) <= 1e-12 * max(1.0, abs(values[0])), (name, values)
        out[name] = float(values[0])
    return out


def box_delta(factors: dict) -> np.ndarray:
    """Normalized delta of each parameter, in :data:`THESIS_BOX`'s order."""
    return np.array([(factors[n] - 0.5 * (lo + hi)) / (0.5 * (hi - lo))
                     for n, (lo, hi) in THESIS_BOX.items()])  # fmt: skip


def box_point(delta) -> dict:
    """The factors at a normalized delta (in :data:`THESIS_BOX`'s order)."""
    return {n: 0.5 * (lo + hi) + 0.5 * (hi - lo) * d
            for (n, (lo, hi)), d in zip(THESIS_BOX.items(), delta, strict=True)}  # fmt: skip


def closed_loop_poles(config: dict, K: np.ndarray) -> np.ndarray:
    """Poles of the satellite about rest closed by tau = -K (attitude, rate), the hub's
    translation states left out: no force depends on them about rest (their columns of
    A are zero), so they only add six poles at 0."""
    plant = state_space(config)
    A_cl = plant.A - plant.B @ K @ plant.C
    n = A_cl.shape[0] // 2
    keep = np.setdiff1d(np.arange(2 * n), [0, 1, 2, n, n + 1, n + 2])
    return np.linalg.eigvals(A_cl[np.ix_(keep, keep)])


def envelope_decay_rate(t: np.ndarray, energy: np.ndarray) -> float:
    """Slowest vibration decay [1/s] from the elastic energy's envelope (docs/linear.md,
    'In the study report'): its maxima over 10-20 s and over the last 10 s, E ~ exp(2
    Re(lambda) t) between the windows' centres."""
    early = energy[(t >= 10.0) & (t < 20.0)].max()
    late = energy[t >= t[-1] - 10.0].max()
    return float(np.log(late / early) / (2.0 * ((t[-1] - 5.0) - 15.0)))
