"""Pointing error indices (ECSS-E-ST-60-10C) and their statistical interpretations.

The indices are taken on an error signal e(t) sampled at a constant period dt: an
attitude error (the error rotation vector's components about the hub axes, or its
magnitude), a payload line-of-sight error (the angle between a boresight fixed in
the hub and where it should point), or a knowledge error (the estimator's attitude
against the truth). Windows of length Δt hold n = round(Δt / dt) records and slide
one record at a time; every window's mean is one cumulative-sum difference, so no
index loops over windows. ``docs/pointing.md`` states the definitions:

* APE / AKE: ``|e(t)|`` at every record;
* MPE / MKE: ``|ē(w)|``, the mean over each window w;
* RPE / RKE: ``|e(t) - ē(w_t)|``, each record against the mean of the window centred
  on it;
* PDE / KDE: ``|ē(w + Δt_s) - ē(w)|``, two windows Δt_s apart (the stability time)
  within one observation;
* PRE / KRE: the same with the two windows one observation period Δt_o apart.

Each index gives a sample (one value per record or per window position); a
statistical interpretation (temporal, ensemble or mixed) reduces the samples of one
run or of a campaign's runs to one value at a confidence level P, with the
distribution-free confidence interval of that order statistic.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
import xarray as xr
from scipy.spatial.transform import Rotation
from scipy.stats import binom

from flexsat.errors import ConfigError

__all__ = [
    "INDICES",
    "INTERPRETATIONS",
    "KNOWLEDGE_INDICES",
    "PERFORMANCE_INDICES",
    "Statistic",
    "axis_errors",
    "error_rotation",
    "index_samples",
    "interpret",
    "knowledge_error",
    "line_of_sight_error",
    "order_statistic",
    "performance_error",
    "uniform_record",
]

PERFORMANCE_INDICES = ("APE", "MPE", "RPE", "PDE", "PRE")
"""The performance error indices, in the standard's order."""
KNOWLEDGE_INDICES = ("AKE", "MKE", "RKE", "KDE", "KRE")
"""The knowledge error indices, each the performance index of the same rank on the
knowledge error (AKE as APE, RKE as RPE...)."""
INDICES = PERFORMANCE_INDICES + KNOWLEDGE_INDICES
INTERPRETATIONS = ("temporal", "ensemble", "mixed")
"""The statistical interpretations of ECSS-E-ST-60-10C (docs/pointing.md)."""

_KIND = {name: "AMRDP"[k % 5] for k, name in enumerate(INDICES)}
_UNIFORM_RTOL = 1e-6  # records whose spacing varies more than this are resampled [-]


def uniform_record(t: np.ndarray, error: np.ndarray) -> tuple[float, np.ndarray, np.ndarray]:
    """The record on a constant period: its own if already constant, else interpolated.

    Parameters
    ----------
    t : ndarray, shape (n,)
        Record times [s], increasing.
    error : ndarray, shape (n,) or (n, k)
        The error at each record, any unit ``u`` [u].

    Returns
    -------
    dt : float
        The period [s]: the median spacing.
    t : ndarray, shape (m,)
        Times on that period from the first record [s].
    error : ndarray, shape (m,) or (m, k)
        The error there (linear interpolation when the spacing was not constant) [u].
    """
    t = np.asarray(t, dtype=float)
    error = np.asarray(error, dtype=float)
    if t.size < 2:
        raise ConfigError(f"the record holds {t.size} sample(s); an index needs at least 2")
    steps = np.diff(t)
    dt = float(np.median(steps))
    if not dt > 0.0:
        raise ConfigError("the record's times do not increase")
    if np.all(np.abs(steps - dt) <= _UNIFORM_RTOL * dt):
        return dt, t, error
    grid = t[0] + dt * np.arange(int(np.floor((t[-1] - t[0]) / dt + 1e-9)) + 1)
    if error.ndim == 1:
        return dt, grid, np.interp(grid, t, error)
    columns = [np.interp(grid, t, error[:, k]) for k in range(error.shape[1])]
    return dt, grid, np.stack(columns, axis=1)


def _magnitude(values: np.ndarray) -> np.ndarray:
    return np.abs(values) if values.ndim == 1 else np.linalg.norm(values, axis=1)


