"""The ``flexsat`` command: thin layer that loads configs, calls the API and prints.

User mistakes (bad config, missing file...) end with one message on stderr and
exit code 2, never a traceback.
"""

from __future__ import annotations

import atexit
import gc
import json
import math
import shutil
import signal
import sys
import warnings
from enum import StrEnum
from pathlib import Path
from typing import Annotated

import typer
from rich.console import Console
from rich.markup import escape

from flexsat._compiled_cache import kernels_cached
from flexsat.cli.tables import format_number, print_table
from flexsat.errors import MAX_MESSAGE_CHARS, FlexsatError, shorten
from flexsat.strict_json import dumps

__all__ = ["app", "main"]

app = typer.Typer(
    name="flexsat",
    help=(
        "Simulator and control-design toolkit for flexible spacecraft: a rigid hub with "
        "flexible appendages and the control-structure interaction between them.\n\n"
        "Without --config every command runs the built-in nominal case study "
        "(hub 150 kg, two 4.5 m solar panels)."
    ),
    no_args_is_help=True,
    add_completion=False,
    pretty_exceptions_enable=False,
    rich_markup_mode=None,  # help texts are plain: "[s]" is a unit, not Rich markup
)
config_app = typer.Typer(
    help="Inspect and copy satellite configurations.", no_args_is_help=True, rich_markup_mode=None
)
app.add_typer(config_app, name="config")
fe_app = typer.Typer(
    help="Finite-element models to modal data (NASTRAN decks).",
    no_args_is_help=True,
    rich_markup_mode=None,
)
app.add_typer(fe_app, name="fe")
fmu_app = typer.Typer(
    help="The plant as an FMU (FMI 2.0 co-simulation, pythonfmu).",
    no_args_is_help=True,
    rich_markup_mode=None,
)
app.add_typer(fmu_app, name="fmu")
robust_app = typer.Typer(
    help="Robust control: mu-analysis of the loops (analyze), H-infinity design (synthesize).",
    no_args_is_help=True,
    rich_markup_mode=None,
)
app.add_typer(robust_app, name="robust")

_console = Console(markup=False)  # names and paths are printed as written, never as markup
_errors = Console(stderr=True, soft_wrap=True)

ConfigOption = Annotated[
    Path | None,
    typer.Option(
        "--config", "-c", help="Satellite config (TOML). Default: the built-in nominal case."
    ),
]
JsonOption = Annotated[
    bool, typer.Option("--json", help="Print one JSON object (SI units) instead of tables.")
]
DurationOption = Annotated[float | None, typer.Option(help="Override the duration [s].")]
RunOutOption = Annotated[
    Path | None,
    typer.Option(help="Write result.nc, metrics.json and the figures to this folder."),
]


class CampaignRunner(StrEnum):
    """Local campaign runners (flexsat.campaigns.runner.RUNNERS)."""

    pool = "pool"
    ensemble = "ensemble"


def _version(value: bool) -> None:
    if value:
        from flexsat import __version__  # the distribution's metadata, read when asked for

        typer.echo(f"flexsat {__version__}")
        raise typer.Exit()


def _announce_compilation() -> None:
    """Say so on stderr when the compiled kernels are not cached yet (first run)."""
    if not kernels_cached():
        _errors.print("compiling the dynamics kernels (first run only, cached on disk)...")


@app.callback()
def _root(
    version: Annotated[
        bool,
        typer.Option("--version", callback=_version, is_eager=True, help="Show the version."),
    ] = False,
) -> None:
    """flexsat command line."""


@app.command()
def modal(
    config: ConfigOption = None,
    json_output: JsonOption = False,
    out: Annotated[
        Path | None,
        typer.Option(help="Write the figures, mode animations and modal.json to this folder."),
    ] = None,
    animate: Annotated[
        list[int] | None,
        typer.Option(help="Mode index (1-based) to animate as a GIF; repeat for more."),
    ] = None,
) -> None:
    """Modal analysis of the coupled satellite: frequencies, mode shapes and classification."""
    from flexsat.config import load_config
    from flexsat.dynamics.plant import Plant
    from flexsat.study.outputs import write_modal

    cfg = load_config(config)  # a config's mistakes are told before any notice
    _announce_compilation()
    plant = Plant.from_config(cfg)
    n_modes = len(plant.dof_names())
    bad = [k for k in animate or [] if not 1 <= k <= n_modes]
    if bad:
        raise FlexsatError(f"--animate: mode index must be in 1..{n_modes}, got {bad}")
    _, summary = write_modal(plant, out, animate)
    if json_output:
        typer.echo(dumps(summary))
        return
    _print_modal(summary)


def _print_modal(summary: dict) -> None:
    rows = [
        [mode["index"], mode["frequency_hz"], mode["kind"], mode["symmetry"],
         mode["hub_dof"] or "-", ", ".join(mode["dominant_dofs"][:3])]
        for mode in summary["modes"]
    ]  # fmt: skip
    header = ("mode", "f [Hz]", "kind", "symmetry", "hub DOF", "dominant DOFs")
    print_table(_console, f"Coupled modes — {summary['config_name']}", header, rows,
                right=(True, True, False, False, False, False))  # fmt: skip
    j_tot = summary["rigid_inertia"]
    rows = [[a, *row] for a, row in zip("xyz", j_tot, strict=True)]
    print_table(_console, "Rigid design inertia J_tot about the hub centre of mass [kg m^2]",
                ("", "x", "y", "z"), rows)  # fmt: skip
    for path in summary.get("files", []):
        _console.print(f"wrote {path}", soft_wrap=True)


@fe_app.command("import")
def fe_import(
    deck: Annotated[Path, typer.Argument(help="NASTRAN bulk data (BDF): grids, sets, RBE2.")],
    op4: Annotated[Path, typer.Option("--op4", help="OP4 file with KAA/MAA (or KFF, KGG).")],
    output: Annotated[Path, typer.Option("--output", "-o", help="Modal data file (.npz, .toml).")],
    interface: Annotated[
        int | None, typer.Option(help="Interface grid id. Default: the deck's b-set grid.")
    ] = None,
    op2: Annotated[
        Path | None, typer.Option(help="SOL 103 OP2 of the deck clamped at the interface.")
    ] = None,
    modes: Annotated[int | None, typer.Option(help="Modes kept, lowest first.")] = None,
    stiffness: Annotated[str | None, typer.Option(help="OP4 stiffness name.")] = None,
    mass: Annotated[str | None, typer.Option(help="OP4 mass name.")] = None,
    damping: Annotated[float, typer.Option(help="Modal damping ratio of every mode [-].")] = 0.0,
    json_output: JsonOption = False,
) -> None:
    """Import a NASTRAN model (OP4 matrices, BDF grids and sets) as modal data."""
    import numpy as np

    from flexsat.config.modal_data import save_modal_data
    from flexsat.fe.nastran import import_nastran

    if not 0.0 <= damping < 1.0:
        raise FlexsatError(f"--damping: must be in [0, 1), got {damping}")
    if output.suffix.lower() not in (".npz", ".toml"):
        raise FlexsatError(f"--output: the suffix must be .npz or .toml, got {output.name!r}")
    model = import_nastran(deck, op4, interface=interface, n_modes=modes, op2=op2,
                           stiffness=stiffness, mass=mass, damping_ratio=damping)  # fmt: skip
    path = save_modal_data(model.modal, output)
    freqs = list(model.modal.frequencies_hz)
    errors = model.frequency_errors
    summary = {
        "interface_grid": model.interface_grid, "tip_grid": model.tip_grid,
        "matrices": [model.stiffness_name, model.mass_name], "dofs": len(model.dofs),
        "mass_kg": model.modal.mass_kg, "frequencies_hz": freqs,
        "op2_frequencies_hz": None if errors is None
        else model.reference_frequencies_hz[: len(errors)].tolist(),
        "file": str(path),
    }  # fmt: skip
    if json_output:
        typer.echo(dumps(summary))
        return
    effective = np.asarray(model.modal.participation_matrix()) ** 2
    rows = []
    for k, f in enumerate(freqs):
        row = [k + 1, f, *(effective[k, :3] / model.modal.mass_kg)]
        if errors is not None:
            row += [model.reference_frequencies_hz[k], errors[k]] if k < len(errors) else ["-"] * 2
        rows.append(row)
    header = ["mode", "f [Hz]", "m_eff,x / m", "m_eff,y / m", "m_eff,z / m"]
    if errors is not None:
        header += ["OP2 f [Hz]", "rel. diff"]
    print_table(_console, f"{model.stiffness_name}/{model.mass_name}: {len(model.dofs)} DOFs, "
                f"clamped at grid {model.interface_grid}, {model.modal.mass_kg:.6g} kg",
                header, rows)  # fmt: skip
    if errors is not None and np.abs(errors).max() > 1e-4:  # round-off is ~1e-6 (OP2 float32)
        _console.print(f"warning: the OP2's frequencies differ by up to "
                       f"{np.abs(errors).max():.2g}: is it this deck clamped at grid "
                       f"{model.interface_grid}?")  # fmt: skip
    _console.print(f"wrote {path}", soft_wrap=True)


