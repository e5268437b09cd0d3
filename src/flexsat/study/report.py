"""The study report: one self-contained HTML file written from the study's outputs.

:func:`write_report` reads ``study.json`` (the manifest of :func:`run_study`) and the
JSON files each part wrote, and embeds the figures (PNG, GIF) as data URIs, so the
file renders offline and can be mailed as it is. Every number shown is read from
those JSON files, never recomputed: each table cell that holds one carries
``data-source`` (the JSON file, relative to the study folder), ``data-path`` (the
key path in it, ``/``-separated) and ``data-value`` (the value as JSON), so a reader
or a test can trace it back. A part that failed shows its error and traceback in
its section; the sections of the other parts are written as usual. A section that
cannot be drawn from its part's outputs fails that part: its error and traceback are
shown there and written into ``study.json`` (``report_failed``: the report failed it).

Sections follow the thesis: the configuration (section 3.1), the model's M(0) and
rigid inertia (appendix B), the coupled modes (table 3.3), the open-loop validation
(section 3.3), the ASMC slew and its requirements (section 5.1), the frequency-domain
analysis of its law (loop margins with the flexible modes), its robust stability
(mu over the thesis's parameter box, the worst case flown), the controller
comparison, and the campaigns (chapter 5). :data:`SECTIONS` lists them; a new section
is one drawing function and one entry there (docs/results.md, 'The study report').

The page reads as a design review: a numbered table of contents, figures at full
width that open at full size on a click, each mode's still at its peak deformation
beside its animation, sortable tables, a caveat at the top of each section whose
thesis comparison does not apply to the configuration, and a print layout.
"""

from __future__ import annotations

import base64
import html
import json
import platform
import traceback
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from flexsat.control.laws import get_law, law_names
from flexsat.files import write_text
from flexsat.study import thesis

__all__ = ["SECTIONS", "Section", "format_value", "write_report"]

_MIME = {".png": "image/png", ".gif": "image/gif", ".svg": "image/svg+xml"}


def format_value(value) -> str:
    """How the report shows a JSON value: 4 significant digits, booleans as pass/fail.

    Parameters
    ----------
    value : float, int, bool, str, list or None
        A value as read from a study JSON file, in the unit its key names [key's
        unit] (None is a quantity that does not exist, e.g. a settling time never
        reached).

    Returns
    -------
    str
    """
    if value is None:
        return "—"
    if isinstance(value, bool):
        return "pass" if value else "fail"
    if isinstance(value, int):
        return str(value)
    if isinstance(value, float):
        if value == 0.0:
            return "0"
        if 1e-3 <= abs(value) < 1e5:
            return f"{value:.4g}"
        return f"{value:.3e}"
    if isinstance(value, list) and value and all(isinstance(v, list) for v in value):
        return "[" + "; ".join(format_value(row) for row in value) + "]"  # matrix, by rows
    if isinstance(value, list):
        return ", ".join(format_value(v) for v in value)
    return str(value)


class _Source:
    """One JSON output of the study, and the table cells that show its values."""

    def __init__(self, root: Path, relative: str) -> None:
        self.relative = relative
        self.data = json.loads((root / relative).read_text())

    def get(self, *path):
        node = self.data
        for key in path:
            node = node[key]
        return node

    def cell(self, *path, tag: str = "td", not_judged: bool = False) -> str:
        value = self.get(*path)
        css = "num"
        text = format_value(value)
        if isinstance(value, bool):
            css = "pass" if value else "fail"
        elif value is None and (not_judged or str(path[-1]) in _VERDICTS):  # neither
            css, text = "notjudged", "not judged"  # pass nor fail
        return (
            f'<{tag} class="{css}" data-source="{html.escape(self.relative)}" '
            f'data-path="{html.escape("/".join(str(p) for p in path))}" '
            f"data-value='{html.escape(json.dumps(value), quote=True)}'>"
            f"{html.escape(text)}</{tag}>"
        )


_VERDICTS = ("r1_pass", "r2_pass", "r3_pass", "passes")
"""Keys whose null value is a verdict not judged: the run was planned to end before its
observation window (docs/control.md, 'How R1 and R2 are judged'); the report says
"not judged" there, not a bare dash. (A null pass rate is "not judged" only where the
campaign counts cases not judged: with no case run, it is a dash.)"""


def _esc(text) -> str:
    return html.escape(str(text))


def _table(
    header: list[str], rows: list[list[str]], caption: str = "", sortable: bool = False
) -> str:
    """Rows are lists of ready cells (``<td>...</td>``) or plain text (escaped).

    A sortable table sorts by a column when its header is clicked (numbers by value,
    from ``data-value``; text alphabetically), again to reverse.
    """

    def cell(item: str) -> str:
        return item if item.startswith(("<td", "<th")) else f"<td>{_esc(item)}</td>"

    head = "".join(f"<th>{_esc(h)}</th>" for h in header)
    body = "".join("<tr>" + "".join(cell(c) for c in row) + "</tr>" for row in rows)
    cap = f"<caption>{_esc(caption)}</caption>" if caption else ""
    css = ' class="sortable"' if sortable else ""
    return f"<table{css}>{cap}<thead><tr>{head}</tr></thead><tbody>{body}</tbody></table>"


def _figure(root: Path, relative: str, caption: str = "") -> str:
    """One figure, full width; a click opens it at full size (see ``_SCRIPT``)."""
    path = root / relative
    data = base64.b64encode(path.read_bytes()).decode("ascii")
    mime = _MIME[path.suffix.lower()]
    text = caption or path.stem.replace("_", " ")
    return (
        f'<figure><img src="data:{mime};base64,{data}" alt="{_esc(text)}" loading="eager" '
        f'title="click to enlarge"><figcaption>{_esc(text)} '
        f"<span class='file'>({_esc(relative)})</span></figcaption></figure>"
    )


_STILL_CAPTION = "at its peak deformation (still)"
_ANIMATED_CAPTION = "over one period (animation)"


