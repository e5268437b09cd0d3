"""The Result API: figures by name, a tidy table, metrics from the stored scenario."""

from __future__ import annotations

import json

import numpy as np
import pytest
from matplotlib.figure import Figure

from flexsat.analysis.openloop import openloop_metrics
from flexsat.analysis.requirements import slew_metrics
from flexsat.errors import FlexsatError
from flexsat.plots.openloop import OPENLOOP_FIGURES
from flexsat.plots.slew import SLEW_FIGURES
from flexsat.simulate import OpenLoopScenario, SlewScenario, run_openloop, run_slew
from flexsat.simulate.result import Result
from flexsat.strict_json import jsonable


@pytest.fixture(scope="module")
def openloop(nominal_plant) -> Result:
    return run_openloop(nominal_plant, OpenLoopScenario(duration_s=20.0), progress=False)


@pytest.fixture(scope="module")
def slews(nominal_plant) -> dict[str, Result]:
    # A tighter actuator than the thesis's: metrics() must judge R3 against it.
    runs = {}
    for kind in ("asmc", "pd"):
        scenario = SlewScenario.model_validate(
            {"duration_s": 10.0, "controller": {"kind": kind}, "actuator": {"t_max_nm": 1.5}}
        )
        runs[kind] = run_slew(nominal_plant, scenario, progress=False)
    return runs


def test_every_variable_carries_cf_units_and_long_name(openloop, slews, tmp_path):
    for result in (openloop, slews["asmc"]):
        ds = Result.from_netcdf(result.to_netcdf(tmp_path / "r.nc")).dataset
        for name, var in [*ds.data_vars.items(), ("time", ds["time"])]:
            assert var.attrs.get("units") and var.attrs.get("long_name"), name


def _same(a: dict, b: dict) -> bool:
    """Equal, NaN (a quantity that does not exist) equal to NaN."""
    return json.dumps(jsonable(a)) == json.dumps(jsonable(b))


def test_metrics_read_the_stored_scenario(openloop, slews):
    assert openloop.kind == "openloop"
    assert _same(openloop.metrics(), openloop_metrics(openloop.dataset))
    asmc = slews["asmc"]
    assert asmc.kind == "slew" and _same(asmc.metrics(), slew_metrics(asmc.dataset))
    # R3 against the stored 1.5 N m limit: the ASMC's software limit is RF T_max =
    # 0.95 x 1.5 = 1.425 N m, so the applied torque stays within 1.5 N m (R3 holds)
    # while the reaching phase uses more than the thesis's 1 N m.
    metrics = asmc.metrics()
    assert metrics["r3_pass"] and 1.0 < max(metrics["max_abs_torque_nm"]) <= 1.5


def test_to_pandas_is_tidy_with_units(openloop):
    table = openloop.to_pandas()
    ds = openloop.dataset
    assert list(table.columns) == ["time_s", "variable", "component", "value", "units",
                                   "long_name"]  # fmt: skip
    expected = sum(v.size for v in ds.data_vars.values() if "time" in v.dims)
    assert len(table) == expected
    omega_z = table[(table.variable == "omega") & (table.component == "z")]
    assert np.array_equal(omega_z.value.to_numpy(), ds["omega"].values[:, 2])
    assert set(omega_z.units) == {"rad/s"}
    tip = table[(table.variable == "tip_displacement") & (table.component == "panel_1.z")]
    assert np.array_equal(tip.value.to_numpy(), ds["tip_displacement"].values[:, 0, 2])
    # The yaw impulse, 1 N m for 10 s, is the final angular momentum about Z [N m s]
    # (conserved by RK4 to round-off; 1e-9 relative).
    H_z = table[(table.variable == "angular_momentum") & (table.component == "z")]
    assert H_z.value.iloc[-1] == pytest.approx(10.0, rel=1e-9)


def test_every_figure_kind_draws(openloop, slews):
    assert openloop.figure_kinds() == OPENLOOP_FIGURES
    assert slews["asmc"].figure_kinds() == SLEW_FIGURES
    for result in (openloop, slews["asmc"]):
        for kind in result.figure_kinds():
            fig = result.plot(kind)
            assert isinstance(fig, Figure) and fig.axes, kind


