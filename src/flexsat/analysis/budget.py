"""Pointing budget (ESSB-HB-E-003): contributors summed per index and axis, and verdicts.

A budget lists the error contributors as the standard classifies them, each with
its distribution: a bias (constant over an observation, drawn once: Gaussian,
uniform or fixed), a random error (varying in time faster than the window:
Gaussian or uniform) or a periodic one (a sinusoid of given amplitude and period).
Each contributes to each index (APE, MPE, RPE, PDE, PRE; the knowledge indices for
knowledge contributors) a mean μ and a standard deviation σ per axis
(:func:`contribution`); the handbook's two summation rules give the index:

* statistical: ``|Σ μ_i|`` + n_P sqrt(Σ σ_i²), n_P = Φ⁻¹((1 + P)/2);
* worst case: Σ e_i(P), each contributor's own P-level value of ``|e_i|``.

A requirement file's ``[pointing]`` table gives each index's bound, window and
confidence; :func:`evaluate` sets the budget and the indices measured on a run or a
campaign (:mod:`flexsat.analysis.pointing`) against them. ``docs/pointing.md``
states the rules and works an example.
"""

from __future__ import annotations

import csv
import io
import math
from pathlib import Path
from typing import Annotated, Literal

import numpy as np
from pydantic import Field, model_validator
from scipy.stats import norm

from flexsat.analysis.pointing import (
    INDICES,
    KNOWLEDGE_INDICES,
    axis_errors,
    index_samples,
    interpret,
    knowledge_error,
    performance_error,
)
from flexsat.config.models import Positive, Real, _Frozen
from flexsat.errors import ConfigError

__all__ = [
    "AXES",
    "Contributor",
    "IndexRequirement",
    "PointingRequirements",
    "budget_rows",
    "contribution",
    "evaluate",
    "gaussian_factor",
    "load_requirements",
    "load_runs",
    "measure",
    "summed",
    "to_csv",
]

AXES = ("x", "y", "z", "total", "los")
"""Axes a row is given for: the hub axes, the total angle and a payload's line of sight."""

_BUDGET_AXES = ("x", "y", "z")  # contributors are given per hub axis
Confidence = Annotated[float, Field(gt=0.0, lt=1.0, allow_inf_nan=False, strict=True)]
Duration = Annotated[float, Field(gt=0.0, le=1e7, allow_inf_nan=False, strict=True)]
Triple = tuple[Real, Real, Real]
NonNegativeTriple = tuple[
    Annotated[float, Field(ge=0.0, allow_inf_nan=False, strict=True)],
    Annotated[float, Field(ge=0.0, allow_inf_nan=False, strict=True)],
    Annotated[float, Field(ge=0.0, allow_inf_nan=False, strict=True)],
]

_DISTRIBUTIONS = {
    "bias": ("gaussian", "uniform", "fixed"),
    "random": ("gaussian", "uniform"),
    "periodic": ("sinusoidal",),
}


class Contributor(_Frozen):
    """One error source of the budget, per hub axis, in degrees (docs/pointing.md)."""

    name: str = Field(min_length=1, max_length=64, description="what it is, for the tables")
    kind: Literal["bias", "random", "periodic"] = Field(
        description="the standard's class: bias, random or periodic"
    )
    distribution: str | None = Field(
        None,
        description="gaussian, uniform or fixed (bias); gaussian or uniform (random); "
        "sinusoidal (periodic); default the first",
    )
    knowledge: bool = Field(False, description="an estimation error: feeds AKE ... KRE")
    mean_deg: Triple = Field((0.0, 0.0, 0.0), description="mean μ per hub axis [deg]")
    sigma_deg: NonNegativeTriple = Field(
        (0.0, 0.0, 0.0), description="standard deviation σ per hub axis (gaussian) [deg]"
    )
    bound_deg: NonNegativeTriple = Field(
        (0.0, 0.0, 0.0), description="half-range B per hub axis (uniform: ±B) [deg]"
    )
    amplitude_deg: NonNegativeTriple = Field(
        (0.0, 0.0, 0.0), description="amplitude A per hub axis (periodic) [deg]"
    )
    period_s: Duration | None = Field(None, description="period T (periodic) [s]")

    @model_validator(mode="after")
    def _consistent(self) -> Contributor:
        allowed = _DISTRIBUTIONS[self.kind]
        distribution = self.distribution or allowed[0]
        if distribution not in allowed:
            raise ValueError(
                f"distribution: a {self.kind} contributor is {' or '.join(allowed)}, "
                f"got {distribution!r}"
            )
        object.__setattr__(self, "distribution", distribution)
        if self.kind == "periodic" and self.period_s is None:
            raise ValueError("period_s: a periodic contributor needs its period [s]")
        return self


