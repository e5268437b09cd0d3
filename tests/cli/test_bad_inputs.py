"""Every bad input a user can give ends with one message and exit code 2, never a traceback.

Each row: the files the user wrote, the command, a fragment the message must hold.
The command runs through the real entry point (:func:`flexsat.cli.main.main`), in
this process (see ``harness.py``). Nothing may be written outside the folders the
command was given, and the message is one line of bounded length.
"""

from __future__ import annotations

import copy
import importlib.util
import math
import os
import tomllib
from dataclasses import dataclass, field

import numpy as np
import pytest

from tests.cli.harness import flexsat, modal_table, npz_bytes, to_toml
from tests.conftest import nominal_dict

FIFO = object()
"""A file's content in :attr:`Bad.files`: the file is a named pipe (FIFO) no one writes to."""


@dataclass(frozen=True)
class Bad:
    id: str
    argv: list[str]
    fragment: str
    files: dict = field(default_factory=dict)
    timeout_s: int = 60  # a command still running then fails the test (Hang)


def _satellite(edit) -> str:
    data = nominal_dict()
    edit(data)
    return to_toml(data)


def _set(path: str, value):
    """An edit of the nominal config: set (or, with ``...``, delete) a dotted path."""

    def edit(data):
        *parents, last = path.split(".")
        node = data
        for part in parents:
            node = node[int(part)] if part.isdigit() else node[part]
        if value is ...:
            del node[int(last) if last.isdigit() else last]
        else:
            node[int(last) if last.isdigit() else last] = copy.deepcopy(value)

    return edit


def _config(id: str, path: str, value, fragment: str, command: str = "show") -> Bad:
    argv = ["config", "show", "--config", "{tmp}/c.toml"] if command == "show" else [
        "modal", "--config", "{tmp}/c.toml"]  # fmt: skip
    return Bad(id, argv, fragment, {"c.toml": _satellite(_set(path, value))})


def _scenario(id: str, body: str, fragment: str, command: str = "openloop") -> Bad:
    return Bad(id, [command, "--scenario", "{tmp}/s.toml"], fragment, {"s.toml": body})


def _campaign(id: str, body: str, fragment: str, *extra: str) -> Bad:
    argv = ["campaign", "{tmp}/k.toml", "--out", "{tmp}/store", *extra]
    return Bad(id, argv, fragment, {"k.toml": body})


_CYLINDER_OFF = {"mass_kg": 150.0}
_FREQ = "appendages.0.target_frequencies_hz"

CONFIGS = [
    _config("unknown top-level key", "colour", "red", "unknown key 'colour'"),
    _config("misspelt key", "hub.mass", 150.0, "did you mean 'mass_kg'"),
    _config("radians-style key", "appendages.0.sadm_angle", 0.5, "did you mean 'sadm_angle_deg'"),
    _config("missing hub mass", "hub.mass_kg", ..., "missing required field 'hub.mass_kg'"),
    _config("negative hub mass", "hub.mass_kg", -150.0, "hub.mass_kg: Input should be greater"),
    _config("zero panel length", "appendages.0.length_m", 0.0, "appendages[0].length_m"),
    _config(
        "string for a number", "hub.radius_m", "0.6", "hub.radius_m: Input should be a valid number"
    ),
    _config("boolean for a number", "appendages.1.width_m", True, "appendages[1].width_m"),
    _config("NaN mass", "hub.mass_kg", math.nan, "hub.mass_kg: Input should be a finite number"),
    _config("infinite density", "appendages.0.surface_density_kg_m2", math.inf, "finite number"),
    _config("zero frequency", f"{_FREQ}.flapping", 0.0, "target_frequencies_hz.flapping"),
    _config("negative damping", "appendages.0.damping_ratio", -0.01, "damping_ratio"),
    _config("damping ratio of one", "appendages.1.damping_ratio", 1.0, "less than 1"),
    _config("SADM angle 400 deg", "appendages.0.sadm_angle_deg", 400.0, "sadm_angle_deg"),
    _config("mass and density", "appendages.0.mass_kg", 6.75, "exactly one of"),
    _config(
        "neither mass nor density", "appendages.0.surface_density_kg_m2", ..., "exactly one of"
    ),
    _config(
        "mount point of two numbers", "appendages.0.mount_point_m", [0.0, 0.8], "mount_point_m"
    ),
    _config("bad span direction", "appendages.0.span_direction", "+x", "span_direction"),
    _config("no appendages", "appendages", [], "at least 1 item"),
    _config("duplicate names", "appendages.1.name", "panel_1", "names must be unique"),
    _config(
        "cylinder and inertia", "hub.inertia_kg_m2", [[1, 0, 0], [0, 1, 0], [0, 0, 1]], "not both"
    ),
    _config("hub without geometry", "hub.radius_m", ..., "give both radius_m and height_m"),
    _config("thick plate", "appendages.0.thickness_m", 2.0, "thickness_m must not exceed"),
    _config("hub as a number", "hub", 3, "hub: expected a TOML table"),
    _config(
        "asymmetric inertia",
        "hub",
        {**_CYLINDER_OFF, "inertia_kg_m2": [[40, 1, 0], [0, 40, 0], [0, 0, 27]]},
        "must be symmetric",
    ),
    _config(
        "indefinite inertia",
        "hub",
        {**_CYLINDER_OFF, "inertia_kg_m2": [[40, 0, 0], [0, -1, 0], [0, 0, 27]]},
        "positive definite",
    ),
    _config(
        "non-physical inertia",
        "hub",
        {**_CYLINDER_OFF, "inertia_kg_m2": [[1, 0, 0], [0, 1, 0], [0, 0, 5]]},
        "J1 + J2 >= J3",
    ),
    _config(
        "all-zero inertia",
        "hub",
        {**_CYLINDER_OFF, "inertia_kg_m2": [[0, 0, 0], [0, 0, 0], [0, 0, 0]]},
        "got all zeros",
    ),
    _config(
        "huge inertia entry",
        "hub",
        {**_CYLINDER_OFF, "inertia_kg_m2": [[1e300, 0, 0], [0, 1e300, 0], [0, 0, 1e300]]},
        "less than or equal to 1000000000000",
    ),
    _config(
        "hub radius 1.34e154 (Hypothesis)",
        "hub.radius_m",
        1.34e154,
        "hub.radius_m: Input should be less than or equal to 1000",
    ),
    _config("panel length 1e200", "appendages.0.length_m", 1e200, "appendages[0].length_m"),
    _config("frequency 1e300", f"{_FREQ}.torsion", 1e300, "less than or equal to 10000"),
    _config("flapping target 1e9 Hz", f"{_FREQ}.flapping", 1e9, "target_frequencies_hz.flapping"),
    _config("panel width 7.5e5 m", "appendages.0.width_m", 7.5e5, "appendages[0].width_m"),
    _config("hub mass 5e-324", "hub.mass_kg", 5e-324, "greater than or equal to 0.0001"),
    _config(
        "hub mass markup",
        "hub.mass_kg",
        "[/x]",
        "hub.mass_kg: Input should be a valid number (got '[/x]')",
    ),
    _config(
        "appendage named with markup",
        "appendages.1.name",
        "[/]p2",
        "appendages[1].name: contains characters",
        command="modal",
    ),
    _config(
        "appendage named with mathtext",
        "appendages.0.name",
        "$p_1$",
        "appendages[0].name: contains characters",
    ),
    _config("satellite named with markup", "name", "[bold]sat", "name: contains characters"),
    _config(
        "mount point inside the hub",
        "appendages.0.mount_point_m",
        [0.0, 0.3, 0.0],
        "is inside the hub",
    ),
    _config(
        "mount point at the hub centre",
        "appendages.0.mount_point_m",
        [0.0, 0.0, 0.0],
        "is inside the hub",
    ),
    _config(
        "mount point 1e6 m away", "appendages.0.mount_point_m", [0.0, 1e6, 0.0], "mount_point_m"
    ),
    _config(
        "ill-conditioned modes",
        "appendages",
        [
            {
                **nominal_dict()["appendages"][k],
                "target_frequencies_hz": {
                    **nominal_dict()["appendages"][k]["target_frequencies_hz"],
                    "flapping": 1e-3,
                    "translation_x": 1e4,
                },
            }
            for k in range(2)
        ],
        "modal analysis ill-conditioned",
        command="modal",
    ),
    Bad(
        "TOML nested 100000 deep",
        ["config", "show", "--config", "{tmp}/c.toml"],
        "nested too deep",
        {"c.toml": "x = " + "[" * 100_000 + "]" * 100_000 + "\n"},
    ),
    Bad(
        "not valid TOML",
        ["modal", "--config", "{tmp}/c.toml"],
        "not valid TOML",
        {"c.toml": "[hub\n"},
    ),
    Bad(
        "not UTF-8",
        ["modal", "--config", "{tmp}/c.toml"],
        "cannot read config file",
        {"c.toml": b'name = "\xff"\n'},
    ),
    Bad("missing config file", ["modal", "--config", "{tmp}/absent.toml"], "config file not found"),
    Bad("config is a folder", ["modal", "--config", "{tmp}"], "cannot read config file"),
]


