"""Sphinx configuration of the flexsat documentation site (``make docs``).

The site is Sphinx with numpydoc (the docstring format of the whole package), MyST
(the Markdown pages in this folder are the theory pages the code cites), autosummary
(the API reference, one page per public module) and sphinx-gallery (the examples in
``examples/``, executed at every build). See docs/documentation.md, 'The site'.
"""

from __future__ import annotations

import importlib
import inspect
import os
import pkgutil
import sys
import typing
from pathlib import Path

import pydantic
from sphinx.errors import PycodeError
from sphinx.pycode import ModuleAnalyzer

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "src"))
sys.path.insert(0, str(ROOT / "docs" / "_ext"))  # gallery_figures, gallery_order
os.environ.setdefault("MPLBACKEND", "Agg")

import flexsat  # noqa: E402

project = "flexsat"
author = "the flexsat developers"
copyright = "the flexsat developers"
release = version = flexsat.__version__

extensions = [
    "sphinx.ext.autodoc",
    "sphinx.ext.mathjax",
    "sphinx.ext.viewcode",
    "numpydoc",
    "myst_parser",
    "sphinx_gallery.gen_gallery",
]

source_suffix = {".rst": "restructuredtext", ".md": "markdown"}
root_doc = "index"
exclude_patterns = ["_build", "Thumbs.db", ".DS_Store", "auto_examples/*.ipynb"]

# MyST: headings get anchors so pages can link to sections; $...$ is math.
myst_enable_extensions = ["dollarmath", "colon_fence"]
myst_heading_anchors = 3

autodoc_member_order = "bysource"
autodoc_typehints = "none"  # numpydoc's Parameters section states the types
numpydoc_show_class_members = False
numpydoc_xref_param_type = False
numpydoc_validation_checks: set[str] = set()  # tests/test_docstrings.py checks them

# The gallery: every script in examples/ is executed and its figures captured.
sphinx_gallery_conf = {
    "examples_dirs": [str(ROOT / "examples")],
    "gallery_dirs": ["auto_examples"],
    "filename_pattern": r"\.py$",  # execute every example, not only plot_*.py
    "ignore_pattern": r"__init__\.py",
    "within_subsection_order": "gallery_order.ReadingOrder",
    "download_all_examples": False,
    "remove_config_comments": True,
    "abort_on_example_error": True,
    "show_memory": False,
    "capture_repr": (),  # a cell ending on a figure shows the figure, not its repr
    # flexsat's figures are made without pyplot: a scraper that sees them
    "image_scrapers": ("gallery_figures.scrape",),
}

html_theme = "pydata_sphinx_theme"
html_title = "flexsat"
html_static_path: list[str] = []
html_theme_options = {
    "navigation_with_keys": False,
    "show_toc_level": 2,
    "secondary_sidebar_items": ["page-toc"],
}
html_show_sourcelink = False


API = Path(__file__).resolve().parent / "api"


def _public_modules() -> list[str]:
    """Every public module of flexsat, packages first (no ``_private`` or ``__main__``)."""
    names = ["flexsat"]
    for info in pkgutil.walk_packages(flexsat.__path__, "flexsat."):
        if not any(part.startswith("_") for part in info.name.split(".")[1:]):
            names.append(info.name)
    return sorted(names)


