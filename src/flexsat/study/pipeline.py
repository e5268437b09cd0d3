"""The thesis study end to end: every part timed, each allowed to fail.

:func:`run_study` runs the parts of :data:`PARTS` (configuration, modal analysis,
open-loop validation, the ASMC slew, the frequency-domain analysis, the robust
stability (mu) of its law, the wheels' microvibration jitter, the controller
comparison, the slew animation, the avionics, unless ``quick`` the three thesis
campaigns, and the law comparison), after compiling every kernel they need up front
(its time is ``compilation_s`` in the manifest; the parts' wall times exclude it),
writes each part's outputs under its own folder, and keeps ``study.json``, the
manifest, up to date after every part: status (ok, failed, skipped, not run), wall
time, the files written and, for a failed part, the error and its traceback. A failed
part does not stop the others (a part whose input failed is marked failed with that
reason). ``parts`` restricts the study to some parts and those they need
(:func:`chosen_parts`, ``flexsat study --parts``): the others are "not run". Finally
it writes ``report.html`` from the manifest and the parts' JSON files.

On two cores or more the parts run in two lanes side by side (:data:`LANES`): this
process runs lane 0 (the campaigns among them, with their progress bars) and a
forked process lane 1, each lane in the order of :data:`PARTS`; the manifest keeps
that order whichever lane finishes first (docs/results.md, 'Two lanes').
"""

from __future__ import annotations

import datetime as dt
import json
import multiprocessing
import os
import time
import traceback
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path

from rich.console import Console
from rich.markup import escape

from flexsat import __version__
from flexsat._compiled_cache import kernels_cached
from flexsat.config.models import SatelliteConfig
from flexsat.control.laws import LAWS
from flexsat.files import ensure_dir
from flexsat.parallel import (
    figure_workers,
    forked_map,
    frozen_heap,
    signals_deferred,
    start_child,
)
from flexsat.study.outputs import (
    derived_properties,
    fly_campaign,
    fly_openloop,
    fly_slew,
    prepare_output_dir,
    write_json,
    write_modal,
)
from flexsat.study.thesis import CAMPAIGNS

__all__ = [
    "CAMPAIGNS",
    "LANES",
    "NOT_RUN",
    "PARTS",
    "Part",
    "StudyContext",
    "chosen_parts",
    "parts_wall_time",
    "run_study",
]

QUICK_ANIMATED_MODES = 2
"""Mode GIFs of the quick study: the lowest flexible modes that drive a hub DOF (the
full study animates up to six)."""
QUICK_ANIMATION_FRAMES = 60
"""Frames of the quick study's slew animation (the full study's: 150)."""

MANIFEST = "study.json"
REPORT = "report.html"
NOT_RUN = "not run"
"""The status of a part left out of a study restricted to some parts (``--parts``)."""


@dataclass
class StudyContext:
    """What every part gets: the satellite, the output folder and the options.

    Parameters
    ----------
    config : SatelliteConfig
        The satellite studied.
    out : Path
        The study folder.
    quick : bool
        The short study (``--quick``).
    progress : bool or None
        Progress bars: None shows them on a terminal only.
    workers : int or None
        Processes of the campaigns and figures (None: the default).
    controllers : tuple of str
        The comparison's laws; empty: every registered law.
    results : dict
        Part name -> its returned outputs, filled as the parts run.
    only : frozenset of str or None
        The parts that run (:func:`chosen_parts`); None: every part.
    """

    config: SatelliteConfig
    out: Path
    quick: bool = False
    progress: bool | None = None
    workers: int | None = None
    controllers: tuple[str, ...] = ()  # the comparison's laws; empty: every registered law
    results: dict = field(default_factory=dict)  # part name -> its returned outputs
    only: frozenset[str] | None = None  # the parts that run; None: every part

    def runs(self, name: str) -> bool:
        """Whether the part called ``name`` is among those that run."""
        return self.only is None or name in self.only

    @property
    def laws(self) -> tuple[str, ...]:
        """The nominal slew's law (the default) first, then the others compared."""
        default = LAWS.default
        chosen = self.controllers or LAWS.names()
        return (default, *(name for name in chosen if name != default))

    @property
    def plant(self):
        from flexsat.dynamics.plant import Plant

        if "plant" not in self.results:
            self.results["plant"] = Plant.from_config(self.config)
        return self.results["plant"]


