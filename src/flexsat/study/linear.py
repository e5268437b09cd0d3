"""Linear analysis and loop margins, written to files: what ``flexsat linearize`` and
``flexsat margins`` share.

Each function returns a JSON-ready summary (SI units, keys ending in their unit)
and, given a folder, writes the model files, ``linear.json`` / ``margins.json``
and the figures there.
"""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from flexsat.errors import ConfigError
from flexsat.study.outputs import prepare_output_dir, write_json

if TYPE_CHECKING:
    from flexsat.dynamics.plant import Plant

__all__ = [
    "family_margins",
    "parse_about",
    "parse_reduction",
    "write_linearize",
    "write_margins",
]

_REDUCTIONS = ("modal", "balanced")


MAX_SPIN_RAD_S = 100.0
"""Largest body-rate component of a steady spin to linearize about [rad/s] (about 16
rev/s, far beyond any spacecraft; a larger one leaves no digit to the joints' motion)."""


def parse_about(text: str) -> str | np.ndarray:
    """``"rest"`` or ``"spin:wx,wy,wz"`` (body rate [rad/s]) -> ``"rest"`` or the vector.

    Parameters
    ----------
    text : str
        The option's value.

    Returns
    -------
    str or ndarray, shape (3,)
        ``"rest"`` or the body rate [rad/s].
    """
    if text == "rest":
        return "rest"
    head, _, tail = text.partition(":")
    try:
        values = [float(v) for v in tail.split(",")]
    except ValueError:
        values = []
    if head != "spin" or len(values) != 3:
        raise ConfigError(f"--about: expected 'rest' or 'spin:wx,wy,wz' [rad/s], got {text!r}")
    if not all(abs(v) <= MAX_SPIN_RAD_S for v in values):  # NaN fails too
        raise ConfigError(f"--about: each spin component must be within +-{MAX_SPIN_RAD_S:g} "
                          f"rad/s, got {text[:80]!r}")  # fmt: skip
    return np.array(values)


def parse_reduction(text: str | None) -> tuple[str, int] | None:
    """``"balanced:16"`` or ``"modal:16"`` -> (method, order); ``None`` -> no reduction.

    Parameters
    ----------
    text : str or None
        The option's value.

    Returns
    -------
    tuple of (str, int) or None
        Method and order.
    """
    if text is None:
        return None
    method, _, order = text.partition(":")
    if method not in _REDUCTIONS or not order.isdigit():
        raise ConfigError(
            f"--reduce: expected 'balanced:N' or 'modal:N' (N states in all), got {text!r}"
        )
    return method, int(order)


def _mode_table(model) -> list[dict]:
    lam = model.poles()
    lam = lam[lam.imag > 1e-9 * max(1.0, float(np.abs(lam).max()))]
    return [
        {
            "frequency_hz": float(abs(v) / (2 * np.pi)),
            "damped_frequency_hz": float(v.imag / (2 * np.pi)),
            "damping_ratio": float(-v.real / abs(v)),
        }
        for v in lam[np.argsort(np.abs(lam))]
    ]


def _matrices(model) -> dict:
    """A, B, C, D (lists of rows, exact floats), x0, u0 and every signal's name and unit."""
    return {
        "state_names": list(model.state_names),
        "state_units": list(model.state_units),
        "input_names": list(model.input_names),
        "input_units": list(model.input_units),
        "output_names": list(model.output_names),
        "output_units": list(model.output_units),
        "A": model.A.tolist(),
        "B": model.B.tolist(),
        "C": model.C.tolist(),
        "D": model.D.tolist(),
        "x0": model.x0.tolist(),
        "u0": model.u0.tolist(),
    }


def write_linearize(
    plant: Plant,
    about: str | np.ndarray = "rest",
    outputs: list[str] | None = None,
    reduction: tuple[str, int] | None = None,
    out: Path | None = None,
    actuated: list[str] | None = None,
) -> tuple[object, dict]:
    """Linearize; with ``out``, ``model.npz``, ``model.mat``, ``linear.json``, figures.

    Parameters
    ----------
    plant : Plant
        The satellite.
    about : str or ndarray, shape (3,)
        ``"rest"`` or a steady body rate [rad/s] (:func:`parse_about`).
    outputs : list of str, optional
        Output groups (default: the model's).
    reduction : tuple of (str, int), optional
        Method and order (:func:`parse_reduction`).
    out : Path, optional
        Where the files go.
    actuated : list of str, optional
        Appendage coordinates given an input each, as in
        :func:`flexsat.linear.linearize`.

    Returns
    -------
    model : flexsat.linear.LinearModel
        The full model (outputs as requested).
    summary : dict
        Sizes; the state-space model ``A``, ``B``, ``C``, ``D`` (lists of rows, SI,
        the same numbers as ``model.npz``) with ``x0``, ``u0`` and the names and
        units of the states, inputs and outputs; the equilibrium; the modes
        (frequency, damping ratio); the reduction's error bound and reduced matrices;
        and ``files`` when ``out`` is given.
    """
    from flexsat.linear import OUTPUT_GROUPS, linearize
    from flexsat.linear.frequency import effective_inertia, rigid_model
    from flexsat.linear.reduce import balanced_truncation, modal_truncation

    model = linearize(plant, about, outputs=outputs or OUTPUT_GROUPS, actuated=actuated or ())
    f_eff, J_eff, J_res = effective_inertia(plant)
    summary = {
        "config_name": plant.config.name,
        "about": "rest" if isinstance(about, str) else "spin",
        "spin_rad_s": model.spin.tolist(),
        "equilibrium_torque_nm": model.u0.tolist(),
        "jacobian": model.jacobian,
        "n_states": model.n_states,
        **_matrices(model),
        "modes": _mode_table(model),
        "effective_inertia": {
            "frequencies_hz": f_eff.tolist(),
            "J_eff_kg_m2": J_eff.tolist(),
            "J_residual_kg_m2": J_res.tolist(),
        },
    }
    reduced = None
    if reduction is not None:
        method, order = reduction
        reduce = balanced_truncation if method == "balanced" else modal_truncation
        reduced = reduce(model, order)
        summary["reduction"] = {
            "method": method,
            "order": order,
            "n_marginal": reduced.n_marginal,
            "error_bound": reduced.error_bound,
            "hankel_singular_values": (
                None if reduced.hankel_singular_values is None
                else reduced.hankel_singular_values.tolist()
            ),
            **_matrices(reduced.model),
        }  # fmt: skip
    if out is not None:
        from flexsat.plots.linear import write_linear_figures

        out = prepare_output_dir(out)
        files = [model.save_npz(out / "model.npz"), model.save_mat(out / "model.mat")]
        if reduced is not None:
            files += [reduced.model.save_npz(out / "reduced.npz")]
            files += [reduced.model.save_mat(out / "reduced.mat")]
        if isinstance(about, str) and {"attitude", "rate"} <= set(outputs or OUTPUT_GROUPS):
            files += write_linear_figures(out, model, rigid_model(plant), (f_eff, J_eff))
        summary["files"] = [str(p) for p in [write_json(out / "linear.json", summary), *files]]
    return model, summary


