"""Parameter modifiers: how a campaign case changes the satellite config and the scenario.

A modifier names a path in the plain-dict form of a config (``hub.mass_kg``,
``appendages[*].target_frequencies_hz.flapping``, ``initial.rate_deg_s[2]``; ``[*]``
means every element) and either sets or scales the value there, with a fixed
number or one drawn from a distribution. Derived paths are computed rather than
read: ``hub.inertia`` (scales the hub's inertia tensor, turning a cylinder into an
explicit inertia), ``appendages[*].inertia`` (scales a panel's mass and so its
inertia; the joints are re-tuned to keep their target frequencies, as the thesis
does), and each appendage model's own (:class:`~flexsat.dynamics.appendages.DerivedPath`):
a chain takes the plate's ``damping_ratio`` and ``target_frequencies_hz.<kind>``
(its ``sadm_angle_deg`` is a field, as the plate's), so the thesis's campaigns
disperse it too.
"""

from __future__ import annotations

import math
import re
from typing import Annotated, Any, Literal

import numpy as np
from pydantic import Field, ValidationError, model_validator
from scipy import special

from flexsat.config.models import HubConfig, _Frozen, table_model
from flexsat.dynamics.appendages import DerivedPath, appendage_model

__all__ = ["Modifier", "ModifierError", "apply_modifiers", "derived_path", "truncnormal_ppf"]

_NORMAL_REACH = 40.0
"""Standard deviations a normal draw is allowed to reach without overflowing a float:
a draw beyond 40 std has probability below 1e-300, so mean +- 40 std bounds it."""


class ModifierError(ValueError):
    """A modifier whose value does not fit the field it targets (the caller names the case)."""


def _is_number(value: Any) -> bool:
    """A finite real number (an int or a float, not a boolean)."""
    return (isinstance(value, int | float) and not isinstance(value, bool)
            and math.isfinite(value))  # fmt: skip


def _numeric(node: Any) -> bool:
    """A number, or a (nested) non-empty list of numbers: what ``op = "scale"`` scales."""
    if isinstance(node, list):
        return bool(node) and all(_numeric(item) for item in node)
    return isinstance(node, int | float) and not isinstance(node, bool)


_APPENDAGE = re.compile(r"appendages\[\d+\]")
_TOKEN = re.compile(r"([A-Za-z_][A-Za-z0-9_]*)|\[(\*|\d+)\]")