@app.command()
def linearize(
    config: ConfigOption = None,
    about: Annotated[
        str, typer.Option(help="'rest' or 'spin:wx,wy,wz', a steady body rate [rad/s].")
    ] = "rest",
    outputs: Annotated[
        str | None,
        typer.Option(help="Output groups, comma-separated: attitude,rate,tip,joint,tau_flex."),
    ] = None,
    reduce: Annotated[
        str | None, typer.Option(help="Also a reduced model: 'balanced:N' or 'modal:N'.")
    ] = None,
    actuated: Annotated[
        list[str] | None,
        typer.Option(
            help="An appendage coordinate with a root actuator ('<appendage>."
            "<coordinate>' or '<coordinate>'): one more input. Repeatable."
        ),
    ] = None,
    json_output: JsonOption = False,
    out: Annotated[
        Path | None,
        typer.Option(help="Write model.npz, model.mat, linear.json and the figures here."),
    ] = None,
) -> None:
    """State-space model of the satellite about rest or a steady spin (A, B, C, D)."""
    from flexsat.config import load_config
    from flexsat.dynamics.plant import Plant
    from flexsat.study.linear import parse_about, parse_reduction, write_linearize

    spin = parse_about(about)
    reduction = parse_reduction(reduce)
    groups = None if outputs is None else [g.strip() for g in outputs.split(",")]
    cfg = load_config(config)  # a config's mistakes are told before any notice
    _announce_compilation()
    plant = Plant.from_config(cfg)
    _, summary = write_linearize(plant, spin, groups, reduction, out, actuated)
    if json_output:
        typer.echo(dumps(summary))
        return
    rows = [[k, mode["frequency_hz"], mode["damping_ratio"]]
            for k, mode in enumerate(summary["modes"], 1)]  # fmt: skip
    print_table(_console, f"Linear model about {summary['about']} — {summary['config_name']}",
                ("mode", "f [Hz]", "damping ratio"), rows)  # fmt: skip
    _console.print(
        f"{summary['n_states']} states, {len(summary['input_names'])} inputs, "
        f"{len(summary['output_names'])} outputs; Jacobian: {summary['jacobian']}"
    )
    if "reduction" in summary:
        red = summary["reduction"]
        _console.print(f"{red['method']} truncation to {red['order']} states: error bound "
                       f"{format_number(red['error_bound'])}")  # fmt: skip
    for path in summary.get("files", []):
        _console.print(f"wrote {path}", soft_wrap=True)


@app.command()
def margins(
    config: ConfigOption = None,
    scenario: Annotated[
        Path | None,
        typer.Option(help="Slew scenario (TOML): its law (pd, smc, asmc). Default: PD defaults."),
    ] = None,
    campaign: Annotated[
        str | None,
        typer.Option(help="Also the margins over a campaign's cases (preset name or TOML)."),
    ] = None,
    json_output: JsonOption = False,
    out: Annotated[
        Path | None, typer.Option(help="Write margins.json and the loop figures here.")
    ] = None,
) -> None:
    """Gain, phase and delay margins of the control loop per axis, flexible modes included."""
    from flexsat.config import load_config
    from flexsat.dynamics.plant import Plant
    from flexsat.simulate.scenario import load_slew
    from flexsat.study.linear import family_margins, write_margins

    slew_scenario = None if scenario is None else load_slew(scenario)
    cfg = load_config(config)  # a config's mistakes are told before any notice
    _announce_compilation()
    plant = Plant.from_config(cfg)
    summary = write_margins(plant, slew_scenario, out)
    if campaign is not None:
        family = family_margins(plant, campaign, slew_scenario, out)
        summary["family"] = family["cases"]
        summary["files"] = summary.get("files", []) + family.get("files", [])
    if json_output:
        typer.echo(dumps(summary))
        return
    _print_margins(summary)
    if "family" in summary:
        rows = [[case, *(axes[a]["delay_margin_s"] for a in "xyz")]
                for case, axes in summary["family"].items()]  # fmt: skip
        print_table(_console, f"Delay margin per case [s] — {campaign}",
                    ("case", "x", "y", "z"), rows)  # fmt: skip
    for path in summary.get("files", []):
        _console.print(f"wrote {path}", soft_wrap=True)


def _print_margins(summary: dict) -> None:
    """The margins of each axis: its crossovers, its flexible peaks, its limits."""
    law, name, axes = summary["law"].upper(), summary["config_name"], summary["axes"]
    rows = [
        [axis, c["frequency_hz"], c["phase_margin_deg"], c["delay_margin_s"],
         "yes" if c["frequency_hz"] == m["delay_crossover_hz"] else ""]
        for axis, m in axes.items() for c in m["crossovers"]
    ]  # fmt: skip
    header = ("axis", "crossover [Hz]", "PM [deg]", "delay margin [s]", "sets it")
    print_table(_console, f"{law} loop gain crossovers — {name}", header, rows)
    rows = [[axis, p["mode_hz"], p["peak_hz"], p["peak_gain_db"], p["stabilized"]]
            for axis, m in axes.items() for p in m["flexible_peaks"]]  # fmt: skip
    header = ("axis", "mode [Hz]", "peak at [Hz]", "peak |L| [dB]", "stabilized")
    print_table(_console, "Flexible modes in each loop (gain-stabilized: peak below 0 dB)",
                header, rows)  # fmt: skip
    rows = [[axis, m["phase_margin_deg"], m["gain_margin"], m["delay_margin_s"],
             m["delay_crossover_hz"]] for axis, m in axes.items()]  # fmt: skip
    header = ("axis", "PM [deg]", "GM [-]", "delay margin [s]", "set at [Hz]")
    print_table(_console, f"{law} loop margins — {name}", header, rows)


@robust_app.command("analyze")
def robust_analyze(
    config: ConfigOption = None,
    scenario: Annotated[
        Path | None,
        typer.Option(help="Slew scenario (TOML): its law (pd, smc, asmc). Default: PD defaults."),
    ] = None,
    controller: Annotated[
        Path | None,
        typer.Option(
            help="A linear controller instead: NPZ of A, B, C, D (attitude, rate -> N m)."
        ),
    ] = None,
    sadm_angle: Annotated[
        float | None, typer.Option(help="Every plate's SADM angle [deg]. Default: the config's.")
    ] = None,
    points: Annotated[int, typer.Option(help="Log-spaced frequencies, 1e-3 ... 200 Hz.")] = 60,
    json_output: JsonOption = False,
    out: Annotated[Path | None, typer.Option(help="Write mu.json and mu.png here.")] = None,
    bound: Annotated[
        str,
        typer.Option(
            help="mu upper bound: diagonal (D, G diagonal, fast) or lmi (full D, G "
            "blocks at the peak frequencies; needs cvxpy)."
        ),
    ] = "diagonal",
) -> None:
    """mu-analysis of the loop over the thesis's parameter box: bounds, k_max, worst case.

    Panel frequencies +-20 %, damping 0 ... nominal, hub and panel inertias +-20 %.
    """
    from flexsat.config import load_config
    from flexsat.simulate.scenario import load_slew
    from flexsat.study.mu import robust_analysis

    slew_scenario = None if scenario is None else load_slew(scenario)
    cfg = load_config(config)
    summary = robust_analysis(cfg, slew_scenario, controller, sadm_angle, points, out, bound)
    if json_output:
        typer.echo(dumps(summary))
        return
    rows = [[p["name"], p["low"], p["high"], p["block_size"]] for p in summary["parameters"]]
    print_table(_console, f"Uncertain parameters — {summary['config_name']}",
                ("parameter", "low [-]", "high [-]", "channels"), rows)  # fmt: skip
    rows = [
        [
            f"mu upper bound (peak, {summary['bound']})",
            summary["peak_upper"],
            summary["peak_frequency_hz"],
        ],
        ["mu lower bound", summary["lower"], summary["lower_frequency_hz"]],
        ["k_max, certified (1/upper)", summary["k_max_lower"], ""],
        ["k_max, not above (1/lower)", summary["k_max_upper"], ""],
    ]
    print_table(_console, f"Robust stability, {summary['law'].upper()} loop",
                ("quantity", "value [-]", "at [Hz]"), rows)  # fmt: skip
    rows = [[k, v] for k, v in summary["worst_factors"].items()]
    print_table(_console, "Worst case (destabilizing point): factor on nominal",
                ("parameter", "factor [-]"), rows)  # fmt: skip
    if not summary["nominal_stable"]:
        _console.print("the loop is unstable at the box's centre: mu bounds do not apply")
    for path in summary.get("files", []):
        _console.print(f"wrote {path}", soft_wrap=True)