def _controller_npz(**overrides) -> bytes:
    """A statespace law's controller file (order 2, dt 1 ms) with ``overrides``; None drops one."""
    arrays = {"A": 0.5 * np.eye(2), "B": np.ones((2, 6)), "C": np.ones((3, 2)),
              "D": np.zeros((3, 6)), "dt": np.array(1e-3)}  # fmt: skip
    arrays.update(overrides)
    return npz_bytes({k: v for k, v in arrays.items() if v is not None})


def _controller(id: str, fragment: str, name: str = "k.npz", **overrides) -> Bad:
    body = f'duration_s = 100.0\n[controller]\nkind = "statespace"\nfile = "{name}"\n'
    content = overrides.pop("content", None) or _controller_npz(**overrides)
    return Bad(
        id, ["slew", "--scenario", "{tmp}/s.toml"], fragment, {"s.toml": body, name: content}
    )


# A discrete state-space controller file (statespace law): shapes, finite, dt = control_dt_s.
STATESPACE_FILES = [
    _controller("controller B of 5 columns", "controller file {tmp}/k.npz: B must have shape (2, 6)", B=np.ones((2, 5))),
    _controller("controller C of 4 rows", "C must have shape (3, 2)", C=np.ones((4, 2))),
    _controller("controller A not square", "A must have shape (2, 2)", A=np.ones((2, 3))),
    _controller("controller with NaN", "A must hold finite entries within +-1e+12", A=np.full((2, 2), np.nan)),
    _controller("controller order 65", "the order (rows of A) must be in 1..64, got 65", A=np.eye(65), B=np.ones((65, 6)), C=np.ones((3, 65))),
    _controller("controller without dt", "missing variable(s) dt (needs A, B, C, D, dt)", dt=None),
    _controller("controller dt negative", "dt must be one number in (0, 10] s", dt=np.array(-1e-3)),
    _controller("controller dt of another loop", "controller.file: the controller was discretized at dt = 0.01 s, the loop runs at control_dt_s = 0.001 s", dt=np.array(1e-2)),
    _controller("controller file not an NPZ", "controller file {tmp}/k.npz: not a readable .npz file", content=b"not a zip"),
    _controller("controller file .txt", "controller file {tmp}/k.txt: the suffix must be .npz or .mat, got '.txt'", name="k.txt"),
    _controller("controller .mat not a MAT file", "controller file {tmp}/k.mat: not a readable .mat file", name="k.mat", content=b"MATLAB 5.0 garbage"),
    Bad("controller file missing", ["slew", "--scenario", "{tmp}/s.toml"], "controller file not found", {"s.toml": '[controller]\nkind = "statespace"\nfile = "absent.npz"\n'}),
    Bad("controller file not named", ["slew", "--scenario", "{tmp}/s.toml"], "controller.file", {"s.toml": '[controller]\nkind = "statespace"\n'}),
    Bad("hybrid controller of another period", ["slew", "--scenario", "{tmp}/s.toml"], "controller.file: the controller was discretized at dt = 0.01 s", {"s.toml": '[controller]\nkind = "hybrid"\nfile = "k.npz"\n', "k.npz": _controller_npz(dt=np.array(1e-2))}),
    Bad("hybrid switch at 0 deg", ["slew", "--scenario", "{tmp}/s.toml"], "controller.switch_pointing_deg", {"s.toml": '[controller]\nkind = "hybrid"\nfile = "k.npz"\nswitch_pointing_deg = 0.0\n', "k.npz": _controller_npz()}),
    # flexsat robust synthesize: options refused before the (slow) synthesis
    Bad("robust synthesize to a .txt", ["robust", "synthesize", "--out", "{tmp}/k.txt"], "--out: the suffix must be .npz or .mat, got '.txt'"),
    Bad("robust synthesize into a missing folder", ["robust", "synthesize", "--out", "{tmp}/none/k.npz"], "--out: the folder {tmp}/none does not exist"),
    Bad("robust synthesize of order 0", ["robust", "synthesize", "--out", "{tmp}/k.npz", "--order", "0"], "--order: must be in 1 ... 64, got 0"),
    Bad("robust synthesize of order 65", ["robust", "synthesize", "--out", "{tmp}/k.npz", "--order", "65"], "--order: must be in 1 ... 64, got 65"),
    Bad("robust synthesize with -1 modes", ["robust", "synthesize", "--out", "{tmp}/k.npz", "--modes", "-1"], "--modes: must be in 0 ... 50, got -1"),
    Bad("robust synthesize at dt 0", ["robust", "synthesize", "--out", "{tmp}/k.npz", "--control-dt", "0"], "--control-dt: must be in (0, 10] s, got 0"),
]  # fmt: skip