@dataclass(frozen=True)
class Part:
    """One section of the study: a name (its folder), a title, and the function.

    Parameters
    ----------
    name : str
        The part's name, also its folder.
    title : str
        Its title in the report.
    run : callable
        ``run(context) -> outputs``.
    needs : tuple of str
        Parts whose outputs it reads (run first, in the same lane).
    full_only : bool
        Skipped with ``--quick``.
    lane : int
        The lane that runs it when the parts run side by side (:data:`LANES`): 0, this
        process; 1, the forked one.
    applies : callable, optional
        ``applies(context) -> reason or None``: why the part cannot run on this
        satellite (it is then skipped with that reason); None: it can.
    """

    name: str
    title: str
    run: Callable[[StudyContext], dict]
    needs: tuple[str, ...] = ()
    full_only: bool = False  # skipped with --quick
    lane: int = 0  # 0: this process; 1: the forked lane
    applies: Callable[[StudyContext], str | None] | None = None


def _relative(ctx: StudyContext, paths) -> list[str]:
    return [Path(p).resolve().relative_to(ctx.out.resolve()).as_posix() for p in paths]


def _configuration(ctx: StudyContext) -> dict:
    payload = {"config": ctx.config.model_dump(mode="json"), **derived_properties(ctx.plant)}
    path = write_json(ctx.out / "configuration" / "configuration.json", payload)
    return {"json": _relative(ctx, [path])[0]}


def _modal(ctx: StudyContext) -> dict:
    animate = None
    if ctx.quick:
        from flexsat.analysis.modal import modal_analysis
        from flexsat.plots.modal import default_animated_modes

        animate = default_animated_modes(modal_analysis(ctx.plant))[:QUICK_ANIMATED_MODES]
    _, summary = write_modal(ctx.plant, ctx.out / "modal", animate)
    files = _relative(ctx, summary["files"])
    return {"json": files[0], "figures": files[1:]}


def _openloop(ctx: StudyContext) -> dict:
    result, metrics = fly_openloop(ctx.plant, None, ctx.out / "openloop", ctx.progress)
    result.raise_for_status()
    files = _relative(ctx, metrics["files"])
    return {"json": files[-1], "result": files[0], "figures": files[1:-1]}


def _slew_with(ctx: StudyContext, kind: str, figures: bool = True, progress=None) -> dict:
    from flexsat.simulate import SlewScenario

    scenario = SlewScenario.model_validate({"controller": {"kind": kind}})
    out = ctx.out / "slew" / kind
    progress = ctx.progress if progress is None else progress
    result, metrics = fly_slew(ctx.plant, scenario, out, progress, figures=figures)
    result.raise_for_status()
    files = _relative(ctx, metrics["files"])
    return {"json": files[-1], "result": files[0], "figures": files[1:-1]}


def _slew(ctx: StudyContext) -> dict:
    return _slew_with(ctx, LAWS.default)


def _comparison(ctx: StudyContext) -> dict:
    from flexsat.plots.comparison import write_comparison_figure
    from flexsat.simulate.result import Result

    runs = {LAWS.default: ctx.results["slew"]}
    # The report shows the comparison figure; each law's own figure set is drawn in
    # the full study only (flexsat slew --out draws it for one law). The laws fly in
    # forked processes side by side (no progress bars: they would interleave).
    others = ctx.laws[1:]
    flown = forked_map(lambda kind: _slew_with(ctx, kind, not ctx.quick, False), others)
    runs.update(zip(others, flown, strict=True))
    datasets = {
        kind: Result.from_netcdf(ctx.out / run["result"]).dataset for kind, run in runs.items()
    }
    figure = write_comparison_figure(datasets, ctx.out / "comparison" / "comparison.png")
    return {
        "runs": {kind: run["json"] for kind, run in runs.items()},
        "figures": _relative(ctx, [figure]),
    }


def _frequency(ctx: StudyContext) -> dict:
    from flexsat.simulate import SlewScenario
    from flexsat.study.linear import write_margins

    summary = write_margins(ctx.plant, SlewScenario(), ctx.out / "frequency")
    files = _relative(ctx, summary["files"])
    return {"json": files[0], "figures": files[1:]}


def _pointing(ctx: StudyContext) -> dict:
    from flexsat.study.jitter import REPORT_WINDOW_S, jitter_scenario, write_jitter

    summary = write_jitter(ctx.plant, jitter_scenario(), ctx.out / "pointing",
                           window_s=REPORT_WINDOW_S)  # fmt: skip
    figure, written, contributors = _relative(ctx, summary["files"])
    return {"json": written, "figures": [figure], "contributors": contributors}