@robust_app.command("jk-min")
def robust_jk_min(
    config: ConfigOption = None,
    scenario: Annotated[
        Path | None,
        typer.Option(help="Slew scenario (TOML) with an ASMC. Default: the thesis's slew."),
    ] = None,
    campaign: Annotated[
        str | None,
        typer.Option(
            help="The truth plants the law must hold: a campaign's cases (a preset name "
            "or a TOML, e.g. montecarlo-critical). Default: the design satellite alone."
        ),
    ] = None,
    margin: Annotated[
        float, typer.Option(help="eta as a fraction of the bound, 0 ... 1 (the thesis: 0.05).")
    ] = 0.05,
    json_output: JsonOption = False,
) -> None:
    """The analytical estimate of the ASMC's minimum robustness gain JK_min, term by term.

    Each term of the lumped disturbance bounded from the model (docs/control.md, 'The
    minimum robustness gain JK_min'): actuator, sloshing, environment and residual
    torques, the inertia mismatch and gyroscopic terms over the truth plants, and the
    flexible torque of a torque step from rest.
    """
    from flexsat.campaigns import load_campaign, resolve_cases
    from flexsat.config import load_config, validate_config
    from flexsat.config.models import SatelliteConfig
    from flexsat.simulate.robustness_gain import jk_min_estimate
    from flexsat.simulate.scenario import load_slew

    cfg = load_config(config)
    truth = ()
    if campaign is not None:
        cases = resolve_cases(load_campaign(campaign), cfg)
        truth = tuple(validate_config(c.plant, model=SatelliteConfig) for c in cases)
    estimate = jk_min_estimate(cfg, load_slew(scenario), truth, margin)
    summary = {"config_name": cfg.name, "campaign": campaign, "truth_plants": len(truth) or 1,
               **estimate.to_dict()}  # fmt: skip
    if json_output:
        typer.echo(dumps(summary))
        return
    names = ("actuator", "sloshing", "environment", "residual", "inertia", "gyroscopic",
             "flexible", "disturbance", "jk_min")  # fmt: skip
    rows = [[name, *summary[f"{name}_nm"]] for name in names]
    title = f"JK_min estimate — {cfg.name}, {summary['truth_plants']} truth plant(s) [N m]"
    print_table(_console, title, ("term", "x", "y", "z"), rows)
    verdict = "fits" if summary["feasible"] else "does not fit"
    _console.print(f"JK_min {verdict} within the law's budget RF T_max = "
                   f"{format_number(summary['budget_nm'])} N m on every axis")  # fmt: skip


@robust_app.command("synthesize")
def robust_synthesize(
    out: Annotated[Path, typer.Option(help="The controller file to write (.npz or .mat).")],
    config: ConfigOption = None,
    order: Annotated[int, typer.Option(help="States of the reduced controller, 1 ... 64.")] = 6,
    modes: Annotated[
        int, typer.Option(help="Flexible modes in the design plant (0: the rigid attitude).")
    ] = 0,
    control_dt: Annotated[
        float, typer.Option(help="Control period it is discretized at [s] (the loop's).")
    ] = 1e-3,
    json_output: JsonOption = False,
    method: Annotated[
        str,
        typer.Option(
            help="hinf (H-infinity mixed sensitivity) or dk (mu-synthesis by D-K "
            "iteration against the parameter box's inertia range; needs dkpy)."
        ),
    ] = "hinf",
    iterations: Annotated[
        int, typer.Option(help="--method dk: D-K steps after the first design, 1 ... 10.")
    ] = 3,
    points: Annotated[
        int,
        typer.Option(
            help="--method dk: frequencies of the D step's grid, log-spaced over 1e-3 ... "
            "1e2 rad/s, 8 ... 200 (fewer: a faster, coarser fit of the scalings)."
        ),
    ] = 30,
) -> None:
    """H-infinity or mu (D-K) design of an attitude controller for the statespace law.

    Weights from the requirements (R1 and R2 bands, the torque limit, the first mode's
    damping: docs/control.md); reduced by balanced truncation, discretized (Tustin).
    """
    from flexsat.config import load_config
    from flexsat.control.laws.statespace import MAX_ORDER, save_controller
    from flexsat.dynamics.plant import Plant
    from flexsat.errors import ConfigError
    from flexsat.linear import linearize
    from flexsat.linear.hinf import synthesize

    if method not in ("hinf", "dk"):
        raise ConfigError(f"--method: hinf or dk, got {method!r}")
    if not 1 <= iterations <= 10:
        raise ConfigError(f"--iterations: must be in 1 ... 10, got {iterations}")
    if not 8 <= points <= 200:
        raise ConfigError(f"--points: must be in 8 ... 200, got {points}")
    if out.suffix.lower() not in (".npz", ".mat"):
        raise ConfigError(f"--out: the suffix must be .npz or .mat, got {out.suffix or 'none'!r}")
    if not out.parent.is_dir():
        raise ConfigError(f"--out: the folder {out.parent} does not exist")
    if not 1 <= order <= MAX_ORDER:
        raise ConfigError(f"--order: must be in 1 ... {MAX_ORDER}, got {order}")
    if not 0 <= modes <= 50:
        raise ConfigError(f"--modes: must be in 0 ... 50, got {modes}")
    if not (math.isfinite(control_dt) and 0.0 < control_dt <= 10.0):
        raise ConfigError(f"--control-dt: must be in (0, 10] s, got {control_dt:g}")
    cfg = load_config(config)
    model = linearize(Plant.from_config(cfg))
    if method == "dk":
        import numpy as np

        from flexsat.linear.dk import synthesize_dk
        from flexsat.linear.uncertain import uncertain_model

        dk = synthesize_dk(model, uncertain_model(cfg), control_dt, order, modes,
                           omega=np.logspace(-3, 2, points), n_iterations=iterations)  # fmt: skip
        design, gamma, full = dk, dk.result.gammas[-1], dk.result.controller.nstates
        extra = {"mu_history": list(dk.result.mu_history), "mu": dk.result.mu,
                 "input_uncertainty": dk.r0, "stopped": dk.result.stopped}  # fmt: skip
    else:
        design = synthesize(model, control_dt, order, modes)
        gamma, full, extra = design.gamma, design.controller.nstates, {}
    save_controller(design.discrete, out)
    summary = {
        "config_name": cfg.name, "method": method, "gamma": gamma,
        "full_order": int(full), "order": int(design.reduced.nstates),
        "reduction_bound": design.reduction_bound, "control_dt_s": control_dt,
        "modes": modes, "file": str(out), **extra,
    }  # fmt: skip
    if json_output:
        typer.echo(dumps(summary))
        return
    rows = [[f"mu after D-K step {i}", m] for i, m in enumerate(extra.get("mu_history", []))]
    rows += [
        ["gamma = ||T_zw||_inf bound", summary["gamma"]],
        ["full controller order", summary["full_order"]],
        ["reduced order (balanced truncation)", summary["order"]],
        ["reduction error bound [N m per unit input]", summary["reduction_bound"]],
        ["control period [s]", control_dt],
    ]
    title = "mu (D-K) controller" if method == "dk" else "H-infinity controller"
    print_table(_console, f"{title} — {cfg.name}", ("quantity", "value"), rows)
    _console.print(f'wrote {out} (kind = "statespace", file = "{out.name}")')


