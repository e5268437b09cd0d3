"""Run one analysis and write its files: what the CLI commands and the study share.

Each function computes a result, its metrics (plain JSON-ready dicts, SI units, keys
ending in their unit) and, given a folder, writes ``metrics.json`` (or
``modal.json``), the NetCDF result and the figures there. The JSON written here is
the one source of the numbers that the CLI prints and the study report shows.
"""

from __future__ import annotations

import sys
import tempfile
from collections.abc import Callable
from pathlib import Path
from typing import TYPE_CHECKING

from flexsat.errors import ConfigError
from flexsat.files import ensure_dir, output_root, write_text
from flexsat.strict_json import dumps

if TYPE_CHECKING:  # the CLI imports this module at start-up: keep numba out of it
    from flexsat.dynamics.plant import Plant

__all__ = [
    "MODAL_PROGRESS_MIN_DOF",
    "derived_properties",
    "fly_campaign",
    "fly_openloop",
    "fly_slew",
    "prepare_output_dir",
    "write_json",
    "write_modal",
    "write_slew_outputs",
]


MODAL_PROGRESS_MIN_DOF = 1000
"""From this many coordinates on, :func:`write_modal` says on stderr what it is doing
(two 512-segment chains, 3078 coordinates, take minutes: the eigenproblem, the JSON of
every mode shape, the figures)."""


def prepare_output_dir(path: str | Path, option: str = "--out") -> Path:
    """Create an output folder now and check it can be written, before any work.

    Parameters
    ----------
    path : str or Path
        The folder.
    option : str
        The command-line option that named it, for the message.

    Returns
    -------
    Path
        The folder.

    Raises
    ------
    ConfigError
        If ``path`` is a file, or the folder cannot be created or written.
    """
    path = Path(path)
    if path.exists() and not path.is_dir():
        raise ConfigError(f"{option} {path}: exists and is not a folder")
    try:
        output_root(path)  # a link below an enclosing output folder is refused
        with tempfile.TemporaryFile(dir=path):
            pass
    except OSError as exc:
        raise ConfigError(f"{option} {path}: cannot write there ({exc.strerror or exc})") from None
    return path


def write_json(path: str | Path, payload: dict) -> Path:
    """Write ``payload`` as strict, indented JSON (:func:`flexsat.files.write_text`).

    Parameters
    ----------
    path : str or Path
        The file.
    payload : dict
        JSON-like data (non-finite floats become null).

    Returns
    -------
    Path
        ``path``.
    """
    return write_text(path, dumps(payload, indent=2))


def derived_properties(plant: Plant) -> dict:
    """What flexsat derives from a config: hub inertia, panel masses, joint tuning.

    Parameters
    ----------
    plant : Plant
        The satellite.

    Returns
    -------
    dict
        ``hub_inertia_kg_m2`` (3x3), and per appendage its name, model and what its
        model describes (a plate: ``mass_kg``, ``centroidal_inertia_kg_m2`` (3x3),
        ``stiffness`` and ``damping`` (6 joint DOFs in the order of
        :meth:`Plant.dof_names`; N m/rad, N m s/rad for rotations, N/m, N s/m for
        translations)).
    """
    return {
        "hub_inertia_kg_m2": plant.hub_J.tolist(),
        "appendages": [
            {"name": app.name, "model": model.name, **model.describe(app, params)}
            for app, model, params in zip(
                plant.config.appendages, plant.models, plant.params, strict=True
            )
        ],
    }


def write_modal(plant: Plant, out: Path | None = None, animate: list[int] | None = None,
                progress: bool | None = None):  # fmt: skip
    """Modal analysis; with ``out``, ``modal.json`` and the modal figures there.

    Parameters
    ----------
    plant : Plant
        The satellite.
    out : Path, optional
        Where the files go.
    animate : list of int, optional
        Modes (1-based) to animate as GIFs.
    progress : bool, optional
        Say each step on stderr; default: for plants of at least
        :data:`MODAL_PROGRESS_MIN_DOF` coordinates.

    Returns
    -------
    analysis : flexsat.analysis.modal.ModalAnalysis
    summary : dict
        ``analysis.to_dict()``, plus ``files`` (written paths) when ``out`` is given.
    """
    from flexsat.analysis.modal import modal_analysis
    from flexsat.plots.modal import write_modal_figures

    show = plant.n_dof >= MODAL_PROGRESS_MIN_DOF if progress is None else progress

    def step(text: str) -> None:
        if show:
            print(f"modal: {text}", file=sys.stderr, flush=True)

    if out is not None:
        prepare_output_dir(out)
    step(f"{plant.n_dof} coordinates: the {plant.n_dof} x {plant.n_dof} eigenproblem and "
         "each mode's kind")  # fmt: skip
    analysis = modal_analysis(plant)
    step("effective masses and modal damping ratios")
    summary = analysis.to_dict()
    if out is not None:
        step(f"writing {Path(out) / 'modal.json'}")
        json_path = write_json(Path(out) / "modal.json", summary)
        step(f"drawing the figures into {out}")
        written = write_modal_figures(analysis, Path(out), mode_indices=animate)
        summary["files"] = [str(p) for p in [json_path, *written]]
    return analysis, summary


