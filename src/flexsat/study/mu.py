"""Robust stability of a satellite's loop: what ``flexsat robust analyze`` computes and writes.

The satellite's uncertain model (:mod:`flexsat.linear.uncertain`, the thesis's
parameters) closed by the scenario's law linearized about rest (or a user's
state-space controller), analysed by :func:`flexsat.linear.mu.analyze`; see
docs/linear.md, 'Robust stability: mu'. :func:`robust_study` is the study's
robustness part (the analysis, a seeded sampling check, the worst cases flown;
docs/linear.md, 'In the study report'); :func:`case_factors` maps a campaign case
onto the uncertain model's factors (docs/linear.md, 'The 24 critical cases').
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from flexsat.config.models import SatelliteConfig
from flexsat.errors import ConfigError
from flexsat.linear.blas_threads import one_blas_thread
from flexsat.study.outputs import prepare_output_dir, write_json

__all__ = [
    "BOUNDS",
    "POINTS_RANGE",
    "case_factors",
    "decay_rate",
    "hold_scenario",
    "load_controller",
    "perturbed_config",
    "robust_analysis",
    "robust_study",
]

BOUNDS = ("diagonal", "lmi")
"""The mu upper bounds ``--bound`` selects (docs/linear.md, 'Robust stability: mu')."""
POINTS_RANGE = (8, 2000)
"""Allowed number of log-spaced frequencies of the grid (the modal frequencies are added)."""
_BAND_HZ = (1e-3, 200.0)
# The tails of the campaign paths the LFT models (docs/linear.md, 'The 24 critical cases').
_CASE_PATHS = (
    "target_frequencies_hz.flapping",
    "target_frequencies_hz.in_plane",
    "target_frequencies_hz.torsion",
    "damping_ratio",
    "inertia",
    "sadm_angle_deg",
)


def case_factors(case, config: SatelliteConfig) -> tuple[dict, float]:
    """The LFT's factors of a campaign case: what its modifiers did to the satellite.

    Parameters
    ----------
    case : ResolvedCase
        A resolved case (:func:`flexsat.campaigns.resolve_cases`) of ``config``.
    config : SatelliteConfig
        The campaign's base satellite, every appendage a plate.

    Returns
    -------
    factors : dict
        Factor on the base value of ``frequency`` (the rotation joints' target
        frequencies, the three alike), ``damping`` (the damping ratio),
        ``hub_inertia`` and ``panel_inertia`` [-], read from the case's satellite
        against the base (the inertias from the modifiers' realised factors, which
        is what ``hub.inertia`` and ``appendages[*].inertia`` are);
        :meth:`flexsat.linear.uncertain.UncertainModel.deltas` turns them into the
        normalized deltas.
    sadm_angle_deg : float
        The case's SADM angle, every plate's [deg].

    Raises
    ------
    ConfigError
        A case that changes something the LFT does not model, or a factor (or SADM
        angle) that differs between appendages or between the three frequencies (the
        LFT applies one factor to every appendage).
    """
    for path in case.parameters:
        tail = path.split(".", 1)[1] if path.startswith("appendages[") else path
        if path != "hub.inertia" and tail not in _CASE_PATHS:
            raise ConfigError(f"case {case.case_id}: {path!r} is not a parameter of the "
                              "uncertain model (it models the rotation joints' target "
                              "frequencies, the damping ratio, hub.inertia, "
                              "appendages[*].inertia and the SADM angle)")  # fmt: skip
    base = config.model_dump()["appendages"]
    found: dict[str, set] = {}
    for k, (app, ref) in enumerate(zip(case.plant["appendages"], base, strict=True)):
        for axis in ("flapping", "in_plane", "torsion"):
            ratio = app["target_frequencies_hz"][axis] / ref["target_frequencies_hz"][axis]
            found.setdefault("frequency", set()).add(round(ratio, 12))
        found.setdefault("damping", set()).add(
            round(app["damping_ratio"] / ref["damping_ratio"], 12)
        )
        found.setdefault("panel_inertia", set()).add(
            float(case.parameters.get(f"appendages[{k}].inertia", 1.0))
        )
        found.setdefault("sadm_angle_deg", set()).add(float(app["sadm_angle_deg"]))
    found["hub_inertia"] = {float(case.parameters.get("hub.inertia", 1.0))}
    for name, values in found.items():
        if len(values) > 1:
            raise ConfigError(f"case {case.case_id}: {name} differs between appendages or "
                              f"frequencies ({sorted(values)}); the uncertain model applies "
                              "one factor to every appendage")  # fmt: skip
    sadm = next(iter(found.pop("sadm_angle_deg")))
    return {name: next(iter(values)) for name, values in found.items()}, sadm


def load_controller(path: str | Path):
    """A user's linear controller from an NPZ holding arrays A, B, C, D.

    Parameters
    ----------
    path : str or Path
        The NPZ; shapes (n, n), (n, 6), (3, n), (3, 6): from ``[phi, theta, psi,
        omega_x, omega_y, omega_z]`` [rad, rad/s] to the body torque [N m].

    Returns
    -------
    LinearController
        The controller.

    Raises
    ------
    ConfigError
        A missing file or array, a wrong shape or a non-finite entry, naming it.
    """
    from flexsat.linear.mu import LinearController

    path = Path(path)
    if not path.is_file():
        raise ConfigError(f"--controller {path}: no such file")
    try:
        with np.load(path, allow_pickle=False) as data:
            arrays = {k: np.asarray(data[k]) for k in data.files}
    except (OSError, ValueError) as exc:
        raise ConfigError(f"--controller {path}: not an NPZ of arrays A, B, C, D ({exc})") from None
    missing = [k for k in "ABCD" if k not in arrays]
    if missing:
        raise ConfigError(f"--controller {path}: missing array {missing[0]} (needs A, B, C, D)")
    return LinearController.from_arrays(*(arrays[k] for k in "ABCD"))


def robust_analysis(
    config: SatelliteConfig,
    scenario=None,
    controller_path: str | Path | None = None,
    sadm_angle_deg: float | None = None,
    points: int = 60,
    out: str | Path | None = None,
    bound: str = "diagonal",
) -> dict:
    """mu-analysis of the satellite's loop over the thesis's parameter box.

    Parameters
    ----------
    config : SatelliteConfig
        The nominal satellite (plates on a fixed SADM angle).
    scenario : SlewScenario, optional
        Its law, linearized about rest (:func:`flexsat.linear.frequency.law_gains`);
        default the PD law's default gains.
    controller_path : str or Path, optional
        A user's controller (:func:`load_controller`) instead of the law.
    sadm_angle_deg : float, optional
        Every plate's SADM angle [deg]; default the config's.
    points : int
        Log-spaced frequencies over 1e-3 ... 200 Hz, within :data:`POINTS_RANGE`.
    out : str or Path, optional
        Folder for ``mu.json`` and ``mu.png``.
    bound : str
        ``"diagonal"`` or ``"lmi"`` (full D, G blocks at the peak frequencies; needs
        cvxpy): :func:`flexsat.linear.mu.analyze`.

    Returns
    -------
    dict
        :meth:`flexsat.linear.mu.MuAnalysis.to_dict` with ``config_name``, ``law``,
        ``sadm_angle_deg``, ``parameters`` (name, factor range, block size) and
        ``files``.

    Raises
    ------
    ConfigError
        ``points`` out of range, a bad controller file, a satellite the uncertain
        model cannot be built for.
    """
    if bound not in BOUNDS:
        raise ConfigError(f"--bound: one of {', '.join(BOUNDS)}, got {bound!r}")
    lo, hi = POINTS_RANGE
    if not lo <= points <= hi:
        raise ConfigError(f"--points: the frequency grid needs {lo} ... {hi} points, got {points}")
    out_dir = None if out is None else prepare_output_dir(out)
    from flexsat.linear.mu import analyze

    config, model, controller, law = _loop(config, scenario, controller_path, sadm_angle_deg)
    result = analyze(model, controller, frequencies_hz=_grid(points), bound=bound)
    summary = _summary(config, model, law, result)
    if out_dir is not None:
        _write_mu(out_dir, summary, result)
    return summary


def _grid(points: int) -> np.ndarray:
    """``points`` log-spaced frequencies over the band [Hz]."""
    return np.logspace(np.log10(_BAND_HZ[0]), np.log10(_BAND_HZ[1]), points)


def _summary(config, model, law: str, result) -> dict:
    """``mu.json``: the loop, the parameters and the analysis."""
    return {
        "config_name": config.name,
        "law": law,
        "sadm_angle_deg": list(model.sadm_angle_deg),
        "parameters": [{"name": p.name, "low": p.low, "high": p.high, "block_size": r}
                       for p, r in zip(model.parameters, model.block_sizes, strict=True)],
        **result.to_dict(),
    }  # fmt: skip


def _write_mu(out_dir: Path, summary: dict, result) -> None:
    """``mu.png`` and ``mu.json`` into ``out_dir``; their paths into ``summary["files"]``."""
    from flexsat.plots.robust import plot_mu
    from flexsat.plots.style import save_figure

    fig = plot_mu(result, f"— {summary['config_name']}, {summary['law']}")
    summary["files"] = [str(save_figure(fig, out_dir / "mu.png", dpi=110)),
                        str(out_dir / "mu.json")]  # fmt: skip
    write_json(out_dir / "mu.json", summary)


def _loop(config, scenario, controller_path, sadm_angle_deg):
    """(config at the SADM angle, its LFT, the controller, the law's name)."""
    from flexsat.dynamics.plant import Plant
    from flexsat.linear.frequency import law_gains
    from flexsat.linear.mu import LinearController
    from flexsat.linear.uncertain import uncertain_model, with_sadm_angle

    if sadm_angle_deg is not None:
        if not (np.isfinite(sadm_angle_deg) and abs(sadm_angle_deg) <= 180.0):
            raise ConfigError(
                f"--sadm-angle: an angle within [-180, 180] deg, got {sadm_angle_deg:g}"
            )
        config = with_sadm_angle(config, sadm_angle_deg)
    model = uncertain_model(config)
    if controller_path is not None:
        return config, model, load_controller(controller_path), "user"
    law_config = None if scenario is None else scenario.controller
    K = law_gains(Plant.from_config(config), law_config)
    law = "pd" if law_config is None else law_config.kind
    return config, model, LinearController.static(K), law


STUDY_POINTS = 60
"""Log-spaced frequencies of the full study's mu grid (``flexsat robust analyze``'s
default); the closed loop's modal frequencies are added."""
QUICK_POINTS = 8
"""Log-spaced frequencies of the quick study's mu grid."""
SAMPLES = 1000
"""Parameter points drawn in the certified box, and as many in the full box."""
SEED = 20261207
"""Root seed of the sampling check (printed in the report)."""
FLIGHT_S = 60.0
"""Simulated time of each worst case flown in the nonlinear simulator [s]."""
EARLY_S = (10.0, 20.0)
"""Window of the elastic energy's early envelope [s]; the late one is the last 10 s."""
DECAY_RESOLUTION = 1e-3
"""What the envelope resolves of a decay rate [1/s]: its maxima miss the beat of close
modes by a few per cent, ~1e-3 1/s over the ~40 s between the two windows."""
_PANEL_START_DEG = (1.0, 1.0, 1.0)  # the first plate's root rotations at t = 0 [deg]


def _max_real(model, loop, delta: np.ndarray) -> float:
    """Largest real part of the closed loop's poles at the parameter point [1/s]."""
    A, B, C, D = loop
    Dl = model.delta_matrix(delta)
    X = np.linalg.solve(np.eye(D.shape[0]) - Dl @ D, Dl)
    return float(np.max(np.linalg.eigvals(A + B @ X @ C).real))


def _factors(model, delta: np.ndarray) -> dict:
    """Each parameter's factor on its nominal value at ``delta`` [-]."""
    return {p.name: float(p.centre + p.half_range * d)
            for p, d in zip(model.parameters, delta, strict=True)}  # fmt: skip


def perturbed_config(config: SatelliteConfig, factors: dict) -> SatelliteConfig:
    """The satellite the campaign modifiers make from the LFT's factors.

    Parameters
    ----------
    config : SatelliteConfig
        The nominal satellite (plates).
    factors : dict
        Factor on the nominal value per parameter of
        :data:`flexsat.linear.uncertain.PARAMETERS` (missing ones: 1) [-].

    Returns
    -------
    SatelliteConfig
        Validated: the rotation joints' target frequencies scaled by ``frequency``,
        the damping ratio by ``damping``, ``hub.inertia`` and ``appendages[*].inertia``
        by their factors (the joints re-tuned to their targets).
    """
    from flexsat.campaigns.modifiers import Modifier, apply_modifiers
    from flexsat.config.load import validate_config

    f = {"frequency": 1.0, "damping": 1.0, "hub_inertia": 1.0, "panel_inertia": 1.0, **factors}
    mods = [
        Modifier(path=f"appendages[*].target_frequencies_hz.{axis}", op="scale",
                 value=f["frequency"])
        for axis in ("flapping", "in_plane", "torsion")
    ] + [
        Modifier(path="appendages[*].damping_ratio", op="scale", value=f["damping"]),
        Modifier(path="hub.inertia", value=f["hub_inertia"]),
        Modifier(path="appendages[*].inertia", value=f["panel_inertia"]),
    ]  # fmt: skip
    data = apply_modifiers(config.model_dump(), mods, np.random.default_rng(0), {})
    return validate_config(data)


def hold_scenario(scenario, panel: str):
    """The law holding rest, no disturbance torque, ``panel`` started 1 deg off about
    each axis, :data:`FLIGHT_S` long (the worst cases' flight).

    Parameters
    ----------
    scenario : SlewScenario
        Its law (and gains) and loop are kept.
    panel : str
        The appendage started deflected (one panel only: the modes that do not move
        the hub are excited too).

    Returns
    -------
    SlewScenario
    """
    from flexsat.simulate.scenario import AppendageInitialState, InitialState

    return scenario.model_copy(update={
        "duration_s": FLIGHT_S, "target_euler_deg": (0.0, 0.0, 0.0),
        "disturbances": scenario.disturbances.model_copy(
            update={"environment_nm": (0.0, 0.0, 0.0), "sloshing_ratio": 0.0,
                    "residual_nm": (0.0, 0.0, 0.0)}),
        "initial": InitialState(appendages=[AppendageInitialState(name=panel,
                                                                  rho_deg=_PANEL_START_DEG)]),
    })  # fmt: skip


def decay_rate(time_s: np.ndarray, elastic_energy_j: np.ndarray) -> float:
    """Slowest decay of the panels' vibration from the elastic energy's envelope [1/s].

    Parameters
    ----------
    time_s : ndarray, shape (n,)
        Record times [s], the run at least :data:`FLIGHT_S` long.
    elastic_energy_j : ndarray, shape (n,)
        The joints' elastic energy per record [J].

    Returns
    -------
    float
        Re(lambda) of the slowest excited mode: E ~ exp(2 Re(lambda) t), from the
        energy's maximum over :data:`EARLY_S` and over the last 10 s (their centres
        apart) [1/s]; negative when the vibration decays.
    """
    t, e = np.asarray(time_s), np.asarray(elastic_energy_j)
    early = np.max(e[(t >= EARLY_S[0]) & (t < EARLY_S[1])])
    late = np.max(e[t >= t[-1] - 10.0])
    span = (t[-1] - 5.0) - 0.5 * (EARLY_S[0] + EARLY_S[1])
    return float(np.log(late / early) / (2.0 * span))


@one_blas_thread
def robust_study(config: SatelliteConfig, scenario, out: str | Path, quick: bool = False) -> dict:
    """The study's robustness part: mu of its law, the sampling check, the worst cases flown.

    Parameters
    ----------
    config : SatelliteConfig
        The study's satellite (plates on a fixed SADM angle).
    scenario : SlewScenario
        The nominal slew's: its law, linearized about rest, closes the loop.
    out : str or Path
        Folder for ``mu.json``, ``mu.png``, ``robust.json`` and each flown case's
        ``<case>/result.nc``.
    quick : bool
        :data:`QUICK_POINTS` frequencies and 100 L-BFGS-B iterations per frequency,
        instead of :data:`STUDY_POINTS` and 200.

    Returns
    -------
    dict
        ``robust.json``: the certified k_max, mu's upper bound at the lower bound's
        frequency, the sampling check (seed, samples, unstable counts, largest real
        parts), and per flown case (``mu_worst``, ``sampled_worst``) its factors,
        deltas, the linear closed loop's largest real part [1/s], the nonlinear
        vibration decay rate [1/s] and its record (relative to ``out``);
        ``mu_worst_decays_slowest``: the mu worst case decays no faster than the
        sampled one, within :data:`DECAY_RESOLUTION`.

    Raises
    ------
    ConfigError
        A satellite the uncertain model cannot be built for.
    """
    from flexsat.dynamics.plant import Plant
    from flexsat.linear.mu import analyze, closed_loop, mu_upper_bound
    from flexsat.simulate import run_slew

    out_dir = prepare_output_dir(out)
    config, model, controller, law = _loop(config, scenario, None, None)
    points, maxiter = (QUICK_POINTS, 100) if quick else (STUDY_POINTS, 200)
    result = analyze(model, controller, frequencies_hz=_grid(points), maxiter=maxiter)
    _write_mu(out_dir, _summary(config, model, law, result), result)
    loop = closed_loop(model, controller)
    upper_at_lower = None
    if result.lower > 0.0:  # a valid upper bound is never below the lower one there
        A, B, C, D = loop
        w = 2.0 * np.pi * result.lower_frequency_hz
        N = C @ np.linalg.solve(1j * w * np.eye(A.shape[0]) - A, B) + D
        upper_at_lower = mu_upper_bound(N, np.ones(model.n_channels, bool), maxiter=maxiter)[0]
    rng = np.random.default_rng(SEED)
    n_p = len(model.parameters)
    k_cert = result.k_max[0]
    certified = np.array([_max_real(model, loop, k_cert * d)
                          for d in rng.uniform(-1.0, 1.0, (SAMPLES, n_p))])  # fmt: skip
    box = rng.uniform(-1.0, 1.0, (SAMPLES, n_p))
    box_re = np.array([_max_real(model, loop, d) for d in box])
    hold = hold_scenario(scenario, config.appendages[0].name)
    cases = {}
    for name, delta in (
        ("mu_worst", result.worst_delta),
        ("sampled_worst", box[np.argmax(box_re)]),
    ):
        factors = _factors(model, delta)
        flown = run_slew(Plant.from_config(perturbed_config(config, factors)), hold,
                         progress=False)  # fmt: skip
        flown.raise_for_status()
        ds = flown.dataset
        path = flown.to_netcdf(out_dir / name / "result.nc")
        cases[name] = {
            "factors": factors, "delta": [float(d) for d in delta],
            "max_real_1_s": _max_real(model, loop, delta),
            "decay_rate_1_s": decay_rate(ds["time"].values, ds["elastic_energy"].values),
            "result": path.relative_to(out_dir).as_posix(),
        }  # fmt: skip
    robust = {
        "law": law, "controller": scenario.controller.model_dump(mode="json"),
        "samples": SAMPLES, "seed": SEED, "k_max_certified": k_cert,
        "upper_at_lower_frequency": upper_at_lower,
        "certified_unstable": int(np.sum(certified >= 0.0)),
        "certified_max_real_1_s": float(np.max(certified)),
        "box_unstable": int(np.sum(box_re >= 0.0)), "box_max_real_1_s": float(np.max(box_re)),
        "flight_s": FLIGHT_S, "started_panel": config.appendages[0].name,
        "started_rho_deg": list(_PANEL_START_DEG), "cases": cases,
        "decay_resolution_1_s": DECAY_RESOLUTION,
        "mu_worst_decays_slowest": bool(cases["mu_worst"]["decay_rate_1_s"]
                                        >= cases["sampled_worst"]["decay_rate_1_s"]
                                        - DECAY_RESOLUTION),
    }  # fmt: skip
    write_json(out_dir / "robust.json", robust)
    return robust