@app.command()
def openloop(
    config: ConfigOption = None,
    scenario: Annotated[
        Path | None,
        typer.Option(help="Open-loop scenario (TOML). Default: the thesis's 1 N m yaw pulse."),
    ] = None,
    duration: DurationOption = None,
    dt: Annotated[float | None, typer.Option(help="Override the RK4 step [s].")] = None,
    solver: Annotated[str | None, typer.Option(help="Override the solver: rk4 or dop853.")] = None,
    json_output: JsonOption = False,
    out: RunOutOption = None,
) -> None:
    """Open-loop run: apply a torque profile to the flexible satellite and watch it respond.

    A run that diverges stops cleanly: its history up to the failure is saved (with
    --out) and the command exits with code 1 after naming the time.
    """
    # the open-loop models, not flexsat.simulate.scenario: the slew's import every law
    from flexsat.config import load_config, validate_config
    from flexsat.dynamics.plant import Plant
    from flexsat.simulate.openloop_scenario import OpenLoopScenario, load_scenario
    from flexsat.study.outputs import fly_openloop

    cfg = load_config(config)  # a config's mistakes are told before any notice
    _announce_compilation()
    plant = Plant.from_config(cfg)
    chosen = load_scenario(scenario)
    given = {"--duration": duration, "--dt": dt, "--solver": solver}
    fields = {"--duration": "duration_s", "--dt": "dt_s", "--solver": "solver"}
    overrides = {fields[option]: value for option, value in given.items() if value is not None}
    # A valid step that does not divide the record interval moves the record interval
    # to a multiple of it; an invalid step is left to the model to refuse.
    record = chosen.record_dt_s
    if dt is not None and 0.0 < dt < math.inf and record % dt > 1e-12 * record:
        overrides["record_dt_s"] = max(dt, round(record / dt) * dt)
    if overrides:
        chosen = validate_config(
            {**chosen.model_dump(), **overrides},
            source=_options(given),
            model=OpenLoopScenario,
        )
    # Without --out only the metrics are printed: no dataset is built (no xarray).
    _, metrics = fly_openloop(plant, chosen, out, progress=None if not json_output else False,
                              dataset=out is not None)  # fmt: skip
    if json_output:
        typer.echo(dumps(metrics))
    else:
        _print_metrics(metrics)
    if metrics["status"] != "ok":  # the run's status and message, as its result has them
        _print_error(metrics["message"])
        raise typer.Exit(1)


@app.command()
def slew(
    config: ConfigOption = None,
    scenario: Annotated[
        Path | None,
        typer.Option(help="Slew scenario (TOML). Default: the thesis's 45/45/45 deg ASMC slew."),
    ] = None,
    controller: Annotated[
        str | None,
        typer.Option(
            help="Override the law: any registered law by name, with its default gains "
            "(built in: asmc, smc, pd, stsmc, ismc), or all (compare every registered law)."
        ),
    ] = None,
    target_euler_deg: Annotated[
        str | None, typer.Option(help="Override the target as 'roll,pitch,yaw' [deg].")
    ] = None,
    duration: DurationOption = None,
    json_output: JsonOption = False,
    out: RunOutOption = None,
) -> None:
    """Closed-loop slew: a control law flies the flexible satellite; R1-R3 checked.

    The controller knows only a rigid design model: J_tot of the rigidized --config
    satellite, or the scenario's design_inertia_kg_m2 (reported in the metrics).
    """
    from flexsat.config import load_config, validate_config
    from flexsat.control.laws import law_names
    from flexsat.dynamics.plant import Plant
    from flexsat.simulate import SlewScenario, load_slew
    from flexsat.simulate.scenario import check_observation_window

    cfg = load_config(config)  # a config's mistakes are told before any notice
    _announce_compilation()
    plant = Plant.from_config(cfg)
    chosen = load_slew(scenario, check_window=duration is None)
    overrides: dict = {}
    if duration is not None:
        overrides["duration_s"] = duration
    if target_euler_deg is not None:
        overrides["target_euler_deg"] = _parse_triple(target_euler_deg, "--target-euler-deg")
    if controller is not None and controller != "all":
        overrides["controller"] = {"kind": controller}
    if overrides:
        given = {"--duration": duration, "--target-euler-deg": target_euler_deg,
                 "--controller": controller}  # fmt: skip
        chosen = validate_config(
            {**chosen.model_dump(by_alias=True), **overrides},
            source=_options(given),
            model=SlewScenario,
        )
    if duration is not None:  # the run the option leaves must still hold its window
        check_observation_window(chosen, f"--duration {duration:g}")
    if controller == "all":
        kinds = law_names()
        runs = {
            kind: validate_config(
                {**chosen.model_dump(by_alias=True), "controller": {"kind": kind}},
                source="options",
                model=SlewScenario,
            )
            for kind in kinds
        }
    else:
        runs = {chosen.controller.kind: chosen}
    results = {}
    failed = []
    for kind, slew_scenario in runs.items():
        sub = out / kind if (out is not None and len(runs) > 1) else out
        metrics, ok, message = _fly(plant, slew_scenario, sub, quiet=json_output)
        results[kind] = metrics
        if not ok:
            failed.append(message)
    if json_output:
        payload = results if controller == "all" else next(iter(results.values()))
        typer.echo(dumps(payload))
    elif controller == "all":
        _print_comparison(results)
    else:
        kind, metrics = next(iter(results.items()))
        _print_metrics(metrics, title=f"Slew with {_law_label(kind)}")
    if failed:
        for message in failed:
            _print_error(message)
        raise typer.Exit(1)


@app.command()
def animate(
    result: Annotated[Path, typer.Argument(help="A result.nc written by openloop or slew.")],
    output: Annotated[
        Path | None,
        typer.Option(
            "--output", "-o", help="GIF or MP4 (needs ffmpeg) to write. Default: RESULT as .gif."
        ),
    ] = None,
    magnification: Annotated[
        float | None,
        typer.Option(
            min=0.0,
            help="Panel-deformation magnification (1: true scale). Default: chosen so the "
            "peak tip displacement shows as 15 % of the panel length.",
        ),
    ] = None,
    fps: Annotated[int, typer.Option(min=1, help="Playback rate, frames per second.")] = 20,
    max_frames: Annotated[
        int, typer.Option(min=2, help="Most frames, picked evenly over the run.")
    ] = 150,
) -> None:
    """3-D animation of a run: the satellite turning, its panels' deformation magnified."""
    from flexsat.files import check_user_file
    from flexsat.plots.animation import result_plant, run_frames, write_animation
    from flexsat.simulate.result import Result

    if not result.exists():
        raise FlexsatError(f"{result}: file not found")
    check_user_file(result, "RESULT", limited=False)  # a FIFO or a device is refused, not read
    try:
        run = Result.from_netcdf(result)
        plant = result_plant(run)
    except FlexsatError as exc:  # not a flexsat result, or its stored config refused
        raise FlexsatError(f"{result}: {exc}") from None
    except (OSError, ValueError):  # not NetCDF, or unreadable
        raise FlexsatError(f"{result}: not a readable NetCDF file") from None
    target = output if output is not None else result.with_suffix(".gif")
    frames = run_frames(
        run, magnification=magnification, max_frames=max_frames, fps=fps, plant=plant
    )
    try:
        written = write_animation(
            run, target, magnification=frames.magnification, fps=fps, max_frames=max_frames
        )
    except OSError as exc:
        raise FlexsatError(f"cannot write {target}: {exc.strerror or exc}") from None
    _console.print(
        f"wrote {written} ({len(frames)} frames, t = {frames.time[0]:.4g} to "
        f"{frames.time[-1]:.4g} s, deformation ×{frames.magnification:.4g})",
        highlight=False,
        markup=False,
        soft_wrap=True,
    )


