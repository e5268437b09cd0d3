"""Seeded fuzz: 300 mutated satellite configs through the real entry point, and 400
mutated modal data files through the loader.

Each config is the nominal one with one to four values replaced by hostile ones
(numbers scaled by up to 1e+-3, extreme or non-finite numbers, markup, wrong types,
deleted or unknown keys), or its TOML text cut or corrupted. ``config show``,
``modal --json`` and the plain ``modal`` table must each end with exit code 0, or 2
and one message: no traceback, no hang.

Each modal data file (docs/modal_format.md) is a small valid one, TOML or NPZ, with
values replaced (hostile numbers, wrong dtypes and shapes, deleted or unknown keys),
an NPZ header forged to ask for far more than the file holds, or its bytes flipped or
cut. :func:`~flexsat.config.modal_data.load_modal_data` is called in this process (the
command line turns its ``ConfigError`` into exit code 2): each file loads or raises
``ConfigError`` with a message, nothing else.
"""

from __future__ import annotations

import io
import signal
import traceback
import zipfile

import numpy as np

from flexsat.config.modal_data import load_modal_data
from flexsat.errors import ConfigError
from tests.cli.harness import Hang, flexsat, modal_table, npz_bytes, to_toml
from tests.conftest import nominal_dict

SEED = 20261201
CASES = 300
COMMANDS = (["config", "show", "--json"], ["modal", "--json"], ["modal"])
# What flexsat prints on stderr when the compiled kernels are not cached yet.
COMPILING = "compiling the dynamics kernels (first run only, cached on disk)...\n"

_NUMBERS = [0, -1, 1, 0.0, -0.0, 5e-324, 1e-300, 1e-12, 1.34e154, 1e200, 1e308, 1.7e308,
            float("inf"), float("-inf"), float("nan"), 10**30, -(10**18)]  # fmt: skip
_STRINGS = ["", "[/x]", "[/]p2", "[bold]", "$x$", "$\\frac{", "0.6", "true", "x" * 300,
            "../../etc", "nom\u00e9", "\u540d", "a b", "{}", "%s%n"]  # fmt: skip


def _leaf_paths(node, prefix=()) -> list[tuple]:
    """Every path to a value of the nominal config, containers included."""
    paths = [prefix] if prefix else []
    if isinstance(node, dict):
        for key, value in node.items():
            paths += _leaf_paths(value, (*prefix, key))
    elif isinstance(node, list):
        for index, value in enumerate(node):
            paths += _leaf_paths(value, (*prefix, index))
    return paths


def _hostile(rng: np.random.Generator):
    kind = rng.integers(7)
    if kind == 0:
        return _NUMBERS[rng.integers(len(_NUMBERS))]
    if kind == 1:
        return float(rng.normal() * 10.0 ** rng.uniform(-12, 12))
    if kind == 2:
        return _STRINGS[rng.integers(len(_STRINGS))]
    if kind == 3:
        return bool(rng.integers(2))
    if kind == 4:
        return [float(v) for v in rng.normal(size=rng.integers(0, 5)) * 10.0 ** rng.uniform(-3, 3)]
    if kind == 5:
        return [[1.0, 0.0, 0.0], [0.0, 1.0], []][rng.integers(3)]
    return {} if rng.integers(2) else {"x": 1}


def _edit_table(data: dict, rng: np.random.Generator, edits: int, actions: tuple, scale) -> None:
    """Up to ``edits - 1`` random edits of ``data`` in place, each at a random leaf.

    ``actions = (n, scaled, removed, unknown)``: an action drawn in ``range(n)`` below
    ``scaled`` rescales a float leaf with ``scale(value, rng)``; ``removed`` drops the
    key, ``unknown`` adds an unknown key beside it; any other puts a hostile value there.
    """
    n, scaled, removed, unknown = actions
    paths = _leaf_paths(data)
    for _ in range(rng.integers(1, edits)):
        path = paths[rng.integers(len(paths))]
        node = data
        try:
            for part in path[:-1]:
                node = node[part]
            action = rng.integers(n)
            current = node[path[-1]]
            if action < scaled and isinstance(current, float):
                node[path[-1]] = scale(current, rng)
            elif action == removed and isinstance(node, dict):
                node.pop(path[-1], None)
            elif action == unknown and isinstance(node, dict):
                node[f"unknown_{rng.integers(100)}"] = _hostile(rng)
            else:
                node[path[-1]] = _hostile(rng)
        except (KeyError, IndexError, TypeError):
            continue  # an earlier edit replaced a parent: skip this one


