"""Loading satellite configurations from TOML, with one clear message per mistake."""

from __future__ import annotations

import difflib
import tomllib
from importlib import resources
from pathlib import Path
from typing import Any

from pydantic import BaseModel, Tag, ValidationError

from flexsat.config.models import SatelliteConfig, appendage_config_class, table_model
from flexsat.errors import ConfigError, shorten
from flexsat.files import read_user_file

__all__ = [
    "PRESETS",
    "TEMPLATES",
    "load_config",
    "nominal",
    "preset_path",
    "read_toml",
    "templates",
    "validate_config",
]

TEMPLATES = {
    "nominal": "satellite: the thesis's case study, table 3.1 (--config FILE)",
    "chain": "satellite: the nominal hub, each panel an 8-segment chain (--config FILE)",
    "openloop": "open-loop scenario: the thesis's 1 N m yaw pulse (openloop --scenario FILE)",
    "slew": "slew scenario, every loop stage documented (slew --scenario FILE)",
    "avionics-slew": "slew scenario with gyro, star tracker, MEKF and reaction wheels "
    "(slew --scenario FILE)",
    "campaign-cases": "campaign of explicit cases, one change each (campaign FILE)",
    "campaign-grid": "campaign crossing the levels of several axes (campaign FILE)",
    "campaign-random": "Monte Carlo campaign, values drawn per case (campaign FILE)",
}
"""What each shipped TOML template is (and the option that reads it), by name: the
curated lines :func:`templates` lists first."""
TEMPLATES_DIR = Path(str(resources.files("flexsat.config") / "presets"))
"""The folder of the shipped templates: each ``<name>.toml`` is the template ``name``."""
PRESETS = ("nominal", "chain")
"""The satellite presets among :data:`TEMPLATES`."""
_MAX_REPORTED = 3  # problems listed in one error message


def templates() -> dict[str, str]:
    """Every shipped template, found in :data:`TEMPLATES_DIR`: name -> what it is.

    Returns
    -------
    dict of str to str
        Those of :data:`TEMPLATES`, in its order, with its lines; then any other TOML
        file of the folder, sorted, described by the first line of its header comment.
    """
    found = {path.stem: path for path in TEMPLATES_DIR.glob("*.toml")}
    listed = {name: line for name, line in TEMPLATES.items() if name in found}
    for name in sorted(set(found) - set(listed)):
        header = [line.lstrip("#").strip() for line in found[name].read_text().splitlines()
                  if line.startswith("#")]  # fmt: skip
        listed[name] = header[0] if header else ""
    return listed


def preset_path(name: str) -> Path:
    """Path of a shipped template TOML file (a name of :func:`templates`; copy it to edit).

    Parameters
    ----------
    name : str
        The template's name, e.g. ``"nominal"``.

    Returns
    -------
    Path

    Raises
    ------
    ConfigError
        If ``name`` is not a template; the message lists them.
    """
    available = templates()
    if name not in available:
        raise ConfigError(f"unknown preset {name!r}; available: {', '.join(available)}")
    return TEMPLATES_DIR / f"{name}.toml"


def nominal() -> SatelliteConfig:
    """The nominal case study of the reference thesis (table 3.1), the built-in default."""
    return load_config(preset_path("nominal"))


def load_config(path: str | Path | None = None) -> SatelliteConfig:
    """Read and validate a satellite configuration.

    Parameters
    ----------
    path : str or Path, optional
        TOML file; ``None`` gives the built-in nominal case study.

    Raises
    ------
    ConfigError
        If the file is missing or unreadable, or any field is invalid; the message
        names the field and the allowed range.

    Notes
    -----
    A file an appendage table names (``file = "wing.npz"``) is relative to the
    folder of this TOML file, not to the working directory.
    """
    if path is None:
        return nominal()
    data = _files_beside(read_toml(path, "config"), Path(path).parent)
    return validate_config(data, source=str(path))


def _files_beside(data: dict[str, Any], folder: Path) -> dict[str, Any]:
    """``data`` with each appendage table's relative ``file`` joined to ``folder``."""
    appendages = data.get("appendages")
    if not isinstance(appendages, list):
        return data
    resolved = []
    for table in appendages:
        name = table.get("file") if isinstance(table, dict) else None
        if isinstance(name, str) and name and not Path(name).is_absolute():
            table = {**table, "file": str(folder / name)}
        resolved.append(table)
    return {**data, "appendages": resolved}


def read_toml(path: str | Path, what: str = "config") -> dict[str, Any]:
    """Parse a TOML file, turning a missing, unreadable or malformed file into a ConfigError.

    Only a regular file of at most :data:`flexsat.files.MAX_INPUT_BYTES` is read
    (:func:`flexsat.files.read_user_file`): a FIFO, a device or a folder is refused.

    Parameters
    ----------
    path : path
        The file.
    what : str
        What the file holds, for the message (``"config"``, ``"scenario"``...).

    Returns
    -------
    dict
        The parsed tables.
    """
    path = Path(path)
    text = read_user_file(path, what)  # a regular file of at most MAX_INPUT_BYTES only
    try:
        return tomllib.loads(text.decode("utf-8"))
    except UnicodeDecodeError as exc:
        raise ConfigError(f"cannot read {what} file {path}: {exc}") from None
    except tomllib.TOMLDecodeError as exc:
        raise ConfigError(f"{path}: not valid TOML: {exc}") from None
    except RecursionError:
        raise ConfigError(f"{path}: not valid TOML: arrays or tables nested too deep") from None