SCENARIOS = [
    _scenario("dt 1e-9 s", "dt_s = 1e-9\nrecord_dt_s = 1e-2\n", "steps is more than the 1e+09 allowed"),
    _scenario("duration 1e6 s", "duration_s = 1e6\n", "GiB in memory"),
    _scenario("slew of 1e6 s", "duration_s = 1e6\n", "GiB in memory", command="slew"),
    _scenario("start_s as a string", '[[torque]]\nstart_s = "0"\ntorque_nm = [0, 0, 1]\n', "torque[0].start_s"),
    _scenario("start_s as a boolean", "[[torque]]\nstart_s = true\ntorque_nm = [0, 0, 1]\n", "torque[0].start_s"),
    _scenario("end before start", "[[torque]]\nstart_s = 5.0\nend_s = 2.0\ntorque_nm = [0, 0, 1]\n", "end_s must be > start_s"),
    _scenario("torque after the end", "duration_s = 10.0\n[[torque]]\nstart_s = 20.0\ntorque_nm = [0, 0, 1]\n", "it would never act"),
    _scenario("two initial states for one panel", '[[initial.appendages]]\nname = "panel_1"\n[[initial.appendages]]\nname = "panel_1"\n', "one initial state per appendage"),
    _scenario("initial state of an unknown panel", '[[initial.appendages]]\nname = "panel_9"\n', "unknown appendage 'panel_9'"),
    _scenario("initial pitch at the singularity", "[initial]\nattitude_deg = [0, 89.5, 0]\n", "pitch must be within"),
    _scenario("large root rotation", '[[initial.appendages]]\nname = "panel_1"\nrho_deg = [50, 0, 0]\n', "rho_deg must stay below 45"),
    _scenario("unknown solver", 'solver = "euler"\n', "solver"),
    _scenario("record step not a multiple", "dt_s = 0.003\nrecord_dt_s = 0.01\n", "whole multiple of dt_s"),
    _scenario("unknown scenario key", "duraton_s = 5.0\n", "did you mean 'duration_s'"),
    _scenario("unknown law", '[controller]\nkind = "magic"\n', "controller"),
    _scenario("negative requirement", "[requirements]\npointing_deg = -1.0\n", "requirements.pointing_deg", command="slew"),
    _scenario("polynomial reference without duration", '[reference]\nkind = "eigenaxis"\nprofile = "polynomial"\n', "duration_s is required", command="slew"),
    _scenario("unknown shaper", '[reference]\nkind = "eigenaxis"\n[reference.shaper]\nkind = "zvdd"\n', "reference.shaper.kind", command="slew"),
    _scenario("negative joint authority", '[joint_actuator]\nkind = "rate_feedback"\ncoordinates = ["eta_ry"]\ngain = 1.0\nlimit = -0.1\n', "joint_actuator.limit", command="slew"),
    _scenario("unknown joint coordinate", '[joint_actuator]\nkind = "rate_feedback"\ncoordinates = ["rho_q"]\ngain = 1.0\nlimit = 0.1\n', "joint_actuator.coordinates: unknown coordinate 'rho_q'", command="slew"),
    _scenario("smooth lambda of zero time constant", '[controller]\nlambda_adaptation = "smooth"\nlambda_time_constant_s = 0.0\n', "controller.lambda_time_constant_s", command="slew"),
    # The observation window R1/R2 are judged over must lie inside the run (it would fail them silently).
    _scenario("window opens after the run", "duration_s = 2.0\n[requirements]\nsettling_deadline_s = 500.0\n", "duration_s = 2 s ends the run before its observation window opens (requirements.settling_deadline_s = 500 s)", command="slew"),
    _scenario("window closes after the run", "duration_s = 20.0\n[requirements]\nsettling_deadline_s = 5.0\nwindow_end_s = 30.0\n", "requirements.window_end_s = 30 s is after the run ends (duration_s = 20 s)", command="slew"),
    Bad("--duration before the default window", ["slew", "--duration", "30"], "--duration 30: duration_s = 30 s ends the run before its observation window opens (requirements.settling_deadline_s = 90 s)"),
    Bad("--duration before the scenario's window", ["slew", "--scenario", "{tmp}/s.toml", "--duration", "4"], "give duration_s > 5 s or requirements.settling_deadline_s < 4 s", {"s.toml": "[requirements]\nsettling_deadline_s = 5.0\n"}),
    Bad("missing scenario file", ["openloop", "--scenario", "{tmp}/absent.toml"], "scenario file not found"),
]  # fmt: skip

PATHS = [
    Bad("openloop --out a file", ["openloop", "--out", "{tmp}/f"], "exists and is not a folder", {"f": "x"}),
    Bad("openloop --out /proc", ["openloop", "--out", "/proc/flexsat-test"], "cannot write there"),
    Bad("slew --out under a file", ["slew", "--out", "{tmp}/f/sub"], "cannot write there", {"f": "x"}),
    Bad("modal --out /proc", ["modal", "--out", "/proc/flexsat-test"], "cannot write there"),
    Bad("study --out a file", ["study", "--quick", "--out", "{tmp}/f"], "exists and is not a folder", {"f": "x"}),
    Bad("campaign --out a file", ["campaign", "sensitivity", "--out", "{tmp}/f"], "exists and is not a folder", {"f": "x"}),
    Bad("preset into a missing folder", ["config", "preset", "-o", "{tmp}/no/such/x.toml"], "does not exist"),
    Bad("preset over a file", ["config", "preset", "-o", "{tmp}/f"], "exists", {"f": "x"}),
    Bad("unknown preset", ["config", "preset", "heavy"], "unknown preset 'heavy'"),
    Bad("replay outside the store", ["campaign", "replay", "{tmp}", "../../outside"], "not a campaign store"),
    Bad("replay of a path as case id", ["campaign", "replay", "{tmp}/store", "../../outside"], "is not a case id",
        {"store/campaign.json": '{"name": "x", "fingerprint": {}}'}),
    Bad("replay of a missing case", ["campaign", "replay", "{tmp}/store", "nominal"], "no case 'nominal'",
        {"store/campaign.json": '{"name": "x", "fingerprint": {}}'}),
    Bad("replay of a damaged case", ["campaign", "replay", "{tmp}/store", "nominal"], "damaged case file",
        {"store/campaign.json": '{"name": "x", "fingerprint": {}}', "store/cases/nominal.json": '{"case_id": "nomi'}),
    Bad("replay without a case", ["campaign", "replay", "{tmp}"], "usage: flexsat campaign replay"),
    Bad("slew target of two numbers", ["slew", "--target-euler-deg", "1,2"], "expected three comma-separated"),
    Bad("animate a missing file", ["animate", "{tmp}/absent.nc"], "file not found"),
    Bad("animate a non-NetCDF file", ["animate", "{tmp}/f.nc"], "not a readable NetCDF file", {"f.nc": "x"}),
    Bad("modal --animate out of range", ["modal", "--animate", "99"], "mode index must be in 1..18"),
    Bad("equations in an unknown format", ["equations", "--format", "html"], "--format must be"),
]  # fmt: skip


def _modal_file(name: str) -> str:
    """The nominal config with its first plate replaced by a modal appendage read from ``name``."""
    data = nominal_dict()
    data["appendages"][0] = {"name": "wing", "model": "modal", "mount_point_m": [0.0, 0.8, 0.0],
                             "file": name}  # fmt: skip
    return to_toml(data)