def _extreme_size(value: float, rng: np.random.Generator) -> float:
    """A valid type, an extreme size: the value scaled by up to 1e+-3, its sign flipped at times."""
    sign = rng.choice([1.0, 1.0, -1.0])
    return float(sign * value * 10.0 ** rng.uniform(-3, 3))


def _mutate(rng: np.random.Generator) -> str:
    data = nominal_dict()
    _edit_table(data, rng, 5, (10, 5, 0, 1), _extreme_size)
    text = to_toml(data)
    if rng.random() < 0.15:  # damaged text: cut, or one character replaced
        cut = int(rng.integers(len(text)))
        text = text[:cut] if rng.random() < 0.5 else text[:cut] + '\x01["]=' + text[cut + 1 :]
    return text


def test_mutated_configs_never_give_a_traceback_or_hang(tmp_path, capsys):
    rng = np.random.default_rng(SEED)
    problems, refused = [], 0
    for k in range(CASES):
        path = tmp_path / f"fuzz_{k:03d}.toml"
        path.write_text(_mutate(rng), encoding="utf-8")
        command = COMMANDS[k % len(COMMANDS)]
        try:
            outcome = flexsat([*command, "--config", str(path)], capsys, timeout_s=30)
        except Hang as exc:
            problems.append(f"{path.name}: {exc}")
            continue
        except Exception:  # a traceback: record it with the input that caused it
            problems.append(f"{path.name} ({' '.join(command)}): {traceback.format_exc()}")
            continue
        if outcome.code not in (0, 2) or "Traceback" in outcome.stderr:
            problems.append(f"{path.name}: exit {outcome.code}: {outcome.stderr[:500]}")
        elif outcome.code == 2:
            refused += 1
            # a cold numba cache adds its one-line notice before the kernels are built
            message = outcome.stderr.removeprefix(COMPILING)
            if not message.startswith("error:") or len(message) > 3000:
                problems.append(f"{path.name}: not one bounded message: {outcome.stderr[:500]}")
    assert not problems, f"{len(problems)} of {CASES} failed (seed {SEED}):\n" + "\n".join(
        problems[:5]
    )
    assert refused > CASES // 3  # the mutations are hostile: most configs are refused


MODAL_SEED = 20261207
MODAL_CASES = 400
_DTYPES = (np.int32, np.int64, np.float16, np.float32, np.complex128, np.bool_, "U8", "S8",
           "datetime64[s]", "<f8", ">f8")  # fmt: skip


def _valid_arrays() -> dict[str, np.ndarray]:
    from flexsat.config.modal_data import modal_data_from_dict

    return modal_data_from_dict(modal_table()).to_arrays()


def _forged_member(key: str, rng: np.random.Generator) -> bytes:
    """A .npy member whose header asks for a shape its data does not hold."""
    shape = tuple(
        int(v) for v in rng.integers(1, 10 ** rng.integers(1, 7), size=rng.integers(1, 4))
    )
    header = io.BytesIO()
    np.lib.format.write_array_header_1_0(
        header, {"descr": "<f8", "fortran_order": False, "shape": shape}
    )
    return header.getvalue() + b"\0" * int(rng.integers(0, 4096))