@app.command()
def plot(
    result: Annotated[Path, typer.Argument(help="A result file written by flexsat (NetCDF).")],
    kind: Annotated[
        list[str] | None,
        typer.Option("--kind", "-k", help="Figure to draw (repeatable); default: every one."),
    ] = None,
    out: Annotated[
        Path | None, typer.Option(help="Folder of the PNG files (default: beside RESULT).")
    ] = None,
    list_kinds: Annotated[
        bool, typer.Option("--list", help="List the figures this result can draw and stop.")
    ] = False,
) -> None:
    """Draw the figures of a stored run (open loop or slew): OUT/KIND.png.

    The run's kind (open loop or slew) and the law that flew it decide which
    figures exist: --list shows them.
    """
    from flexsat.files import check_user_file
    from flexsat.simulate.result import Result

    if not result.exists():
        raise FlexsatError(f"RESULT {result}: no such file")
    check_user_file(result, "RESULT", limited=False)  # a FIFO or a device is refused, not read
    try:
        loaded = Result.from_netcdf(result)
    except (OSError, ValueError) as exc:
        raise FlexsatError(f"RESULT {result}: not a NetCDF result ({exc})") from None
    if "q" not in loaded.dataset or "config" not in loaded.dataset.attrs:
        raise FlexsatError(f"RESULT {result}: not a flexsat simulation result")
    names = loaded.figure_kinds()
    if list_kinds:
        for name in names:
            _console.print(name)
        return
    chosen = tuple(kind or names)
    unknown = [k for k in chosen if k not in names]
    if unknown:
        raise FlexsatError(
            f"--kind {unknown[0]}: not a figure of this {loaded.kind} run; choose one of "
            + ", ".join(names)
        )
    from flexsat.plots.results import write_result_figures
    from flexsat.study.outputs import prepare_output_dir

    folder = prepare_output_dir(out if out is not None else result.parent)
    for path in write_result_figures(loaded.dataset, folder, chosen):
        _console.print(f"wrote {path}", soft_wrap=True)


@app.command()
def campaign(
    name: Annotated[
        str,
        typer.Argument(
            help="A preset (flexsat config preset --list names them), a campaign TOML "
            "file, or 'replay STORE CASE_ID'."
        ),
    ],
    replay_args: Annotated[
        list[str] | None, typer.Argument(help="With 'replay': the store folder and case id.")
    ] = None,
    config: ConfigOption = None,
    workers: Annotated[
        int | None, typer.Option(min=1, help="Local worker processes (default: all cores).")
    ] = None,
    scheduler: Annotated[
        str | None, typer.Option(help="Dask scheduler address, e.g. tcp://127.0.0.1:8786.")
    ] = None,
    dask_local: Annotated[
        int | None, typer.Option(min=1, help="Start a Dask LocalCluster with N workers.")
    ] = None,
    runner: Annotated[
        CampaignRunner,
        typer.Option(
            help="Local runs: 'pool' (a case per worker process) or 'ensemble' "
            "(batches in one compiled call, --workers threads)."
        ),
    ] = CampaignRunner.pool,
    cases: Annotated[
        int | None,
        typer.Option(
            help="Random cases to draw (random campaigns; default the campaign's "
            "[random] n). The nominal case comes on top when the campaign "
            "includes it: --cases 100 runs 101 cases."
        ),
    ] = None,
    duration: Annotated[
        float | None, typer.Option(help="Override every case's duration [s] (quick looks).")
    ] = None,
    out: Annotated[
        Path | None, typer.Option(help="Store folder (default out/campaigns/NAME).")
    ] = None,
    resume: Annotated[bool, typer.Option(help="Skip the cases already in the store.")] = False,
    json_output: JsonOption = False,
    controller: Annotated[
        str | None,
        typer.Option(
            help="Fly every case with this registered law (its default gains) "
            "instead of the campaign's [base.controller]."
        ),
    ] = None,
) -> None:
    """Robustness campaign: many slews of a varied plant, stored case by case (Parquet, CSV).

    An interrupted campaign resumes with --resume without recomputing finished
    cases. 'flexsat campaign replay STORE CASE_ID' re-runs one stored case alone.
    """
    from flexsat.campaigns import load_campaign, replay_case
    from flexsat.campaigns.definition import CampaignDefinition
    from flexsat.config import load_config, validate_config
    from flexsat.study.outputs import fly_campaign

    if name == "replay":
        if not replay_args or len(replay_args) != 2:
            raise FlexsatError("usage: flexsat campaign replay STORE CASE_ID")
        store, case_id = replay_args
        from flexsat.files import output_root

        result = replay_case(store, case_id)
        target = output_root(store) / "replays" / f"{case_id}.nc"  # a linked replays/ refused
        result.to_netcdf(target)
        metrics = result.metrics()  # R1-R3 from the case's stored scenario
        if json_output:
            typer.echo(dumps({**metrics, "files": [str(target)]}))
            return
        _print_metrics({**metrics, "files": [str(target)]}, f"Replay of {case_id}")
        _console.print(f"replayed {case_id}: {result.dataset.attrs['status']}")
        return
    if scheduler and dask_local:
        raise FlexsatError("give either --scheduler or --dask-local, not both")
    definition = load_campaign(name)
    if duration is not None:
        data = definition.model_dump(mode="json")
        data["base"] = {**data["base"], "duration_s": duration}
        definition = validate_config(data, source="--duration", model=CampaignDefinition)
    if controller is not None:
        from flexsat.control.laws import get_law

        try:
            get_law(controller)
        except ValueError as exc:
            raise FlexsatError(f"--controller: {exc}") from None
        data = definition.model_dump(mode="json")
        data["base"] = {**data["base"], "controller": {"kind": controller}}
        definition = validate_config(data, source="--controller", model=CampaignDefinition)
    stem = definition.name if controller is None else f"{definition.name}-{controller}"
    store = out or Path("out") / "campaigns" / stem
    summary = fly_campaign(
        definition, load_config(config), store, workers=workers, resume=resume, n_random=cases,
        scheduler=scheduler, dask_local=dask_local, progress=not json_output,
        runner=runner.value,
    )  # fmt: skip
    if json_output:
        typer.echo(dumps(summary))
        return
    from flexsat.campaigns.runner import SUMMARY_ROWS

    title = summary.get("cases_text", f"{summary['cases']} cases")
    print_table(_console, f"Campaign {definition.name}: {title}", ("quantity", "value"),
                [[label, summary[key]] for key, label in SUMMARY_ROWS])  # fmt: skip
    for group in summary["worst_by_requirement"]:
        _console.print(f"  {_worst_line(group)}")
    if "worst_case" in summary:  # a search: what it found, by the metric it searched
        found = summary["worst_case"]
        _console.print(f"  worst-case search: {found['case_id']}  {found['metric']} = "
                       f"{format_number(found['value'])} (worst_case.json)")  # fmt: skip
    _console.print(f"wrote {summary['parquet']} and {summary['csv']}", soft_wrap=True)
    for path in summary["figures"]:
        _console.print(f"wrote {path}", soft_wrap=True)


def _worst_line(group: dict) -> str:
    """One requirement's worst cases on a line (``summary["worst_by_requirement"]``)."""
    verdict = {True: " pass", False: " FAIL", None: ""}
    cases = ", ".join(
        f"{c['case_id']} {'—' if c['value'] is None else format_number(c['value'])}"
        f"{verdict[c['passes']]}" for c in group["cases"]
    )  # fmt: skip
    failing = "" if group["verdict"] is None else f"; {group['failing']} failing"
    return (f"worst {group['requirement']} (by {group['metric']} [{group['unit']}]{failing}): "
            f"{cases or 'none'}")  # fmt: skip