def _animation(ctx: StudyContext) -> dict:
    from flexsat.plots.animation import write_animation
    from flexsat.simulate.result import Result

    result = Result.from_netcdf(ctx.out / ctx.results["slew"]["result"])
    frames = {"max_frames": QUICK_ANIMATION_FRAMES} if ctx.quick else {}
    path = write_animation(result, ctx.out / "slew" / LAWS.default / "animation.gif", **frames)
    return {"figures": _relative(ctx, [path])}


def _campaigns(ctx: StudyContext) -> dict:
    from flexsat.campaigns import load_campaign

    summaries, figures = {}, []
    for name in CAMPAIGNS:
        store = ctx.out / "campaigns" / name
        summary = fly_campaign(
            load_campaign(name),
            ctx.config,
            store,
            progress=ctx.progress is not False,
            workers=ctx.workers,
            resume=True,
        )
        summaries[name] = _relative(ctx, [store / "summary.json"])[0]
        figures += _relative(ctx, summary["figures"])
    return {"summaries": summaries, "figures": figures}


def _laws(ctx: StudyContext) -> dict:
    from flexsat.study.laws import law_comparison

    law_comparison(ctx.config, ctx.out, ctx.laws, quick=ctx.quick, workers=ctx.workers,
                   progress=ctx.progress is not False, default_law=LAWS.default)  # fmt: skip
    return {"json": _relative(ctx, [ctx.out / "laws" / "laws.json"])[0]}


def _campaigns_fly(ctx: StudyContext) -> str | None:
    """Why the thesis's campaigns cannot fly this satellite (a path one of them varies
    that its appendage model does not have, an initial state it cannot take), or None.

    Every case of :data:`CAMPAIGNS` is resolved against the config (about 0.7 s for the
    three, no run flown); the answer is kept for the other part that asks.
    """
    from flexsat.campaigns import load_campaign
    from flexsat.campaigns.definition import CaseStream
    from flexsat.errors import FlexsatError

    key = "campaigns fly"  # not a part's name: the answer, shared by the parts that ask
    if key not in ctx.results:
        ctx.results[key] = None
        for name in CAMPAIGNS:
            try:
                for _ in CaseStream(load_campaign(name), ctx.config, None, strict=True):
                    pass
            except FlexsatError as exc:
                ctx.results[key] = (f"not applicable: the {name} campaign cannot fly this "
                                    f"satellite ({exc})")  # fmt: skip
                break
    return ctx.results[key]


def _robust(ctx: StudyContext) -> dict:
    from flexsat.simulate import SlewScenario
    from flexsat.study.mu import robust_study

    out = ctx.out / "robust"
    robust = robust_study(ctx.config, SlewScenario(), out, quick=ctx.quick)
    flown = [out / case["result"] for case in robust["cases"].values()]
    mu_json, robust_json, figure = _relative(ctx, [out / "mu.json", out / "robust.json",
                                                   out / "mu.png"])  # fmt: skip
    return {"mu": mu_json, "json": robust_json, "results": _relative(ctx, flown),
            "figures": [figure]}  # fmt: skip


def _uncertain_model_builds(ctx: StudyContext) -> str | None:
    """Why the satellite has no uncertain model (an appendage that is not a plate on a
    fixed SADM angle), or None."""
    from flexsat.errors import ConfigError
    from flexsat.linear.uncertain import uncertain_model

    key = "uncertain model"  # not a part's name: the answer, kept
    if key not in ctx.results:
        ctx.results[key] = None
        try:
            uncertain_model(ctx.config)
        except ConfigError as exc:
            ctx.results[key] = f"not applicable: {exc}"
    return ctx.results[key]


def _avionics(ctx: StudyContext) -> dict:
    from flexsat.study.avionics import avionics_study

    written = avionics_study(ctx.plant, ctx.out / "avionics", quick=ctx.quick)
    return {"json": _relative(ctx, [written["json"]])[0],
            "figures": _relative(ctx, written["figures"])}  # fmt: skip