def validate_config(
    data: dict[str, Any], source: str = "config", model: type[BaseModel] = SatelliteConfig
) -> Any:
    """Validate a plain dict as ``model`` and turn the first error into a :class:`ConfigError`.

    Parameters
    ----------
    data : dict
        The parsed table (from TOML or JSON).
    source : str
        What the data came from, for the message (a file name).
    model : type of pydantic.BaseModel
        The model to validate against; default :class:`SatelliteConfig`.

    Returns
    -------
    pydantic.BaseModel
        The validated, frozen model.

    Raises
    ------
    ConfigError
        Naming the field path and the allowed range of the first error.
    """
    try:
        return model.model_validate(data)
    except ValidationError as exc:
        problems = [_describe(error, model, data) for error in exc.errors()[:_MAX_REPORTED]]
        more = exc.error_count() - len(problems)
        suffix = f"; and {more} more" if more > 0 else ""
        raise ConfigError(f"{source}: {'; '.join(problems)}{suffix}") from None


def _describe(error: dict[str, Any], model: type[BaseModel], data: Any = None) -> str:
    location = shorten(_location(error["loc"]))
    kind = error["type"]
    if kind == "extra_forbidden":
        known = _known_keys(model, error["loc"][:-1], data)
        hint = difflib.get_close_matches(str(error["loc"][-1]), known, n=1)
        suggestion = f"; did you mean {hint[0]!r}?" if hint else ""
        return f"unknown key {location!r}{suggestion} (allowed here: {', '.join(known)})"
    if kind == "missing":
        return f"missing required field {location!r}"
    if kind == "union_tag_invalid":
        ctx = error.get("ctx", {})
        allowed, got = ctx.get("expected_tags"), ctx.get("tag")
        return f"{location}.kind: must be one of {allowed} (got {shorten(repr(got))})"
    if kind in ("model_type", "dict_type"):
        got = shorten(repr(error.get("input")))
        return f"{location}: expected a TOML table (section), got {got}"
    message = shorten(error["msg"].removeprefix("Value error, "), 400)
    if kind == "string_pattern_mismatch":
        message = f"contains characters that are not allowed (allowed: {error['ctx']['pattern']})"
    if "input" in error and error["loc"] and not isinstance(error["input"], dict):
        return f"{location}: {message} (got {shorten(repr(error['input']))})"
    return f"{location}: {message}"


def _location(loc: tuple[Any, ...]) -> str:
    """``('appendages', 0, 'length_m')`` -> ``appendages[0].length_m``."""
    text = ""
    for part in loc:
        text += f"[{part}]" if isinstance(part, int) else (f".{part}" if text else str(part))
    return text or "(top level)"


def _known_keys(model: type[BaseModel], loc: tuple[Any, ...], data: Any = None) -> list[str]:
    """Field names of the (sub)model at ``loc``, for unknown-key suggestions.

    A discriminated union (the controller's ``kind``) puts the member's tag in the
    error path (``controller.asmc.gain``): that segment selects the member. An
    appendage table is validated by the class its ``model`` key names: the table
    itself, found in ``data`` along ``loc``, selects it.
    """
    candidates: list[tuple[str | None, type[BaseModel]]] = [(None, model)]
    node = data  # the table the candidates describe
    for part in loc:
        if isinstance(part, int):
            node = _child(node, part)
            continue
        candidates = _by_table(candidates, node)
        models = [m for _, m in candidates]
        if any(part in m.model_fields for m in models):
            candidates = [member for m in models if part in m.model_fields
                          for member in _members(m.model_fields[part].annotation)]  # fmt: skip
            node = _child(node, part)
        else:  # a union member's tag: the same table
            candidates = [(tag, m) for tag, m in candidates if tag == part]
        if not candidates:
            return []
    return sorted({name for _, m in _by_table(candidates, node) for name in m.model_fields})


def _child(node: Any, part: Any) -> Any:
    """``node[part]`` of parsed TOML data, None where the path leaves it."""
    try:
        return node[part]
    except (KeyError, IndexError, TypeError):
        return None


def _by_table(candidates: list[tuple[str | None, type[BaseModel]]],
              table: Any) -> list[tuple[str | None, type[BaseModel]]]:  # fmt: skip
    """The candidates with an appendage table's open class (``BaseModel``) replaced by the
    config class its ``model`` key names (the default model's without ``table``)."""
    resolved = []
    for tag, m in candidates:
        if m is BaseModel:
            try:
                m = appendage_config_class(table_model(table))
            except ValueError:  # an unknown model: its own error says so
                continue
        resolved.append((tag, m))
    return resolved


def _members(annotation: Any) -> list[tuple[str | None, type[BaseModel]]]:
    """(tag, model) of every BaseModel inside an annotation such as ``list[Model]``,
    ``Model | None`` or a tagged union; the tag is the member's pydantic ``Tag``, if any."""
    if isinstance(annotation, type) and issubclass(annotation, BaseModel):
        return [(None, annotation)]
    tag = next((m.tag for m in getattr(annotation, "__metadata__", ()) if isinstance(m, Tag)), None)
    return [(tag or inner, m) for arg in getattr(annotation, "__args__", ())
            for inner, m in _members(arg)]  # fmt: skip