@app.command()
def study(
    config: ConfigOption = None,
    out: Annotated[Path, typer.Option(help="Output folder of the study.")] = Path("out"),
    quick: Annotated[
        bool, typer.Option(help="Skip the campaigns: modal, open loop, slews and animation.")
    ] = False,
    workers: Annotated[
        int | None, typer.Option(min=1, help="Campaign worker processes (default: all cores).")
    ] = None,
    controller: Annotated[
        str,
        typer.Option(
            help="Laws of the controller comparison: registered law names, comma "
            "separated, or all (every registered law)."
        ),
    ] = "all",
    parts: Annotated[
        str | None,
        typer.Option(
            help="Run only these parts of the study (comma separated; the parts they "
            "need run too), the others shown as not run. Default: every part."
        ),
    ] = None,
) -> None:
    """The thesis study end to end, then an HTML report: OUT/report.html.

    Modal analysis, open-loop validation, the nominal slew with the default law
    (the thesis's ASMC), the controller comparison (every registered law, or those
    of --controller), the slew animation and, unless --quick, the three
    thesis campaigns. A part that fails is reported in its section and the others
    go on; the command then exits with code 1. With --parts, only the parts named
    (configuration, modal, openloop, slew, frequency, robust, pointing, comparison,
    animation, avionics, campaigns, laws) and those they need run.
    """
    from flexsat.config import load_config
    from flexsat.control.laws import get_law
    from flexsat.errors import ConfigError
    from flexsat.study import run_study
    from flexsat.study.pipeline import chosen_parts

    chosen_names = None
    if parts is not None:
        chosen_names = [name.strip() for name in parts.split(",") if name.strip()]
        try:
            chosen_parts(chosen_names)
        except ConfigError as exc:
            raise ConfigError(f"--parts: {exc}") from None
    cfg = load_config(config)
    _announce_compilation()
    chosen = () if controller == "all" else tuple(c.strip() for c in controller.split(","))
    for name in chosen:
        try:
            get_law(name)
        except ValueError as exc:
            raise FlexsatError(f"--controller: {exc}") from None
    source = str(config) if config is not None else "the built-in nominal case"
    manifest = run_study(
        cfg, out, quick=quick, config_source=source, workers=workers, console=_errors,
        controllers=chosen, parts=chosen_names,
    )  # fmt: skip
    failed = [part["title"] for part in manifest["parts"] if part["status"] == "failed"]
    _console.print(f"report: {manifest['report']}")
    if failed:
        _print_error(f"failed parts: {', '.join(failed)}")
        raise typer.Exit(1)


SensorEndpointOption = Annotated[
    str,
    typer.Option(help="Where the plant sends sensor packets: udp://HOST:PORT, or ZeroMQ "
                 "tcp://HOST:PORT or ipc://PATH (extra 'realtime')."),
]  # fmt: skip
CommandEndpointOption = Annotated[
    str, typer.Option(help="Where the plant listens for commands (same schemes).")
]
PriorityOption = Annotated[
    int | None,
    typer.Option(help="Run under SCHED_FIFO at this priority, 1..99 (Linux; CAP_SYS_NICE)."),
]


@app.command()
def serve(
    scenario: Annotated[Path, typer.Argument(help="Slew scenario (TOML): plant, stages, timing.")],
    config: ConfigOption = None,
    speed: Annotated[
        float, typer.Option(help="Simulated seconds per wall second, in (0, 1000].")
    ] = 1.0,
    lockstep: Annotated[
        bool, typer.Option(help="Wait for each command instead of holding a late one.")
    ] = False,
    sensor_endpoint: SensorEndpointOption = "udp://127.0.0.1:47101",
    command_endpoint: CommandEndpointOption = "udp://127.0.0.1:47102",
    client_timeout: Annotated[
        float, typer.Option(help="A client silent this long ends the run [s], in (0, 3600].")
    ] = 1.0,
    start_timeout: Annotated[
        float, typer.Option(help="Longest wait for the client's HELLO [s], in (0, 3600].")
    ] = 60.0,
    priority: PriorityOption = None,
    json_output: JsonOption = False,
    out: RunOutOption = None,
) -> None:
    """Serve the plant in real time: sensor packets out, torque commands in (docs/realtime.md).

    The slew's plant and sensing and actuation chains run paced to the wall clock;
    a client (flexsat fsw, or your flight software) answers each sensor packet with
    a body torque, applied at the next control instant. Prints R1-R3, deadline
    overruns, pacing jitter and latency.
    """
    from flexsat.analysis.requirements import slew_metrics
    from flexsat.config import load_config
    from flexsat.dynamics.plant import Plant
    from flexsat.realtime.server import check_options, check_priority
    from flexsat.realtime.server import serve as serve_plant
    from flexsat.realtime.transport import plant_link
    from flexsat.simulate import load_slew
    from flexsat.study.outputs import prepare_output_dir, write_slew_outputs

    check_options(speed, client_timeout, start_timeout)
    check_priority(priority)
    cfg = load_config(config)
    chosen = load_slew(scenario)
    link = plant_link(sensor_endpoint, command_endpoint)
    if out is not None:
        prepare_output_dir(out)
    _announce_compilation()
    try:
        result, stats = serve_plant(
            Plant.from_config(cfg), chosen, link, speed=speed, lockstep=lockstep,
            client_timeout_s=client_timeout, start_timeout_s=start_timeout,
            log=lambda line: _errors.print(line, markup=False, highlight=False),
            priority=priority,
        )  # fmt: skip
    finally:
        link.close()
    metrics = {**slew_metrics(result.dataset), "realtime": stats.summary()}
    if out is not None:
        write_slew_outputs(result, metrics, out)
    if json_output:
        typer.echo(dumps(metrics))
        return
    _print_metrics({k: v for k, v in metrics.items() if k != "realtime"}, "Served slew")
    print_table(_console, f"Real-time run (speed {speed:g}{', lock-step' if lockstep else ''})",
                ("metric", "value"), list(stats.summary().items()))  # fmt: skip


@app.command()
def fsw(
    scenario: Annotated[
        Path, typer.Argument(help="The slew scenario the plant serves: its law and gains.")
    ],
    config: ConfigOption = None,
    sensor_endpoint: SensorEndpointOption = "udp://127.0.0.1:47101",
    command_endpoint: CommandEndpointOption = "udp://127.0.0.1:47102",
    connect_timeout: Annotated[
        float, typer.Option(help="Longest wait for the plant [s], in (0, 3600].")
    ] = 60.0,
    silence: Annotated[
        float, typer.Option(help="A plant silent this long is gone [s], in (0, 3600].")
    ] = 5.0,
    priority: PriorityOption = None,
    json_output: JsonOption = False,
) -> None:
    """Reference flight software: the scenario's law answering a served plant (flexsat serve)."""
    from flexsat.config import load_config
    from flexsat.dynamics.plant import Plant
    from flexsat.realtime.fsw import fly_remote
    from flexsat.realtime.server import check_priority
    from flexsat.realtime.transport import check_seconds, client_link
    from flexsat.simulate import load_slew

    check_seconds("--connect-timeout", connect_timeout)
    check_seconds("--silence", silence)
    check_priority(priority)
    cfg = load_config(config)
    chosen = load_slew(scenario)
    link = client_link(sensor_endpoint, command_endpoint)
    try:
        summary = fly_remote(Plant.from_config(cfg), chosen, link,
                             connect_timeout_s=connect_timeout, silence_s=silence,
                             priority=priority)  # fmt: skip
    finally:
        link.close()
    if json_output:
        typer.echo(dumps(summary))
    else:
        _print_metrics(summary, "Flight software")


@fmu_app.command("export")
def fmu_export(
    config: Annotated[
        Path | None,
        typer.Argument(help="Satellite config (TOML). Default: the built-in nominal case."),
    ] = None,
    output: Annotated[
        Path, typer.Option("--output", "-o", help="The FMU to write (.fmu); its folder is created.")
    ] = Path("plant.fmu"),
    dt: Annotated[
        float, typer.Option(help="Default of the FMU's RK4 step parameter dt [s], in (0, 0.1].")
    ] = 1e-3,
    json_output: JsonOption = False,
) -> None:
    """Export the open-loop plant as an FMI 2.0 co-simulation FMU (docs/realtime.md).

    Body torque in (tau_x, tau_y, tau_z [N.m]); attitude quaternion, body rate, Euler
    angles and each appendage's tip displacement out; the RK4 step and the initial
    attitude and rate as parameters. Needs the extra 'fmu' (pythonfmu).
    """
    from flexsat.config import load_config
    from flexsat.realtime.fmu import export_fmu, fmu_variables

    if output.suffix.lower() != ".fmu":
        raise FlexsatError(f"--output: the suffix must be .fmu, got {output.name!r}")
    if not 0.0 < dt <= 0.1:
        raise FlexsatError(f"--dt: must be in (0, 0.1] s, got {dt:g}")
    cfg = load_config(config)
    path = export_fmu(cfg, output, dt)
    variables = fmu_variables(cfg, dt)
    counts = {kind: sum(v.causality == kind for v in variables)
              for kind in ("input", "parameter", "output")}  # fmt: skip
    summary = {"fmu": str(path), "fmi_version": "2.0", "kind": "co-simulation",
               **{f"{kind}s": n for kind, n in counts.items()}}  # fmt: skip
    if json_output:
        typer.echo(dumps(summary))
    else:
        _print_metrics(summary, "FMU")


