"""Bad chain appendages: one clear message naming the field, exit code 2 (the CLI table)."""

from __future__ import annotations

import copy
import tomllib

import pytest

from flexsat.config import preset_path
from tests.cli import test_bad_inputs as table
from tests.cli.harness import to_toml
from tests.cli.test_bad_inputs import Bad, _set


def _chain(id: str, path: str, value, fragment: str) -> Bad:
    data = tomllib.loads(preset_path("chain").read_text())
    _set(path, copy.deepcopy(value))(data)
    argv = ["config", "show", "--config", "{tmp}/c.toml"]
    return Bad(id, argv, fragment, {"c.toml": to_toml(data)})


_J = "appendages.0.joint"
_DIAG = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 5.0]]  # 1 + 1 < 5
_SEGMENT = {"mass_kg": 1.0, "inertia_kg_m2": _DIAG, "com_m": [0, 0.5, 0], "next_joint_m": [0, 1, 0],
            "joint": {"dofs": ["rx"], "stiffness": {"rx": 10.0}}}  # fmt: skip

CHAINS = [
    _chain("chain with zero segments", "appendages.0.segments", 0, "appendages[0].segments"),
    _chain("chain with an empty segment list", "appendages.0.segment_list", [],
           "appendages[0].segment_list"),
    _chain("unknown joint DOF name", f"{_J}.dofs", ["rx", "twist"], "appendages[0].joint.dofs"),
    _chain("joint DOF given twice", f"{_J}.dofs", ["rx", "rx"], "each DOF at most once"),
    _chain("negative joint stiffness", f"{_J}.stiffness", {"rx": -1.0, "ry": 1.0, "rz": 1.0},
           "appendages[0].joint.stiffness.rx"),
    _chain("stiffness on a locked DOF", f"{_J}.stiffness",
           {"rx": 1.0, "ry": 1.0, "rz": 1.0, "x": 5.0}, "['x'] locked"),
    _chain("initial value on a locked DOF", f"{_J}.initial", {"z": 0.1}, "['z'] locked"),
    _chain("segment inertia breaks the triangle inequality", "appendages.0.segment_list",
           [_SEGMENT], "J1 + J2 >= J3"),
    _chain("beam without the property a free DOF needs", "appendages.0.beam",
           {"EI_flap_N_m2": 1.0}, "give beam.GJ_N_m2"),
    _chain("negative damping ratio", f"{_J}.damping_ratio", -0.1,
           "appendages[0].joint.damping_ratio"),
    _chain("mount matrix that is not a rotation", "appendages.0.mount_matrix",
           [[1.0, 0.0, 0.0], [0.0, 2.0, 0.0], [0.0, 0.0, 1.0]], "mount_matrix must be a rotation"),
    _chain("unknown span direction", "appendages.0.span_direction", "up",
           "appendages[0].span_direction"),
]  # fmt: skip


@pytest.mark.parametrize("row", CHAINS, ids=[row.id for row in CHAINS])
def test_bad_chain_gives_one_message_and_exit_code_2(row: Bad, tmp_path, capsys, monkeypatch):
    table.test_bad_input_gives_one_message_and_exit_code_2(row, tmp_path, capsys, monkeypatch)
