"""flexsat plot draws a stored run's figures; flexsat config preset lists and writes templates."""

from __future__ import annotations

import pytest

from flexsat.campaigns import load_campaign
from flexsat.config import PRESETS, TEMPLATES, load_config, nominal, preset_path
from flexsat.simulate import OpenLoopScenario, SlewScenario, load_scenario, load_slew
from flexsat.simulate.result import Result
from tests.cli.harness import flexsat


@pytest.fixture(scope="module")
def stored_run(nominal_plant, tmp_path_factory):
    from flexsat.simulate import run_openloop

    folder = tmp_path_factory.mktemp("run")
    result = run_openloop(nominal_plant, OpenLoopScenario(duration_s=15.0), progress=False)
    return result.to_netcdf(folder / "result.nc")


def test_plot_draws_the_chosen_figures_beside_the_result(stored_run, capsys):
    outcome = flexsat(["plot", str(stored_run), "--kind", "attitude", "--kind", "energy"],
                      capsys)  # fmt: skip
    assert outcome.code == 0, outcome.stderr
    for name in ("attitude", "energy"):
        assert (stored_run.parent / f"{name}.png").is_file()
    assert not (stored_run.parent / "quaternion.png").exists()


def test_plot_lists_the_kinds_of_the_run(stored_run, capsys):
    outcome = flexsat(["plot", str(stored_run), "--list"], capsys)
    assert outcome.code == 0
    assert outcome.stdout.split() == list(Result.from_netcdf(stored_run).figure_kinds())


@pytest.mark.parametrize(
    ("argv", "fragment"),
    [
        (["plot", "{run}", "--kind", "sliding_variables"],
         "--kind sliding_variables: not a figure of this openloop run; choose one of attitude"),
        (["plot", "{tmp}/absent.nc"], "no such file"),
        (["plot", "{tmp}/junk.nc"], "not a NetCDF result"),
    ],
)  # fmt: skip
def test_plot_refuses_with_one_message(stored_run, tmp_path, capsys, argv, fragment):
    (tmp_path / "junk.nc").write_text("not netcdf")
    argv = [a.format(run=stored_run, tmp=tmp_path) for a in argv]
    outcome = flexsat(argv, capsys)
    assert outcome.code == 2 and fragment in outcome.stderr and "Traceback" not in outcome.stderr


def test_preset_lists_every_template(capsys):
    outcome = flexsat(["config", "preset", "--list"], capsys)
    assert outcome.code == 0
    for name in TEMPLATES:
        assert name in outcome.stdout


def test_every_template_is_the_documented_default_and_commented(tmp_path, capsys):
    # The scenario templates are the thesis's defaults written out in full: loading
    # one gives exactly the model's default.
    loaders = {
        "nominal": (load_config, nominal()),
        "openloop": (load_scenario, OpenLoopScenario()),
        "slew": (load_slew, SlewScenario()),
        # presets beyond the thesis's defaults: they load to what they document
        "chain": (load_config, load_config(preset_path("chain"))),
        "avionics-slew": (load_slew, load_slew(preset_path("avionics-slew"))),
    }
    for name in TEMPLATES:
        target = tmp_path / f"{name}.toml"
        assert flexsat(["config", "preset", name, "-o", str(target)], capsys).code == 0
        text = target.read_text()
        assert text == preset_path(name).read_text()
        if name in loaders:
            load, default = loaders[name]
            assert load(target) == default, name
        else:
            assert load_campaign(str(target)).name.startswith("my-")
        if name not in PRESETS:  # a satellite's second panel repeats the first's comments
            # Commented line by line: the settings carry their unit and range beside them
            # (a few, like a case id's modifier list, are explained by the block above).
            settings = [ln for ln in text.splitlines() if "=" in ln and not ln.startswith("#")]
            commented = [ln for ln in settings if "#" in ln]
            assert len(commented) >= 0.6 * len(settings), name