class IndexRequirement(_Frozen):
    """One index's bound, window and confidence."""

    bound_deg: Positive = Field(description="the bound the index must stay within [deg]")
    window_s: Duration | None = Field(None, description="Δt, the window length [s]")
    stability_s: Duration | None = Field(
        None, description="PDE/KDE: Δt_s, the time between the two windows [s]"
    )
    observation_s: Duration | None = Field(
        None, description="PRE/KRE: Δt_o, the time between two observations' windows [s]"
    )
    confidence: Confidence | None = Field(
        None, description="P of this index, in (0, 1); default the table's [-]"
    )
    axes: tuple[Literal["x", "y", "z", "total", "los"], ...] | None = Field(
        None, description="axes measured; default every one the data hold"
    )


class PointingRequirements(_Frozen):
    """The ``[pointing]`` table of a requirement file (docs/pointing.md)."""

    confidence: Confidence = Field(0.9973, description="P, the confidence level [-]")
    interval: Confidence = Field(
        0.95, description="γ, the confidence of the estimate's interval [-]"
    )
    interpretation: Literal["temporal", "ensemble", "mixed"] = Field(
        "temporal", description="the statistical interpretation"
    )
    summation: Literal["statistical", "worst_case"] = Field(
        "statistical", description="the budget total the verdict uses"
    )
    boresight: Triple | None = Field(
        None, description="a payload boresight, hub frame: adds the line of sight [-]"
    )
    start_s: Annotated[float, Field(ge=0.0, le=1e7, allow_inf_nan=False, strict=True)] = Field(
        0.0, description="records before it (the slew itself) are left out [s]"
    )
    indices: dict[str, IndexRequirement] = Field(
        default_factory=dict, description="each index's requirement, by name (APE ...)"
    )
    contributors: tuple[Contributor, ...] = Field((), description="the budget's error sources")

    @model_validator(mode="after")
    def _known(self) -> PointingRequirements:
        for name, req in self.indices.items():
            if name not in INDICES:
                raise ValueError(
                    f"indices.{name}: unknown index; choose one of {', '.join(INDICES)}"
                )
            kind = INDICES.index(name) % 5
            if kind > 0 and req.window_s is None:
                raise ValueError(f"indices.{name}.window_s: {name} needs a window length [s]")
            if kind == 3 and req.stability_s is None:
                raise ValueError(f"indices.{name}.stability_s: {name} needs Δt_s [s]")
            if kind == 4 and req.observation_s is None:
                raise ValueError(f"indices.{name}.observation_s: {name} needs Δt_o [s]")
        if self.boresight is not None and not np.linalg.norm(self.boresight) > 0.0:
            raise ValueError("boresight: must be a non-zero vector in the hub frame")
        return self


def load_requirements(path: str | Path) -> PointingRequirements:
    """Read the ``[pointing]`` table of a TOML requirement file.

    Parameters
    ----------
    path : str or Path
        The TOML file.

    Returns
    -------
    PointingRequirements
        The validated table.

    Raises
    ------
    ConfigError
        A missing or malformed file, no ``[pointing]`` table, or a field out of its
        range, named as ``pointing.<field>``.
    """
    from flexsat.config.load import read_toml, validate_config

    data = read_toml(path, "requirements")
    if not isinstance(data.get("pointing"), dict):
        raise ConfigError(f"{path}: pointing: no [pointing] table")
    return validate_config({"pointing": data["pointing"]}, str(path), _RequirementFile).pointing


class _RequirementFile(_Frozen):
    """A requirement file: its ``[pointing]`` table (other tables are not read)."""

    pointing: PointingRequirements