def _figures(root: Path, files: list[str]) -> str:
    """The figures in order; a PNG and a GIF of the same name (a mode's still at its peak
    deformation and its animation) side by side."""
    stems = {}
    for f in files:
        stems.setdefault(Path(f).with_suffix("").as_posix(), []).append(f)
    parts, done = [], set()
    for f in files:
        stem = Path(f).with_suffix("").as_posix()
        if stem in done:
            continue
        done.add(stem)
        group = stems[stem]
        pngs = [g for g in group if g.endswith(".png")]
        gifs = [g for g in group if g.endswith(".gif")]
        if pngs and gifs:
            name = Path(stem).name.replace("_", " ")
            parts.append(
                '<div class="pair">'
                + _figure(root, pngs[0], f"{name} {_STILL_CAPTION}")
                + _figure(root, gifs[0], f"{name} {_ANIMATED_CAPTION}")
                + "</div>"
            )
        else:
            parts += [_figure(root, g) for g in group]
    return '<div class="figures">' + "".join(parts) + "</div>"


# -- sections -------------------------------------------------------------------------


def _configuration(root: Path, outputs: dict, context: dict) -> str:
    src = _Source(root, outputs["json"])
    config = src.get("config")
    parts = [
        f"<p>Configuration <b>{_esc(config['name'])}</b>, from {_esc(context['source'])}."
        " Every parameter as validated, then what flexsat derives from them.</p>"
    ]
    hub_rows = [
        [".".join(path), src.cell("config", "hub", *path)] for path in _leaves(config["hub"])
    ]
    parts.append(_table(["hub parameter", "value"], hub_rows, "Hub (SI units; see key names)"))
    names = [a["name"] for a in config["appendages"]]
    # Each model has its own parameters: a row per parameter any appendage has, "—"
    # (:data:`_ABSENT`) in the columns of those whose model has no such parameter.
    rows = [
        [".".join(path), *(_cell_if(src, "config", "appendages", i, *path)
                           for i in range(len(names)))]
        for path in _union(_leaves(a) for a in config["appendages"])
        if path != ("name",)
    ]  # fmt: skip
    parts.append(_table(["appendage parameter", *names], rows,
                        "Appendages (— : not a parameter of that appendage's model)"))  # fmt: skip
    parts.append(
        _table(
            ["", "value"],
            [["hub inertia [kg m²] (rows)", src.cell("hub_inertia_kg_m2")]],
            "Derived: hub inertia about the hub centre of mass",
        )
    )
    keys = _union([(key,) for key in a if key not in ("name", "model")]
                  for a in src.get("appendages"))  # fmt: skip
    derived = [
        [key, *(_cell_if(src, "appendages", i, key) for i in range(len(names)))] for (key,) in keys
    ]
    parts.append(
        _table(
            ["derived", *names],
            derived,
            "Derived per appendage, as its model describes it (— : not a quantity of that "
            "model); a plate's: mass, centroidal inertia, joint stiffness and damping "
            "(joint DOFs ρ_x, ρ_y, ρ_z [N m/rad, N m s/rad], η_x, η_y, η_z [N/m, N s/m])",
        )
    )
    return "".join(parts)


_ABSENT = "<td class='absent'>—</td>"
"""The cell of a parameter an appendage's model does not have."""


def _union(paths_per_item) -> list[tuple]:
    """The key paths of several items, each once, in the order they first appear."""
    return list(dict.fromkeys(path for paths in paths_per_item for path in paths))


def _cell_if(src: _Source, *path) -> str:
    """``src.cell(*path)``, or :data:`_ABSENT` where ``path`` is not in the file (an
    appendage whose model has no such parameter)."""
    node = src.data
    for key in path:
        if (isinstance(node, dict) and key in node) or (isinstance(node, list) and key < len(node)):
            node = node[key]
        else:
            return _ABSENT
    return src.cell(*path)


def _leaves(data: dict, prefix: tuple = ()) -> list[tuple]:
    """Key paths to the non-dict values of a nested dict, in order."""
    paths = []
    for key, value in data.items():
        if isinstance(value, dict):
            paths += _leaves(value, (*prefix, key))
        else:
            paths.append((*prefix, key))
    return paths


def _matrix(src: _Source, rows: range, cols: range, caption: str) -> str:
    body = [[str(i + 1), *(src.cell("mass_matrix", i, j) for j in cols)] for i in rows]
    return _table(["row", *(str(j + 1) for j in cols)], body, caption)


def _model(root: Path, outputs: dict, context: dict) -> str:
    src = _Source(root, outputs["json"])
    M = np.asarray(src.get("mass_matrix"))
    # Each appendage's coordinates are the DOFs named "<appendage>.<coordinate>".
    blocks: dict[str, list[int]] = {}
    for j, name in enumerate(src.get("dof_names")[6:], start=6):
        blocks.setdefault(name.split(".", 1)[0], []).append(j)
    parts = [
        "<p>The mass matrix M(q) at q = 0 (thesis appendix B), in the DOF order "
        f"{_esc(', '.join(src.get('dof_names')))}; and the rigid design inertia.</p>"
    ]
    parts.append(_matrix(src, range(6), range(6), "M(0) hub block, eq. B.2"))
    for k, cols in enumerate(blocks.values()):
        parts.append(_matrix(src, range(6), cols, f"M(0) hub–appendage {k + 1} coupling"))
        parts.append(_matrix(src, cols, cols, f"M(0) appendage {k + 1} block"))
    if context["nominal"]:
        deviation = float(np.abs(M - thesis.appendix_b_mass_matrix()).max())
        verdict = "within" if deviation <= thesis.PRINTED_2DP else "OUTSIDE"
        parts.append(
            f"<p class='check'>Largest deviation from appendix B: {deviation:.2g} "
            f"({verdict} the ±0.005 of its two printed decimals).</p>"
        )
    j_rows = [
        [axis, src.cell("rigid_inertia", i, i), f"{thesis.J_TOT_NOMINAL[i, i]:.2f}"]
        for i, axis in enumerate("xyz")
    ]
    parts.append(
        _table(
            ["axis", "J_tot [kg m²] flexsat", "thesis (section 3.1)"],
            j_rows,
            "Rigid design inertia J_tot (diagonal) about the hub centre of mass",
        )
    )
    return "".join(parts)