# Input files that are not regular files: a FIFO would block a read for ever, /dev/zero fill
# the memory. Each is refused at once (10 s bound: far above the millisecond it takes, far
# below the harness's 60 s) with the one message of flexsat.files.read_user_file.
_NOT_REGULAR = "not a regular file"
SPECIAL_FILES = [
    Bad("config is a FIFO", ["config", "show", "--config", "{tmp}/c.toml"], f"cannot read config file {{tmp}}/c.toml: {_NOT_REGULAR}", {"c.toml": FIFO}, 10),
    Bad("config is /dev/zero", ["modal", "--config", "/dev/zero"], f"cannot read config file /dev/zero: {_NOT_REGULAR}", {}, 10),
    Bad("scenario is a FIFO", ["openloop", "--scenario", "{tmp}/s.toml"], f"cannot read scenario file {{tmp}}/s.toml: {_NOT_REGULAR}", {"s.toml": FIFO}, 10),
    Bad("slew scenario is /dev/zero", ["slew", "--scenario", "/dev/zero"], f"cannot read scenario file /dev/zero: {_NOT_REGULAR}", {}, 10),
    Bad("campaign is a FIFO", ["campaign", "{tmp}/k.toml", "--out", "{tmp}/store"], f"cannot read campaign file {{tmp}}/k.toml: {_NOT_REGULAR}", {"k.toml": FIFO}, 10),
    Bad("campaign is /dev/zero", ["campaign", "/dev/zero", "--out", "{tmp}/store"], f"cannot read campaign file /dev/zero: {_NOT_REGULAR}", {}, 10),
    Bad("modal data TOML is a FIFO", ["modal", "--config", "{tmp}/c.toml"], f"cannot read modal data file {{tmp}}/m.toml: {_NOT_REGULAR}", {"c.toml": _modal_file("m.toml"), "m.toml": FIFO}, 10),
    Bad("modal data NPZ is a FIFO", ["modal", "--config", "{tmp}/c.toml"], f"cannot read modal data file {{tmp}}/m.npz: {_NOT_REGULAR}", {"c.toml": _modal_file("m.npz"), "m.npz": FIFO}, 10),
    Bad("plot a FIFO", ["plot", "{tmp}/r.nc"], f"cannot read RESULT file {{tmp}}/r.nc: {_NOT_REGULAR}", {"r.nc": FIFO}, 10),
    Bad("animate a FIFO", ["animate", "{tmp}/r.nc"], f"cannot read RESULT file {{tmp}}/r.nc: {_NOT_REGULAR}", {"r.nc": FIFO}, 10),
]  # fmt: skip


def _modal_npz(**arrays) -> bytes:
    """The NPZ of :func:`~tests.cli.harness.modal_table` with ``arrays`` replaced."""
    from flexsat.config.modal_data import modal_data_from_dict

    return npz_bytes({**modal_data_from_dict(modal_table()).to_arrays(), **arrays})


def _forged_npz() -> bytes:
    """A valid NPZ but for output_mode_shapes: its header asks for (2000, 1000000) float64,
    14.9 GiB, over 64 KiB of data."""
    import io
    import zipfile

    header = io.BytesIO()
    np.lib.format.write_array_header_1_0(
        header, {"descr": "<f8", "fortran_order": False, "shape": (2000, 1_000_000)}
    )
    buffer = io.BytesIO()
    with zipfile.ZipFile(io.BytesIO(_modal_npz())) as source, zipfile.ZipFile(buffer, "w") as out:
        for info in source.infolist():
            forged = info.filename == "output_mode_shapes.npy"
            out.writestr(
                info.filename, header.getvalue() + bytes(65536) if forged else source.read(info)
            )
    return buffer.getvalue()


def _modal_toml(**changes) -> str:
    return to_toml({**modal_table(), **changes})


def _chains(count: int, segments: int) -> str:
    """``count`` uniform 3-DOF chains of ``segments`` segments around the nominal hub."""
    data = {
        "name": "chains",
        "hub": {"mass_kg": 150.0, "radius_m": 0.6, "height_m": 1.5},
        "appendages": [],
    }
    for k in range(count):
        angle = 2.0 * math.pi * k / count
        data["appendages"].append(
            {
                "name": f"c{k}",
                "model": "chain",
                "segments": segments,
                "span_direction": "+y",
                "mount_point_m": [0.8 * math.sin(-angle), 0.8 * math.cos(angle), 0.0],
                "mount_yaw_deg": math.degrees(angle),
                "length_m": 4.5,
                "width_m": 1.5,
                "thickness_m": 0.02,
                "surface_density_kg_m2": 1.0,
                "joint": {"dofs": ["rx", "ry", "rz"], "damping_ratio": 0.005},
                "beam": {"EI_flap_N_m2": 123.0, "EI_in_plane_N_m2": 491.0, "GJ_N_m2": 58.3},
            }
        )
    return to_toml(data)


def _chain_joint(**joint) -> str:
    data = tomllib.loads(_chains(2, 4))
    data["appendages"][0]["joint"] = {
        "dofs": ["x", "rx"],
        "stiffness": {"x": 1e3, "rx": 10.0},
        "damping_ratio": 0.005,
        **joint,
    }
    del data["appendages"][0]["beam"]
    return to_toml(data)


_MODAL = ["modal", "--config", "{tmp}/c.toml"]
_MEKF_ALONE = '[[sensor_stages]]\nkind = "mekf"\n'
# Crafted modal data files, huge numbers that reached the solvers, and nonsense the
# boundary accepted: each now refused with its field and range (docs/modal_format.md,
# docs/model.md 'Allowed ranges of the physical inputs' and 'Geometric interference').
ROBUSTNESS = [
    Bad("truncated modal NPZ", _MODAL, "cannot read modal data file {tmp}/m.npz: File is not a zip file", {"c.toml": _modal_file("m.npz"), "m.npz": _modal_npz()[:700]}),
    Bad("0-d output_names", _MODAL, "output_names: expected an array of shape (k,), got shape ()", {"c.toml": _modal_file("m.npz"), "m.npz": _modal_npz(output_names=np.array("tip"))}),
    Bad("0-d output_mode_shapes", _MODAL, "output_mode_shapes: expected an array of shape (k, n, 3), got shape ()", {"c.toml": _modal_file("m.npz"), "m.npz": _modal_npz(output_mode_shapes=np.array(0.5))}),
    Bad("NPZ header asking 14.9 GiB", _MODAL, "output_mode_shapes: shape (2000, 1000000) holds more than the 6000000 numbers", {"c.toml": _modal_file("m.npz"), "m.npz": _forged_npz()}, 10),
    Bad("modal frequency 1e200 Hz", _MODAL, "frequencies_hz: each must be within [0.001, 1e+08] Hz, mode 2 is 1e+200 Hz", {"c.toml": _modal_file("m.toml"), "m.toml": _modal_toml(frequencies_hz=[0.8, 1e200])}),
    Bad("modal frequency 1e-300 Hz", _MODAL, "frequencies_hz: each must be within [0.001, 1e+08] Hz, mode 1 is 1e-300 Hz", {"c.toml": _modal_file("m.toml"), "m.toml": _modal_toml(frequencies_hz=[1e-300, 2.5])}),
    Bad("linearize about a spin of 1e300 rad/s", ["linearize", "--about", "spin:1e300,0,0", "--out", "{tmp}/lin"], "--about: each spin component must be within +-100 rad/s"),
    Bad("64 chains of 512 segments", ["modal", "--config", "{tmp}/c.toml", "--out", "{tmp}/m"], "coordinates; its dense 98310 x 98310 matrices", {"c.toml": _chains(64, 512)}),
    _scenario("environment torque 1e300 N m", "[disturbances]\nenvironment_nm = [1e300, 0.0, 0.0]\n", "disturbances.environment_nm: each axis must be within +-actuator.t_max_nm = +-2 N m", command="slew"),
    _scenario("initial eta_m 1e300 m", '[[initial.appendages]]\nname = "panel_1"\neta_m = [1e300, 0, 0]\n', "initial.appendages[0].eta_m[0]: Input should be less than or equal to 10 (got 1e+300)"),
    _scenario("initial rate 1e300 deg/s", "[initial]\nrate_deg_s = [0, 0, 1e300]\n", "initial.rate_deg_s[2]: Input should be less than or equal to 10000 (got 1e+300)"),
    Bad("chain joint initial 1e300 m", ["config", "show", "--config", "{tmp}/c.toml"], "appendages[0].joint: initial.x: 1e+300 m, must be within +-10 m", {"c.toml": _chain_joint(initial={"x": 1e300})}),
    _config("two panels on one mount point", "appendages.1.mount_point_m", [0.0, 0.8, 0.0], "appendages[1].mount_point_m [0.0, 0.8, 0.0] is the mount point of appendages[0]"),
    _config("panel spanning through the hub", "appendages.0.span_direction", "-y", "appendages[0] (panel_1) passes through the hub"),
    _scenario("MEKF without gyro or star tracker", _MEKF_ALONE, "sensor_stages[0].kind: an MEKF needs a gyro or a star tracker", command="slew"),
]  # fmt: skip