def test_plot_works_for_a_user_who_imported_only_flexsat(openloop, tmp_path):
    # The simulation layer names nothing of the figures above it: Result.plot finds
    # them through its registry, which imports flexsat.plots by name on first use.
    import subprocess
    import sys

    path = openloop.to_netcdf(tmp_path / "r.nc")
    code = (
        "import sys\n"
        "import flexsat\n"
        "from flexsat.simulate.result import Result\n"
        f"result = Result.from_netcdf({str(path)!r})\n"
        "print('flexsat.plots' in sys.modules)\n"
        "fig = result.plot('attitude')\n"
        "print(type(fig).__name__, len(fig.axes) > 0, result.figure_kinds()[0])\n"
    )
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr
    assert done.stdout.split() == ["False", "Figure", "True", OPENLOOP_FIGURES[0]]


def test_a_law_without_a_sliding_surface_has_no_surface_figures(slews):
    kinds = slews["pd"].figure_kinds()
    assert "sliding_variables" not in kinds and "adaptation" not in kinds
    assert "phase_plane" in kinds and len(kinds) == len(SLEW_FIGURES) - 2
    with pytest.raises(FlexsatError, match="not a figure of this slew run; choose one of"):
        slews["pd"].plot("sliding_variables")


def test_summary_and_notebook_view(slews):
    from rich.console import Console

    result = slews["asmc"]
    console = Console(width=120, record=True)
    console.print(result.summary())
    text = console.export_text()
    assert "compilation excluded" in text and "r1_pass" in text
    html = result._repr_html_()
    assert html.startswith("<table>") and "final_pointing_error_deg" in html


def test_the_open_loop_attitude_figure_draws_only_meaningful_signals(openloop):
    # A yaw torque on the symmetric satellite: roll and pitch stay numerically zero,
    # so two panels (yaw angle, yaw rate) instead of six.
    fig = openloop.plot("attitude")
    assert len(fig.axes) == 2
    assert "not drawn, numerically zero: roll" in fig._suptitle.get_text()


def test_record_quaternions_are_scipys_zyx_rotations():
    # Independent formulation: scipy's Rotation.from_euler("ZYX") composes the same
    # elementary quaternions in the same order (so the same sign); rounding only:
    # 1e-15 absolute on unit quaternions (measured 2e-16).
    from scipy.spatial.transform import Rotation

    from flexsat.simulate.result import _quaternions

    euler = np.random.default_rng(18).uniform(-1.5, 1.5, size=(200, 3))
    xyzw = Rotation.from_euler("ZYX", euler[:, ::-1]).as_quat()
    expected = np.column_stack([xyzw[:, 3], xyzw[:, :3]])
    assert np.max(np.abs(_quaternions(euler) - expected)) <= 1e-15


def test_the_dataset_built_from_its_parts_is_xarrays_own(slews):
    # _dataset skips xarray's per-array checks; the result must be the dataset
    # xr.Dataset(...) builds from the same pieces: same values, dims, dtypes
    # (coordinates included) and attributes (identical, not only equal).
    import xarray as xr

    from flexsat.simulate.result import _dataset

    ds = slews["asmc"].dataset
    data_vars = {name: (var.dims, var.values, dict(var.attrs))
                 for name, var in ds.data_vars.items()}  # fmt: skip
    coords = {name: (ds[name].values, dict(ds[name].attrs)) for name in ds.dims}
    built = _dataset(data_vars, coords, dict(ds.attrs))
    expected = xr.Dataset(data_vars, coords={name: (name, *pair) for name, pair in coords.items()},
                          attrs=dict(ds.attrs))  # fmt: skip
    assert built.identical(expected) and built.identical(ds)
    assert all(built[name].dtype == expected[name].dtype for name in coords)
    assert built["dof"].dtype.kind == "U" and built["time"].attrs["units"] == "s"
