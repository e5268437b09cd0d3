"""The state layout and the status codes: one place that says where state lives and what failed."""

from __future__ import annotations

import numpy as np

from flexsat.compiled import status
from flexsat.dynamics.appendages import PlateModel, appendage_model, appendage_model_names
from flexsat.dynamics.plant import Plant
from flexsat.simulate.run_setup import run_attributes
from tests.conftest import three_panels


def test_layout_of_three_plates():
    plant = Plant.from_config(three_panels())
    lay = plant.layout
    assert [b.offset for b in lay.blocks] == [6, 12, 18]
    assert all(b.count == 6 and b.model == "plate" for b in lay.blocks)
    assert lay.n_dof == plant.n_dof == 24
    assert (lay.q, lay.qd) == (slice(0, 24), slice(24, 48))
    assert (lay.work_in, lay.dissipated, lay.size) == (48, 49, 50)
    name = lay.blocks[1].appendage
    assert lay.block(name).slice == slice(12, 18)
    assert lay.dof_names()[12:18] == [f"{name}.{n}" for n in lay.blocks[1].names]
    assert lay.dof_units()[12:18] == ["m", "m", "m", "rad", "rad", "rad"]


def test_packed_plant_groups_appendages_by_model(nominal_plant):
    packed = nominal_plant.packed
    assert len(packed.pass1) == 1  # one model, one kernel call per derivative
    np.testing.assert_array_equal(packed.members[0], [[0, 6], [1, 12]])
    assert packed.params[0].shape[0] == 2
    assert not packed.articulated  # the plate transmits no inertia: bare-hub solve


def test_plate_is_registered():
    assert "plate" in appendage_model_names()
    assert isinstance(appendage_model("plate"), PlateModel)


def test_every_failure_status_has_one_message(nominal_plant):
    codes = (status.STATUS_HUB_GIMBAL_LOCK, status.STATUS_JOINT_GIMBAL_LOCK,
             status.STATUS_NOT_FINITE, status.STATUS_STEP_TOO_SMALL,
             status.STATUS_STEP_BUDGET, status.STATUS_CONTROL_FAILED)  # fmt: skip
    assert set(status.STATUS_MESSAGES) == set(codes)
    assert status.STATUS_OK not in status.STATUS_MESSAGES

    class _Scenario:
        name = "s"

        def model_dump(self, **_):
            return {}

    attrs = run_attributes(nominal_plant, _Scenario(), "open-loop", status.STATUS_NOT_FINITE,
                           1.5, 0.0, 10)  # fmt: skip
    assert attrs["message"].endswith(status.STATUS_MESSAGES[status.STATUS_NOT_FINITE])