_ROBUST = ["robust", "analyze", "--points", "8"]
_MU_K = {"A": -np.eye(2), "B": np.zeros((2, 6)), "C": np.zeros((3, 2)), "D": np.zeros((3, 6))}
ROBUST_ANALYZE = [
    Bad("robust analyze on 3 frequencies", ["robust", "analyze", "--points", "3"], "--points: the frequency grid needs 8 ... 2000 points, got 3"),
    Bad("robust analyze at SADM 500 deg", [*_ROBUST, "--sadm-angle", "500"], "--sadm-angle: an angle within [-180, 180] deg, got 500"),
    Bad("robust analyze of a missing controller", [*_ROBUST, "--controller", "{tmp}/none.npz"], "--controller {tmp}/none.npz: no such file"),
    Bad("robust analyze of a text controller", [*_ROBUST, "--controller", "{tmp}/k.npz"], "--controller {tmp}/k.npz: not an NPZ of arrays A, B, C, D", {"k.npz": "A = 1\n"}),
    Bad("robust analyze of a controller without D", [*_ROBUST, "--controller", "{tmp}/k.npz"], "--controller {tmp}/k.npz: missing array D", {"k.npz": npz_bytes({k: v for k, v in _MU_K.items() if k != "D"})}),
    Bad("robust analyze of a controller with B 2 x 5", [*_ROBUST, "--controller", "{tmp}/k.npz"], "controller.B: expected shape (2, 6)", {"k.npz": npz_bytes({**_MU_K, "B": np.zeros((2, 5))})}),
    Bad("robust analyze of a controller with a NaN", [*_ROBUST, "--controller", "{tmp}/k.npz"], "controller.A: every entry must be a finite number", {"k.npz": npz_bytes({**_MU_K, "A": np.full((2, 2), np.nan)})}),
]  # fmt: skip
ROBUSTNESS += ROBUST_ANALYZE  # the inputs of `flexsat robust analyze`

CAMPAIGNS = [
    _campaign("campaign named with ../", 'name = "../../../outside"\n', "name: contains characters"),
    _campaign("campaign named with an absolute path", 'name = "/tmp/outside"\n', "name: contains characters"),
    _campaign("unknown modifier path", 'name = "k"\n[[cases]]\nid = "a"\nplant = [{ path = "hub.colour", value = 1.0 }]\n', "no 'colour'"),
    _campaign("uniform bounds reversed", 'name = "k"\n[[cases]]\nid = "a"\nplant = [{ path = "hub.mass_kg", uniform = [2.0, 1.0] }]\n', "low < high"),
    _campaign("case value out of range", 'name = "k"\n[[cases]]\nid = "a"\nplant = [{ path = "hub.mass_kg", value = -5.0 }]\n', "campaign case 'a' (plant): hub.mass_kg"),
    _campaign("case id with a slash", 'name = "k"\n[[cases]]\nid = "a/b"\n', "cases[0].id"),
    _campaign("random n negative", 'name = "k"\n[random]\nn = -3\n', "random.n"),
    _campaign("base dt 1e-9 s", 'name = "k"\n[base]\ndt_s = 1e-9\ncontrol_dt_s = 1e-3\nrecord_dt_s = 1e-2\n', "steps is more than"),
    _campaign("base of 1e6 s", 'name = "k"\n[base]\nduration_s = 1e6\n', "GiB in memory"),
    # a modifier's value and bounds checked against the field it targets, before any case runs
    _campaign("scale factor as text", 'name = "k"\n[[cases]]\nid = "a"\nplant = [{ path = "hub.mass_kg", op = "scale", value = "x" }]\n', "cases[0].plant[0]: hub.mass_kg: op = 'scale' takes a finite number as its factor (value), got 'x'"),
    _campaign("hub inertia factor as text", 'name = "k"\n[[cases]]\nid = "a"\nplant = [{ path = "hub.inertia", op = "scale", value = "x" }]\n', "hub.inertia: op = 'scale' takes a finite number as its factor"),
    _campaign("hub inertia set to text", 'name = "k"\n[[cases]]\nid = "a"\nplant = [{ path = "hub.inertia", value = "x" }]\n', "modifier 'hub.inertia' (op = 'set'): hub.inertia takes a finite number (a scale factor"),
    _campaign("uniform to infinity", 'name = "k"\n[[cases]]\nid = "a"\nplant = [{ path = "hub.mass_kg", uniform = [0.8, inf] }]\n', "hub.mass_kg: uniform takes finite numbers (|x| <= 1.798e+308), got [0.8, inf]"),
    _campaign("uniform wider than a float", 'name = "k"\n[[cases]]\nid = "a"\nplant = [{ path = "hub.mass_kg", op = "scale", uniform = [-1e308, 1e308] }]\n', "high - low must be <= 1.798e+308"),
    _campaign("scaled appendage name", 'name = "k"\n[[cases]]\nid = "a"\nplant = [{ path = "appendages[0].name", op = "scale", value = 3 }]\n', "modifier 'appendages[0].name' (op = 'scale'): appendages[0].name is 'panel_1', not a number"),
    _campaign("worst-case metric unknown", 'name = "k"\n[worst_case]\nmetric = "happiness"\nparameters = [{ path = "hub.mass_kg", bounds = [100.0, 200.0] }]\n', "worst_case.metric: 'happiness' is not a numeric slew metric"),
    _campaign("duplicate case id", 'name = "k"\n[[cases]]\nid = "a"\n[[cases]]\nid = "a"\n', "campaign k: duplicate case ids: 'a'"),
    _campaign("scheduler and local cluster", 'name = "k"\n', "either --scheduler or --dask-local", "--scheduler", "tcp://127.0.0.1:1", "--dask-local", "2"),
    Bad("unknown campaign", ["campaign", "no-such-campaign"], "neither a preset"),
    Bad("negative case count", ["campaign", "montecarlo-random", "--cases", "-3", "--out", "{tmp}/s"], "--cases must be >= 1"),
    Bad("zero workers", ["campaign", "sensitivity", "--workers", "0"], "Invalid value for '--workers'"),
    Bad("campaign of an unknown law", ["campaign", "sensitivity", "--controller", "lqr", "--out", "{tmp}/s"], "--controller: unknown control law 'lqr'"),
]  # fmt: skip


