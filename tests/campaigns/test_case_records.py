"""A campaign case's row from its records (no xarray dataset) is the dataset path's row.

:func:`flexsat.campaigns.cases.run_case` computes a row's metrics and history from the
slew's :class:`~flexsat.analysis.run_records.RunRecords`; the same functions given the
:class:`~flexsat.simulate.result.Result` dataset of :func:`flexsat.simulate.run_slew`
must give the same row bit for bit (``==`` on every field, NaN equal to NaN, same
types), on the reduced and the full model, for a law with an adaptive slope (ASMC,
``lambda_act``) and one without (PD), and for a diverging case (its finite part).
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

from flexsat.analysis.openloop import finite_part
from flexsat.analysis.run_records import Record, RunRecords
from flexsat.campaigns.cases import HISTORY_KEY, case_inputs, case_row, finish_row, run_case
from flexsat.campaigns.definition import CampaignDefinition, CaseStream, Reduced
from flexsat.config import nominal, validate_config
from flexsat.simulate import run_slew
from flexsat.simulate.batch import fly_whole
from flexsat.simulate.closedloop import finish_slew, prepare_slew
from flexsat.simulate.result import dataset_of

TIMES = ("case_wall_time_s", "case_cpu_time_s")  # the case's own clock: not compared


def _case(reduced: bool, law: str):
    """The second case of ``montecarlo-random`` (a random draw; the campaign's root seed
    7 is in the preset), 120 s, flown by ``law``."""
    from flexsat.campaigns import load_campaign

    data = load_campaign("montecarlo-random").model_dump(mode="json")
    if reduced:
        data["reduced"] = Reduced().model_dump(mode="json")
    definition = validate_config(data, model=CampaignDefinition)
    case = list(CaseStream(definition, nominal(), 2))[1]
    if law == case.scenario["controller"]["kind"]:
        return case
    return dataclasses.replace(case, scenario={**case.scenario, "controller": {"kind": law}})


def _dataset_row(case) -> dict:
    """The row through the dataset of run_slew's Result (the path before RunRecords)."""
    row = case_row(case)
    finish_row(row, run_slew(*case_inputs(case), progress=False).dataset)
    return row


def _same(a, b, where: str = "row") -> None:
    """``a == b`` exactly, NaN equal to NaN, types and array dtypes included."""
    assert type(a) is type(b), f"{where}: {type(a).__name__} != {type(b).__name__}"
    if isinstance(a, dict):
        assert list(a) == list(b), f"{where}: keys {list(a)} != {list(b)}"
        for key in a:
            _same(a[key], b[key], f"{where}[{key!r}]")
    elif isinstance(a, (list, tuple)):
        assert len(a) == len(b), where
        for k, (x, y) in enumerate(zip(a, b, strict=True)):
            _same(x, y, f"{where}[{k}]")
    elif isinstance(a, np.ndarray):
        assert a.dtype == b.dtype and a.shape == b.shape, where
        assert np.array_equal(a, b, equal_nan=a.dtype.kind in "fc"), where
    elif isinstance(a, float):
        assert a == b or (math.isnan(a) and math.isnan(b)), f"{where}: {a!r} != {b!r}"
    else:
        assert a == b, f"{where}: {a!r} != {b!r}"


@pytest.mark.parametrize("reduced", [True, False], ids=["reduced", "full"])
@pytest.mark.parametrize("law", ["asmc", "pd"])
def test_a_case_row_from_its_records_is_the_dataset_rows(reduced, law):
    case = _case(reduced, law)
    assert case_inputs(case)[1].controller.kind == law
    row = run_case(case)
    assert row["status"] == "ok", row["error"]
    expected = _dataset_row(case)
    for key in TIMES:
        assert row.pop(key) >= 0.0
    _same(row, expected)
    assert ("lambda_act" in row[HISTORY_KEY]) == (law == "asmc")  # both kinds of law seen


def test_a_diverging_case_row_from_its_records_is_the_dataset_rows():
    # 1 MN m of environment torque against a 1e7 N m actuator (tests/simulate/
    # test_divergence.py): the state overflows within 0.1 s; the metrics read the
    # finite part, cut by RunRecords.finite_part on one side and by
    # analysis.openloop.finite_part's xarray cut on the other.
    case = _case(True, "pd")
    scenario = {**case.scenario, "duration_s": 20.0,
                "actuator": {**case.scenario["actuator"], "t_max_nm": 1e7},
                "disturbances": {**case.scenario["disturbances"],
                                 "environment_nm": [1e6, 1e6, 1e6]}}  # fmt: skip
    case = dataclasses.replace(case, scenario=scenario)
    row = run_case(case)
    assert row["status"] == "failed" and "non-finite" in row["error"]
    assert 0.0 < row["metrics"]["finite_until_s"] < 0.1
    expected = _dataset_row(case)
    for key in TIMES:
        row.pop(key)
    _same(row, expected)


def test_the_records_are_the_datasets_variables():
    case = _case(True, "asmc")
    run = prepare_slew(*case_inputs(case))
    records = finish_slew(run, *fly_whole(run), 0.0, as_records=True)
    assert isinstance(records, RunRecords)
    result = run_slew(*case_inputs(case), progress=False)
    built = dataset_of(records)
    # the same dataset but for the loop's wall time, an attribute
    assert built.attrs.pop("wall_time_s") == 0.0
    assert result.dataset.attrs.pop("wall_time_s") >= 0.0
    assert built.identical(result.dataset)
    assert list(built.coords) == list(result.dataset.coords)
    assert list(built.data_vars) == list(result.dataset.data_vars)
    # no copies: the dataset holds the records' arrays
    assert built.variables["omega"].values is records.variables["omega"].values


def test_the_finite_part_of_records_is_the_datasets():
    # A non-finite record at row 5 in a variable whose time axis is its second, a column
    # NaN from the first record on (a quantity the model lacks: not a divergence), an
    # integer variable: the cut is the xarray one's, row for row.
    m = 9
    t = np.arange(m) * 0.5
    late = np.ones((3, m))
    late[1, 5] = np.inf
    absent = np.ones((m, 2))
    absent[:, 1] = np.nan
    attrs = {"units": "1", "long_name": "test"}
    records = RunRecords({
        "late": Record(("axis", "time"), late, attrs),
        "absent": Record(("time", "pair"), absent, attrs),
        "count": Record(("time",), np.arange(m), attrs),
        "time": Record(("time",), t, {"units": "s"}),
        "axis": Record(("axis",), np.array(["x", "y", "z"]), {}),
    }, {"status": "failed"})  # fmt: skip
    cut = records.finite_part()
    reference = finite_part(dataset_of(records))
    assert cut.variables["time"].values.size == reference.sizes["time"] == 5
    for name, var in cut.variables.items():
        assert var.dims == reference.variables[name].dims
        expected = reference.variables[name].values
        assert np.array_equal(var.values, expected, equal_nan=expected.dtype.kind == "f")
    # all finite but the absent column: nothing is cut, nothing is copied
    late[1, 5] = 1.0
    assert records.finite_part() is records