def _modal(root: Path, outputs: dict, context: dict) -> str:
    src = _Source(root, outputs["json"])
    reference = {row[0]: row for row in thesis.TABLE_3_3}
    rows = []
    for i, mode in enumerate(src.get("modes")):
        if mode["frequency_hz"] == 0.0:
            continue
        ref = reference.get(mode["index"])
        if ref is not None:
            theirs = [f"{ref[1]:.2f}", ref[2], ref[3], ref[4] or "—"]
        elif mode["index"] > 12 and len(src.get("modes")) == 18:
            theirs = [f"≥ {thesis.TRANSLATION_MODES_MIN_HZ:.0f}", "translation", "", ""]
        else:
            theirs = ["", "", "", ""]
        cells = [
            src.cell("modes", i, key)
            for key in ("index", "frequency_hz", "kind", "symmetry", "hub_dof")
        ]
        rows.append([*cells, *theirs])
    header = [
        "mode",
        "f [Hz]",
        "kind",
        "symmetry",
        "hub DOF",
        "thesis f [Hz]",
        "thesis kind",
        "thesis symmetry",
        "thesis hub DOF",
    ]
    caption = "Coupled modes at q = 0 beside thesis table 3.3 (rigid-body modes omitted)"
    return _table(header, rows, caption) + _figures(root, outputs["figures"])


def _compare_rows(src: _Source, reference: dict) -> list[list[str]]:
    rows = []
    for key in src.data:
        if key in ("files", "message", "status", "controller"):
            continue
        ref = reference.get(key)
        theirs = [format_value(ref[0]), ref[1]] if ref else ["", ""]
        rows.append([key, src.cell(key), *theirs])
    return rows


def _openloop(root: Path, outputs: dict, context: dict) -> str:
    src = _Source(root, outputs["json"])
    parts = [
        "<p>1 N m about the body Z axis for 10 s, then free, to 120 s (thesis section "
        "3.3). Vector quantities are given x, y, z; the thesis's value is the z "
        "component where it is a vector.</p>",
        _table(
            ["metric", "flexsat", "thesis", "thesis source"],
            _compare_rows(src, thesis.OPEN_LOOP),
            "Open-loop metrics",
        ),
        _figures(root, outputs["figures"]),
    ]
    return "".join(parts)


def _slew(root: Path, outputs: dict, context: dict) -> str:
    src = _Source(root, outputs["json"])
    verdicts = [
        ["R1 pointing", src.cell("r1_pass"), src.cell("ape_deg"),
         "APE < 0.05 deg over the window"],
        ["R2 jitter", src.cell("r2_pass"), src.cell("max_rate_error_deg_s"),
         "< 1e-3 deg/s at every record of the window"],
        ["R3 torque", src.cell("r3_pass"), src.cell("max_abs_torque_nm"),
         "≤ 2 N m per axis at every record of the run"],
    ]  # fmt: skip
    window = [
        ["observation window (start, end) [s]", src.cell("observation_window_s")],
        ["RPE over the window [deg]", src.cell("rpe_deg")],
        ["RPE averaging window [s]", src.cell("rpe_window_s")],
        ["pointing error at the end [deg]", src.cell("final_pointing_error_deg")],
        ["residual rate at the end [deg/s]", src.cell("final_rate_error_deg_s")],
    ]
    parts = [
        "<p>The nominal 45/45/45 deg slew with the adaptive sliding-mode law "
        "(thesis section 5.1), 120 s, disturbances at their maximum.</p>",
        "<p>R1 and R2 are judged over an observation window, from the scenario's "
        "settling deadline (90 s unless the scenario says otherwise) to the end of the "
        "run: the pointing error must stay below its band at every record of the window "
        "(its largest value there is the absolute performance error, APE, of "
        "ECSS-E-ST-60-10C), and so must the residual rate. A run planned to end before "
        "the window closes is not judged (neither pass nor fail); one that stops before "
        "it closes fails both. The relative performance error (RPE) is the largest "
        "distance of the error vector from its mean over consecutive windows of the "
        "stated duration: the pointing stability, bias removed. R3 holds at every "
        "record.</p>",
        _table(
            ["requirement", "verdict", "value over the window / peak", "bound"],
            verdicts,
            "Requirements (bounds of the thesis scenario)",
        ),
        _table(["quantity", "flexsat"], window, "Observation window and pointing errors"),
        _table(
            ["metric", "flexsat", "thesis", "thesis source"],
            _compare_rows(src, thesis.CLOSED_LOOP),
            "Slew metrics",
        ),
        _figures(root, outputs["figures"]),
    ]
    return "".join(parts)


def _comparison(root: Path, outputs: dict, context: dict) -> str:
    sources = {kind: _Source(root, rel) for kind, rel in outputs["runs"].items()}
    first = next(iter(sources.values()))
    keys = [k for k in first.data if k not in ("files", "message", "controller")]
    rows = [[key, *(src.cell(key) for src in sources.values())] for key in keys]
    labels = [get_law(kind).label if kind in law_names() else kind for kind in sources]
    header = ["metric", *labels]
    return "".join(
        [
            f"<p>The same slew, plant and disturbances flown by {', '.join(labels)} with their "
            "default gains; the first is the nominal slew's law.</p>",
            _table(header, rows, "Controller comparison"),
            _figures(root, outputs["figures"]),
        ]
    )


def _animation(root: Path, outputs: dict, context: dict) -> str:
    return (
        "<p>The nominal slew in 3D: hub, panels with their joint deformation magnified "
        "(factor in the frame), body axes and time.</p>" + _figures(root, outputs["figures"])
    )