def _budget_result() -> bytes:
    """A 1 s slew result (11 records at the target attitude), as NetCDF bytes."""
    import xarray as xr

    t = np.arange(11) * 0.1
    identity = np.tile([1.0, 0.0, 0.0, 0.0], (t.size, 1))
    ds = xr.Dataset(
        {"quaternion": (("time", "component"), identity)},
        coords={"time": t},
        attrs={"target_quaternion": [1.0, 0.0, 0.0, 0.0]},
    )
    return bytes(ds.to_netcdf())


def _budget(id: str, pointing: str, fragment: str) -> Bad:
    argv = ["budget", "{tmp}/result.nc", "--requirements", "{tmp}/req.toml", "--out", "{tmp}/b"]
    files = {"result.nc": _budget_result(), "req.toml": f"[pointing]\n{pointing}\n"}
    return Bad(id, argv, fragment, files)


def _jitter(
    id: str,
    options: list[str],
    fragment: str,
    stepper: str | None = None,
    microvibration: str | None = None,
) -> Bad:
    """``flexsat jitter`` with ``options``, a [stepper] file and a scenario's microvibration."""
    argv, files = ["jitter", "--speeds", "100:6000:20", *options], {}
    if stepper is not None:
        argv += ["--stepper", "{tmp}/st.toml"]
        files["st.toml"] = stepper
    if microvibration is not None:
        argv += ["--scenario", "{tmp}/s.toml"]
        files["s.toml"] = f'[actuator]\nkind = "wheels"\n{microvibration}'
    return Bad(id, argv, fragment, files)


_STEP = '[stepper]\ncoordinate = "panel_1.eta_ry"\nrate_deg_s = 0.06\n'
_ONE = "harmonics = [{number = 1.0, amplitude_nm = 0.01}]\n"
_VIB = "[actuator.microvibration]\n"
JITTER = [
    _jitter("jitter speeds of two numbers", ["--speeds", "100:6000"], "--speeds: expected LOW:HIGH:COUNT, e.g. 100:6000:400, got '100:6000'"),
    _jitter("jitter speeds descending", ["--speeds", "6000:100:10"], "--speeds: need 0 < LOW < HIGH <= 1e6 rpm and 2 <= COUNT <= 100000, got '6000:100:10'"),
    _jitter("jitter speeds of one speed", ["--speeds", "100:6000:1"], "2 <= COUNT <= 100000, got '100:6000:1'"),
    _jitter("jitter window zero", ["--window", "0"], "--window: the RPE window must be finite and > 0 s, got 0"),
    _jitter("jitter window infinite", ["--window", "inf"], "--window: the RPE window must be finite and > 0 s, got inf"),
    _jitter("jitter window negative", ["--window", "-2"], "--window: the RPE window must be finite and > 0 s, got -2"),
    _jitter("jitter boresight zero", ["--boresight", "0,0,0"], "boresight: three finite numbers, not all zero"),
    _jitter("jitter boresight of two numbers", ["--boresight", "1,2"], "--boresight: expected three comma-separated numbers, got '1,2'"),
    _jitter("jitter stepper step angle zero", [], "{tmp}/st.toml: stepper: step_angle_deg: Input should be greater than 0", stepper=_STEP + "step_angle_deg = 0.0\n" + _ONE),
    _jitter("jitter stepper harmonic number zero", [], "stepper: harmonics[0].number: Input should be greater than 0", stepper=_STEP + "step_angle_deg = 0.01\nharmonics = [{number = 0.0, amplitude_nm = 0.01}]\n"),
    _jitter("jitter stepper on an unknown coordinate", [], "actuated: unknown coordinate 'panel_1.alpha'", stepper=_STEP.replace("eta_ry", "alpha") + "step_angle_deg = 0.01\n" + _ONE),
    _jitter("jitter stepper file without its table", [], "{tmp}/st.toml: a [stepper] table is needed", stepper="rate_deg_s = 0.06\n"),
    _jitter("jitter negative imbalance", [], "actuator.microvibration.static_imbalance_kg_m: Input should be greater than or equal to 0", microvibration=_VIB + "static_imbalance_kg_m = -1e-5\n"),
    _jitter("jitter harmonic number zero", [], "actuator.microvibration.radial_force[0].number: Input should be greater than 0", microvibration=_VIB + "radial_force = [{number = 0.0, coefficient = 1e-6}]\n"),
    _jitter("jitter wheels without microvibration", [], 'actuator.microvibration: the jitter needs [actuator] kind = "wheels"', microvibration=""),
    Bad("jitter stepper file missing", ["jitter", "--stepper", "{tmp}/none.toml"], "stepper file not found"),
]  # fmt: skip

_RPE = "[pointing.indices.RPE]\nbound_deg = 0.01\n"
BUDGET = [
    _budget("budget window longer than the run", _RPE + "window_s = 50.0", "pointing.indices.RPE.window_s: 50 s is longer than the record: at most 1.1 s"),
    _budget("budget drift separation beyond the run", "[pointing.indices.PDE]\nbound_deg = 0.01\nwindow_s = 0.5\nstability_s = 0.8", "pointing.indices.PDE.stability_s: 0.8 s is longer than the record"),
    _budget("budget confidence 1.5", "confidence = 1.5\n" + _RPE + "window_s = 0.5", "pointing.confidence: Input should be less than 1 (got 1.5)"),
    _budget("budget confidence 0", "[pointing.indices.APE]\nbound_deg = 0.01\nconfidence = 0.0", "pointing.indices.APE.confidence: Input should be greater than 0"),
    _budget("budget unknown index", "[pointing.indices.XPE]\nbound_deg = 0.01", "pointing: indices.XPE: unknown index; choose one of APE, MPE, RPE"),
    _budget("budget RPE without a window", _RPE, "indices.RPE.window_s: RPE needs a window length"),
    _budget("budget unknown interpretation", 'interpretation = "spatial"', "pointing.interpretation: Input should be 'temporal', 'ensemble' or 'mixed'"),
    _budget("budget ensemble of one run", 'interpretation = "ensemble"\n[pointing.indices.APE]\nbound_deg = 0.01', "pointing.interpretation: 'ensemble' needs a campaign"),
    Bad("budget of a missing result", ["budget", "{tmp}/none.nc", "--requirements", "{tmp}/req.toml"], "RESULT_OR_CAMPAIGN {tmp}/none.nc: no such file or folder", {"req.toml": "[pointing]\n"}),
]  # fmt: skip
BUDGET += JITTER  # the microvibration part of the pointing budget


