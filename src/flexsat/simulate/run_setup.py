"""What every run sets up: its size check, compiled chunks, progress bar, dataset attributes."""

from __future__ import annotations

import json
import math
import os
import warnings
from dataclasses import dataclass

from rich.progress import BarColumn, Progress, TextColumn, TimeRemainingColumn

from flexsat import __version__
from flexsat.compiled.status import status_message
from flexsat.errors import ConfigError

__all__ = [
    "PROGRESS_MIN_STEPS",
    "LongRunWarning",
    "RunEstimate",
    "check_run_size",
    "chunk_steps",
    "progress_bar",
    "run_attributes",
]

PROGRESS_MIN_STEPS = 200_000  # runs shorter than this (~1 s of wall time) show no bar
_CHUNK_STEPS = 10_000  # compiled steps between progress updates


def chunk_steps(*multiples: int) -> int:
    """Steps per compiled call: about 10 000, a multiple of every given period.

    Parameters
    ----------
    *multiples : int
        Periods in steps (control, record).

    Returns
    -------
    int
        Their least common multiple times the largest factor keeping it near 10 000.
    """
    period = math.lcm(*multiples)
    return max(period, (_CHUNK_STEPS // period) * period)


def run_attributes(plant, scenario, kind: str, status: int, t_fail: float, wall: float,
                   steps: int) -> dict:  # fmt: skip
    """Dataset attributes of a run: configs as JSON, version, status and timing.

    Parameters
    ----------
    plant : Plant
        The plant flown.
    scenario : OpenLoopScenario or SlewScenario
        The scenario flown.
    kind : str
        "open-loop" or "slew", for the title.
    status : int
        The run's status (0: completed).
    t_fail : float
        Time of the failure [s] (read only if ``status`` is non-zero).
    wall : float
        Wall time of the run [s].
    steps : int
        Steps taken.

    Returns
    -------
    dict
        The attributes (str, float and int values).
    """
    message = ""
    if status:
        message = f"simulation stopped at t = {t_fail:.6g} s: {status_message(status)}"
    return {
        "title": f"flexsat {kind} run '{scenario.name}' of '{plant.config.name}'",
        "flexsat_version": __version__,
        "config": json.dumps(plant.config.model_dump(mode="json")),
        "scenario": json.dumps(scenario.model_dump(mode="json", by_alias=True)),
        "status": "ok" if status == 0 else "failed",
        "message": message,
        "failure_time_s": t_fail if status else -1.0,
        "wall_time_s": wall,
        "steps": steps,
    }


class progress_bar:
    """Context manager yielding (progress, task) or (None, None) when hidden.

    Parameters
    ----------
    show : bool
        Show a rich progress bar.
    total_s : float
        The simulated time the bar counts to [s].
    """

    def __init__(self, show: bool, total_s: float) -> None:
        self.show, self.total = show, total_s
        self.progress = None

    def __enter__(self):
        if not self.show:
            return None, None
        self.progress = Progress(
            TextColumn("simulating"), BarColumn(),
            TextColumn("{task.completed:.1f}/{task.total:.0f} s"), TimeRemainingColumn(),
            transient=True,
        )  # fmt: skip
        self.progress.start()
        return self.progress, self.progress.add_task("run", total=self.total)

    def __exit__(self, *exc) -> None:
        if self.progress is not None:
            self.progress.stop()


# Measured on the nominal satellite (18 DOF): about 830 B per record of an open-loop
# dataset and 1130 B of a slew's (its joint forces included), i.e. 8 B x (6 per DOF
# + 40) at most; the records, the dataset built from them and the NetCDF writer hold
# up to three copies.
_BYTES_PER_RECORD_PER_DOF = 48.0
_BYTES_PER_RECORD = 320.0
_COPIES = 3.0
# a conservative RK4 cost per step and DOF, for the announced estimate only (bench_scaling.py)
_SECONDS_PER_STEP_PER_DOF = 0.25e-6
LONG_RUN_S = 600.0
"""Runs estimated to take longer than this [s] are announced with their estimate."""


class LongRunWarning(UserWarning):
    """A run is expected to take long; the message gives the estimate."""


@dataclass(frozen=True)
class RunEstimate:
    """What a run will cost: steps, records, peak memory [bytes] and wall time [s].

    Attributes
    ----------
    steps : int
        RK4 steps.
    records : int
        Recorded rows.
    memory_bytes : float
        Peak memory of the records, the dataset and its writer [bytes].
    wall_time_s : float
        Estimated wall time [s].
    fits_in_memory : bool
        False for a run whose records must be streamed to disk.
    record_bytes : float
        Size of one record [bytes].
    available_bytes : float
        Memory the records may use [bytes].
    """

    steps: int
    records: int
    memory_bytes: float
    wall_time_s: float
    fits_in_memory: bool = True
    record_bytes: float = 0.0
    available_bytes: float = 0.0


def check_run_size(n_dof: int, scenario, available_bytes: float | None = None, *,
                   can_stream: bool = False) -> RunEstimate:  # fmt: skip
    """Estimate a run's cost before it starts; refuse what cannot fit in memory.

    Parameters
    ----------
    n_dof : int
        Generalized coordinates of the plant.
    scenario : OpenLoopScenario or SlewScenario
        The run's scenario (duration, step, record interval).
    available_bytes : float, optional
        Memory the records may use [bytes]; default: half the machine's physical
        memory.
    can_stream : bool
        The caller streams records that do not fit to disk
        (:mod:`flexsat.simulate.stream`): such a run is not refused, its estimate
        says ``fits_in_memory = False``.

    Raises
    ------
    ConfigError
        If the records would not fit and cannot be streamed, or even streamed one
        variable of them would not fit (what metrics and figures read at a time);
        the message gives the estimate and the fix.

    Warns
    -----
    LongRunWarning
        If the run is expected to take more than :data:`LONG_RUN_S`.
    """
    steps = scenario.n_steps
    records = steps // scenario.record_every + 1
    per_record = _BYTES_PER_RECORD + _BYTES_PER_RECORD_PER_DOF * n_dof
    limit = available_bytes if available_bytes is not None else 0.5 * _physical_memory()
    memory = _COPIES * per_record * records
    estimate = RunEstimate(
        steps, records, memory, _SECONDS_PER_STEP_PER_DOF * n_dof * steps, memory <= limit,
        per_record, limit,
    )  # fmt: skip
    # Streamed, the records' metrics and figures still read one variable (q, the
    # widest) at a time: that column has to fit in the machine's memory.
    column = _COPIES * 8.0 * n_dof * records
    if not estimate.fits_in_memory and (not can_stream or column > 0.5 * _physical_memory()):
        raise ConfigError(
            f"record_dt_s: the run would keep {records:.3g} records, about "
            f"{estimate.memory_bytes / 2**30:.3g} GiB in memory (at most {limit / 2**30:.3g} "
            "GiB here); record less often (a larger record_dt_s) or shorten duration_s"
        )
    if estimate.wall_time_s > LONG_RUN_S:
        kept = "keeps" if estimate.fits_in_memory else "streams to disk"
        warnings.warn(
            f"this run takes {steps:.3g} steps, about {estimate.wall_time_s / 60:.0f} min, "
            f"and {kept} about {per_record * records / 2**30:.2g} GiB of records",
            LongRunWarning,
            stacklevel=2,
        )
    return estimate


def _physical_memory() -> float:
    try:
        return float(os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES"))
    except (ValueError, OSError, AttributeError):  # not reported: assume 8 GiB
        return 8.0 * 2**30