class Modifier(_Frozen):
    """Set or scale one config value, by a constant or a random draw.

    Give exactly one of ``value``, ``uniform``, ``normal``, ``truncnormal``.

    Parameters
    ----------
    path : str
        Config path; ``[*]`` targets every element of a list (each draws its own).
    op : {"set", "scale"}
        Set the value, or scale it by a factor.
    value : any
        A constant [the target's unit, or - for a factor].
    uniform : tuple of 2 float, optional
        (low, high) of a uniform draw [the target's unit, or -].
    normal : tuple of 2 float, optional
        (mean, std) of a normal draw [the target's unit, or -].
    truncnormal : tuple of 4 float, optional
        (mean, std, low, high) of a truncated normal draw [the target's unit, or -].
    """

    path: Annotated[str, Field(min_length=1)]
    op: Literal["set", "scale"] = "set"
    value: Any = None
    uniform: tuple[float, float] | None = None
    normal: tuple[float, float] | None = None
    truncnormal: tuple[float, float, float, float] | None = Field(
        None, description="(mean, std, low, high)"
    )

    @model_validator(mode="after")
    def _one_source(self) -> Modifier:
        given = [
            name for name in ("value", "uniform", "normal", "truncnormal")
            if getattr(self, name) is not None
        ]  # fmt: skip
        if len(given) != 1:
            raise ValueError(
                f"{self.path}: give exactly one of value, uniform, normal, truncnormal"
            )
        if self.uniform is not None and not self.uniform[0] < self.uniform[1]:
            raise ValueError(f"{self.path}: uniform bounds must satisfy low < high")
        if self.normal is not None and not self.normal[1] > 0:
            raise ValueError(f"{self.path}: normal std must be > 0")
        if self.truncnormal is not None:
            mean, std, low, high = self.truncnormal
            if not (std > 0 and low < high):
                raise ValueError(f"{self.path}: truncnormal needs std > 0 and low < high")
        self._finite_numbers()
        return self

    def _finite_numbers(self) -> None:
        """Refuse what no draw or scaling could turn into a number: non-finite
        parameters, a range wider than a float holds, a factor that is not a number."""
        for name in ("uniform", "normal", "truncnormal"):
            numbers = getattr(self, name)
            if numbers is not None and not all(math.isfinite(x) for x in numbers):
                raise ValueError(f"{self.path}: {name} takes finite numbers (|x| <= "
                                 f"{np.finfo(float).max:.4g}), got {list(numbers)}")  # fmt: skip
        if self.uniform is not None and not math.isfinite(self.uniform[1] - self.uniform[0]):
            raise ValueError(f"{self.path}: uniform = {list(self.uniform)} is wider than a float "
                             f"holds: high - low must be <= {np.finfo(float).max:.4g}")  # fmt: skip
        if self.normal is not None:
            mean, std = self.normal
            if not math.isfinite(abs(mean) + _NORMAL_REACH * std):
                limit = np.finfo(float).max
                raise ValueError(f"{self.path}: normal = {list(self.normal)}: |mean| + "
                                 f"{_NORMAL_REACH:g} std must be <= {limit:.4g}")  # fmt: skip
        if self.op == "scale" and self.value is not None and not _is_number(self.value):
            raise ValueError(f"{self.path}: op = 'scale' takes a finite number as its factor "
                             f"(value), got {_shown(self.value)}")  # fmt: skip

    def draw(self, rng: np.random.Generator) -> float | Any:
        """The number this modifier applies (constant, or one draw from ``rng``)."""
        if self.value is not None:
            return self.value
        if self.uniform is not None:
            return float(rng.uniform(*self.uniform))
        if self.normal is not None:
            return float(rng.normal(*self.normal))
        mean, std, low, high = self.truncnormal
        return truncnormal_ppf(rng.uniform(), mean, std, low, high)


def truncnormal_ppf(u: float, mean: float, std: float, low: float, high: float) -> float:
    """The ``u`` quantile of the normal (mean, std) truncated to [low, high].

    x = mean + std Phi^-1(Phi(a) + u (Phi(b) - Phi(a))), with a, b the standardized
    bounds, from scipy's ``ndtr`` and ``ndtri``, without the distribution machinery
    ``scipy.stats.truncnorm.ppf`` puts around the same quantile, which was a quarter of
    a campaign process's work per random case. An
    interval above the mean is mirrored below it, where Phi keeps its digits; a narrow
    one far in a tail, where Phi(b) - Phi(a) cancels, goes to ``truncnorm.ppf``.
    Agrees with ``truncnorm.ppf`` to 1e-12 std (``tests/campaigns/test_modifiers.py``).

    Parameters
    ----------
    u : float
        Probability in [0, 1] [-].
    mean, std : float
        Mean and standard deviation of the normal, std > 0 [unit of the parameter].
    low, high : float
        Bounds, low < high [unit of the parameter].

    Returns
    -------
    float
        The quantile, in [low, high] [unit of the parameter].
    """
    z = _standard_ppf(u, (low - mean) / std, (high - mean) / std)
    return float(min(max(mean + std * z, low), high))


def _standard_ppf(u: float, a: float, b: float) -> float:
    """The ``u`` quantile of the standard normal truncated to [a, b]."""
    if a > 0.0:  # the upper tail, mirrored: Phi near 1 would lose its digits
        return -_standard_ppf(1.0 - u, -b, -a)
    pa, pb = special.ndtr(a), special.ndtr(b)
    if not pb - pa > 1e-3 * pb:  # narrow and far out (or underflowed): cancellation
        # imported here: scipy.stats costs every campaign worker 0.3 s to import, and
        # only this rare branch needs it
        from scipy import stats

        return float(stats.truncnorm.ppf(u, a, b))
    return float(special.ndtri(pa + u * (pb - pa)))