def _modal_npz(rng: np.random.Generator) -> bytes:
    arrays = _valid_arrays()
    forged = {}
    for _ in range(rng.integers(1, 4)):
        key = list(arrays)[rng.integers(len(arrays))]
        action = rng.integers(9)
        value = arrays[key]
        if action == 0:  # another dtype
            try:
                arrays[key] = value.astype(_DTYPES[rng.integers(len(_DTYPES))])
            except (TypeError, ValueError):
                arrays[key] = np.array("x")
        elif action == 1:  # a 0-d array
            arrays[key] = np.array(value.ravel()[0] if value.size else 1.0)
        elif action == 2:  # another shape
            arrays[key] = np.atleast_1d(value)[..., None] if rng.random() < 0.5 else value.T
        elif action == 3:  # cut along the first axis
            arrays[key] = np.atleast_1d(value)[: int(rng.integers(0, max(value.size, 1)))]
        elif action == 4:  # hostile numbers
            if value.dtype.kind == "f" and value.size:
                flat = value.astype(float).ravel()
                flat[rng.integers(flat.size)] = _NUMBERS[rng.integers(len(_NUMBERS))]
                arrays[key] = flat.reshape(value.shape)
        elif action == 5:
            arrays.pop(key)
        elif action == 6:
            arrays[f"unknown_{rng.integers(100)}"] = np.zeros(int(rng.integers(0, 5)))
        elif action == 7:  # a header asking for far more than the data
            forged[key] = _forged_member(key, rng)
        else:  # Python objects (refused: never unpickled)
            arrays[key] = np.array([{"x": 1}], dtype=object)
    data = npz_bytes(arrays)
    if forged:
        buffer = io.BytesIO()
        with zipfile.ZipFile(io.BytesIO(data)) as source, zipfile.ZipFile(buffer, "w") as out:
            for info in source.infolist():
                key = info.filename.removesuffix(".npy")
                out.writestr(info.filename, forged.get(key, source.read(info)))
        data = buffer.getvalue()
    return data


def _modal_toml(rng: np.random.Generator) -> bytes:
    data = modal_table()
    _edit_table(data, rng, 4, (8, 3, 3, 4),
                lambda value, rng: float(value * 10.0 ** rng.uniform(-300, 300)))  # fmt: skip
    return to_toml(data).encode()


def _damaged(content: bytes, rng: np.random.Generator) -> bytes:
    """``content`` cut short, or with a few bytes flipped."""
    if rng.random() < 0.4:
        return content[: int(rng.integers(len(content)))]
    flipped = bytearray(content)
    for _ in range(rng.integers(1, 9)):
        flipped[rng.integers(len(flipped))] ^= 1 << int(rng.integers(8))
    return bytes(flipped)


def test_mutated_modal_data_files_load_or_give_one_message(tmp_path):
    rng = np.random.default_rng(MODAL_SEED)
    print(f"seed {MODAL_SEED}")
    problems, refused = [], 0

    def hang(signum, frame):
        raise Hang("ran more than 10 s")

    previous = signal.signal(signal.SIGALRM, hang)
    try:
        for k in range(MODAL_CASES):
            npz = k % 2 == 1
            content = _modal_npz(rng) if npz else _modal_toml(rng)
            if rng.random() < 0.3:
                content = _damaged(content, rng)
            path = tmp_path / f"modal_{k:03d}.{'npz' if npz else 'toml'}"
            path.write_bytes(content)
            signal.alarm(10)
            try:
                load_modal_data(path)
            except ConfigError as exc:
                refused += 1
                if not str(exc) or len(str(exc)) > 3000:
                    problems.append(f"{path.name}: not one bounded message: {str(exc)[:300]}")
            except Exception:  # anything else: record it with the input that caused it
                problems.append(f"{path.name}: {traceback.format_exc()}")
            finally:
                signal.alarm(0)
    finally:
        signal.signal(signal.SIGALRM, previous)
    assert not problems, f"{len(problems)} of {MODAL_CASES} failed (seed {MODAL_SEED}):\n" + (
        "\n".join(problems[:5])
    )
    assert refused > MODAL_CASES // 2  # most mutations are hostile
    assert refused < MODAL_CASES  # and some harmless: the valid files do load


# --- campaign files -------------------------------------------------------------------

CAMPAIGN_SEED = 20261207
CAMPAIGN_CASES = 320