def _options(given: dict) -> str:
    """The options the user gave, to name them in a validation message."""
    return ", ".join(option for option, value in given.items() if value is not None)


def _parse_triple(text: str, option: str) -> list[float]:
    try:
        values = [float(v) for v in text.split(",")]
    except ValueError:
        values = []
    if len(values) != 3:
        raise FlexsatError(f"{option}: expected three comma-separated numbers, got {text!r}")
    return values


def _fly(plant, scenario, out: Path | None, quiet: bool) -> tuple[dict, bool, str]:
    """Run one slew, write its files, return (metrics, ok, message)."""
    from flexsat.study.outputs import fly_slew

    result, metrics = fly_slew(plant, scenario, out, progress=None if not quiet else False)
    return metrics, result.ok, result.message


def _print_comparison(results: dict) -> None:
    keys = [k for k in next(iter(results.values())) if k not in ("files", "controller")]
    print_table(_console, "Controller comparison (same slew, same plant, same disturbances)",
                ("metric", *(_law_label(kind) for kind in results)),
                [[key, *(results[kind][key] for kind in results)] for key in keys])  # fmt: skip


def _law_label(name: str) -> str:
    from flexsat.control.laws import get_law

    return get_law(name).label


def _print_metrics(metrics: dict, title: str = "Open-loop run") -> None:
    rows = [[key, value] for key, value in metrics.items() if key != "files"]
    print_table(_console, title, ("metric", "value"), rows)
    for path in metrics.get("files", []):
        _console.print(f"wrote {path}", soft_wrap=True)


@config_app.command("show")
def config_show(config: ConfigOption = None, json_output: JsonOption = False) -> None:
    """Validate a config and print it as tables, with the derived mass, inertia and joint tuning."""
    from flexsat.config import load_config
    from flexsat.dynamics.plant import Plant
    from flexsat.study.outputs import derived_properties

    cfg = load_config(config)
    derived = derived_properties(Plant.from_config(cfg))
    payload = {"config": cfg.model_dump(mode="json"), "derived": derived}
    if json_output:
        typer.echo(json.dumps(payload))
    else:
        _print_config(payload)


def _print_config(payload: dict) -> None:
    """The config and what flexsat derives from it, as tables (SI units, see key names)."""
    config, derived = payload["config"], payload["derived"]
    top = {k: v for k, v in config.items() if k not in ("name", "appendages")}
    print_table(_console, f"Satellite {config['name']}", ("parameter", "value"),
                list(_flat(top).items()))  # fmt: skip
    _print_per_appendage("Appendages (-: not set, n/a: not a parameter of that "
                         "appendage's model)", "parameter", config["appendages"])  # fmt: skip
    inertia = derived["hub_inertia_kg_m2"]
    rows = [[a, *row] for a, row in zip("xyz", inertia, strict=True)]
    print_table(_console, "Derived: hub inertia about the hub centre of mass [kg m^2]",
                ("", "x", "y", "z"), rows)  # fmt: skip
    _print_per_appendage("Derived per appendage (joint DOFs in the order of the plant's "
                         "coordinates; N m/rad, N m s/rad, N/m, N s/m)", "quantity",
                         derived["appendages"])  # fmt: skip


def _print_per_appendage(title: str, label: str, appendages: list[dict]) -> None:
    flat = [_flat({k: v for k, v in a.items() if k != "name"}) for a in appendages]
    keys = list(dict.fromkeys(key for item in flat for key in item))
    rows = [[key, *(item.get(key, "n/a") for item in flat)] for key in keys]
    print_table(_console, title, (label, *(a["name"] for a in appendages)), rows)


def _flat(data: dict, prefix: str = "") -> dict:
    """Leaf values of nested dicts (and lists of dicts) by dotted path."""
    out: dict = {}
    for key, value in data.items():
        path = f"{prefix}{key}"
        if isinstance(value, dict) and value:
            out.update(_flat(value, f"{path}."))
        elif isinstance(value, list) and value and all(isinstance(v, dict) for v in value):
            for k, item in enumerate(value):
                out.update(_flat(item, f"{path}[{k}]."))
        else:
            out[path] = value
    return out


@config_app.command("preset")
def config_preset(
    name: Annotated[
        str, typer.Argument(help="Template name (see --list), e.g. 'nominal' or 'slew'.")
    ] = "nominal",
    output: Annotated[
        Path | None, typer.Option("--output", "-o", help="Copy the template to this file.")
    ] = None,
    list_templates: Annotated[
        bool, typer.Option("--list", help="List the templates: satellite, scenarios, campaigns.")
    ] = False,
) -> None:
    """Print a shipped template (satellite, scenario, campaign), or copy it to edit.

    Every template is commented line by line: units, allowed ranges, and which
    command reads it. --list names them all.
    """
    from flexsat.campaigns.definition import campaign_presets
    from flexsat.config import preset_path, templates

    if list_templates:
        print_table(_console, "Templates (flexsat config preset NAME -o FILE)",
                    ("name", "what it is"), list(templates().items()),
                    right=(False, False))  # fmt: skip
        _console.print("The campaign presets run by name: flexsat campaign "
                       + " | ".join(campaign_presets()))  # fmt: skip
        return
    source = preset_path(name)
    if output is None:
        typer.echo(source.read_text())
        return
    if output.exists() or output.is_symlink():  # a dangling link is never written through
        raise FlexsatError(f"{output} exists; choose another file name")
    if not output.parent.is_dir():
        raise FlexsatError(f"-o {output}: the folder {output.parent} does not exist")
    try:
        shutil.copyfile(source, output)
    except OSError as exc:
        raise FlexsatError(f"-o {output}: cannot write it ({exc.strerror or exc})") from None
    _console.print(f"wrote {output}", soft_wrap=True)


@app.command()
def equations(
    appendages: Annotated[
        int, typer.Option(min=1, max=4, help="Number of appendages of the derived topology.")
    ] = 2,
    fmt: Annotated[str, typer.Option("--format", help="'pretty' or 'latex'.")] = "pretty",
    small_angle: Annotated[
        bool, typer.Option(help="Use the small-angle panel rate of thesis eq. 2.31.")
    ] = False,
) -> None:
    """Print the symbolic Lagrangian model (energies and equations of motion)."""
    from flexsat.dynamics.symbolic import derive

    if fmt not in ("pretty", "latex"):
        raise FlexsatError(f"--format must be 'pretty' or 'latex', got {fmt!r}")
    model = derive(appendages, "small_angle" if small_angle else "exact")
    typer.echo(model.equations_text(fmt))


@app.command()
def budget(
    result_or_campaign: Annotated[
        Path,
        typer.Argument(help="A slew's result.nc (flexsat slew --out) or a campaign store folder."),
    ],
    requirements: Annotated[
        Path, typer.Option("--requirements", help="TOML file with a [pointing] table.")
    ],
    json_output: Annotated[
        bool,
        typer.Option("--json", help="Print one JSON object instead of tables (keys name units)."),
    ] = False,
    out: Annotated[
        Path | None, typer.Option(help="Write budget.json and budget.csv to this folder.")
    ] = None,
) -> None:
    """Pointing budget (ECSS-E-ST-60-10C): indices measured, contributors summed, verdicts.

    The [pointing] table gives each index's bound, window and confidence, the
    statistical interpretation and the contributors (docs/pointing.md).
    """
    from flexsat.analysis.budget import evaluate, load_requirements, load_runs, to_csv

    chosen = load_requirements(requirements)
    kind, datasets = load_runs(result_or_campaign)
    report = {"source": str(result_or_campaign), "kind": kind, **evaluate(datasets, chosen)}
    if out is not None:
        from flexsat.files import write_text
        from flexsat.study.outputs import prepare_output_dir, write_json

        folder = prepare_output_dir(out)
        write_json(folder / "budget.json", report)
        rows = [{"table": "measured", **r} for r in report["measured"]]
        rows += [{"table": "budget", **r} for r in report["budget"]]
        write_text(folder / "budget.csv", to_csv(rows))
    if json_output:
        typer.echo(dumps(report))
        return
    _print_budget(report)
    if out is not None:
        _console.print(f"wrote {out / 'budget.json'} and {out / 'budget.csv'}", soft_wrap=True)