def load_runs(path: str | Path) -> tuple[str, list]:
    """The runs a budget is measured on: a slew's result file or a campaign store.

    Parameters
    ----------
    path : str or Path
        A result written by ``flexsat slew --out`` (``result.nc``), or the folder of
        a campaign store (``flexsat campaign --out``), whose decimated case
        histories ``histories/<case id>.nc`` are read, by case id.

    Returns
    -------
    kind : str
        ``"result"`` or ``"campaign"``.
    datasets : list of xarray.Dataset
        The run, or one dataset per stored case (by case id).

    Raises
    ------
    ConfigError
        A missing path, a file that is not a slew's result, or a folder that is not
        a campaign store with histories.
    """
    import xarray as xr

    from flexsat.files import check_user_file

    path = Path(path)
    if not path.exists():
        raise ConfigError(f"RESULT_OR_CAMPAIGN {path}: no such file or folder")
    if path.is_dir():
        if not (path / "campaign.json").exists():
            raise ConfigError(f"RESULT_OR_CAMPAIGN {path}: not a campaign store (no campaign.json)")
        histories = []
        for history in sorted((path / "histories").glob("*.nc")):  # the store's layout
            try:
                with xr.open_dataset(history) as ds:
                    histories.append(ds.load())
            except (OSError, ValueError) as exc:
                raise ConfigError(f"RESULT_OR_CAMPAIGN {history}: unreadable ({exc})") from None
        if not histories:
            raise ConfigError(f"RESULT_OR_CAMPAIGN {path}: the campaign stores no case history")
        return "campaign", histories
    check_user_file(path, "RESULT_OR_CAMPAIGN", limited=False)
    try:
        with xr.open_dataset(path) as ds:
            dataset = ds.load()
    except (OSError, ValueError) as exc:
        raise ConfigError(f"RESULT_OR_CAMPAIGN {path}: not a NetCDF result ({exc})") from None
    if "quaternion" not in dataset or "target_quaternion" not in dataset.attrs:
        raise ConfigError(f"RESULT_OR_CAMPAIGN {path}: not a flexsat slew result")
    return "result", [dataset]


def gaussian_factor(confidence: float) -> float:
    """n_P = Φ⁻¹((1 + P)/2): P of a zero-mean Gaussian lies within ±n_P σ.

    Parameters
    ----------
    confidence : float
        P, in (0, 1) [-].

    Returns
    -------
    float
        n_P [-].
    """
    return float(norm.ppf(0.5 * (1.0 + confidence)))


def _kind(index: str) -> str:
    return "AMRDP"[INDICES.index(index) % 5]


def contribution(contributor: Contributor, index: str, req: IndexRequirement) -> dict:
    """What one contributor adds to one index, per hub axis.

    Bias: all of it to the absolute and mean indices, nothing to the relative,
    drift and reproducibility ones (constant over an observation). Random: all to
    the absolute one, its spread to the relative one, its mean to the mean one (its
    spread averages out of a window, its correlation time taken much shorter than
    Δt). Periodic, amplitude A and period T: a sinusoid of amplitude A for APE,
    A ``|sinc(Δt/T)|`` for MPE (its window mean), A ``|1 - sinc(Δt/T)|`` for RPE (a record
    against the mean of the window centred on it), and
    2 A ``|sinc(Δt/T) sin(π Δ/T)|`` for PDE and PRE (Δ = Δt_s or Δt_o), with
    sinc(x) = sin(πx)/(πx): exact for the indices of :mod:`flexsat.analysis.pointing`.

    Parameters
    ----------
    contributor : Contributor
        The source.
    index : str
        One of :data:`flexsat.analysis.pointing.INDICES`.
    req : IndexRequirement
        Its window and separations.

    Returns
    -------
    dict
        ``distribution`` and, each shape (3,) [deg]: ``mean``, ``sigma`` and
        ``scale`` (the uniform's half-range or the sinusoid's amplitude).
    """
    zero = np.zeros(3)
    knowledge = index in KNOWLEDGE_INDICES
    kind = _kind(index)
    mean, sigma = np.asarray(contributor.mean_deg), np.asarray(contributor.sigma_deg)
    scale = np.asarray(contributor.bound_deg)
    dist = contributor.distribution
    if contributor.knowledge != knowledge:
        factor = 0.0
    elif contributor.kind == "bias":
        factor = 1.0 if kind in "AM" else 0.0
    elif contributor.kind == "random":  # its mean is a constant: in APE and MPE only
        factor = 1.0 if kind in "AMR" else 0.0
        mean = mean if kind in "AM" else zero
        if kind == "M":  # the spread averages out of the window mean
            sigma, scale = zero, zero
    else:
        period = float(contributor.period_s)
        scale = np.asarray(contributor.amplitude_deg)
        mean = zero
        s = np.sinc(req.window_s / period) if kind != "A" else 1.0
        separation = req.stability_s if kind == "D" else req.observation_s
        factor = {"A": 1.0, "M": abs(s), "R": abs(1.0 - s),
                  "D": 0.0, "P": 0.0}[kind]  # fmt: skip
        if kind in "DP":
            factor = abs(2.0 * s * math.sin(math.pi * separation / period))
    if dist == "fixed":
        sigma = zero
    if dist == "uniform":
        sigma = zero
    return {"distribution": dist, "mean": factor * mean, "sigma": factor * sigma,
            "scale": factor * scale}  # fmt: skip