def apply_modifiers(
    data: dict, modifiers: list[Modifier], rng: np.random.Generator, realised: dict
) -> dict:
    """A copy of ``data`` with the modifiers applied in order.

    Random values are drawn from ``rng`` once per targeted element, in order, so a
    case is reproducible from its seed; every applied value is recorded in
    ``realised`` under its concrete path.

    Parameters
    ----------
    data : dict
        A config as plain data (``model_dump``).
    modifiers : list of Modifier
        Applied in order.
    rng : numpy.random.Generator
        The case's generator.
    realised : dict
        Receives every applied value under its concrete path.

    Returns
    -------
    dict
        The modified copy.

    Raises
    ------
    KeyError
        If a path does not exist in ``data`` (the caller reports it).
    ModifierError
        If a value does not fit its target: a derived path (``hub.inertia``...) takes
        a finite number, ``op = "scale"`` a numeric field (the caller reports it).
    """
    data = _copied(data)
    for modifier in modifiers:
        for concrete, parent, key in _targets(data, modifier.path):
            value = modifier.draw(rng)
            derived = derived_path(concrete, parent, key)
            _check_fits(modifier, concrete, None if derived is not None else parent[key], derived,
                        value)  # fmt: skip
            if derived is not None:
                if modifier.op not in derived.ops:
                    raise KeyError(f"{concrete} takes op = {' or '.join(map(repr, derived.ops))}"
                                   f" on this appendage model, not {modifier.op!r}")  # fmt: skip
                _apply_derived(modifier, concrete, derived, parent, value)
            elif modifier.op == "scale":
                parent[key] = _scaled(parent[key], value)
            else:
                parent[key] = value
            realised[concrete] = value
    return data


def _check_fits(modifier: Modifier, concrete: str, current: Any, derived: DerivedPath | None,
                value: Any) -> None:  # fmt: skip
    """Refuse a value its target cannot take, naming the modifier and what it takes."""
    where = f"modifier {modifier.path!r} (op = {modifier.op!r})"
    if derived is not None:
        if not _is_number(value):
            what = "a scale factor" if derived.factor else "its value"
            raise ModifierError(f"{where}: {concrete} takes a finite number ({what}, |x| <= "
                                f"{np.finfo(float).max:.4g}), got {_shown(value)}")  # fmt: skip
    elif modifier.op == "scale" and not _numeric(current):
        raise ModifierError(f"{where}: {concrete} is {_shown(current)}, not a number or a "
                            "list of numbers: only numeric fields can be scaled (use op = "
                            "'set')")  # fmt: skip


def _apply_derived(modifier: Modifier, concrete: str, derived: DerivedPath, parent: dict,
                   value: float) -> None:  # fmt: skip
    """Compute a derived path; a table it cannot be computed from (refused by an
    earlier modifier's value) is named, as a refused value would be."""
    try:
        derived.apply(parent, value)
    except ValidationError as exc:
        first = exc.errors()[0]
        field = ".".join(str(part) for part in first["loc"])
        raise ModifierError(f"modifier {modifier.path!r}: {concrete} is computed from the "
                            f"values around it, and {field} = {_shown(first.get('input'))} is "
                            f"refused: {first['msg']}") from None  # fmt: skip


def _shown(value: Any) -> str:
    """A value for a message, cut to 60 characters."""
    text = repr(value)
    return text if len(text) <= 60 else text[:57] + "..."


def _copied(node: Any) -> Any:
    """A copy of plain data (dicts, lists and immutable leaves: a config's
    ``model_dump``): what ``copy.deepcopy`` gives, at a fifth of its cost (0.3 ms
    per config, in the campaign's main process for every case)."""
    if isinstance(node, dict):
        return {key: _copied(value) for key, value in node.items()}
    if isinstance(node, list):
        return [_copied(value) for value in node]
    return node


def _scaled(current: Any, factor: float) -> Any:
    if isinstance(current, list):
        return [_scaled(item, factor) for item in current]
    return current * factor


