"""Every public function and class has a numpydoc docstring that matches its signature.

The public API is everything a package's or a module's ``__all__`` names
(``flexsat``, ``flexsat.simulate``, ``flexsat.control.laws``,
``flexsat.dynamics.kernels``...); a module without ``__all__`` exports every function
and class it defines without a leading underscore. Like python-control's docstring
meta-test, this parses each docstring (``numpydoc.validate``) and checks that it has a
summary, that its Parameters section lists exactly the signature's parameters, in
order, each with a type and a description, and that every quantity carries its unit:
a parameter or return value of a numeric type (float, array) states it in brackets,
``[rad/s]``, ``[N m]``, ``[-]`` for a dimensionless number. A pydantic model documents
its fields in its docstring or once in each field's ``description`` (the site
turns those into the model's Parameters section); a dataclass or a named tuple may
document its fields as Attributes.
"""

from __future__ import annotations

import dataclasses
import importlib
import inspect
import pkgutil
import re
import warnings

import pydantic
import pytest

import flexsat

numpydoc_validate = pytest.importorskip("numpydoc.validate")

# numpydoc's checks that make a docstring wrong for a reader (the others are style:
# "See Also", "Examples", an extended summary are welcome but not required).
CHECKS = {
    "GL08",  # no docstring
    "SS01",  # no summary
    "GL07",  # sections in the wrong order (Parameters before Returns...)
    "PR01",  # a parameter of the signature not documented
    "PR02",  # a documented parameter not in the signature
    "PR03",  # parameters documented out of order
    "PR04",  # a parameter without a type
    "PR07",  # a parameter without a description
}
# A numeric type: its quantity has a unit.
NUMERIC = re.compile(r"\b(float|ndarray|array_like|array|complex|Quantity)\b")
UNIT = re.compile(r"\[[^\]]+\]")


def _modules() -> list[str]:
    """Every importable module of flexsat, packages first (their names are the shorter)."""
    names = ["flexsat"]
    for info in pkgutil.walk_packages(flexsat.__path__, "flexsat."):
        if not any(p.startswith("_") for p in info.name.split(".")[1:]):
            names.append(info.name)
    packages = [n for n in names if hasattr(importlib.import_module(n), "__path__")]
    return packages + [n for n in names if n not in packages]


def _is_public_kind(obj: object) -> bool:
    return inspect.isclass(obj) or inspect.isfunction(obj) or hasattr(obj, "py_func")


def _public_names(module) -> list[str]:
    """A module's ``__all__``, or else every non-underscore function or class it defines."""
    if hasattr(module, "__all__"):
        return list(module.__all__)
    return [
        name
        for name, obj in vars(module).items()
        if not name.startswith("_")
        and _is_public_kind(obj)
        and getattr(getattr(obj, "py_func", obj), "__module__", None) == module.__name__
    ]


def _public_objects() -> dict[str, object]:
    """``module.name`` of each public function, class or compiled function, once.

    Public: what a package's or a module's ``__all__`` names; a module without
    ``__all__`` exports every function and class it defines without a leading
    underscore. An object is listed under the first (package-level) name found.
    """
    found: dict[int, tuple[str, object]] = {}
    for name in _modules():
        module = importlib.import_module(name)
        for attr in _public_names(module):
            obj = getattr(module, attr)
            if _is_public_kind(obj):
                found.setdefault(id(obj), (f"{name}.{attr}", obj))
    return dict(found.values())


PUBLIC = _public_objects()


def _is_model(obj: object) -> bool:
    return inspect.isclass(obj) and issubclass(obj, pydantic.BaseModel)


def _unitless(items) -> list[str]:
    """Names of numeric parameters or returns whose description states no unit."""
    return [
        item.name or item.type
        for item in items
        if NUMERIC.search(item.type) and not UNIT.search(" ".join(item.desc))
    ]


def test_the_public_api_is_found():
    assert len(PUBLIC) > 350
    assert "flexsat.simulate.run_slew" in PUBLIC and "flexsat.Plant" in PUBLIC
    assert "flexsat.compiled.linalg3.cross" in PUBLIC  # a module's own __all__


def _defined_at(obj: object) -> str:
    """``module.qualname`` of an object (a compiled function's Python function)."""
    function = getattr(obj, "py_func", obj)
    return f"{function.__module__}.{function.__qualname__}"


def _fields(obj: object) -> list[str] | None:
    """The fields a class's generated constructor takes (dataclass, named tuple, model)."""
    if _is_model(obj):
        return list(obj.model_fields)
    if dataclasses.is_dataclass(obj):
        return [f.name for f in dataclasses.fields(obj) if f.init]
    if inspect.isclass(obj) and issubclass(obj, tuple) and hasattr(obj, "_fields"):
        return list(obj._fields)
    return None


@pytest.mark.parametrize("path", sorted(PUBLIC))
def test_public_docstring(path):
    obj = PUBLIC[path]
    fields = _fields(obj)
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # an unknown section is a parse error
        # by where it is defined: a package's name may also be a module's
        report = numpydoc_validate.validate(_defined_at(obj))
        doc = numpydoc_validate.Validator(numpydoc_validate.get_doc_object(obj)).doc
    # A record's fields are its constructor's parameters: documented either in
    # Parameters or in Attributes (a model's also in its fields' descriptions). A
    # protocol is never constructed: its signature is typing's (*args, **kwargs).
    protocol = getattr(obj, "_is_protocol", False)
    matching = ("PR01", "PR02", "PR03") if fields is not None or protocol else ()
    errors = [
        f"{code}: {message}"
        for code, message in report["errors"]
        if code in CHECKS and code not in matching
    ]
    if fields is not None:
        documented = {
            name.strip()
            for section in ("Parameters", "Attributes")
            for item in doc[section]
            for name in item.name.split(",")  # "q, qd : ndarray" documents both
        }
        described = {
            name for name, field in getattr(obj, "model_fields", {}).items() if field.description
        }
        missing = [n for n in fields if n not in documented | described and not n.startswith("_")]
        if missing:
            errors.append(f"fields not documented: {', '.join(missing)}")
        for name, field in getattr(obj, "model_fields", {}).items():
            if name not in documented and field.description and "float" in str(field.annotation):
                if not UNIT.search(field.description):
                    errors.append(f"field {name!r}: no [unit] in its description")
    for section in ("Parameters", "Attributes", "Returns", "Yields"):
        missing = _unitless(doc[section])
        if missing:
            errors.append(f"{section}: no [unit] for {', '.join(missing)}")
    assert not errors, "\n".join([path, *errors])