def _frequency(root: Path, outputs: dict, context: dict) -> str:
    src = _Source(root, outputs["json"])
    keys = [
        ("phase_margin_deg", "phase margin [deg]"),
        ("gain_crossover_hz", "at [Hz]"),
        ("gain_margin", "gain margin [-] (— : infinite)"),
        ("phase_crossover_hz", "at [Hz]"),
        ("delay_margin_s", "delay margin [s]"),
        ("delay_crossover_hz", "at [Hz]"),
        ("crossovers_hz", "every gain crossover [Hz]"),
    ]
    rows = [[axis, *(src.cell("axes", axis, key) for key, _ in keys)] for axis in src.get("axes")]
    law = _esc(str(src.get("law")).upper())
    axes = src.get("axes")
    crossings = [
        [axis, *(src.cell("axes", axis, "crossovers", k, key)
                 for key in ("frequency_hz", "phase_margin_deg", "delay_margin_s")),
         "sets the delay margin" if c["frequency_hz"] == m["delay_crossover_hz"] else ""]
        for axis, m in axes.items() for k, c in enumerate(m.get("crossovers", []))
    ]  # fmt: skip
    peaks = [
        [axis, *(src.cell("axes", axis, "flexible_peaks", k, key)
                 for key in ("mode_hz", "peak_hz", "peak_gain_db", "stabilized"))]
        for axis, m in axes.items() for k in range(len(m.get("flexible_peaks", [])))
    ]  # fmt: skip
    return "".join([
        f"<p>The nominal slew's law ({law}) linearized about rest and closed around the "
        "flexible plant, one axis at a time (the loop broken at that axis's torque, the "
        "others closed); the sliding-mode laws inside their boundary layer with Λ and JK "
        "at their steady-state values. Bode plots compare the flexible plant with its "
        "rigid model (alternating pole–zero pairs of the flexible modes); the loop-gain "
        "figure marks the flexible modes (dotted), every 0 dB crossover with its phase "
        "margin, the crossover that sets the delay margin (red) and each flexible "
        "peak with its loop gain, so a flexible peak that crosses 0 dB shows as two "
        "extra crossovers and a smaller delay margin.</p>",
        _table(["axis", *(label for _, label in keys)], rows,
               f"Loop margins of the {law} law per axis", sortable=True),
        _table(["axis", "gain crossover [Hz]", "phase margin [deg]", "delay margin [s]", ""],
               crossings, "Every gain crossover: its phase margin and the delay that "
               "brings it onto −180°", sortable=True),
        "<p>A flexible mode is <em>gain-stabilized</em> when its peak loop gain stays "
        "below 0 dB, whatever its phase; <em>phase-stabilized</em> when the peak rises "
        "above 0 dB: it adds two gain crossovers, and the loop is stable only because "
        "the phase there keeps away from −180° (their margins above).</p>",
        _table(["axis", "mode [Hz]", "peak at [Hz]", "peak loop gain [dB]", "stabilized"],
               peaks, "Peak loop gain of each flexible mode seen by the loop", sortable=True),
        _figures(root, outputs["figures"]),
    ])  # fmt: skip


def _robust(root: Path, outputs: dict, context: dict) -> str:
    mu, rob = _Source(root, outputs["mu"]), _Source(root, outputs["json"])
    law = _esc(str(rob.get("law")).upper())
    bounds = [
        ["peak of the upper bound [-]", mu.cell("peak_upper")],
        ["frequency of the peak [Hz]", mu.cell("peak_frequency_hz")],
        ["lower bound [-]", mu.cell("lower")],
        ["frequency of the lower bound [Hz]", mu.cell("lower_frequency_hz")],
        ["upper bound at the lower bound's frequency [-]", rob.cell("upper_at_lower_frequency")],
        ["k_max certified, 1 / peak of the upper bound [-]", mu.cell("k_max_lower")],
        ["k_max at most, 1 / lower bound [-]", mu.cell("k_max_upper")],
        ["loop stable at the box's centre", mu.cell("nominal_stable")],
    ]
    worst = [
        [p["name"], mu.cell("parameters", i, "low"), mu.cell("parameters", i, "high"),
         mu.cell("worst_delta", i), mu.cell("worst_factors", p["name"])]
        for i, p in enumerate(mu.get("parameters"))
    ]  # fmt: skip
    resolution = rob.get("decay_resolution_1_s")
    sampling = [
        ["cases drawn in the certified box (k_max × the box)", rob.cell("samples")],
        ["unstable in the certified box", rob.cell("certified_unstable")],
        ["largest real part in the certified box [1/s]", rob.cell("certified_max_real_1_s")],
        ["cases drawn in the full box", rob.cell("samples")],
        ["unstable in the full box", rob.cell("box_unstable")],
        ["largest real part in the full box [1/s]", rob.cell("box_max_real_1_s")],
        ["the μ worst case's largest real part [1/s]",
         rob.cell("cases", "mu_worst", "max_real_1_s")],
        [f"the μ worst case flown decays no faster than the sampled one (within "
         f"{format_value(resolution)} 1/s)", rob.cell("mu_worst_decays_slowest")],
    ]  # fmt: skip
    names = [p["name"] for p in mu.get("parameters")]
    labels = {"mu_worst": "μ worst case", "sampled_worst": "sampled worst case"}
    flown = [
        [labels.get(case, case), *(rob.cell("cases", case, "factors", n) for n in names),
         rob.cell("cases", case, "max_real_1_s"), rob.cell("cases", case, "decay_rate_1_s")]
        for case in rob.get("cases")
    ]  # fmt: skip
    rho = ", ".join(format_value(r) for r in rob.get("started_rho_deg"))
    return "".join([
        f"<p>The nominal slew's law ({law}) linearized about rest (the sliding-mode laws "
        "inside their boundary layer) closed around the satellite's uncertain model, an "
        "upper LFT in the thesis's parameters (rotation-joint target frequencies ±20 %, "
        "damping ratio from 0 to the nominal, hub and panel inertias ±20 %; each a "
        "normalized δ in [−1, 1], the box's centre at δ = 0), at the configuration's "
        "SADM angle (docs/linear.md, 'Robust stability: mu'). The loop is stable for "
        "every parameter point within k × the box for every k below the certified "
        "k_max = 1 / peak of μ's upper bound; the lower bound is a destabilizing point "
        "found on the box's boundary, the worst-case parameter combination.</p>",
        _table(["quantity", "value"], bounds, f"μ bounds and k_max of the {law} loop"),
        _table(["parameter", "factor at δ = −1", "factor at δ = +1", "worst δ",
                "worst factor"], worst,
               "Worst-case parameter combination (the destabilizing point)"),
        f"<p>The sampling check, in the linear model (seed {_esc(rob.get('seed'))}): "
        "parameter points drawn uniformly in the certified box must all be stable, and "
        "no point of the full box may have a closed-loop pole further right than the μ "
        "worst case. Then the μ worst case and the sampled worst case (the drawn point "
        "with the rightmost pole) are flown in the nonlinear simulator: the law holding "
        f"rest, no disturbance torque, {_esc(rob.get('started_panel'))} started "
        f"{_esc(rho)} deg off about its root axes, {format_value(rob.get('flight_s'))} s; "
        "each compared by the slowest decay of the panels' vibration, from the elastic "
        "energy's envelope (its maximum over 10–20 s and over the last 10 s), which "
        "resolves decay rates to about "
        f"{format_value(resolution)} 1/s.</p>",
        _table(["check", "value"], sampling, "Sampling check in the linear model"),
        _table(["case", *(f"{n} factor" for n in names), "largest real part, linear [1/s]",
                "vibration decay rate, nonlinear [1/s]"], flown,
               "Worst cases flown in the nonlinear simulator"),
        _figures(root, outputs["figures"]),
    ])  # fmt: skip