PARTS = (
    Part("configuration", "Configuration", _configuration),
    Part("modal", "Modal analysis", _modal),
    Part("openloop", "Open-loop validation", _openloop, lane=1),
    Part("slew", f"Nominal slew with {LAWS.get(LAWS.default).label}", _slew, lane=1),
    Part("frequency", "Frequency domain: plant, loop gain and margins", _frequency, lane=1),
    Part(
        "robust",
        "Robust stability: μ over the thesis's parameter box",
        _robust,
        applies=_uncertain_model_builds,
    ),
    Part("pointing", "Pointing budget: wheel microvibration", _pointing),
    Part("comparison", "Controller comparison", _comparison, needs=("slew",), lane=1),
    Part("animation", "Slew animation", _animation, needs=("slew",), lane=1),
    Part("avionics", "Avionics in the loop: what the thesis could not say", _avionics),
    Part("campaigns", "Robustness campaigns", _campaigns, full_only=True, applies=_campaigns_fly),
    Part("laws", "Law comparison over the campaigns", _laws, applies=_campaigns_fly),
)
"""The study's parts, in the order they appear in the report (and run, lane by lane)."""


def chosen_parts(names) -> frozenset[str]:
    """The parts ``names`` asks for and every part they need (:attr:`Part.needs`, in turn
    their needs): what a study restricted to ``names`` runs.

    Parameters
    ----------
    names : str or iterable of str
        Names of parts of :data:`PARTS`, at least one.

    Returns
    -------
    frozenset of str

    Raises
    ------
    ConfigError
        A name that is no part's, or no name at all; the message lists the parts.
    """
    from flexsat.errors import ConfigError, shorten

    by_name = {part.name: part for part in PARTS}
    allowed = ", ".join(by_name)
    asked = [names] if isinstance(names, str) else list(names)
    if not asked:
        raise ConfigError(f"no part named: name one or more of {allowed}")
    for name in asked:
        if name not in by_name:
            raise ConfigError(f"unknown part {shorten(repr(name))}: the study's parts are "
                              f"{allowed}")  # fmt: skip
    chosen: set[str] = set()
    pending = list(asked)
    while pending:
        name = pending.pop()
        if name not in chosen:
            chosen.add(name)
            pending += by_name[name].needs
    return frozenset(chosen)


LANES = 2
"""Lanes the parts run in side by side when :func:`flexsat.parallel.figure_workers`
allows two processes. Each part's ``lane`` splits the quick study's CPU time about
evenly (measured: lane 0, configuration, modal, avionics and laws, 17 CPU-s; lane 1,
the open loop, the slew and what reads it, and the frequency part, 17 CPU-s); the
campaigns of the full study stay in this process, whose progress bars they show. The
robustness part, added since, runs in lane 0: in a quick study at load 9 the lanes took
115 s (lane 0, the robustness part 46 s of it) and 94 s; in lane 1 it would have made
them 69 s and 140 s."""