def _nastran(id: str, change: str, extra: list[str], fragment: str) -> Bad:
    """``flexsat fe import`` of the frame deck of tests/fe/nastran_decks.py, changed."""
    from tests.fe.nastran_decks import deck_files

    argv = ["fe", "import", "{tmp}/d.bdf", "--op4", "{tmp}/m.op4", "-o", "{tmp}/w.npz",
            "--interface", "10", *extra]  # fmt: skip
    return Bad(id, argv, fragment, deck_files(change))


NASTRAN = [
    _nastran("NASTRAN interface grid not in the deck", "", ["--interface", "999"], "interface: grid 999 is not in the deck"),
    _nastran("NASTRAN singular stiffness", "singular", [], "KGG: singular stiffness: point 40 component 1 has no stiffness with grid 10 clamped"),
    _nastran("NASTRAN matrix size not the deck's", "size", [], "KGG is 24 x 24 but the deck's g-set has 30 DOFs"),
    _nastran("NASTRAN non-symmetric stiffness", "asymmetric", [], "KGG is not symmetric"),
    _nastran("NASTRAN OP4 without the named matrix", "", ["--stiffness", "KAA"], "no matrix 'KAA' (it holds KGG, MGG)"),
    _nastran("NASTRAN BDF that does not parse", "binary", [], "not a NASTRAN bulk data file"),
    _nastran("NASTRAN OP4 that is no OP4", "garbage", [], "m.op4: not an OP4 file"),
    _nastran("NASTRAN OP2 without eigenvalues", "", ["--op2", "{tmp}/x.op2"], "no eigenvalue table (LAMA)"),
    _nastran("NASTRAN modes out of range", "", ["--modes", "0"], "modes: must be in 1..18"),
    _nastran("NASTRAN damping out of range", "", ["--damping", "1.5"], "--damping: must be in [0, 1)"),
    _nastran("NASTRAN output of another kind", "", ["-o", "{tmp}/w.txt"], "--output: the suffix must be .npz or .toml, got 'w.txt'"),
    _nastran("NASTRAN stiffness not free-free", "grounded", [], "KGG: rigid motions about grid 10 are not free"),
    Bad("NASTRAN deck is a FIFO", ["fe", "import", "{tmp}/d.bdf", "--op4", "{tmp}/m.op4", "-o", "{tmp}/w.npz"], f"cannot read NASTRAN bulk data file {{tmp}}/d.bdf: {_NOT_REGULAR}", {"d.bdf": FIFO}, 10),
    Bad("NASTRAN deck missing", ["fe", "import", "{tmp}/none.bdf", "--op4", "{tmp}/m.op4", "-o", "{tmp}/w.npz"], "NASTRAN bulk data file not found"),
] if importlib.util.find_spec("pyyeti") else []  # fmt: skip

# The [orbit] table (docs/orbit.md, 'The orbit table'): closed orbits above the
# atmosphere, well-formed element sets, a target on the orbit only with one.
_TLE_1 = "1 25544U 98067A   26060.50000000  .00016717  00000-0  10270-3 0  9006"
ORBIT = [
    _scenario("orbit below the surface", "[orbit]\naltitude_m = -100e3\n", "orbit: the orbit's perigee a (1 - e) = 6278.14 km is -100 km above the surface", command="slew"),
    _scenario("perigee inside the atmosphere", "[orbit]\nsemi_major_axis_m = 7.0e6\neccentricity = 0.1\n", "give semi_major_axis_m (1 - eccentricity) >= 6478.14 km", command="slew"),
    _scenario("eccentricity 1", "[orbit]\neccentricity = 1.0\n", "orbit.eccentricity: must be in [0, 1) (a closed orbit), got 1", command="slew"),
    _scenario("hyperbolic orbit", "[orbit]\neccentricity = 1.5\n", "orbit.eccentricity: must be in [0, 1)", command="slew"),
    _scenario("TLE checksum wrong", f'[orbit]\ntle = ["{_TLE_1}", "2 25544  51.6400 208.9163 0006317  69.9862  25.2906 15.49560532  1008"]\n', "orbit.tle: tle line 2: checksum '8' does not match its contents (expected 9)", command="slew"),
    _scenario("TLE line cut short", f'[orbit]\ntle = ["{_TLE_1[:60]}", "2 25544  51.6400 208.9163 0006317  69.9862  25.2906 15.49560532  1008"]\n', "orbit.tle: tle line 1 must be 69 characters, got 60", command="slew"),
    _scenario("TLE lines swapped", f'[orbit]\ntle = ["2 25544  51.6400 208.9163 0006317  69.9862  25.2906 15.49560532  1008", "{_TLE_1}"]\n', "orbit.tle: tle line 1 must start with '1 '", command="slew"),
    _scenario("TLE and elements", f'[orbit]\naltitude_m = 500e3\ntle = ["{_TLE_1}", "2 25544  51.6400 208.9163 0006317  69.9862  25.2906 15.49560532  1009"]\n', "give the tle or the elements, not both", command="slew"),
    _scenario("epoch not a time", '[orbit]\nepoch = "yesterday"\n', "orbit.epoch: 'yesterday' is not an ISO 8601 UTC time", command="slew"),
    _scenario("epoch not in UTC", '[orbit]\nepoch = "2026-03-20T12:00:00+02:00"\n', "is not in UTC", command="slew"),
    _scenario("nadir pointing without an orbit", '[reference]\nkind = "nadir"\n', "reference.kind = 'nadir' points at a target along the orbit: add an [orbit] table", command="slew"),
    # the [environment] table (docs/environment.md, 'The environment table')
    _scenario("surface coefficient above 1", "[orbit]\naltitude_m = 500e3\n[environment.models.srp]\n[environment.surfaces.front]\nspecular = 1.2\ndiffuse = 0.0\nabsorbed = 0.0\n", "environment.surfaces.front.specular: Input should be less than or equal to 1 (got 1.2)", command="slew"),
    _scenario("surface coefficient negative", "[orbit]\naltitude_m = 500e3\n[environment.models.srp]\n[environment.surfaces.hub]\nspecular = -0.1\ndiffuse = 0.3\nabsorbed = 0.8\n", "environment.surfaces.hub.specular: Input should be greater than or equal to 0 (got -0.1)", command="slew"),
    _scenario("surface coefficients summing to 0.9", "[orbit]\naltitude_m = 500e3\n[environment.models.srp]\n[environment.surfaces.back]\nspecular = 0.3\ndiffuse = 0.3\nabsorbed = 0.3\n", "environment.surfaces.back: specular + diffuse + absorbed must sum to 1 (within 1e-06), got 0.3 + 0.3 + 0.3 = 0.9", command="slew"),
    _scenario("unknown environment model", "[orbit]\naltitude_m = 500e3\n[environment.models.albedo]\n", "unknown environment model 'albedo': must be one of gravity_gradient, srp, drag, magnetic", command="slew"),
    _scenario("environment without an orbit", "[environment.models.magnetic]\n", "environment: the environment models need the orbit: add an [orbit] table", command="slew"),
    _scenario("magnetorquers without the field", "[orbit]\naltitude_m = 500e3\n[environment.models.drag]\n[environment.magnetorquers]\n", "magnetorquers: they act on the geomagnetic field: add the magnetic model ([environment.models.magnetic])", command="slew"),
    _scenario("magnetorquer limit negative", "[orbit]\naltitude_m = 500e3\n[environment.models.magnetic]\n[environment.magnetorquers]\ndipole_max_a_m2 = -1.0\n", "environment.magnetorquers.dipole_max_a_m2: Input should be greater than 0 (got -1.0)", command="slew"),
    _scenario("magnetorquer gain above 1/s", "[orbit]\naltitude_m = 500e3\n[environment.models.magnetic]\n[environment.magnetorquers]\ngain_1_s = 5.0\n", "environment.magnetorquers.gain_1_s: Input should be less than or equal to 1 (got 5.0)", command="slew"),
    _scenario("environment period zero", "[orbit]\naltitude_m = 500e3\n[environment]\nperiod_s = 0.0\n[environment.models.drag]\n", "environment.period_s: Input should be greater than 0 (got 0.0)", command="slew"),
    _scenario("magnetorquers without wheels", "[orbit]\naltitude_m = 500e3\n[environment.models.magnetic]\n[environment.magnetorquers]\n", "environment.magnetorquers: they dump the reaction wheels' momentum: the [actuator] must be kind = 'wheels'", command="slew"),
]  # fmt: skip