def _pointing(root: Path, outputs: dict, context: dict) -> str:
    src = _Source(root, outputs["json"])
    names, window = src.get("outputs"), src.get("window_s")
    law = _esc(str(src.get("law")).upper())
    at = [["RMS", *(src.cell("rms_arcsec", n) for n in names)],
          [f"RPE RMS over {window:g} s",
           *(src.cell("rpe_rms_arcsec", n) for n in names)]]  # fmt: skip
    lines = [[f"line {k + 1}", src.cell("lines", k, "frequency_hz"),
              *(src.cell("lines", k, "amplitude_arcsec", n) for n in names)]
             for k in range(len(src.get("lines")))]  # fmt: skip
    worst = [[f"#{k + 1}", src.cell("worst", k, "speed_rpm"), src.cell("worst", k, "rms_arcsec")]
             for k in range(len(src.get("worst")))]  # fmt: skip
    return "".join([
        "<p>The four wheels spinning at their initial speed with an illustrative "
        "imbalance and harmonic table (docs/pointing.md, 'Microvibration': the "
        "empirical wheel model, its lines carried through the flexible satellite "
        f"linearized about rest, every flexible mode kept, the {law} law's loop closed "
        "through the wheels' motors). Each line is a sinusoid: its amplitude per hub "
        "axis, the RMS of all lines together, and their RPE, each record less the "
        f"mean of the {window:g} s window around it (the periodic column of "
        "docs/pointing.md, 'What each class adds to each index'). The sweep takes every "
        "wheel at one speed from 1 % of the wheels' limit to it; the Campbell diagram "
        "shows where a harmonic crosses a mode of the closed loop.</p>",
        _table(["", *(f"{n} [arcsec]" for n in names)], at,
               f"Microvibration jitter at {src.get('speed_rpm'):g} rpm, {law} loop"),
        _table(["line", "frequency [Hz]", *(f"{n} [arcsec]" for n in names)], lines,
               "Each line's amplitude per hub axis"),
        _table(["", "speed [rpm]", f"RPE RMS over {window:g} s, the axes together [arcsec]"],
               worst, "Worst wheel speeds of the sweep"),
        _figures(root, outputs["figures"]),
    ])  # fmt: skip


def _campaign_cases(root: Path, store: str) -> str:
    """Every case of a stored campaign, one row each, sortable by any column."""
    keys = ("final_pointing_error_deg", "ape_deg", "max_rate_error_deg_s", "settling_time_s",
            "r1_pass", "r2_pass", "r3_pass")  # fmt: skip
    rows = []
    for path in sorted((root / store / "cases").glob("*.json")):
        case = _Source(root, path.relative_to(root).as_posix())
        metrics = case.get("metrics") or {}
        cells = [case.cell("metrics", k) if k in metrics else "" for k in keys]
        rows.append([case.cell("case_id"), case.cell("status"), *cells])
    return _table(["case", "status", *keys], rows,
                  "Every case (click a column header to sort)", sortable=True)  # fmt: skip


def _rate_not_judged(summary: dict, key: str) -> bool:
    """Whether a campaign's pass rate ``key`` counts cases not judged (``r1_not_judged``):
    its null value then means that no case was judged."""
    return key.endswith("_pass_rate") and bool(
        summary.get(key.removesuffix("_pass_rate") + "_not_judged")
    )


_SUMMARY_TABLE_FIGURE = "summary_table.png"  # shown as the HTML tables above instead


def _campaign_worst(src: _Source) -> str:
    """The worst cases of a campaign by each requirement (R1, R2, R3) and by the final
    pointing error: failing cases first, then by the metric (``worst_by_requirement``)."""
    rows = []
    for g, group in enumerate(src.get("worst_by_requirement")):
        ranked_by = f"{group['metric']} [{group['unit']}]"
        failing = src.cell("worst_by_requirement", g, "failing") if group["verdict"] else "—"
        for i, case in enumerate(group["cases"]):
            verdict = (src.cell("worst_by_requirement", g, "cases", i, "passes")
                       if group["verdict"] else "—")  # fmt: skip
            value = src.cell("worst_by_requirement", g, "cases", i, "value")
            rows.append([group["requirement"], ranked_by, failing, str(i + 1), case["case_id"],
                         value, verdict])  # fmt: skip
    header = ["requirement", "ranked by", "failing cases", "rank", "case", "value", "verdict"]
    return _table(header, rows, "Worst cases per requirement (failing cases first)")


def _campaigns(root: Path, outputs: dict, context: dict) -> str:
    from flexsat.campaigns.runner import SUMMARY_ROWS

    parts = []
    for name, rel in outputs["summaries"].items():
        src = _Source(root, rel)
        # a summary written before a row was added has no value for it: left out
        rows = [[label, src.cell(key, not_judged=_rate_not_judged(src.data, key))]
                for key, label in SUMMARY_ROWS if key in src.data]  # fmt: skip
        store = Path(rel).parent.as_posix()
        parts.append(f"<h3>{_esc(name)}</h3>")
        counted = src.data.get("cases_text", f"{src.get('cases')} cases")
        parts.append(
            _table(
                ["quantity", "value"],
                rows,
                f"Campaign {name}, {counted} (store {store}: results.parquet, results.csv)",
            )
        )
        parts.append(_campaign_worst(src))
        parts.append(_campaign_cases(root, store))
        figures = [
            f
            for f in outputs["figures"]
            if f.startswith(store + "/") and not f.endswith(_SUMMARY_TABLE_FIGURE)
        ]
        parts.append(_figures(root, figures))  # fmt: skip
    return "".join(parts)