def run_study(
    config: SatelliteConfig,
    out: str | Path,
    *,
    quick: bool = False,
    config_source: str = "built-in nominal case",
    progress: bool | None = None,
    workers: int | None = None,
    console: Console | None = None,
    controllers: tuple[str, ...] = (),
    parts=None,
) -> dict:
    """Run the study into ``out`` and write ``out/report.html``.

    Parameters
    ----------
    config : SatelliteConfig
        The satellite studied (campaigns vary it; the controller keeps the nominal
        design model).
    out : str or Path
        Output folder (created). Each part writes under ``out/<part name>/``.
    quick : bool
        Skip the campaigns (the parts marked ``full_only``).
    config_source : str
        Where the config came from, shown in the report.
    progress : bool or None
        Progress bars of the runs: None shows them on a terminal only.
    workers : int, optional
        Campaign worker processes (default: all cores).
    console : rich.console.Console, optional
        Where each part's outcome is announced; default: standard error.
    controllers : tuple of str, optional
        Registered laws flown in the comparison besides the default one; empty:
        every registered law.
    parts : iterable of str, optional
        Run only these parts of :data:`PARTS` and those they need
        (:func:`chosen_parts`); the others are recorded with the status
        :data:`NOT_RUN`. None (the default): every part.

    Returns
    -------
    dict
        The manifest (also in ``out/study.json``) with ``report`` added: the
        report's path.

    Raises
    ------
    ConfigError
        ``out`` cannot be written, or a part's folder in it is a symbolic link
        (:func:`flexsat.files.ensure_dir`), or ``parts`` names no part or an unknown
        one, before any part runs.
    """
    from flexsat.study.report import write_report

    only = None if parts is None else chosen_parts(parts)
    out = prepare_output_dir(out)
    for part in PARTS:  # a part's folder that is a link is refused before any work
        if (out / part.name).is_symlink():
            ensure_dir(out / part.name)
    console = console or Console(stderr=True)
    ctx = StudyContext(config, out, quick, progress, workers, tuple(controllers), only=only)
    manifest = {
        "flexsat_version": __version__,
        "created_utc": dt.datetime.now(dt.UTC).strftime("%Y-%m-%d %H:%M:%S UTC"),
        "config_name": config.name,
        "config_source": config_source,
        "quick": quick,
        # the parts chosen with their needs (--parts), in the report's order; None: all
        "chosen_parts": None if only is None else [p.name for p in PARTS if p.name in only],
        "parts": [],
    }
    lanes = LANES if figure_workers() > 1 else 1
    manifest["compilation_s"], per_lane = _compile(ctx, console, lanes)
    manifest["estimate"] = _estimate(ctx, console, lanes)
    done: dict[str, dict] = {}

    def record(part: Part, entry: dict) -> None:
        done[part.name] = entry
        manifest["parts"] = [done[p.name] for p in PARTS if p.name in done]
        manifest["total_wall_time_s"] = parts_wall_time(manifest["parts"], lanes)
        write_json(out / MANIFEST, manifest)
        _announce(console, part, entry, manifest["estimate"], done)

    # each lane's own kernels, loaded before its first part: compilation, not the parts'
    manifest["compilation_s"] += _run_parts(ctx, record, lanes, per_lane)
    write_json(out / MANIFEST, manifest)
    report = write_report(out)
    # a part whose section the report could not draw is failed there: study.json says so
    manifest["parts"] = json.loads((out / MANIFEST).read_text())["parts"]
    for entry in manifest["parts"]:
        if entry.get("report_failed"):
            _announce(console, next(p for p in PARTS if p.name == entry["name"]), entry)
    manifest["report"] = str(report)
    return manifest


def _compile_runs(ctx: StudyContext) -> list[tuple[dict | str | None, frozenset[str]]]:
    """The short runs that compile every loop the parts fly, each with the parts that
    fly that loop (their lanes decide which process loads it, :func:`_compile`).

    In the order two compiling processes take them (:func:`_compile`): the first law's
    slew, which builds the study's plant (its plates' kernels) and compiles the closed
    loop every other slew shares (one numba type for every stage chain of up to four
    stages, :data:`flexsat.simulate.coupled.CHAIN_SLOTS`). Meanwhile the other process
    compiles what needs neither: ``"stages"``, the laws and stages of the other runs
    (they need no plant), then ``"drive plant"`` (its chain kernels; its plates are
    tuned on the plates' kernels, which the first process has cached by then), then
    the open loop. No part flies ``"stages"`` or ``"drive plant"``: their parts are
    empty. The runs after them load what they fly from the disk cache: the delay, the
    avionics chain, the solar arrays on a drive, the hybrid damping and the other
    laws. Measured on an empty cache: the plates' kernels 8-12 s, the first law's
    slew 25-35 s more, the other runs' stages about 10 s, the open loop 10-15 s, the
    drive's plant 14-17 s.

    A run is the fields of a :class:`flexsat.simulate.SlewScenario`, ``"stages"``,
    ``"open loop"``, ``"drive plant"`` or None: the solar arrays on a drive
    (:func:`flexsat.study.avionics.sadm_study`).
    """
    from flexsat.study.avionics import AVIONICS, delayed
    from flexsat.study.laws import HYBRID_DAMPING

    laws = [{"controller": {"kind": kind}} for kind in ctx.laws]
    every_law = frozenset({"slew", "comparison", "laws", "robust"})
    avionics = frozenset({"avionics"})
    runs = [(laws[0], every_law), ("stages", frozenset()), ("drive plant", frozenset()),
            ("open loop", frozenset({"openloop"})),
            (delayed(1), avionics), (AVIONICS, avionics), (None, avionics),
            ({"joint_actuator": HYBRID_DAMPING}, frozenset({"laws"})),
            *((law, every_law) for law in laws[1:])]  # fmt: skip
    if ctx.only is None:
        return runs
    # a study of some parts flies the runs of those parts only, and the first law's slew,
    # which the estimate's calibration flies (:func:`_split_runs`); the steps no part
    # flies ("stages", "drive plant") stay: they are flown only to fill an empty cache
    return [(fields, parts & ctx.only) for k, (fields, parts) in enumerate(runs)
            if k == 0 or not parts or parts & ctx.only]  # fmt: skip


