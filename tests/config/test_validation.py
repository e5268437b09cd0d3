"""Config validation: bad input is refused with one message naming the field and range."""

from __future__ import annotations

import copy
import math

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from flexsat.config import load_config, nominal, validate_config
from flexsat.errors import ConfigError
from tests.conftest import nominal_dict


def _edit(path: str, value):
    """A nominal dict with the dotted ``path`` set to ``value`` (or removed for ...)."""
    data = nominal_dict()
    *parents, last = path.split(".")
    node = data
    for part in parents:
        node = node[int(part)] if part.isdigit() else node[part]
    if value is ...:
        del node[last]
    else:
        node[last] = value
    return data


BAD_CONFIGS = [
    # (what, data, fragment the message must contain)
    ("unknown top-level key", _edit("colour", "red"), "unknown key 'colour'"),
    ("misspelt key gets a hint", _edit("hub.mass", 150.0), "did you mean 'mass_kg'"),
    ("radians-style key", _edit("appendages.0.sadm_angle", 0.5), "did you mean 'sadm_angle_deg'"),
    ("missing hub mass", _edit("hub.mass_kg", ...), "missing required field 'hub.mass_kg'"),
    (
        "negative hub mass",
        _edit("hub.mass_kg", -150.0),
        "hub.mass_kg: Input should be greater than or equal to 0.0001",
    ),
    (
        "zero panel length",
        _edit("appendages.0.length_m", 0.0),
        "appendages[0].length_m: Input should be greater than or equal to 0.001",
    ),
    (
        "string for a number",
        _edit("hub.radius_m", "0.6"),
        "hub.radius_m: Input should be a valid number",
    ),
    ("boolean for a number", _edit("appendages.1.width_m", True), "appendages[1].width_m"),
    ("NaN mass", _edit("hub.mass_kg", math.nan), "hub.mass_kg: Input should be a finite number"),
    ("infinite density", _edit("appendages.0.surface_density_kg_m2", math.inf), "finite number"),
    (
        "zero frequency",
        _edit("appendages.0.target_frequencies_hz.flapping", 0.0),
        "target_frequencies_hz.flapping: Input should be greater than or equal to 0.001",
    ),
    (
        "negative damping ratio",
        _edit("appendages.0.damping_ratio", -0.01),
        "damping_ratio: Input should be greater than or equal to 0",
    ),
    (
        "damping ratio of one",
        _edit("appendages.1.damping_ratio", 1.0),
        "damping_ratio: Input should be less than 1",
    ),
    (
        "SADM angle out of range",
        _edit("appendages.0.sadm_angle_deg", 400.0),
        "sadm_angle_deg: Input should be less than or equal to 360",
    ),
    (
        "both mass and density",
        _edit("appendages.0.mass_kg", 6.75),
        "exactly one of surface_density_kg_m2 and mass_kg",
    ),
    (
        "neither mass nor density",
        _edit("appendages.0.surface_density_kg_m2", ...),
        "exactly one of surface_density_kg_m2 and mass_kg",
    ),
    (
        "mount point of two numbers",
        _edit("appendages.0.mount_point_m", [0.0, 0.8]),
        "appendages[0].mount_point_m",
    ),
    (
        "bad span direction",
        _edit("appendages.0.span_direction", "+x"),
        "span_direction: Input should be '+y' or '-y'",
    ),
    ("no appendages", _edit("appendages", []), "appendages: List should have at least 1 item"),
    ("duplicate names", _edit("appendages.1.name", "panel_1"), "appendage names must be unique"),
    (
        "hub cylinder and inertia",
        _edit("hub.inertia_kg_m2", [[1, 0, 0], [0, 1, 0], [0, 0, 1]]),
        "not both",
    ),
    ("hub without geometry", _edit("hub.radius_m", ...), "give both radius_m and height_m"),
    ("thick plate", _edit("appendages.0.thickness_m", 2.0), "thickness_m must not exceed"),
    ("hub as a number", _edit("hub", 3), "hub: expected a TOML table"),
]

_HUB_NO_CYLINDER = {"mass_kg": 150.0}
BAD_INERTIAS = [
    ("asymmetric inertia", [[40, 1, 0], [0, 40, 0], [0, 0, 27]], "must be symmetric"),
    ("indefinite inertia", [[40, 0, 0], [0, -1, 0], [0, 0, 27]], "positive definite"),
    ("non-physical inertia", [[1, 0, 0], [0, 1, 0], [0, 0, 5]], "J1 + J2 >= J3"),
    ("NaN in inertia", [[40, 0, 0], [0, math.nan, 0], [0, 0, 27]], "finite number"),
]


@pytest.mark.parametrize(("what", "data", "fragment"), BAD_CONFIGS, ids=[c[0] for c in BAD_CONFIGS])
def test_bad_config_is_refused_with_a_clear_message(what, data, fragment):
    with pytest.raises(ConfigError) as caught:
        validate_config(data)
    message = str(caught.value)
    assert fragment in message
    assert "\n" not in message  # one message, one line


@pytest.mark.parametrize(
    ("what", "inertia", "fragment"), BAD_INERTIAS, ids=[c[0] for c in BAD_INERTIAS]
)
def test_bad_hub_inertia_is_refused(what, inertia, fragment):
    data = nominal_dict()
    data["hub"] = dict(_HUB_NO_CYLINDER, inertia_kg_m2=inertia)
    with pytest.raises(ConfigError, match="hub") as caught:
        validate_config(data)
    assert fragment in str(caught.value)