_LAW_ROWS = (
    ("cases", ("cases",)), ("failed", ("failed",)),
    ("R1 pass rate", ("r1_pass_rate",)), ("R2 pass rate", ("r2_pass_rate",)),
    ("R3 pass rate", ("r3_pass_rate",)),
    *((f"R1 settling {q} [s]", ("settling_time_s", q)) for q in ("min", "median", "p90", "max")),
    ("never in R1", ("settling_time_s", "never")),
    *((f"R2 settling {q} [s]", ("r2_settling_time_s", q))
      for q in ("min", "median", "p90", "max")),
    ("never in R2", ("r2_settling_time_s", "never")),
    ("peak tau_flex [N m]", ("peak_flex_torque_nm",)),
    ("peak tip displacement [m]", ("peak_tip_displacement_m",)),
    ("control energy median [J]", ("control_energy_j", "median")),
    ("control energy max [J]", ("control_energy_j", "max")),
    ("residual elastic energy median [J]", ("residual_elastic_energy_j", "median")),
    ("residual elastic energy max [J]", ("residual_elastic_energy_j", "max")),
)  # fmt: skip


def _laws(root: Path, outputs: dict, context: dict) -> str:
    src = _Source(root, outputs["json"])
    variants = src.get("variants")
    labels = [get_law(v).label if v in law_names() else v for v in variants]
    scope = ("the first case of each campaign (quick study)" if src.get("quick")
             else "every case of each campaign")  # fmt: skip
    parts = [
        f"<p>Each law with its default gains, and the ASMC with root actuators on the "
        f"panels (hybrid active damping), flown through {scope}. Control energy is "
        "the integral of |tau . omega|; residual elastic energy the largest elastic "
        "energy over the last 10 s. A campaign of slews from rest may fly the reduced "
        "model (root translations locked, 20 ms step: the verdicts of the laws it flies "
        "kept, peak tau_flex within 5.1 %, docs/campaigns.md, 'Reduced models'); each "
        "campaign names its model.</p>"
    ]
    models = src.data.get("models", {})
    for name in src.get("campaigns"):
        rows = [[label, *(src.cell("campaigns", name, v, *path) for v in variants)]
                for label, path in _LAW_ROWS]  # fmt: skip
        model = models.get(name, "full")
        full_too = [get_law(v).label if v in law_names() else v
                    for v in src.data.get("full_model_variants", {}).get(name, [])]  # fmt: skip
        model += f" model ({', '.join(full_too)} on the full one)" if full_too else " model"
        parts.append(f"<h3>{_esc(name)}</h3><p>Flown on the {_esc(model)}.</p>")
        parts.append(_table(["figure", *labels], rows, f"Laws over the {name} campaign"))
    return "".join(parts)


def _avionics(root: Path, outputs: dict, context: dict) -> str:
    from flexsat.study.avionics import SWEEP_HEADER, render_avionics

    def cell(relative, *path):
        return _Source(root, relative).cell(*path)

    side, sweep, sadm, sentence = render_avionics(root, outputs, cell)
    return "".join([
        "<p>The thesis's slew with a gyro, a star tracker, the MEKF and four reaction "
        "wheels beside the ideal loop, both against the thesis's disturbances at their "
        "maximum, then the ideal loop with a computational delay "
        "(docs/control.md, 'Avionics in the loop'), each delay called stable, in a limit "
        "cycle or diverging from its residual-rate envelope over the observation window "
        "(docs/control.md, 'Stability verdict of the delay sweep'). The figures: the "
        "stability boundary "
        "against delay, then the avionics run's attitude estimation (the MEKF's error "
        "inside its ±3σ, its NEES against the χ² interval) and its wheels (momentum, "
        "the fullest wheel against its limit).</p>",
        _table(["metric", "ideal", "avionics"], side, "Ideal loop and realistic avionics"),
        _table(list(SWEEP_HEADER), sweep, "Sweep over the computational delay"),
        _table(["metric", "arrays held", "arrays turning"], sadm,
               "Ideal loop, plates on a solar-array drive: held and turning") if sadm else "",
        f"<p>{_esc(sentence)}</p>",
        _figures(root, outputs["figures"]),
    ])  # fmt: skip


@dataclass(frozen=True)
class Section:
    """One section of the report: what it draws, from which part's outputs.

    Parameters
    ----------
    name : str
        The section's anchor.
    draw : callable
        ``draw(root, outputs, context) -> html`` gets the study folder, the part's
        outputs (the manifest's ``outputs`` of part ``part``) and the context
        (``source``, ``nominal``).
    part : str, optional
        The part whose outputs it draws; default: the section's name.
    title : str, optional
        Default: the part's title.
    caveat : str, optional
        Shown at the top of the section when the configuration is not the thesis's
        nominal case (its thesis values then do not apply as they are).
    """

    name: str
    draw: Callable[[Path, dict, dict], str]
    part: str | None = None  # default: the section's name
    title: str | None = None  # default: the part's title
    caveat: str | None = None


_THESIS_CAVEAT = (
    "This configuration is not the thesis's nominal case: the thesis's values beside "
    "flexsat's are those of its nominal satellite, given for orientation only."
)

SECTIONS: list[Section] = [
    Section("configuration", _configuration),
    Section("model", _model, part="modal", title="Model: M(0) and rigid inertia",
            caveat="Appendix B's matrix is the nominal satellite's: no comparison is made."),
    Section("modal", _modal, caveat=_THESIS_CAVEAT),
    Section("openloop", _openloop, caveat=_THESIS_CAVEAT),
    Section("slew", _slew, caveat=_THESIS_CAVEAT),
    Section("frequency", _frequency),
    Section("robust", _robust),
    Section("pointing", _pointing),
    Section("comparison", _comparison),
    Section("animation", _animation),
    Section("avionics", _avionics),
    Section("campaigns", _campaigns,
            caveat="The campaigns vary this configuration, not the thesis's nominal one: "
                   "their pass rates are not the thesis's chapter 5 results."),
    Section("laws", _laws,
            caveat="The laws fly this configuration's campaigns, not the thesis's nominal "
                   "ones."),
]  # fmt: skip
"""The report's sections, in order. A new section is one function and one entry here
(and, for new outputs, one part in :data:`flexsat.study.pipeline.PARTS`)."""