def _moments(part: dict) -> tuple[np.ndarray, np.ndarray]:
    """Mean and standard deviation of a contribution, per axis [deg]."""
    if part["distribution"] == "uniform":
        return part["mean"], part["scale"] / math.sqrt(3.0)
    if part["distribution"] == "sinusoidal":
        return part["mean"], part["scale"] / math.sqrt(2.0)
    return part["mean"], part["sigma"]


def _own_value(part: dict, confidence: float) -> np.ndarray:
    """The P-level value of ``|e_i|`` for one contribution, per axis [deg]."""
    mean = np.abs(part["mean"])
    if part["distribution"] == "uniform":
        return mean + confidence * part["scale"]  # |U(-B, B)|'s P-quantile is P B
    if part["distribution"] == "sinusoidal":  # |A sin|'s P-quantile is A sin(π P / 2)
        return part["scale"] * math.sin(0.5 * math.pi * confidence)
    return mean + gaussian_factor(confidence) * part["sigma"]


def summed(parts: list[dict], confidence: float) -> dict:
    """The handbook's two summations of an index's contributions, per axis.

    Parameters
    ----------
    parts : list of dict
        :func:`contribution` outputs.
    confidence : float
        P in (0, 1) [-].

    Returns
    -------
    dict
        Each shape (3,) [deg]: ``mean`` Σ μ_i, ``sigma`` sqrt(Σ σ_i²),
        ``statistical`` ``|Σ μ_i|`` + n_P sqrt(Σ σ_i²) and ``worst_case`` Σ e_i(P).
    """
    mean, variance, worst = np.zeros(3), np.zeros(3), np.zeros(3)
    for part in parts:
        mu, sigma = _moments(part)
        mean, variance = mean + mu, variance + sigma**2
        worst = worst + _own_value(part, confidence)
    sigma = np.sqrt(variance)
    return {"mean": mean, "sigma": sigma,
            "statistical": np.abs(mean) + gaussian_factor(confidence) * sigma,
            "worst_case": worst}  # fmt: skip


def budget_rows(requirements: PointingRequirements) -> list[dict]:
    """The budget of every required index on each hub axis (no contributors: none).

    Parameters
    ----------
    requirements : PointingRequirements
        The indices and the contributors.

    Returns
    -------
    list of dict
        One per (index, axis): ``index``, ``axis``, ``confidence``, ``mean_deg``,
        ``sigma_deg``, ``statistical_deg`` and ``worst_case_deg`` [deg].
    """
    if not requirements.contributors:
        return []
    rows = []
    for index, req in requirements.indices.items():
        confidence = req.confidence or requirements.confidence
        parts = [contribution(c, index, req) for c in requirements.contributors]
        total = summed(parts, confidence)
        for k, axis in enumerate(_BUDGET_AXES):
            rows.append({"index": index, "axis": axis, "confidence": confidence,
                         "mean_deg": float(total["mean"][k]),
                         "sigma_deg": float(total["sigma"][k]),
                         "statistical_deg": float(total["statistical"][k]),
                         "worst_case_deg": float(total["worst_case"][k])})  # fmt: skip
    return rows


def _run_errors(ds, boresight) -> dict:
    """The error signals of one dataset by (index family, axis) [deg]."""
    signals = {}
    if "quaternion" in ds and "target_quaternion" in ds.attrs:  # a slew's result
        for axis, values in axis_errors(performance_error(ds), boresight).items():
            signals["performance", axis] = np.degrees(values)
        known = knowledge_error(ds)
        if known is not None:
            for axis, values in axis_errors(known, boresight).items():
                signals["knowledge", axis] = np.degrees(values)
    elif "pointing_error_deg" in ds:  # a campaign case's decimated history
        signals["performance", "total"] = np.asarray(ds["pointing_error_deg"].values, float)
    return signals