def _fly_short(ctx: StudyContext, fields: dict | str | None) -> None:
    """Fly one run of :func:`_compile_runs` for 20 ms (it compiles or loads its loop)."""
    from flexsat.simulate import OpenLoopScenario, SlewScenario, run_openloop, run_slew
    from flexsat.simulate.stage_chain import loop_stages
    from flexsat.study.avionics import sadm_plant, sadm_runs, sadm_study

    short = {"duration_s": 0.02, "record_dt_s": 0.01}
    if fields == "stages":  # the other slews' laws and stages: no plant needed
        slews = [f for f, _ in _compile_runs(ctx)[1:] if isinstance(f, dict)]
        for each in slews + sadm_runs(ctx.config):
            loop_stages(SlewScenario.model_validate({**short, **each}))
    elif fields == "open loop":
        run_openloop(ctx.plant, OpenLoopScenario.model_validate(short), progress=False)
    elif fields == "drive plant":  # building it compiles its kernels (not the plates')
        sadm_plant(ctx.config)
    elif fields is None:  # the arrays on a drive
        sadm_study(ctx.plant, duration_s=short["duration_s"])
    else:
        run_slew(ctx.plant, SlewScenario.model_validate({**short, **fields}),
                 progress=False)  # fmt: skip


def _fly_each(ctx: StudyContext, runs: list) -> float:
    """Fly ``runs`` (of :func:`_compile_runs`) one after the other; return the wall time
    [s]. A run that fails is left for the part that needs it to report."""
    start = time.perf_counter()
    try:
        for fields in runs:
            _fly_short(ctx, fields)
    except Exception:  # the part that needs it reports the problem
        pass
    return time.perf_counter() - start


def _compile(ctx: StudyContext, console: Console, lanes: int = 1) -> tuple[float, dict]:
    """Compile (or load from the disk cache) every kernel the study runs, up front.

    A 20 ms open-loop run and a 20 ms slew per compiled loop the parts fly
    (:func:`_compile_runs`): one per law, the avionics chain, the delay stage, the
    hybrid damping and the solar-array drive; the parts' wall times then exclude
    compilation, which the manifest gives apart (``compilation_s``), and the forked
    processes the parts fly their runs in inherit the compiled loops instead of each
    compiling them. When the disk cache holds no kernels yet
    (:func:`flexsat._compiled_cache.kernels_cached`), two forked processes first
    compile the runs into it side by side, in the order of :func:`_compile_runs`,
    each building the plant it needs (the first one the study's: this process has
    built none yet), and this process then loads them from it.

    With two lanes, this process loads only the loops that parts of both lanes fly;
    a loop that only one lane's parts fly is loaded by that lane before its first
    part (:func:`_run_parts`), both lanes side by side.

    Parameters
    ----------
    ctx : StudyContext
        The study.
    console : Console
        Where the step is announced.
    lanes : int
        Lanes the parts will run in (1 or 2).

    Returns
    -------
    seconds : float
        Wall time of this step [s].
    per_lane : dict
        Lane -> the runs left for it to fly (empty with one lane).
    """
    cached = kernels_cached()
    console.print("loading the simulation kernels from the disk cache..." if cached else
                  "compiling the simulation kernels (the first run only; later runs load "
                  "them from the disk cache)...", highlight=False)  # fmt: skip
    start = time.perf_counter()
    shared, per_lane = [], {}
    try:
        runs = _compile_runs(ctx)
        shared, per_lane = _split_runs(runs, lanes)
        if not cached:  # each process compiles its share into the cache
            forked_map(lambda fields: _fly_short(ctx, fields), [fields for fields, _ in runs])
    except Exception:  # the part that needs it reports the problem
        pass
    _fly_each(ctx, shared)
    elapsed = time.perf_counter() - start
    console.print(f"{'loaded' if cached else 'compiled'} in {elapsed:.1f} s; the wall times "
                  "below exclude it", highlight=False)  # fmt: skip
    return elapsed, per_lane