# -- page -----------------------------------------------------------------------------


def _draw(root: Path, section: Section, entry: dict | None, context: dict) -> str | None:
    """The body of ``section`` for a part that ran (None for one that failed or was
    skipped). A section that cannot be drawn fails its part: the entry is marked failed
    with the error and its traceback (the report's banner and ``study.json`` say so)
    and the body shows the error."""
    if entry is None or (entry["status"] != "ok" and not entry.get("report_failed")):
        return None
    try:
        return section.draw(root, entry["outputs"], context)
    except Exception as exc:  # the part is failed, the report still written
        error = f"the report's {section.name} section could not be drawn: {exc!r}"
        # an earlier section of the same part may have failed already: both errors kept
        entry.update(status="failed", report_failed=True,
                     error="; ".join(filter(None, [entry.get("error"), error])),
                     traceback="".join(filter(None, [entry.get("traceback"),
                                                     traceback.format_exc()])))  # fmt: skip
        return f"<div class='error'><p>This section could not be drawn: {_esc(repr(exc))}</p></div>"


def _section(root: Path, section: Section, number: int, entry: dict | None,
             context: dict, body: str | None = None) -> str:  # fmt: skip
    name = section.name
    title = f"{number}. {_title(section, entry)}"
    anchor = f'<section id="{name}"><h2>{_esc(title)}</h2>'
    if entry is None:
        return anchor + "<p class='error'>This part did not run (the study stopped).</p></section>"
    status = entry["status"]
    head = (
        f"<p class='meta'>{_badge(status)} "
        f"wall time {entry['wall_time_s']:.1f} s (compilation excluded)</p>"
    )
    if section.caveat and not context["nominal"]:
        head += f"<p class='caveat'>{_esc(section.caveat)}</p>"
    if status in ("skipped", "not run"):
        return anchor + head + f"<p class='note'>{_esc(entry['error'])}</p></section>"
    if status == "failed":
        trace = f"<pre>{_esc(entry['traceback'])}</pre>" if entry.get("traceback") else ""
        failure = (f"<div class='error'><p>This part failed: {_esc(entry['error'])}</p>{trace}"
                   "</div>")  # fmt: skip
        return anchor + head + failure + (body or "") + "</section>"
    return anchor + head + (body or "") + "</section>"


def _title(section: Section, entry: dict | None) -> str:
    return section.title or (entry["title"] if entry else section.name)


def _badge(status: str) -> str:
    """A part's status as a coloured badge (``not run``: class ``notrun``)."""
    return f"<span class='badge {status.replace(' ', '')}'>{_esc(status)}</span>"


def _summary(manifest: dict) -> str:
    """The parts' table: status, wall time and the estimate said before the study (a
    part that was not estimated, skipped or not run, shows a dash)."""
    estimate = manifest.get("estimate") or {}
    planned = estimate.get("parts", {})

    def said(seconds: float | None) -> str:
        return "—" if seconds is None else f"{seconds:.1f}"

    rows = []
    for entry in manifest["parts"]:
        name = entry["name"]
        rows.append(
            [
                f"<td><a href='#{name}'>{_esc(entry['title'])}</a></td>",
                f"<td>{_badge(entry['status'])}</td>",
                f"{entry['wall_time_s']:.1f}",
                said(planned.get(name)),
            ]
        )
    rows.append(["total", "", f"{manifest.get('total_wall_time_s', 0.0):.1f}",
                 said(estimate.get("total_s"))])  # fmt: skip
    if "compilation_s" in manifest:
        rows.append(["compilation, before the parts (not in their times)", "",
                     f"{manifest['compilation_s']:.1f}", ""])  # fmt: skip
    return _table(["part", "status", "wall time [s], compilation excluded", "estimate [s]"],
                  rows, "Parts of the study")  # fmt: skip


def write_report(study_dir: str | Path) -> Path:
    """Write ``study_dir/report.html`` from the study's manifest and outputs.

    Parameters
    ----------
    study_dir : str or Path
        A folder written by :func:`flexsat.study.run_study` (it holds ``study.json``).

    Returns
    -------
    Path
        The report's path.
    """
    from flexsat.config import nominal
    from flexsat.config.models import SatelliteConfig
    from flexsat.study.outputs import write_json

    root = Path(study_dir)
    manifest = json.loads((root / "study.json").read_text())
    redrawn = [entry for entry in manifest["parts"] if entry.pop("report_failed", False)]
    for entry in redrawn:  # failed by a section of an earlier report: drawn again
        entry.update(status="ok", error=None, traceback=None)
    entries = {entry["name"]: entry for entry in manifest["parts"]}
    context = {"source": manifest["config_source"], "nominal": False}
    config_entry = entries.get("configuration")
    if config_entry and config_entry["status"] == "ok":
        data = _Source(root, config_entry["outputs"]["json"]).get("config")
        context["nominal"] = SatelliteConfig.model_validate(data) == nominal()
    present = [
        (section, entries.get(section.part or section.name))
        for section in SECTIONS
        if (section.part or section.name) in entries
    ]
    bodies = [_draw(root, section, entry, context) for section, entry in present]
    if redrawn or any(entry.get("report_failed") for entry in manifest["parts"]):
        write_json(root / "study.json", manifest)  # the parts a section failed
    sections = [
        _section(root, section, k, entry, context, body)
        for k, ((section, entry), body) in enumerate(zip(present, bodies, strict=True), start=1)
    ]
    toc = "".join(
        f"<li><a href='#{section.name}'>{_esc(_title(section, entry))}</a></li>"
        for section, entry in present
    )
    failed = [e["title"] for e in manifest["parts"] if e["status"] == "failed"]
    banner = (
        f"<p class='problem'>Failed parts: {_esc(', '.join(failed))}.</p>"
        if failed
        else "<p class='success'>Every part that ran succeeded.</p>"
    )
    title = f"flexsat study — {manifest['config_name']}"
    page = f"""<!doctype html>
<html lang="en"><head><meta charset="utf-8">
<meta name="viewport" content="width=device-width, initial-scale=1">
<title>{_esc(title)}</title><style>{_CSS}</style></head>
<body><header><h1>{_esc(title)}</h1>
<p class="meta">flexsat {_esc(manifest["flexsat_version"])} · Python
{_esc(platform.python_version())} · {_esc(manifest["created_utc"])} ·
configuration from {_esc(manifest["config_source"])}{" · quick study" if manifest["quick"] else ""}
</p>{banner}</header>
<nav aria-label="contents"><h2>Contents</h2><ol>{toc}</ol></nav>
<main>{_summary(manifest)}{"".join(sections)}</main>
<div id="lightbox" hidden></div>
<footer><p>Every number above is read from the JSON files next to this report
(data-source and data-path on each cell). Units are SI unless a key or heading says
otherwise.</p></footer><script>{_SCRIPT}</script></body></html>
"""
    return write_text(root / "report.html", page)  # a link there is replaced, never followed