def _print_budget(report: dict) -> None:
    """The measured indices and the budget as two tables, and the overall verdict."""
    verdict = {True: "pass", False: "FAIL"}
    if report["measured"]:
        print_table(
            _console,
            f"Measured on {report['runs']} run(s) from {report['start_s']:g} s, "
            f"{report['interpretation']} interpretation [deg] (interval: "
            f"{report['interval']:g} confidence)",
            ["index", "axis", "P", "value", "low", "high", "bound", "verdict"],
            [[r["index"], r["axis"], r["confidence"], r["value_deg"], r["ci_low_deg"],
              r["ci_high_deg"], r["bound_deg"], verdict[r["pass"]]]
             for r in report["measured"]],
        )  # fmt: skip
    if report["budget"]:
        levels = sorted({r["confidence"] for r in report["budget"]})
        shared = f" at P = {levels[0]:g}" if len(levels) == 1 else ""
        columns = ["mean", "sigma", "stat", "worst", "bound", "verdict"]
        print_table(
            _console,
            f"Budget{shared} [deg]: statistical (stat) and worst-case (worst) sums, verdict "
            f"on the {report['summation'].replace('_', '-')} one",
            ["index", "axis", *([] if shared else ["P"]), *columns],
            [[r["index"], r["axis"], *([] if shared else [r["confidence"]]), r["mean_deg"],
              r["sigma_deg"], r["statistical_deg"], r["worst_case_deg"], r["bound_deg"],
              verdict[r["pass"]]] for r in report["budget"]],
        )  # fmt: skip
    _console.print(f"pointing requirements: {verdict[report['pass']]}")


@app.command()
def jitter(
    config: ConfigOption = None,
    scenario: Annotated[
        Path | None,
        typer.Option(
            help="Slew scenario (TOML) whose [actuator] is the wheels with an "
            "[actuator.microvibration] table. Default: the study's illustrative one."
        ),
    ] = None,
    speeds: Annotated[
        str | None,
        typer.Option(
            help="Speeds swept, 'LOW:HIGH:COUNT' [rpm]. Default: 1 % of the wheels' "
            "limit to it, 400 speeds."
        ),
    ] = None,
    window: Annotated[
        float | None, typer.Option(help="RPE window: adds the windowed jitter [s].")
    ] = None,
    boresight: Annotated[
        str | None,
        typer.Option(help="Payload boresight 'X,Y,Z', hub frame: sweep its line of sight."),
    ] = None,
    stepper: Annotated[
        Path | None,
        typer.Option(help="TOML file with a [stepper] table: a SADM stepper's harmonics added."),
    ] = None,
    json_output: JsonOption = False,
    out: Annotated[
        Path | None, typer.Option(help="Write jitter.json and campbell.png to this folder.")
    ] = None,
) -> None:
    """Microvibration jitter: wheel (and SADM stepper) harmonics through the closed loop.

    The jitter at the wheels' initial speed, and the speeds where it is worst
    (docs/pointing.md, 'Microvibration').
    """
    from flexsat.config import load_config
    from flexsat.config.load import read_toml, validate_config
    from flexsat.dynamics.plant import Plant
    from flexsat.linear.jitter import StepperConfig
    from flexsat.simulate.scenario import load_slew
    from flexsat.study.jitter import jitter_scenario, write_jitter

    chosen = jitter_scenario() if scenario is None else load_slew(scenario, check_window=False)
    swept = None if speeds is None else _parse_speeds(speeds)
    if window is not None and not 0.0 < window < float("inf"):
        raise FlexsatError(f"--window: the RPE window must be finite and > 0 s, got {window:g}")
    aim = None if boresight is None else _parse_triple(boresight, "--boresight")
    motor = None
    if stepper is not None:
        table = read_toml(stepper, "stepper").get("stepper")
        if not isinstance(table, dict):
            raise FlexsatError(f"{stepper}: a [stepper] table is needed")
        motor = validate_config(table, source=f"{stepper}: stepper", model=StepperConfig)
    cfg = load_config(config)
    plant = Plant.from_config(cfg)
    summary = write_jitter(plant, chosen, out, speeds_rpm=swept, window_s=window,
                           boresight=aim, stepper=motor)  # fmt: skip
    if json_output:
        typer.echo(dumps(summary))
        return
    names = summary["outputs"]
    rows = [["RMS", *(summary["rms_arcsec"][n] for n in names)]]
    if "rpe_rms_arcsec" in summary:
        rows.append([f"RPE RMS ({summary['window_s']:g} s)",
                     *(summary["rpe_rms_arcsec"][n] for n in names)])  # fmt: skip
    if "stepper" in summary:
        rows.append([f"stepper alone ({summary['stepper']['step_rate_hz']:g} steps/s)",
                     *(summary["stepper"]["rms_arcsec"][n] for n in names)])  # fmt: skip
    print_table(_console, f"Jitter at {summary['speed_rpm']:g} rpm, "
                f"{summary['law'].upper()} loop [arcsec]", ["", *names], rows)  # fmt: skip
    print_table(_console, "Worst wheel speeds of the sweep", ["speed [rpm]", "RMS [arcsec]"],
                [[w["speed_rpm"], w["rms_arcsec"]] for w in summary["worst"]])  # fmt: skip
    for path in summary.get("files", []):
        _console.print(f"wrote {path}", soft_wrap=True)


def _parse_speeds(text: str):
    """'LOW:HIGH:COUNT' as COUNT speeds from LOW to HIGH [rpm], checked."""
    import numpy as np

    parts = text.split(":")
    try:
        low, high, count = float(parts[0]), float(parts[1]), int(parts[2])
        if len(parts) != 3:
            raise ValueError
    except (ValueError, IndexError):
        raise FlexsatError(
            f"--speeds: expected LOW:HIGH:COUNT, e.g. 100:6000:400, got {text!r}"
        ) from None
    if not (0.0 < low < high <= 1e6) or not 2 <= count <= 100_000:
        raise FlexsatError(
            f"--speeds: need 0 < LOW < HIGH <= 1e6 rpm and 2 <= COUNT <= 100000, got {text!r}"
        )
    return np.linspace(low, high, count)


def main() -> None:
    """Entry point: run the app, turning flexsat errors into a message and exit code 2.

    Errors of the file system (full disk, permissions) also end with one message and
    code 2, Ctrl-C with "interrupted" and code 130 (a campaign says what it stored).
    """
    warnings.showwarning = _print_warning
    # The command's process ends with it: skip the interpreter's last garbage
    # collection, which walks every object flexsat loaded (numba's types, xarray,
    # pydantic's models) for 0.4-0.6 s. Files are closed where they are written, and
    # objects freed by reference counting are still finalized (CHANGELOG.md,
    # 'Exits without the last collection').
    atexit.register(gc.freeze)
    signal.signal(signal.SIGINT, _on_ctrl_c)
    try:
        app()
    except SystemExit as exc:  # typer ends a command stopped by Ctrl-C with a silent 130
        if exc.code == 130 and _ctrl_c:
            _print_error("interrupted")
        raise
    except FlexsatError as exc:
        _print_error(str(exc))
        sys.exit(exc.exit_code)
    except OSError as exc:  # a full disk or a permission, met while writing results
        where = f"{exc.filename}: " if exc.filename else ""
        _print_error(f"{where}{exc.strerror or exc}")
        sys.exit(2)
    except KeyboardInterrupt:
        _print_error("interrupted")
        sys.exit(130)


_ctrl_c: list[int] = []  # the SIGINTs :func:`_on_ctrl_c` received (a campaign has its own)


def _on_ctrl_c(signum, frame) -> None:
    """Python's own SIGINT handling (``KeyboardInterrupt``), remembering the signal:
    typer turns the interrupt into exit code 130 before :func:`main` sees it."""
    _ctrl_c.append(signum)
    raise KeyboardInterrupt


def _print_warning(message, category, filename, lineno, file=None, line=None) -> None:
    """Warnings (a long run's estimate...) as one plain line on stderr."""
    _errors.print(f"[yellow]warning:[/] {escape(shorten(str(message), MAX_MESSAGE_CHARS))}",
                  highlight=False)  # fmt: skip


def _print_error(message: str) -> None:
    """One error line on stderr; the message is plain text (never read as markup)."""
    # no emoji codes either: '--speeds 6000:100:10' is printed as written
    _errors.print(f"[bold red]error:[/] {escape(shorten(message, MAX_MESSAGE_CHARS))}",
                  highlight=False, emoji=False)  # fmt: skip
