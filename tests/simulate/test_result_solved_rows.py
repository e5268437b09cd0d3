"""The closed loop keeps each record's q_ddot and constraint forces from the first RK4
stage (``LoopRecords.solved``); the derived records must not change for it.

Reference: the same records derived with every row solved afresh
(``build_dataset(..., solved=None)``, :func:`flexsat.dynamics.records.derive_records`).
Both evaluate the same kernel on the same state, torque and joint forces, in the
same order of operations, so the comparison is exact: any difference would mean the
kept row belongs to another state or torque (a row off by one, a stale constraint
force from a later RK4 stage).
"""

from __future__ import annotations

import numpy as np
import pytest

from flexsat.dynamics.plant import Plant
from flexsat.simulate.closedloop import _compiled_loop, prepare_slew
from flexsat.simulate.result import build_dataset
from flexsat.simulate.scenario import SlewScenario
from tests.conftest import config_from, variant

_DERIVED = ("omega_dot", "tau_flex", "tau_net", "omega", "angular_momentum")


def _flown(plant: Plant, scenario: SlewScenario):
    run = prepare_slew(plant, scenario)
    status, _, rows = _compiled_loop(run, None, None)
    assert status == 0
    return run, rows


def _datasets(run, rows: int):
    """The records derived from the kept rows and from fresh solves."""
    at = run.layout.plant
    rec_x, rec_ctrl = run.rec_x[:rows], run.rec_ctrl[:rows]
    args = (run.plant, run.rec_t[:rows], rec_x[:, at.q], rec_x[:, at.qd],
            rec_x[:, at.work_in], rec_x[:, at.dissipated], rec_ctrl[:, run.layout.tau_cmd],
            rec_ctrl[:, run.layout.tau_applied], {})  # fmt: skip
    common = {"frames": run.rec_frame[:rows], "joint_force": run.rec_Q[:rows]}
    kept = build_dataset(*args, **common, solved=run.rec_solved[:rows].copy())
    fresh = build_dataset(*args, **common)
    return kept, fresh


@pytest.mark.parametrize(
    ("locked", "settings"),
    [
        ((), {}),  # the thesis's model, 1 ms
        (("eta_x", "eta_y", "eta_z"), {"dt_s": 0.02, "control_dt_s": 0.02,
                                       "record_dt_s": 0.02}),  # the reduced model
        (("eta_x", "eta_y", "eta_z"), {"dt_s": 0.01, "control_dt_s": 0.02,
                                       "record_dt_s": 0.03}),  # records off the instants
    ],
)  # fmt: skip
def test_kept_rows_give_the_records_of_a_fresh_solve(locked, settings):
    plant = Plant.from_config(config_from(variant(locked_dofs=list(locked))))
    run, rows = _flown(plant, SlewScenario(duration_s=3.0, **settings))
    kept_rows = ~np.isnan(run.rec_solved[:rows, 0, 0])
    # every record but the last (no step follows it) is kept by the loop
    assert kept_rows[:-1].all() and not kept_rows[-1]
    if locked:  # the reduced model's joints carry constraint forces: kept too
        assert np.abs(run.rec_solved[: rows - 1, 1]).max() > 0.0
    kept, fresh = _datasets(run, rows)
    for name in _DERIVED:
        np.testing.assert_array_equal(kept[name].values, fresh[name].values, err_msg=name)


def test_a_coupled_run_leaves_every_row_to_the_records(nominal_plant):
    """With continuous actuation stages (wheels) the recorded applied torque is the
    control instant's, not the one the plant steps under between instants: the loop
    keeps nothing and the records solve every row, as before."""
    run, rows = _flown(nominal_plant, SlewScenario(duration_s=1.0, actuator={"kind": "wheels"}))
    assert np.isnan(run.rec_solved[:rows, 0, 0]).all()