# The real-time plant and its flight software: options refused before a port is bound.
_SERVE = ["serve", "{tmp}/s.toml"]
_FSW = ["fsw", "{tmp}/s.toml"]
_SLEW_FILE = {"s.toml": 'name = "served"\n'}
REALTIME = [
    Bad("serve speed zero", [*_SERVE, "--speed", "0"], "--speed: must be in (0, 1000], got 0", _SLEW_FILE),
    Bad("serve speed too fast", [*_SERVE, "--speed", "5000"], "--speed: must be in (0, 1000], got 5000", _SLEW_FILE),
    Bad("fmu export suffix", ["fmu", "export", "-o", "{tmp}/plant.zip"], "--output: the suffix must be .fmu, got 'plant.zip'"),
    Bad("fmu export dt too long", ["fmu", "export", "-o", "{tmp}/plant.fmu", "--dt", "0.5"], "--dt: must be in (0, 0.1] s, got 0.5"),
    Bad("fmu export config missing", ["fmu", "export", "{tmp}/absent.toml", "-o", "{tmp}/plant.fmu"], "absent.toml"),
    Bad("serve client timeout negative", [*_SERVE, "--client-timeout", "-1"], "--client-timeout: must be in (0, 3600] s, got -1", _SLEW_FILE),
    Bad("serve endpoint scheme", [*_SERVE, "--sensor-endpoint", "http://127.0.0.1:80"], "--sensor-endpoint: expected udp://HOST:PORT, tcp://HOST:PORT (ZeroMQ) or ipc://PATH (ZeroMQ), got 'http://127.0.0.1:80'", _SLEW_FILE),
    Bad("serve port out of range", [*_SERVE, "--command-endpoint", "udp://127.0.0.1:70000"], "--command-endpoint: expected a host and a port in 1-65535", _SLEW_FILE),
    Bad("serve endpoint without port", [*_SERVE, "--command-endpoint", "udp://127.0.0.1"], "--command-endpoint: expected a host and a port in 1-65535", _SLEW_FILE),
    Bad("serve mixed transports", [*_SERVE, "--sensor-endpoint", "tcp://127.0.0.1:47901"], "--sensor-endpoint and --command-endpoint: both udp://, or both ZeroMQ", _SLEW_FILE),
    Bad("serve scenario missing", ["serve", "{tmp}/absent.toml"], "absent.toml"),
    Bad("fsw silence zero", [*_FSW, "--silence", "0"], "--silence: must be in (0, 3600] s, got 0", _SLEW_FILE),
    Bad("serve priority zero", [*_SERVE, "--priority", "0"], "--priority: must be in 1..99 (SCHED_FIFO), got 0", _SLEW_FILE),
    Bad("fsw priority above 99", [*_FSW, "--priority", "100"], "--priority: must be in 1..99 (SCHED_FIFO), got 100", _SLEW_FILE),
    Bad("fsw connect timeout too long", [*_FSW, "--connect-timeout", "1e5"], "--connect-timeout: must be in (0, 3600] s, got 100000", _SLEW_FILE),
]  # fmt: skip

TABLE = (CONFIGS + SCENARIOS + PATHS + SPECIAL_FILES + ROBUSTNESS + CAMPAIGNS + BUDGET + NASTRAN
         + ORBIT + REALTIME + STATESPACE_FILES)  # fmt: skip


def test_the_table_is_at_least_sixty_rows():
    assert len(TABLE) >= 60
    assert len({row.id for row in TABLE}) == len(TABLE)


@pytest.mark.parametrize("row", TABLE, ids=[row.id for row in TABLE])
def test_bad_input_gives_one_message_and_exit_code_2(row: Bad, tmp_path, capsys, monkeypatch):
    monkeypatch.chdir(tmp_path)  # default output folders land in the test's folder
    for name, content in row.files.items():
        path = tmp_path / name
        path.parent.mkdir(parents=True, exist_ok=True)
        if content is FIFO:
            os.mkfifo(path)
        else:
            path.write_bytes(content if isinstance(content, bytes) else content.encode())
    before = sorted(p.relative_to(tmp_path) for p in tmp_path.rglob("*"))
    argv = [arg.replace("{tmp}", str(tmp_path)) for arg in row.argv]
    outcome = flexsat(argv, capsys, timeout_s=row.timeout_s)
    assert outcome.code == 2, outcome.stderr
    assert row.fragment.replace("{tmp}", str(tmp_path)) in " ".join(outcome.stderr.split()), (
        outcome.stderr
    )
    assert "Traceback" not in outcome.stderr
    assert len(outcome.stderr) < 3000  # one bounded message
    created = sorted(set(p.relative_to(tmp_path) for p in tmp_path.rglob("*")) - set(before))
    # Refused before any work: nothing but (at most) the empty output folders given.
    assert all((tmp_path / p).is_dir() and not any((tmp_path / p).iterdir()) for p in created), (
        created
    )


def test_an_unreachable_scheduler_is_refused_before_the_store_exists(tmp_path, capsys):
    outcome = flexsat(["campaign", "sensitivity", "--scheduler", "tcp://127.0.0.1:1",
                       "--out", str(tmp_path / "store")], capsys)  # fmt: skip
    assert outcome.code == 2
    assert "cannot connect to the Dask scheduler tcp://127.0.0.1:1" in outcome.stderr
    assert not (tmp_path / "store").exists()


def test_a_5_mb_name_gives_a_short_message(tmp_path, capsys):
    path = tmp_path / "c.toml"
    path.write_text(_satellite(_set("name", "x" * 5_000_000)))
    outcome = flexsat(["config", "show", "--config", str(path)], capsys)
    assert outcome.code == 2
    assert "name: String should have at most 64 characters" in outcome.stderr
    assert len(outcome.stderr) < 1000