def fly_openloop(plant: Plant, scenario=None, out: Path | None = None, progress=None, *,
                 dataset: bool = True):  # fmt: skip
    """Open-loop run and its metrics; with ``out``, result.nc, figures, metrics.json.

    Parameters
    ----------
    plant : Plant
        The satellite.
    scenario : OpenLoopScenario, optional
        Default: the thesis's 1 N m yaw pulse.
    out : Path, optional
        A run whose records do not fit in memory streams them to ``out/result.nc``.
    progress : bool or None
        Progress bar: None shows it on a terminal only.
    dataset : bool
        Build the result's dataset. False (only without ``out``): the metrics are
        computed from the records as plain arrays, the same numbers, without xarray
        (``flexsat openloop`` without ``--out``, docs/performance.md, 'Start-up').

    Returns
    -------
    result : Result or RunRecords
        The run; its records (:class:`~flexsat.analysis.run_records.RunRecords`) when
        ``dataset`` is False and the run was held in memory.
    metrics : dict
        :func:`flexsat.analysis.openloop.openloop_metrics`, plus ``files``.
    """
    from flexsat.analysis.openloop import openloop_metrics
    from flexsat.analysis.run_records import RunRecords
    from flexsat.simulate.openloop import run_openloop
    from flexsat.simulate.openloop_scenario import OpenLoopScenario

    def figures() -> list[Path]:  # matplotlib is imported only when figures are drawn
        from flexsat.analysis.modal import modal_analysis
        from flexsat.plots.openloop import write_openloop_figures

        return write_openloop_figures(result.dataset, modal_analysis(plant), Path(out))

    from flexsat.simulate.run_setup import check_run_size

    scenario = scenario or OpenLoopScenario()
    record_path = None
    if out is not None:
        prepare_output_dir(out)
        fits = check_run_size(plant.n_dof, scenario, can_stream=True).fits_in_memory
        record_path = None if fits else Path(out) / "result.nc"  # streamed into place
    if not dataset and out is not None:
        raise ValueError("fly_openloop: the files of out need the dataset (dataset=True)")
    result = run_openloop(plant, scenario, progress=progress, record_path=record_path,
                          records=not dataset)  # fmt: skip
    metrics = openloop_metrics(result if isinstance(result, RunRecords) else result.dataset)
    if out is not None:
        _write_run(result, metrics, Path(out), figures)
    return result, metrics


def fly_slew(plant: Plant, scenario=None, out: Path | None = None, progress=None, *,
             figures: bool = True):  # fmt: skip
    """Closed-loop slew and its requirement metrics; with ``out``, its files there.

    Parameters
    ----------
    plant : Plant
        The satellite.
    scenario : SlewScenario, optional
        Default: the thesis's 45/45/45 deg ASMC slew.
    out : Path, optional
        Where the files go (records that do not fit in memory, and those of a run
        along an orbit, stream there as the run goes).
    progress : bool or None
        Progress bar: None shows it on a terminal only.
    figures : bool
        With ``out``, also draw the figure set (result.nc and metrics.json always).

    Returns
    -------
    result : Result
    metrics : dict
        :func:`flexsat.analysis.requirements.slew_metrics` (R1-R3 from the
        scenario's requirements), plus the controller's ``design_inertia_kg_m2``
        (3x3) and ``files``.
    """
    from flexsat.analysis.requirements import slew_metrics
    from flexsat.simulate import SlewScenario, run_slew
    from flexsat.simulate.run_setup import check_run_size

    def draw() -> list[Path]:
        from flexsat.plots.slew import write_slew_figures

        return write_slew_figures(result.dataset, Path(out)) if figures else []

    scenario = scenario or SlewScenario()
    estimate = check_run_size(plant.n_dof, scenario, can_stream=True)
    fits, record_path = estimate.fits_in_memory, None
    if out is not None:
        prepare_output_dir(out)
        # streamed into place: records that do not fit, and a run along an orbit (long
        # by nature: docs/orbit.md, 'Long runs')
        if not fits or scenario.orbit is not None:
            record_path = Path(out) / "result.nc"
    result = run_slew(plant, scenario, progress=progress, record_path=record_path,
                      record_budget_bytes=None if fits else estimate.available_bytes)  # fmt: skip
    metrics = slew_metrics(result.dataset)  # the stored scenario's requirements
    J = result.dataset.attrs["design_inertia"]
    metrics["design_inertia_kg_m2"] = [list(J[3 * i : 3 * i + 3]) for i in range(3)]
    if out is not None:
        _write_run(result, metrics, Path(out), draw)
    return result, metrics