def _split_runs(runs: list, lanes: int) -> tuple[list, dict[int, list]]:
    """Split :func:`_compile_runs` into those this process flies before the lanes start
    (loops the parts of both lanes fly) and, per lane, those only its parts fly.

    Returns ``(shared, {lane: runs})``; with one lane every run is shared. A run no
    part flies (only compiled, the drive's plant) is in neither, but the first, the
    first law's slew, is always shared: the estimate's calibration
    (:func:`flexsat.study.estimate.calibrate`) flies that loop in this process before
    the lanes start, and would otherwise time its loading (a study of some parts,
    ``--parts``, may fly it in one lane or not at all).
    """
    runs = [(k, fields, parts) for k, (fields, parts) in enumerate(runs) if k == 0 or parts]
    if lanes < 2:
        return [fields for _, fields, _ in runs], {}
    lane_of = {part.name: part.lane for part in PARTS}
    shared, per_lane = [], {lane: [] for lane in range(lanes)}
    for k, fields, parts in runs:
        used = {lane_of[name] for name in parts}
        (per_lane[used.pop()] if len(used) == 1 and k > 0 else shared).append(fields)
    return shared, per_lane


def _run_parts(
    ctx: StudyContext,
    record: Callable[[Part, dict], None],
    lanes: int,
    prepare: dict | None = None,
) -> float:
    """Run every part of :data:`PARTS` on ``lanes`` lanes; ``record(part, entry)`` each.

    With two lanes, lane 1 runs in a forked process (it inherits the compiled
    kernels and ``ctx``, and runs without progress bars) and sends each part's entry
    back as it finishes; this process runs lane 0 and records lane 1's entries
    between its own parts, then waits for the rest. A lane that dies leaves its
    unfinished parts failed with its exit code. ``prepare`` maps a lane to the short
    runs it flies before its first part (:func:`_compile`); returns the longer
    lane's time for them [s] (0 without any).
    """
    prepare = prepare or {}
    if lanes < 2:
        for part in PARTS:
            record(part, _run_part(part, ctx))
        return 0.0
    forked = [part for part in PARTS if part.lane == 1]
    context = multiprocessing.get_context("fork")
    receive, send = context.Pipe(duplex=False)
    lane = context.Process(target=_run_lane, name="flexsat-lane-1",
                           args=(forked, ctx, send, prepare.get(1, []), os.getpid()))  # fmt: skip
    with frozen_heap(), signals_deferred():
        lane.start()
    send.close()  # the lane holds the only writing end: its exit ends the reading
    pending = {part.name: part for part in forked}
    prepared = [_fly_each(ctx, prepare.get(0, []))]

    def collect(block: bool) -> None:
        while pending and (block or receive.poll()):
            try:
                name, entry, results = receive.recv()
            except EOFError:  # the lane stopped before sending every part
                lane.join()
                error = f"the process running it stopped (exit code {lane.exitcode})"
                for part in list(pending.values()):
                    record(part, _entry(part, "failed", error))
                pending.clear()
                return
            if name is None:  # the lane's short runs, before its parts: their time
                prepared.append(entry)
                continue
            if results is not None:  # a failed or skipped part has no outputs to read
                ctx.results[name] = results
            record(pending.pop(name), entry)

    try:
        for part in PARTS:
            if part.lane != 1:
                record(part, _run_part(part, ctx))
                collect(block=False)
        collect(block=True)
    finally:
        if lane.is_alive():  # interrupted: the lane goes with this process
            lane.terminate()
        lane.join()
        receive.close()
    return max(prepared)


def _run_lane(parts: list[Part], ctx: StudyContext, send, runs: list, parent_pid: int) -> None:
    """Lane 1 in its forked process: fly ``runs`` (its share of :func:`_compile`) and send
    (None, their time [s], None), then run ``parts`` in order, send (name, entry,
    outputs) each. Ctrl-C is the study's process's to handle; the lane exits with it
    (``parent_pid``), even killed."""
    start_child(parent_pid)
    ctx.progress = False  # two lanes' progress bars would interleave
    send.send((None, _fly_each(ctx, list(runs)), None))
    for part in parts:
        entry = _run_part(part, ctx)
        send.send((part.name, entry, ctx.results.get(part.name)))
    send.close()


def parts_wall_time(entries: list[dict], lanes: int) -> float:
    """The parts' wall time: the longer lane's parts, one after another [s].

    Each lane runs its parts back to back, after loading the kernels only it flies
    (counted in ``compilation_s``). Subtracting that loading from the elapsed time
    would be wrong when one lane runs parts while the other is still loading.

    Parameters
    ----------
    entries : list of dict
        The manifest's part entries (``name``, ``wall_time_s`` [s]).
    lanes : int
        1, or :data:`LANES` when the parts ran side by side.

    Returns
    -------
    float
        The sum of the wall times of the lane whose parts took longest [s].
    """
    lane = {part.name: part.lane if lanes > 1 else 0 for part in PARTS}
    totals: dict[int, float] = {}
    for entry in entries:
        key = lane[entry["name"]]
        totals[key] = totals.get(key, 0.0) + entry["wall_time_s"]
    return max(totals.values(), default=0.0)