def write_margins(plant: Plant, scenario=None, out: Path | None = None) -> dict:
    """PD loop gain per axis about rest and its margins; with ``out``, figures and JSON.

    Parameters
    ----------
    plant : Plant
        The satellite.
    scenario : SlewScenario, optional
        Its controller (PD, SMC or ASMC) is linearized about rest, the sliding-mode
        laws inside their boundary layer with Lambda and JK at their steady-state
        values; default: the PD law's default gains.
    out : Path, optional
        Where the figures and ``margins.json`` go.

    Returns
    -------
    dict
        ``axes``: per axis the margins of :class:`flexsat.linear.frequency.LoopMargins`
        (every gain crossover with its phase and delay margins, the peak loop gain of
        each flexible mode and whether it is gain- or phase-stabilized, the delay
        margin and the crossover that sets it).
    """
    from flexsat.linear import linearize
    from flexsat.linear.frequency import (
        effective_inertia,
        law_gains,
        loop_margins,
        pd_loop,
        rigid_model,
    )

    law = _law(scenario)
    model = linearize(plant, outputs=["attitude", "rate"])
    K = law_gains(plant, law)
    loops = {axis: pd_loop(model, K, axis) for axis in "xyz"}
    modes_hz = np.array([mode["frequency_hz"] for mode in _mode_table(model)])
    margins = {axis: loop_margins(loop, modes_hz=modes_hz) for axis, loop in loops.items()}
    summary = {
        "config_name": plant.config.name,
        "law": law.kind,
        "gains": law.model_dump(mode="json", by_alias=True),
        "axes": {axis: m.to_dict() for axis, m in margins.items()},
    }
    if out is not None:
        from flexsat.plots.linear import write_linear_figures

        out = prepare_output_dir(out)
        effective = effective_inertia(plant)[:2]
        files = write_linear_figures(out, model, rigid_model(plant), effective, loops, margins)
        summary["files"] = [str(p) for p in [write_json(out / "margins.json", summary), *files]]
    return summary


def family_margins(
    plant: Plant, campaign: str | Path, scenario=None, out: Path | None = None
) -> dict:
    """PD loop margins over every case of a campaign (sensitivity, Monte Carlo...).

    Each case perturbs the truth plant; the controller keeps the design model of
    ``plant`` (the campaign's base configuration), as in the campaigns. With ``out``,
    ``margins_family.json`` and ``loop_family.png`` (one curve per case and axis).

    Parameters
    ----------
    plant : Plant
        The design (base) satellite.
    campaign : str or Path
        The campaign file.
    scenario : SlewScenario, optional
        The controller, as for :func:`write_margins`.
    out : Path, optional
        Where the files go.

    Returns
    -------
    dict
        ``cases``: one entry per case id with its margins per axis.
    """
    from flexsat.campaigns.definition import load_campaign, resolve_cases
    from flexsat.config.models import SatelliteConfig
    from flexsat.dynamics.plant import Plant
    from flexsat.linear import linearize
    from flexsat.linear.frequency import law_gains, loop_margins, pd_loop

    K = law_gains(plant, _law(scenario))
    cases = resolve_cases(load_campaign(campaign), plant.config)
    loops: dict[str, dict] = {}
    table: dict[str, dict] = {}
    for case in cases:
        truth = Plant.from_config(SatelliteConfig.model_validate(case.plant))
        model = linearize(truth, outputs=["attitude", "rate"])
        loops[case.case_id] = {axis: pd_loop(model, K, axis) for axis in "xyz"}
        modes_hz = np.array([mode["frequency_hz"] for mode in _mode_table(model)])
        table[case.case_id] = {
            axis: loop_margins(loop, modes_hz=modes_hz).to_dict()
            for axis, loop in loops[case.case_id].items()
        }
    summary = {"config_name": plant.config.name, "campaign": str(campaign), "cases": table}
    if out is not None:
        from flexsat.plots.linear import plot_loop_family
        from flexsat.plots.style import save_figure

        out = prepare_output_dir(out)
        figure = save_figure(plot_loop_family(loops, table), out / "loop_family.png", dpi=110)
        json_path = write_json(out / "margins_family.json", summary)
        summary["files"] = [str(json_path), str(figure)]
    return summary


def _law(scenario):
    from flexsat.control.laws.pd import PDConfig

    return PDConfig() if scenario is None else scenario.controller