def measure(datasets: list, requirements: PointingRequirements) -> list[dict]:
    """Every required index measured on one run or a campaign's runs, per axis.

    Parameters
    ----------
    datasets : list of xarray.Dataset
        One slew result, or a campaign's stored case histories (their pointing
        error magnitude only: the ``total`` axis).
    requirements : PointingRequirements
        Indices, windows, confidence and interpretation.

    Returns
    -------
    list of dict
        One per (index, axis) the data hold: ``index``, ``axis``, ``value_deg``,
        ``ci_low_deg``, ``ci_high_deg``, ``samples`` and ``where``
        (:class:`flexsat.analysis.pointing.Statistic`).
    """
    runs = []
    for ds in datasets:
        t = np.asarray(ds["time"].values, dtype=float)
        keep = t >= requirements.start_s - 1e-9
        if np.count_nonzero(keep) < 2:
            raise ConfigError(
                f"pointing.start_s: {requirements.start_s:g} s leaves no record to judge "
                f"(the run ends at {t[-1]:g} s)"
            )
        finite_signals = {}
        for key, values in _run_errors(ds, requirements.boresight).items():
            values = values[keep]
            finite = np.all(np.isfinite(values.reshape(values.shape[0], -1)), axis=1)
            finite_signals[key] = (t[keep][finite], values[finite])
        runs.append(finite_signals)
    rows = []
    for index, req in requirements.indices.items():
        family = "knowledge" if index in KNOWLEDGE_INDICES else "performance"
        confidence = req.confidence or requirements.confidence
        separation = req.stability_s if _kind(index) == "D" else req.observation_s
        for axis in req.axes or AXES:
            if not all((family, axis) in run for run in runs):
                continue
            try:
                samples = [index_samples(*run[family, axis], index, req.window_s, separation)
                           for run in runs]  # fmt: skip
            except ConfigError as exc:
                raise ConfigError(f"pointing.indices.{exc}") from None
            try:
                stat = interpret(samples, requirements.interpretation, confidence,
                                 requirements.interval)  # fmt: skip
            except ConfigError as exc:
                raise ConfigError(f"pointing.{exc}") from None
            rows.append({"index": index, "axis": axis, "confidence": confidence,
                         "value_deg": stat.value, "ci_low_deg": stat.low,
                         "ci_high_deg": stat.high, "samples": stat.samples,
                         "where": stat.where})  # fmt: skip
    return rows


def evaluate(datasets: list, requirements: PointingRequirements) -> dict:
    """The budget, the measured indices and their verdicts against the requirements.

    A measured index passes when its estimate is within its bound (``pass``) and,
    more strictly, when the upper end of its confidence interval is
    (``pass_at_ci``); a budget row passes when its total by the chosen summation is.

    Parameters
    ----------
    datasets : list of xarray.Dataset
        See :func:`measure`.
    requirements : PointingRequirements
        The ``[pointing]`` table.

    Returns
    -------
    dict
        ``interpretation``, ``summation``, ``runs``, ``measured`` and ``budget``
        (lists of rows with ``bound_deg`` and their verdicts) and ``pass`` (all).
    """
    if not datasets:
        raise ConfigError("no run to measure: the campaign stores no case history")
    measured = measure(datasets, requirements)
    for row in measured:
        bound = requirements.indices[row["index"]].bound_deg
        row["bound_deg"] = bound
        row["pass"] = bool(row["value_deg"] <= bound)
        row["pass_at_ci"] = bool(row["ci_high_deg"] <= bound)
    budget = budget_rows(requirements)
    key = f"{requirements.summation}_deg"
    for row in budget:
        bound = requirements.indices[row["index"]].bound_deg
        row["bound_deg"] = bound
        row["pass"] = bool(row[key] <= bound)
    verdicts = [row["pass"] for row in measured + budget]
    return {"interpretation": requirements.interpretation,
            "summation": requirements.summation, "interval": requirements.interval,
            "runs": len(datasets), "start_s": requirements.start_s, "measured": measured,
            "budget": budget, "pass": bool(verdicts) and all(verdicts)}  # fmt: skip


def to_csv(rows: list[dict]) -> str:
    """Rows of :func:`evaluate` as CSV text (one header, the union of their keys).

    Parameters
    ----------
    rows : list of dict
        The rows.

    Returns
    -------
    str
        The CSV text.
    """
    keys = list(dict.fromkeys(k for row in rows for k in row))
    buffer = io.StringIO()
    writer = csv.DictWriter(buffer, fieldnames=keys, lineterminator="\n")
    writer.writeheader()
    writer.writerows(rows)
    return buffer.getvalue()