def _records(seconds: float, dt: float, field: str, available: int, span_s: float) -> int:
    """A duration as a whole number of records, refused when the record is too short."""
    if not (np.isfinite(seconds) and seconds > 0.0):
        raise ConfigError(f"{field}: must be a finite duration > 0 s, got {seconds}")
    count = round(seconds / dt)
    if count < 1:
        raise ConfigError(
            f"{field}: {seconds:g} s is shorter than the record's spacing ({dt:g} s); "
            f"choose at least {dt:g} s"
        )
    if count > available:
        raise ConfigError(
            f"{field}: {seconds:g} s is longer than the record: at most {span_s:g} s "
            f"(records every {dt:g} s)"
        )
    return count


def index_samples(
    t: np.ndarray,
    error: np.ndarray,
    index: str,
    window_s: float | None = None,
    separation_s: float | None = None,
) -> tuple[np.ndarray, np.ndarray]:
    """The samples of one pointing index on one record (docs/pointing.md, 'Indices').

    Parameters
    ----------
    t : ndarray, shape (n,)
        Record times [s], increasing (resampled to a constant period if not).
    error : ndarray, shape (n,) or (n, k)
        The error signal, any unit ``u``: a scalar component (its absolute value is
        the index) or k components (their Euclidean norm is) [u].
    index : str
        One of :data:`INDICES`.
    window_s : float, optional
        Δt, the window length [s]; every index but APE/AKE needs it.
    separation_s : float, optional
        For PDE/KDE the stability time Δt_s, for PRE/KRE the observation period
        Δt_o: the time between the two windows' starts [s].

    Returns
    -------
    times : ndarray, shape (m,)
        Time of each sample [s]: the record's (APE, RPE) or its window's start.
    samples : ndarray, shape (m,)
        The index at each, >= 0 [u].

    Raises
    ------
    ConfigError
        An unknown index, a missing or non-positive duration, or a window (with its
        separation) longer than the record, naming the field.
    """
    if index not in _KIND:
        raise ConfigError(f"index: unknown index {index!r}; choose one of {', '.join(INDICES)}")
    dt, t, error = uniform_record(t, error)
    kind = _KIND[index]
    if kind == "A":
        return t, _magnitude(error)
    span_s = float(t[-1] - t[0]) + dt  # n records stand for n periods
    if window_s is None:
        raise ConfigError(f"{index}.window_s: {index} needs a window length")
    n = _records(window_s, dt, f"{index}.window_s", t.size, span_s)
    # sums of the departures from the record's mean: their round-off scales with the
    # signal's variation, not with its level (a 30 deg offset summed over 1e6 records)
    offset = error.mean(axis=0)
    zero = np.zeros((1, *error.shape[1:]))
    summed = np.cumsum(np.concatenate([zero, error - offset]), axis=0)
    means = (summed[n:] - summed[:-n]) / n + offset  # means[i]: records i .. i + n - 1
    if kind == "M":
        return t[: means.shape[0]], _magnitude(means)
    if kind == "R":
        half = n // 2  # record i + half is the centre of window i
        return t[half : half + means.shape[0]], _magnitude(
            error[half : half + means.shape[0]] - means
        )
    if separation_s is None:
        what = "stability_s" if kind == "D" else "observation_s"
        raise ConfigError(f"{index}.{what}: {index} needs the time between its two windows")
    field = f"{index}.{'stability_s' if kind == 'D' else 'observation_s'}"
    s = _records(separation_s, dt, field, t.size - n, span_s - n * dt)  # after the window
    return t[: means.shape[0] - s], _magnitude(means[s:] - means[:-s])


def error_rotation(ds: xr.Dataset) -> np.ndarray:
    """The attitude error's rotation vector q_d^-1 (x) q at each record, hub frame [rad].

    Parameters
    ----------
    ds : xarray.Dataset
        A slew's dataset (``quaternion``, and ``reference_quaternion`` for a moving
        target, else ``attrs["target_quaternion"]``).

    Returns
    -------
    ndarray, shape (n, 3)
        The rotation vector [rad].
    """
    from flexsat.analysis.requirements import error_rotation_vector

    if "reference_quaternion" in ds.variables:  # a moving target: the reference produced
        return error_rotation_vector(
            ds.variables["quaternion"].values, ds.variables["reference_quaternion"].values
        )
    return error_rotation_vector(
        ds.variables["quaternion"].values, np.asarray(ds.attrs["target_quaternion"], dtype=float)
    )


def performance_error(ds: xr.Dataset) -> np.ndarray:
    """The performance error of a slew: its attitude error's rotation vector.

    Parameters
    ----------
    ds : xarray.Dataset
        A slew's dataset (:func:`error_rotation`).

    Returns
    -------
    ndarray, shape (n, 3)
        θ of q_d^-1 (x) q, hub frame [rad].
    """
    return error_rotation(ds)