_PATHS = ["hub.mass_kg", "hub.inertia", "hub", "hub.radius_m", "appendages", "appendages[*]",
          "appendages[0].name", "appendages[*].inertia", "appendages[9].inertia",
          "appendages[*].target_frequencies_hz", "appendages[*].target_frequencies_hz.flapping",
          "appendages[*].sadm_angle_deg", "appendages[*].damping_ratio", "appendages[*].model",
          "initial.rate_deg_s", "initial.rate_deg_s[7]", "initial.rate_deg_s[*]",
          "initial.appendages", "actuator.gain[*]", "disturbances.sloshing_ratio",
          "duration_s", "dt_s", "[*]", "hub..mass_kg", "hub.mass_kg[0]", "", "x" * 200,
          "appendages[-1].inertia", "controller.kind"]  # fmt: skip
_SOURCES = ("value", "uniform", "normal", "truncnormal")


def _trimmed(name: str) -> dict:
    """A preset as plain data, its cases cut to a few (every structure kept) so that
    checking a mutation resolves a handful of cases, not dozens."""
    import tomllib
    from importlib import resources

    preset = resources.files("flexsat.campaigns") / "presets" / f"{name}.toml"
    data = tomllib.loads(preset.read_text(encoding="utf-8"))
    data["cases"] = data.get("cases", [])[:3]
    for axis in data.get("grid", {}).get("axes", []):
        axis["levels"] = axis["levels"][:2]
    if "random" in data:
        data["random"]["n"] = 2
    return data


def _search_base() -> dict:
    """A worst-case search (no preset has one): its parameters' bounds mutated too."""
    return {"name": "search", "base": {"duration_s": 120.0},
            "worst_case": {"metric": "final_pointing_error_deg", "maxiter": 2, "parameters": [
                {"path": "hub.mass_kg", "bounds": [120.0, 180.0]},
                {"path": "appendages[*].sadm_angle_deg", "bounds": [0.0, 90.0]},
                {"path": "hub.inertia", "op": "scale", "bounds": [0.8, 1.2]}]}}  # fmt: skip


def _hostile_modifier(rng: np.random.Generator) -> dict:
    """A modifier of a random path, op and value source, each possibly hostile."""
    modifier = {"path": _PATHS[rng.integers(len(_PATHS))]}
    if rng.random() < 0.7:
        modifier["op"] = ["set", "scale", "set", "scale", "set", "scale", "add", 3][rng.integers(8)]
    source = _SOURCES[rng.integers(len(_SOURCES))]
    sizes = {"value": None, "uniform": 2, "normal": 2, "truncnormal": 4}
    if sizes[source] is None and rng.random() < 0.5:  # a plausible number
        modifier[source] = float(rng.choice([-1.0, 1.0]) * 10.0 ** rng.uniform(-3, 3))
    elif sizes[source] is None or rng.random() < 0.2:
        modifier[source] = _hostile(rng)
    else:
        modifier[source] = [_NUMBERS[rng.integers(len(_NUMBERS))] if rng.random() < 0.4
                            else float(rng.normal() * 10.0 ** rng.uniform(-3, 3))
                            for _ in range(sizes[source])]  # fmt: skip
    return modifier