def _module_page(name: str, modules: list[str]) -> str:
    """The reST of one module's page: its docstring, its submodules, its ``__all__``.

    An object is documented in the module that defines it; a package (or a module
    that re-exports) lists the names it re-exports with a link to that definition.
    """
    module = importlib.import_module(name)
    title = f"``{name}``"
    lines = [title, "=" * len(title), "", f".. automodule:: {name}", ""]
    children = [m for m in modules if m.rpartition(".")[0] == name]
    if children:
        lines += [".. rubric:: Modules", "", ".. toctree::", "   :maxdepth: 1", ""]
        lines += [f"   {child}" for child in children] + [""]
    defined, reexported = [], []
    for item in getattr(module, "__all__", []):
        obj = getattr(module, item)
        home = getattr(obj, "__module__", None)
        if inspect.ismodule(obj):
            continue
        if inspect.isclass(obj) or inspect.isfunction(obj) or hasattr(obj, "py_func"):
            (defined if home == name else reexported).append((item, obj, home))
        else:
            defined.append((item, obj, name))
    if reexported:
        lines += [".. rubric:: Re-exported here", ""]
        lines += [f"- :py:obj:`{item} <{home}.{item}>`" for item, _, home in reexported]
        lines.append("")
    for item, obj, _ in defined:
        if inspect.isclass(obj) and issubclass(obj, BaseException):
            lines += [f".. autoexception:: {name}.{item}", ""]
        elif inspect.isclass(obj):
            lines += [f".. autoclass:: {name}.{item}", "   :members:", ""]
        elif inspect.isfunction(obj) or hasattr(obj, "py_func"):
            lines += [f".. autofunction:: {name}.{item}", ""]
        else:
            lines += [f".. autodata:: {name}.{item}", "   :no-value:", ""]
    return "\n".join(lines)


def _write_api(app) -> None:
    """Write ``api/<module>.rst`` for every public module (only files that changed),
    and remove the pages of modules that no longer exist (a renamed module)."""
    modules = _public_modules()
    API.mkdir(exist_ok=True)
    for stale in set(API.glob("*.rst")) - {API / f"{name}.rst" for name in modules}:
        stale.unlink()
    for name in modules:
        page, text = API / f"{name}.rst", _module_page(name, modules)
        if not page.is_file() or page.read_text(encoding="utf-8") != text:
            page.write_text(text, encoding="utf-8")


def _type_name(annotation) -> str:
    """A field's type as a reader writes it: ``float``, ``{"rk4", "dop853"}``, ``tuple``."""
    if typing.get_origin(annotation) is typing.Literal:
        return "{" + ", ".join(repr(v) for v in typing.get_args(annotation)) + "}"
    origin = typing.get_origin(annotation) or annotation
    return getattr(origin, "__name__", None) or str(annotation).replace("typing.", "")


def _pydantic_internals(app, what, name, obj, skip, options):
    """pydantic's own class attributes (``model_config``...) are not the model's API."""
    return True if name in ("model_config", "model_fields", "model_computed_fields") else None


def _pydantic_fields(app, what, name, obj, options, lines):
    """Append a model's fields as a numpydoc Parameters section (its constructor).

    A pydantic model's constructor takes its fields; each field's ``description``
    (with its unit) is its documentation, written once in the model.
    """
    if what != "class" or not (inspect.isclass(obj) and issubclass(obj, pydantic.BaseModel)):
        return
    if any(line.strip() == "Parameters" for line in lines):
        return
    fields = obj.model_fields
    if not fields:
        return
    lines += ["", "Parameters", "----------"]
    for field_name, field in fields.items():
        default = "" if field.is_required() else ", optional"
        lines.append(f"{field_name} : {_type_name(field.annotation)}{default}")
        # a description is plain text: reST's markup characters stand for themselves
        text = (field.description or "").replace("|", "\\|").replace("*", "\\*")
        lines.append(f"    {text}")


def _no_type_docstring(app, what, name, obj, options, lines):
    """A constant without its own doc comment shows nothing, not its type's docstring."""
    if what not in ("data", "attribute"):
        return
    module, _, attribute = name.rpartition(".")
    try:
        documented = ("", attribute) in ModuleAnalyzer.for_module(module).find_attr_docs()
    except PycodeError:  # not a module-level constant
        return
    if not documented:
        lines.clear()


def setup(app):
    app.connect("autodoc-process-docstring", _no_type_docstring, priority=400)
    app.connect("builder-inited", _write_api)
    app.connect("autodoc-skip-member", _pydantic_internals)
    # before numpydoc (priority 500) turns the sections into reST
    app.connect("autodoc-process-docstring", _pydantic_fields, priority=400)