def knowledge_error(ds: xr.Dataset) -> np.ndarray | None:
    """The knowledge error: the estimator's ``estimation_error`` record.

    Parameters
    ----------
    ds : xarray.Dataset
        A slew's dataset.

    Returns
    -------
    ndarray, shape (n, 3), or None
        2 vec(q_hat^-1 (x) q_true) in the hub frame, recorded by the MEKF stage
        (``flexsat.control.stages.mekf``) [rad]; None for a run flown without an
        estimator.
    """
    if "estimation_error" not in ds:
        return None
    return np.asarray(ds.variables["estimation_error"].values, dtype=float)


def line_of_sight_error(rotation: np.ndarray, boresight: Sequence[float]) -> np.ndarray:
    """The line-of-sight error of a boresight fixed in the hub [rad], two components.

    The error rotation R(θ) moves the boresight b to b' = R b; the line-of-sight
    error is the rotation that takes b to b', ε = angle(b, b') (b x b') / ``|b x b'|``,
    perpendicular to b. Its components along u and v = b x u (u the hub axis
    least aligned with b, made perpendicular to b) are returned; their norm is the
    angle between b and b', exactly (no small-angle approximation).

    Parameters
    ----------
    rotation : ndarray, shape (n, 3)
        The error rotation vector θ, hub frame [rad].
    boresight : sequence of 3 floats
        b, the boresight in the hub frame (normalised here) [-].

    Returns
    -------
    ndarray, shape (n, 2)
        ε along u and v [rad].
    """
    b = np.asarray(boresight, dtype=float)
    b = b / np.linalg.norm(b)
    moved = Rotation.from_rotvec(np.asarray(rotation, dtype=float)).apply(b)
    cross = np.cross(b, moved)
    sine = np.linalg.norm(cross, axis=1)
    angle = np.arctan2(sine, moved @ b)
    with np.errstate(invalid="ignore", divide="ignore"):
        epsilon = np.where(sine[:, None] > 0.0, cross * (angle / sine)[:, None], 0.0)
    u = np.eye(3)[int(np.argmin(np.abs(b)))]
    u = u - (u @ b) * b
    u /= np.linalg.norm(u)
    v = np.cross(b, u)
    return np.stack([epsilon @ u, epsilon @ v], axis=1)


def axis_errors(rotation: np.ndarray, boresight: Sequence[float] | None = None) -> dict:
    """The error signals an index is taken on, by axis name.

    Parameters
    ----------
    rotation : ndarray, shape (n, 3)
        An error rotation vector, hub frame [rad].
    boresight : sequence of 3 floats, optional
        A payload boresight in the hub frame [-]: adds ``"los"``.

    Returns
    -------
    dict of str to ndarray
        ``"x"``, ``"y"``, ``"z"``: the components, shape (n,) [rad]; ``"total"``: the
        vector (n, 3), whose norm is the rotation angle [rad]; ``"los"``: the
        line-of-sight error (n, 2) [rad] (:func:`line_of_sight_error`).
    """
    rotation = np.asarray(rotation, dtype=float)
    axes = {name: rotation[:, k] for k, name in enumerate("xyz")}
    axes["total"] = rotation
    if boresight is not None:
        axes["los"] = line_of_sight_error(rotation, boresight)
    return axes


@dataclass(frozen=True)
class Statistic:
    """An index reduced to one value at a confidence level.

    Attributes
    ----------
    value : float
        The estimate: an order statistic of the samples [u].
    low, high : float
        Its distribution-free confidence interval [u]; ``high`` is inf when the
        sample is too small to bound the quantile from above.
    samples : int
        How many samples the order statistic was taken among.
    where : float
        The time of the worst sample for the ensemble interpretation [s], the
        number of the worst run (from 0) for the temporal one [-]; NaN otherwise.
    """

    value: float
    low: float
    high: float
    samples: int
    where: float = float("nan")

    def as_dict(self) -> dict:
        """The fields as plain floats and ints."""
        return {"value": self.value, "ci_low": self.low, "ci_high": self.high,
                "samples": self.samples, "where": self.where}  # fmt: skip