def _mutate_campaign(rng: np.random.Generator, bases: list[dict]) -> str:
    import copy

    data = copy.deepcopy(bases[rng.integers(len(bases))])
    lists = [p for p in _leaf_paths(data) if p[-1] in ("plant", "scenario", "parameters")]
    if lists and rng.random() < 0.5:  # one modifier added or replaced, the rest intact
        where = lists[rng.integers(len(lists))]
        node = data
        for part in where:
            node = node[part]
        modifier = _hostile_modifier(rng)
        if where[-1] == "parameters":  # a search's parameter: a path, an op and bounds
            low = float(rng.normal() * 10.0 ** rng.uniform(-3, 3))
            modifier = {"path": modifier["path"], "op": modifier.get("op", "set"),
                        "bounds": [low, low + 10.0 ** rng.uniform(-3, 3)]}  # fmt: skip
        if node and rng.random() < 0.5:
            node[rng.integers(len(node))] = modifier
        else:
            node.append(modifier)
        return to_toml(data)
    for _ in range(rng.integers(1, 3)):
        paths = _leaf_paths(data)
        path = paths[rng.integers(len(paths))]
        node = data
        try:
            for part in path[:-1]:
                node = node[part]
            action = rng.integers(10)
            current = node[path[-1]]
            if (
                action < 3
                and isinstance(current, list)
                and (not current or (isinstance(current[0], dict) and "path" in current[0]))
            ):
                current.append(_hostile_modifier(rng))  # a list of modifiers: one more
            elif action < 3 and isinstance(current, dict) and "path" in current:
                node[path[-1]] = _hostile_modifier(rng)  # fmt: skip
            elif action < 5 and isinstance(current, float | int) and not isinstance(current, bool):
                node[path[-1]] = (
                    current * float(rng.choice([-1.0, 1.0])) * 10.0 ** rng.uniform(-300, 300)
                )
            elif action == 5 and isinstance(node, dict):
                node.pop(path[-1], None)
            elif action == 6 and isinstance(node, dict):
                node[f"unknown_{rng.integers(100)}"] = _hostile(rng)
            elif action == 7 and path[-1] == "path":
                node[path[-1]] = _PATHS[rng.integers(len(_PATHS))]
            else:
                node[path[-1]] = _hostile(rng)
        except (KeyError, IndexError, TypeError):
            continue  # an earlier edit replaced a parent: skip this one
    text = to_toml(data)
    if rng.random() < 0.1:  # damaged text: cut, or one character replaced
        cut = int(rng.integers(len(text)))
        text = text[:cut] if rng.random() < 0.5 else text[:cut] + '\x01["]=' + text[cut + 1 :]
    return text


def test_mutated_campaigns_are_refused_in_one_message_before_any_case_runs(tmp_path):
    """Campaign files (the presets, cut to a few cases, and a worst-case search) with one
    to three values, modifiers or keys made hostile, or their text damaged, go through
    what ``flexsat campaign`` checks before any case runs (in this process: the cases
    are resolved, never flown): each is accepted or refused with a FlexsatError of
    exit code 2 and one bounded message, never another exception."""
    from flexsat.campaigns.definition import CAMPAIGN_PRESETS, CaseStream, load_campaign
    from flexsat.campaigns.worstcase import check_search
    from flexsat.config import nominal
    from flexsat.errors import FlexsatError

    print(f"campaign fuzz seed {CAMPAIGN_SEED}")
    satellite = nominal()
    bases = [_trimmed(name) for name in CAMPAIGN_PRESETS] + [_search_base()]
    rng = np.random.default_rng(CAMPAIGN_SEED)
    problems, refused = [], 0
    for k in range(CAMPAIGN_CASES):
        path = tmp_path / f"campaign_{k:03d}.toml"
        path.write_text(_mutate_campaign(rng, bases), encoding="utf-8")
        try:
            definition = load_campaign(path)
            if definition.worst_case is not None:
                check_search(definition, definition.worst_case, satellite)
            else:  # a preset's own count of random cases, cut to 2 (each is resolved alike)
                CaseStream(definition, satellite, None if definition.random is None else 2)
        except FlexsatError as exc:
            refused += 1
            message = str(exc)
            if exc.exit_code != 2 or not message or len(message) > 3000:
                problems.append(f"{path.name}: exit {exc.exit_code}, message {message[:300]!r}")
        except Exception:  # a traceback: record it with the input that caused it
            problems.append(
                f"{path.name}: {traceback.format_exc()[-1500:]}\n{path.read_text()[:1500]}"
            )
    assert not problems, (
        f"{len(problems)} of {CAMPAIGN_CASES} failed (seed {CAMPAIGN_SEED}):\n"
        + "\n".join(problems[:3])
    )
    assert refused > CAMPAIGN_CASES // 3  # the mutations are hostile: most are refused