def _write_run(result, metrics: dict, out: Path, figures: Callable[[], list[Path]]) -> None:
    """result.nc (always, a failed run's history too), the figures if it succeeded, and
    metrics.json into ``out``; the written paths are added to ``metrics["files"]``."""
    ensure_dir(out)
    files = [result.to_netcdf(out / "result.nc")]
    metrics["files"] = [str(p) for p in [*files, out / "metrics.json"]]
    write_json(out / "metrics.json", metrics)  # first: a figure that fails loses no number
    if result.ok:
        files += figures()
        metrics["files"] = [str(p) for p in [*files, out / "metrics.json"]]
        write_json(out / "metrics.json", metrics)


def write_slew_outputs(result, metrics: dict, out: Path, figures: bool = True) -> None:
    """A flown slew's files in ``out``, as :func:`fly_slew` writes them: result.nc,
    metrics.json and (a finished run, ``figures``) the slew's figure set; the written
    paths are added to ``metrics["files"]``.

    Parameters
    ----------
    result : Result
        The slew (a served one too: :func:`flexsat.realtime.server.serve`).
    metrics : dict
        Its metrics, written as metrics.json.
    out : Path
        The folder (created; :func:`prepare_output_dir` first to fail early).
    figures : bool
        Draw the figure set.
    """

    def draw() -> list[Path]:
        from flexsat.plots.slew import write_slew_figures

        return write_slew_figures(result.dataset, Path(out)) if figures else []

    _write_run(result, metrics, Path(out), draw)


def fly_campaign(definition, config, store: Path, *, progress: bool = True, **backend) -> dict:
    """Run a campaign into ``store``; write and return its summary with the figures.

    Parameters
    ----------
    definition : CampaignDefinition
        The campaign.
    config : SatelliteConfig
        The base plant the campaign varies.
    store : Path
        Campaign store folder (resumable: see :func:`flexsat.campaigns.run_campaign`).
    progress : bool
        Show a progress bar.
    **backend
        ``workers``, ``scheduler``, ``dask_local``, ``resume``, ``n_random``, ``runner``:
        passed on.

    Returns
    -------
    dict
        :func:`flexsat.campaigns.summarize` (``cases`` stored, ``cpu_time_s`` of
        every stored case, ``campaign_wall_time_s`` of every run into the store...)
        plus this run's ``computed_this_run``, ``resumed_this_run`` (cases found
        stored) and ``run_wall_time_s`` [s]; ``case_counts`` and ``cases_text`` (where
        the cases come from: ``"101 cases: 100 drawn + the nominal"``), ``parquet``,
        ``csv`` and ``figures``; also written to ``store/summary.json``.
    """
    from flexsat.campaigns import run_campaign, summarize
    from flexsat.campaigns.definition import describe_counts
    from flexsat.campaigns.runner import CampaignInterrupted
    from flexsat.plots.campaign import write_campaign_figures
    from flexsat.plots.campaign_statistics import write_statistics_figures

    run = run_campaign(definition, config, store, progress=progress, **backend)
    summary = {
        **summarize(store),
        "computed_this_run": run["ran"],
        "resumed_this_run": run["resumed"],
        "run_wall_time_s": run["wall_time_s"],
        "parquet": str(run["parquet"]),
        "csv": str(run["csv"]),
    }
    if "case_counts" in run:  # where the cases come from (a search has evaluations)
        summary["case_counts"] = run["case_counts"]
        summary["cases_text"] = describe_counts(run["case_counts"])
    try:
        figures = write_campaign_figures(store)
        figures += write_statistics_figures(store)
    except ValueError:  # no successful case history to draw
        figures = []
    except KeyboardInterrupt:  # the cases are stored; their figures can be drawn again
        interrupted = CampaignInterrupted(
            f"campaign {definition.name} interrupted (SIGINT) while drawing its figures: its "
            f"{summary['cases']} cases are stored in {store}; run the same command with "
            "--resume to draw them"
        )
        interrupted.exit_code = 130
        raise interrupted from None
    if "worst_case" in run:  # a worst-case search: what it found
        summary["worst_case"] = {k: run[k] for k in ("case_id", "metric", "value", "parameters")}
    summary["figures"] = [str(path) for path in figures]
    write_json(Path(store) / "summary.json", summary)
    return summary