def test_explicit_hub_inertia_is_accepted():
    data = nominal_dict()
    data["hub"] = dict(
        _HUB_NO_CYLINDER, inertia_kg_m2=[[41.625, 0, 0], [0, 41.625, 0], [0, 0, 27.0]]
    )
    cfg = validate_config(data)
    assert cfg.hub.inertia()[2, 2] == 27.0


def test_nominal_preset_is_table_3_1():
    cfg = nominal()
    hub = cfg.hub.inertia()
    # Table 3.1 prints J_hub = diag(41.6, 41.6, 27.0) to 1 decimal (eqs. 2.3-2.4).
    assert hub[0, 0] == pytest.approx(41.6, abs=0.05)
    assert hub[2, 2] == pytest.approx(27.0, abs=0.05)
    for app in cfg.appendages:
        assert app.mass == pytest.approx(6.75)  # table 3.1, exact: 1 kg/m^2 * 4.5 m * 1.5 m
        # Table 3.1 prints J_p = diag(11.4, 1.3, 12.7) to 1 decimal (eqs. 2.9-2.11).
        j = app.centroidal_inertia()
        assert [j[0, 0], j[1, 1], j[2, 2]] == pytest.approx([11.4, 1.3, 12.7], abs=0.05)


def test_models_are_immutable():
    cfg = nominal()
    with pytest.raises(Exception, match="frozen"):
        cfg.hub.mass_kg = 1.0


def test_missing_and_malformed_files(tmp_path):
    with pytest.raises(ConfigError, match="not found"):
        load_config(tmp_path / "absent.toml")
    bad = tmp_path / "bad.toml"
    bad.write_text("[hub\nmass_kg = 1")
    with pytest.raises(ConfigError, match="not valid TOML"):
        load_config(bad)


# -- property-based: whatever a user writes, the only failure is a ConfigError -------

_leaf = st.one_of(
    st.none(),
    st.booleans(),
    st.integers(min_value=-(10**6), max_value=10**6),
    st.floats(allow_nan=True, allow_infinity=True),
    st.text(max_size=8),
    st.lists(st.floats(allow_nan=True, allow_infinity=True), max_size=4),
)
_PATHS = [
    "name", "hub", "hub.mass_kg", "hub.radius_m", "hub.height_m", "hub.inertia_kg_m2",
    "appendages", "appendages.0", "appendages.0.mount_point_m", "appendages.0.length_m",
    "appendages.0.width_m", "appendages.0.thickness_m", "appendages.0.damping_ratio",
    "appendages.0.sadm_angle_deg", "appendages.0.mount_yaw_deg", "appendages.0.span_direction",
    "appendages.0.target_frequencies_hz", "appendages.0.target_frequencies_hz.torsion",
    "appendages.1.surface_density_kg_m2", "appendages.1.name", "appendages.1.mass_kg",
]  # fmt: skip


@settings(max_examples=300, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(edits=st.lists(st.tuples(st.sampled_from(_PATHS), _leaf), min_size=1, max_size=4))
def test_random_configs_fail_only_with_config_errors(edits):
    data = nominal_dict()
    for path, value in edits:
        data = _set_lenient(data, path, value)
    try:
        cfg = validate_config(data)
    except ConfigError as exc:
        assert str(exc)
        return
    # Anything accepted must be usable: build the plant.
    from flexsat.dynamics.plant import Plant

    Plant.from_config(cfg)


def _set_lenient(data: dict, path: str, value) -> dict:
    """Set a dotted path if its parents exist and are containers; else leave data alone."""
    data = copy.deepcopy(data)
    *parents, last = path.split(".")
    node = data
    for part in parents:
        try:
            node = node[int(part)] if part.isdigit() else node[part]
        except (KeyError, IndexError, TypeError, ValueError):
            return data
    if isinstance(node, dict):
        node[last] = value
    elif isinstance(node, list) and last.isdigit() and int(last) < len(node):
        node[int(last)] = value
    return data


def test_huge_hub_radius_is_refused_with_its_range():
    """Regression: Hypothesis once drew hub.radius_m = 1.34e154, and J = m r^2 overflowed."""
    data = nominal_dict()
    data["hub"]["radius_m"] = 1.34e154
    with pytest.raises(ConfigError, match=r"hub\.radius_m: .*less than or equal to 1000"):
        validate_config(data)


@pytest.mark.parametrize(
    ("mount", "yaw", "span", "refused"),
    [
        ([0.0, 0.6, 0.0], 0.0, "+y", False),  # root on the surface (r = 0.6 m), outward
        ([0.0, 0.6, 0.0], 0.0, "-y", True),  # the same root, spanning back through the hub
        # Yawed 90 deg at 0.8 m: the 1.5 m chord lies along Y_B, its inner edge at
        # y = 0.8 - 0.75 = 0.05 m, inside the 0.6 m radius.
        ([0.0, 0.8, 0.0], 90.0, "+y", True),
        # The chord's inner edge at y = 1.35 - 0.75 = 0.6 m: on the surface, accepted.
        ([0.0, 1.35, 0.0], 90.0, "+y", False),
    ],
)  # fmt: skip
def test_a_plate_may_touch_the_hub_but_not_enter_it(mount, yaw, span, refused):
    # docs/model.md, 'Geometric interference': the nominal hub, radius 0.6 m, height 1.5 m.
    data = nominal_dict()
    data["appendages"][0].update(mount_point_m=mount, mount_yaw_deg=yaw, span_direction=span)
    if refused:
        with pytest.raises(
            ConfigError, match=r"appendages\[0\] \(panel_1\) passes through the hub"
        ):
            validate_config(data)
    else:
        validate_config(data)