def order_statistic(samples: np.ndarray, confidence: float, interval: float = 0.95) -> Statistic:
    """The P-quantile of a sample and its distribution-free confidence interval.

    The estimate is the order statistic x_(r), r = ceil(P n) (numpy's
    ``inverted_cdf``). The interval [x_(l), x_(u)] takes l and u from the
    binomial distribution B(n, P) of the number of samples below the true quantile
    (l = its (1 - γ)/2 quantile, u = its (1 + γ)/2 quantile + 1): it holds the true
    quantile with probability >= γ for independent samples of any continuous
    distribution. x_(u) beyond the sample (u > n) is +inf: the sample cannot bound
    the quantile from above.

    Parameters
    ----------
    samples : ndarray, shape (n,)
        The samples, any unit ``u`` [u]; NaN samples are left out.
    confidence : float
        P in (0, 1] [-].
    interval : float
        γ, the confidence of the interval, in (0, 1) [-].

    Returns
    -------
    Statistic
        Estimate, interval and sample count (NaN everywhere for an empty sample).
    """
    x = np.sort(np.asarray(samples, dtype=float).ravel())
    x = x[~np.isnan(x)]
    n = x.size
    if n == 0:
        return Statistic(float("nan"), float("nan"), float("nan"), 0)
    rank = min(n, max(1, int(np.ceil(confidence * n - 1e-9))))
    if confidence >= 1.0:
        return Statistic(float(x[-1]), float(x[-1]), float(x[-1]), n)
    low_rank = int(binom.ppf(0.5 * (1.0 - interval), n, confidence))
    high_rank = int(binom.ppf(0.5 * (1.0 + interval), n, confidence)) + 1
    low = float(x[low_rank - 1]) if low_rank >= 1 else float("-inf")
    high = float(x[high_rank - 1]) if high_rank <= n else float("inf")
    return Statistic(float(x[rank - 1]), low, high, n)


def interpret(
    runs: Sequence[tuple[np.ndarray, np.ndarray]],
    interpretation: str,
    confidence: float,
    interval: float = 0.95,
) -> Statistic:
    """One index's samples over one or several runs, reduced at a confidence level.

    * ``temporal``: for each run, the P-quantile over its samples (the index is met
      a fraction P of the time); the worst run's;
    * ``ensemble``: at each sample time, the P-quantile across the runs (a fraction
      P of the ensemble meets it); the worst time's. The runs' samples are
      interpolated onto the first run's times inside the span they all cover;
    * ``mixed``: the P-quantile of every run's samples pooled (a fraction P of the
      ensemble's time).

    Parameters
    ----------
    runs : sequence of (times, samples)
        Each run's :func:`index_samples` output [s], [u].
    interpretation : str
        One of :data:`INTERPRETATIONS`.
    confidence : float
        P, in (0, 1] (1: the worst case) [-].
    interval : float
        γ of the confidence interval (:func:`order_statistic`) [-].

    Returns
    -------
    Statistic
        The value and its interval; ``where`` is the worst run (temporal) or the
        worst time [s] (ensemble).

    Raises
    ------
    ConfigError
        An unknown interpretation, a confidence outside (0, 1], or an ensemble of
        fewer than two runs or without a common span.
    """
    if interpretation not in INTERPRETATIONS:
        raise ConfigError(
            f"interpretation: {interpretation!r} is not one of {', '.join(INTERPRETATIONS)}"
        )
    if not 0.0 < confidence <= 1.0:
        raise ConfigError(f"confidence: must be in (0, 1], got {confidence}")
    if interpretation == "mixed":
        return order_statistic(np.concatenate([s for _, s in runs]), confidence, interval)
    if interpretation == "temporal":
        stats = [order_statistic(s, confidence, interval) for _, s in runs]
        worst = int(np.nanargmax([s.value for s in stats]))
        s = stats[worst]
        return Statistic(s.value, s.low, s.high, s.samples, float(worst))
    if len(runs) < 2:
        raise ConfigError("interpretation: 'ensemble' needs a campaign (two runs or more)")
    times = runs[0][0]
    start = max(float(t[0]) for t, _ in runs)
    end = min(float(t[-1]) for t, _ in runs)
    times = times[(times >= start - 1e-9) & (times <= end + 1e-9)]
    if times.size == 0:
        raise ConfigError("interpretation: 'ensemble': the runs share no time span")
    table = np.stack([np.interp(times, t, s) for t, s in runs])  # (runs, times)
    ordered = np.sort(table, axis=0)
    n = table.shape[0]
    rank = min(n, max(1, int(np.ceil(confidence * n - 1e-9))))
    worst = int(np.argmax(ordered[rank - 1]))
    s = order_statistic(table[:, worst], confidence, interval)
    return Statistic(s.value, s.low, s.high, s.samples, float(times[worst]))