def _derived(prefix: str, node: Any) -> dict[str, DerivedPath]:
    """Derived paths under ``prefix``: ``hub.inertia``, and each appendage model's own."""
    if prefix == "hub":
        return {"inertia": DerivedPath(_scale_hub_inertia)}
    if _APPENDAGE.fullmatch(prefix) and isinstance(node, dict):
        return appendage_model(table_model(node)).modifiers
    return {}


def derived_path(concrete: str, parent: Any, key: Any) -> DerivedPath | None:
    """The derived path a target of :func:`_targets` names, or None for a config field.

    Parameters
    ----------
    concrete : str
        The target's concrete path (``appendages[0].target_frequencies_hz.flapping``).
    parent : dict or list
        The container the target sits in (for a derived path, the table it changes).
    key : str or int
        The target's key in ``parent`` (for a derived path, its possibly dotted name).

    Returns
    -------
    DerivedPath or None
        What computes the path, when ``parent`` has no field ``key``.
    """
    if not isinstance(parent, dict) or key in parent:
        return None
    return _derived(concrete[: -len(key) - 1], parent).get(key)


def _scale_hub_inertia(hub: dict, factor: float) -> None:
    inertia = HubConfig.model_validate(hub).inertia() * factor
    hub.pop("radius_m", None)
    hub.pop("height_m", None)
    hub["inertia_kg_m2"] = inertia.tolist()


def _targets(data: dict, path: str):
    """(concrete path, parent container, key) for every element the path names."""
    tokens = _TOKEN.findall(path)
    if "".join(name or f"[{index}]" for name, index in tokens) != path.replace(".", ""):
        raise KeyError(f"malformed path {path!r}")
    nodes = [("", data)]
    for k, (name, index) in enumerate(tokens):
        last = k == len(tokens) - 1
        following = []
        for prefix, node in nodes:
            if name:
                if not isinstance(node, dict):
                    raise KeyError(f"{prefix!r} has no fields, in {path!r}")
                if name not in node:  # a derived path, its name the rest of the path
                    rest = [part for part, _ in tokens[k:]]
                    dotted = ".".join(rest) if all(rest) else None
                    if dotted not in _derived(prefix, node):
                        raise KeyError(_missing(name, prefix, node, path))
                    yield f"{prefix}.{dotted}" if prefix else dotted, node, dotted
                    continue
                concrete = f"{prefix}.{name}" if prefix else name
                if last:
                    yield concrete, node, name
                else:
                    following.append((concrete, node[name]))
            else:
                if not isinstance(node, list):
                    raise KeyError(f"{prefix!r} is not a list in {path!r}")
                indices = range(len(node)) if index == "*" else [int(index)]
                for i in indices:
                    if i >= len(node):
                        raise KeyError(f"index {i} out of range at {prefix!r} in {path!r}")
                    if last:
                        yield f"{prefix}[{i}]", node, i
                    else:
                        following.append((f"{prefix}[{i}]", node[i]))
        nodes = following


def _missing(name: str, prefix: str, node: dict, path: str) -> str:
    """The message for a path that names no field: what the table offers instead."""
    where = prefix or "the top level"
    derived = sorted(_derived(prefix, node))
    if _APPENDAGE.fullmatch(prefix):
        model = table_model(node)
        fields = sorted(_leaves(node))
        return (f"no {name!r} at {where} (a {model!r} appendage) of {path!r}: its paths are "
                f"{', '.join(fields + derived)}")  # fmt: skip
    return f"no {name!r} at {where} of {path!r}"


def _leaves(table: dict) -> list[str]:
    """The paths of a table's numbers, one level of nesting deep (for :func:`_missing`)."""
    out = []
    for key, value in table.items():
        if isinstance(value, dict):
            out += [f"{key}.{sub}" for sub, leaf in value.items() if isinstance(leaf, int | float)]
        elif isinstance(value, list | tuple):
            if value and all(isinstance(leaf, int | float) for leaf in value):
                out.append(f"{key}[i]")
        elif isinstance(value, int | float) and not isinstance(value, bool):
            out.append(key)
    return out