def _entry(part: Part, status: str = "ok", error: str | None = None) -> dict:
    """A part's manifest entry before its run's outputs and time are known."""
    return {"name": part.name, "title": part.title, "status": status, "wall_time_s": 0.0,
            "outputs": {}, "error": error, "traceback": None}  # fmt: skip


def _run_part(part: Part, ctx: StudyContext) -> dict:
    if not ctx.runs(part.name):
        return _entry(part, NOT_RUN, "not run: the study was asked for other parts (--parts)")
    if part.full_only and ctx.quick:
        return _entry(part, "skipped", "skipped with --quick; run the study without it for "
                                       "this part")  # fmt: skip
    missing = [name for name in part.needs if name not in ctx.results]
    if missing:
        return _entry(part, "failed", f"not run: it needs the {', '.join(missing)} part, "
                                      "which failed")  # fmt: skip
    entry = _entry(part)
    start = time.perf_counter()
    try:
        reason = part.applies(ctx) if part.applies is not None else None
        if reason is not None:
            return _entry(part, "skipped", reason)
        entry["outputs"] = ctx.results[part.name] = part.run(ctx)
    except Exception as exc:  # a failed part is reported; the study goes on
        entry["status"] = "failed"
        entry["error"] = f"{type(exc).__name__}: {exc}"
        entry["traceback"] = traceback.format_exc()
    entry["wall_time_s"] = time.perf_counter() - start
    return entry


def _estimate(ctx: StudyContext, console: Console, lanes: int) -> dict | None:
    """Calibrate, print the study's estimate per part (:mod:`flexsat.study.estimate`)
    before the first part, and return it for the manifest (``basis``, ``parts``: part
    name -> estimated wall time [s], ``total_s``); None if no slew could be flown to
    calibrate it (the parts then say why)."""
    from flexsat.study import estimate

    try:
        basis = estimate.calibrate(ctx.plant, ctx.workers)
        rows = estimate.study_estimate(ctx, [p for p in PARTS if ctx.runs(p.name)], basis)
    except Exception as exc:  # the parts that fly the same satellite report the problem
        console.print(f"no estimate: {escape(f'{type(exc).__name__}: {exc}')}", highlight=False)
        return None
    lane_of = {part.name: part.lane if lanes > 1 else 0 for part in PARTS}
    total = estimate.total_s(rows, lane_of)
    estimate.print_estimate(console, rows, basis, {p.name: p.title for p in PARTS}, total)
    return {"basis": basis.describe(), "parts": {name: seconds for name, _, seconds in rows},
            "total_s": total}  # fmt: skip


def _announce(console: Console, part: Part, entry: dict, estimate: dict | None = None,
              done: dict | None = None) -> None:  # fmt: skip
    """One line per part: its outcome and wall time, then, with an estimate, a bar of
    the study's progress (the estimated time of the parts done, against the total)."""
    from rich.progress_bar import ProgressBar
    from rich.table import Table

    style = {"ok": "green", "failed": "bold red", "skipped": "yellow", NOT_RUN: "dim"}[
        entry["status"]
    ]
    line = f"[{style}]{entry['status']:>7}[/] {part.title} ({entry['wall_time_s']:.1f} s"
    expected = (estimate or {}).get("parts", {}).get(part.name)
    line += f", estimate {expected:.0f} s)" if expected is not None else ")"
    if entry["status"] != "ok":
        line += f": {escape(entry['error'])}"
    console.print(line, highlight=False)
    if not estimate or sum(estimate["parts"].values()) <= 0.0 or done is None:
        return
    planned = sum(estimate["parts"].values())
    finished = sum(estimate["parts"].get(name, 0.0) for name in done)
    row = Table.grid(padding=(0, 1))
    row.add_row("        study", ProgressBar(total=planned, completed=finished, width=30),
                f"{min(finished / planned, 1.0):4.0%} of the estimate, {len(done)}/"
                f"{len(PARTS)} parts")  # fmt: skip
    console.print(row)
