"""The command line imports what a command uses, when it uses it (docs/performance.md,
'Start-up').

Each check runs in a fresh interpreter (a subprocess) and reads ``sys.modules`` after
the import or the command: no timing is asserted, only which heavy modules were
loaded. numba, SciPy's rotations and signal processing, matplotlib and the plant are
each a sizeable share of a command's start-up.
"""

from __future__ import annotations

import json
import subprocess
import sys

import pytest

HEAVY = ("numba", "scipy.spatial", "scipy.signal", "matplotlib", "flexsat.dynamics.plant")
"""Modules that neither ``import flexsat``, ``import flexsat.cli.main`` nor ``--help``
may load."""

_DRIVER = """
import json, sys
args = sys.argv[1:]
if args and args[0] == "import":
    for name in args[1:]:
        __import__(name)
else:
    from flexsat.cli.main import main
    sys.argv = ["flexsat", *args]
    try:
        main()
    except SystemExit as exc:
        if exc.code:
            raise
print("MODULES " + json.dumps(sorted(sys.modules)), file=sys.stderr)
"""


def loaded(*args: str) -> set[str]:
    """The modules loaded by ``import <names>`` (``args = ("import", ...)``) or by the
    command ``flexsat *args``, in a fresh interpreter."""
    proc = subprocess.run([sys.executable, "-c", _DRIVER, *args], capture_output=True,
                          text=True, timeout=600)  # fmt: skip
    assert proc.returncode == 0, proc.stderr[-2000:]
    line = next(x for x in proc.stderr.splitlines() if x.startswith("MODULES "))
    return set(json.loads(line.removeprefix("MODULES ")))


def heavy(modules: set[str], names=HEAVY) -> list[str]:
    """Which of ``names`` (a package counts with its submodules) are in ``modules``."""
    return [n for n in names if any(m == n or m.startswith(n + ".") for m in modules)]


@pytest.mark.parametrize("module", ["flexsat", "flexsat.cli.main"])
def test_importing_the_package_or_the_command_line_loads_nothing_heavy(module):
    modules = loaded("import", module)
    assert module in modules
    assert heavy(modules, (*HEAVY, "scipy", "pydantic", "xarray")) == []


@pytest.mark.parametrize("args", [["--help"], ["openloop", "--help"], ["slew", "--help"],
                                  ["modal", "--help"], ["--version"]])  # fmt: skip
def test_help_and_version_load_no_compiled_code(args):
    modules = loaded(*args)
    assert "flexsat.cli.main" in modules
    assert heavy(modules) == []


def test_the_public_names_still_import_on_demand():
    modules = loaded("import", "flexsat")
    assert "flexsat.dynamics.plant" not in modules
    from flexsat import Plant, nominal  # the names the package exposes, resolved lazily

    assert Plant.from_config(nominal()).n_dof == 18  # hub 6 + two thesis plates 6 each


def test_openloop_json_loads_neither_figures_spectra_nor_the_closed_loop():
    modules = loaded("openloop", "--json", "--duration", "2")
    assert "flexsat.simulate.openloop" in modules  # the run did happen
    # The open-loop scenario models alone: not the slew's, which name every law and
    # loop stage; neither the closed loop, the study nor the figures.
    assert heavy(modules, ("matplotlib", "scipy.signal", "flexsat.plots",
                           "flexsat.simulate.closedloop", "flexsat.study.pipeline",
                           "scipy.integrate", "flexsat.simulate.scenario",
                           "flexsat.control.laws", "flexsat.control.stages")) == []  # fmt: skip
    # SciPy's rotations (scipy.spatial): the plate packs its mount with flexsat's own
    # (bit for bit SciPy's); a satellite of plates does not load the chain's kernels.
    assert heavy(modules, ("scipy.spatial", "flexsat.dynamics.appendages.chain",
                           "flexsat.dynamics.appendages.chain_kernels")) == []  # fmt: skip
    # Without --out the metrics come from the records as plain arrays: no dataset,
    # so neither xarray nor pandas (0.4 s of start-up).
    assert heavy(modules, ("xarray", "pandas")) == []


def test_openloop_with_out_still_builds_the_dataset(tmp_path):
    modules = loaded("openloop", "--json", "--duration", "2", "--out", str(tmp_path / "run"))
    assert "xarray" in modules  # result.nc is the dataset's
    assert (tmp_path / "run" / "result.nc").is_file()


def test_the_scenario_models_load_neither_xarray_nor_pandas():
    modules = loaded("import", "flexsat.simulate.scenario")
    assert heavy(modules, ("xarray", "pandas", "scipy.spatial")) == []


def test_slew_json_loads_neither_figures_nor_spectra(tmp_path):
    scenario = tmp_path / "short.toml"  # a 0.1 s slew whose observation window fits in it
    scenario.write_text("duration_s = 0.1\n[requirements]\nsettling_deadline_s = 0.05\n")
    modules = loaded("slew", "--scenario", str(scenario), "--json")
    assert "flexsat.simulate.closedloop" in modules  # the run did happen
    assert heavy(modules, ("matplotlib", "scipy.signal", "flexsat.plots")) == []
