"""Pieces shared by the open-loop and closed-loop drivers."""

from __future__ import annotations

import json
import math

from rich.progress import BarColumn, Progress, TextColumn, TimeRemainingColumn

from flexsat import __version__
from flexsat.dynamics.status import status_message

__all__ = ["PROGRESS_MIN_STEPS", "chunk_steps", "progress_bar", "run_attributes"]

PROGRESS_MIN_STEPS = 200_000  # runs shorter than this (~1 s of wall time) show no bar
_CHUNK_STEPS = 10_000  # compiled steps between progress updates


def chunk_steps(*multiples: int) -> int:
    """Steps per compiled call: about 10 000, a multiple of every given period."""
    period = math.lcm(*multiples)
    return max(period, (_CHUNK_STEPS // period) * period)


def run_attributes(plant, scenario, kind: str, status: int, t_fail: float, wall: float,
                   steps: int) -> dict:  # fmt: skip
    """Dataset attributes of a run: configs as JSON, version, status and timing."""
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
    """Context manager yielding (progress, task) or (None, None) when hidden."""

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