_CSS = """
body{font-family:system-ui,sans-serif;margin:0;color:#222;line-height:1.45}
header,main,footer{max-width:1400px;margin:0 auto;padding:0 2rem;width:100%;
  box-sizing:border-box}
@media (min-width:1500px){
  body{display:grid;grid-template-columns:17rem minmax(0,1fr);grid-template-areas:
    "nav header" "nav main" "nav footer"}
  header{grid-area:header} main{grid-area:main} footer{grid-area:footer}
  nav{grid-area:nav;position:sticky;top:0;align-self:start;max-height:100vh;overflow:auto;
    border-right:1px solid #dde;padding:1rem}
}
nav{padding:0 2rem;font-size:.9rem}
nav h2{font-size:1rem;border:none;margin:.5rem 0}
nav ol{padding-left:1.4rem;margin:0}
h1{font-size:1.8rem;margin-bottom:.2rem}
h2{border-bottom:2px solid #ccd;padding-bottom:.2rem;margin-top:2.5rem}
h3{margin-top:1.5rem}
table{border-collapse:collapse;margin:1rem 0;font-size:.9rem}
caption{text-align:left;font-weight:600;padding:.3rem 0}
th,td{border:1px solid #ccd;padding:.2rem .5rem;vertical-align:top}
th{background:#eef}
table.sortable th{cursor:pointer;user-select:none}
table.sortable th::after{content:" ⇅";color:#99a;font-size:.8em}
table.sortable th[aria-sort=ascending]::after{content:" ▲";color:#334}
table.sortable th[aria-sort=descending]::after{content:" ▼";color:#334}
td.num{text-align:right;font-variant-numeric:tabular-nums}
td.pass{color:#0a6b2d;font-weight:600}
td.notjudged{color:#555;font-style:italic}
td.fail{color:#b00020;font-weight:600}
.badge{border-radius:.3rem;padding:.05rem .4rem;font-size:.8rem;color:#fff}
.badge.ok{background:#0a6b2d}
.badge.failed{background:#b00020}
.badge.skipped{background:#a66a00}
.badge.notrun{background:#667}
.error,.problem{color:#b00020}
.error pre{color:#222;background:#fbeaea;padding:.5rem;overflow-x:auto;font-size:.75rem}
.success{color:#0a6b2d}
.note{color:#555;font-style:italic}
.caveat{background:#fff6e0;border-left:4px solid #a66a00;padding:.4rem .7rem}
.meta{color:#555}
.check{font-weight:600}
.figures{display:flex;flex-direction:column;gap:1.5rem;margin:1rem 0}
.pair{display:grid;grid-template-columns:repeat(auto-fit,minmax(420px,1fr));gap:1rem}
figure{margin:0}
figure img{display:block;width:100%;max-width:1300px;height:auto;border:1px solid #eee;
  cursor:zoom-in}
.pair figure img{max-width:700px}
figcaption{font-size:.85rem;color:#555}
.file{color:#999}
#lightbox{position:fixed;inset:0;background:rgba(20,20,30,.88);display:flex;
  align-items:center;justify-content:center;z-index:10;cursor:zoom-out}
#lightbox[hidden]{display:none}
#lightbox img{max-width:98vw;max-height:98vh;background:#fff}
footer{margin-top:3rem;color:#777;font-size:.8rem}
@media print{
  nav,#lightbox{display:none}
  header,main,footer{max-width:none;padding:0}
  body{font-size:10pt}
  h2{break-before:page;margin-top:0}
  figure,table,.pair{break-inside:avoid}
  figure img{max-width:100%;cursor:auto;border:none}
  .pair{grid-template-columns:1fr 1fr}
  table.sortable th::after{content:""}
}
"""

# Click a figure: the same image at full size over the page (click or Esc closes it).
# Click a sortable table's header: its rows sorted by that column (numbers by value).
_SCRIPT = """
(function(){
  var box=document.getElementById('lightbox');
  function close(){box.hidden=true;box.textContent='';}
  document.querySelectorAll('figure img').forEach(function(img){
    img.addEventListener('click',function(){
      var big=new Image();big.src=img.src;big.alt=img.alt;
      box.textContent='';box.appendChild(big);box.hidden=false;});
  });
  box.addEventListener('click',close);
  document.addEventListener('keydown',function(e){if(e.key==='Escape')close();});
  function key(cell){
    if(!cell)return [1,''];
    var v=cell.getAttribute('data-value');
    if(v!==null){try{var x=JSON.parse(v);if(typeof x==='number')return [0,x];
      if(typeof x==='boolean')return [0,x?1:0];}catch(err){}}
    return [1,cell.textContent.trim().toLowerCase()];
  }
  document.querySelectorAll('table.sortable').forEach(function(table){
    table.querySelectorAll('thead th').forEach(function(th,col){
      th.addEventListener('click',function(){
        var up=th.getAttribute('aria-sort')!=='ascending';
        table.querySelectorAll('thead th').forEach(function(o){o.removeAttribute('aria-sort');});
        th.setAttribute('aria-sort',up?'ascending':'descending');
        var body=table.tBodies[0];
        var rows=Array.prototype.slice.call(body.rows);
        rows.sort(function(a,b){
          var p=key(a.cells[col]),q=key(b.cells[col]);
          var c=p[0]-q[0]||(p[1]<q[1]?-1:p[1]>q[1]?1:0);
          return up?c:-c;});
        rows.forEach(function(r){body.appendChild(r);});
      });
    });
  });
})();
"""
