"""Seeded fuzz: 300 mutated satellite configs through the real entry point.

Each config is the nominal one with one to four values replaced by hostile ones
(numbers scaled by up to 1e+-3, extreme or non-finite numbers, markup, wrong types,
deleted or unknown keys), or its TOML text cut or corrupted. ``config show``,
``modal --json`` and the plain ``modal`` table must each end with exit code 0, or 2
and one message: no traceback, no hang.
"""

from __future__ import annotations

import traceback

import numpy as np

from tests.cli.harness import Hang, flexsat, to_toml
from tests.conftest import nominal_dict

SEED = 20261201
CASES = 300
COMMANDS = (["config", "show", "--json"], ["modal", "--json"], ["modal"])

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


def _mutate(rng: np.random.Generator) -> str:
    data = nominal_dict()
    paths = _leaf_paths(data)
    for _ in range(rng.integers(1, 5)):
        path = paths[rng.integers(len(paths))]
        node = data
        try:
            for part in path[:-1]:
                node = node[part]
            action = rng.integers(10)
            current = node[path[-1]]
            if action < 5 and isinstance(current, float):  # a valid type, an extreme size
                sign = rng.choice([1.0, 1.0, -1.0])
                node[path[-1]] = float(sign * current * 10.0 ** rng.uniform(-3, 3))
            elif action == 0 and isinstance(node, dict):
                node.pop(path[-1], None)
            elif action == 1 and isinstance(node, dict):
                node[f"unknown_{rng.integers(100)}"] = _hostile(rng)
            else:
                node[path[-1]] = _hostile(rng)
        except (KeyError, IndexError, TypeError):
            continue  # an earlier edit replaced a parent: skip this one
    text = to_toml(data)
    if rng.random() < 0.15:  # damaged text: cut, or one character replaced
        cut = int(rng.integers(len(text)))
        text = text[:cut] if rng.random() < 0.5 else text[:cut] + "\x01[\"]=" + text[cut + 1 :]
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
            if not outcome.stderr.startswith("error:") or len(outcome.stderr) > 3000:
                problems.append(f"{path.name}: not one bounded message: {outcome.stderr[:500]}")
    assert not problems, f"{len(problems)} of {CASES} failed (seed {SEED}):\n" + "\n".join(
        problems[:5]
    )
    assert refused > CASES // 3  # the mutations are hostile: most configs are refused
