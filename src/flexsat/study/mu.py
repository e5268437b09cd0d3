"""Robust stability of a satellite's loop: what ``flexsat robust analyze`` computes and writes.

The satellite's uncertain model (:mod:`flexsat.linear.uncertain`, the thesis's
parameters) closed by the scenario's law linearized about rest (or a user's
state-space controller), analysed by :func:`flexsat.linear.mu.analyze`; see
docs/linear.md, 'Robust stability: mu'.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from flexsat.config.models import SatelliteConfig
from flexsat.errors import ConfigError
from flexsat.study.outputs import prepare_output_dir, write_json

__all__ = ["POINTS_RANGE", "case_factors", "load_controller", "robust_analysis"]

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
    from flexsat.dynamics.plant import Plant
    from flexsat.linear.frequency import law_gains
    from flexsat.linear.mu import LinearController, analyze
    from flexsat.linear.uncertain import uncertain_model, with_sadm_angle

    lo, hi = POINTS_RANGE
    if not lo <= points <= hi:
        raise ConfigError(f"--points: the frequency grid needs {lo} ... {hi} points, got {points}")
    out_dir = None if out is None else prepare_output_dir(out)
    if sadm_angle_deg is not None:
        if not (np.isfinite(sadm_angle_deg) and abs(sadm_angle_deg) <= 180.0):
            raise ConfigError(
                f"--sadm-angle: an angle within [-180, 180] deg, got {sadm_angle_deg:g}"
            )
        config = with_sadm_angle(config, sadm_angle_deg)
    model = uncertain_model(config)
    if controller_path is not None:
        controller, law = load_controller(controller_path), "user"
    else:
        law_config = None if scenario is None else scenario.controller
        K = law_gains(Plant.from_config(config), law_config)
        controller, law = (
            LinearController.static(K),
            "pd" if law_config is None else law_config.kind,
        )
    grid = np.logspace(np.log10(_BAND_HZ[0]), np.log10(_BAND_HZ[1]), points)
    result = analyze(model, controller, frequencies_hz=grid)
    summary = {
        "config_name": config.name,
        "law": law,
        "sadm_angle_deg": list(model.sadm_angle_deg),
        "parameters": [{"name": p.name, "low": p.low, "high": p.high, "block_size": r}
                       for p, r in zip(model.parameters, model.block_sizes, strict=True)],
        **result.to_dict(),
    }  # fmt: skip
    if out_dir is not None:
        from flexsat.plots.robust import plot_mu
        from flexsat.plots.style import save_figure

        fig = plot_mu(result, f"— {config.name}, {law}")
        summary["files"] = [str(save_figure(fig, out_dir / "mu.png", dpi=110)),
                            str(out_dir / "mu.json")]  # fmt: skip
        write_json(out_dir / "mu.json", summary)
    return summary
