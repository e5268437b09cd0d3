"""The docs stay true to the code: the equation table resolves, citations resolve.

docs/model.md ends with a table from each equation of the reference thesis's chapters
2-5 to the function that computes it. These tests import every ``module:function``
the table names, check that every equation of those chapters has exactly one row, and
check that every citation of a docs section ("docs/model.md, 'Heading'") anywhere in
the repository names a heading that exists and that nothing cites a file outside the
repository.
"""

from __future__ import annotations

import importlib
import re
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
DOCS = ROOT / "docs"
# Numbered equations per chapter in the thesis (the last number of each chapter).
EQUATIONS_PER_CHAPTER = {2: 50, 3: 10, 4: 30, 5: 10}
REFERENCE = re.compile(r"`(flexsat(?:\.\w+)*:\w+(?:\.\w+)*)`")
CITATION = re.compile(r"docs/(\w+\.md)`?, (?:'([^']+)'|\"([^\"]+)\")")
# The history of measurements, cited the same way: "CHANGELOG.md, 'Heading'".
CHANGELOG_CITATION = re.compile(r"(?<![/\w])CHANGELOG\.md`*, (?:'([^']+)'|\"([^\"]+)\")")


def _table_rows() -> list[list[str]]:
    text = (DOCS / "model.md").read_text(encoding="utf-8")
    section = text.split("\n## Equation table\n", 1)[1].split("\n## ", 1)[0]
    rows = [line for line in section.splitlines() if line.startswith("| ")]
    cells = [[c.strip() for c in re.split(r"(?<!\\)\|", row)[1:-1]] for row in rows]
    assert cells[0][:3] == ["eq.", "quantity", "code that runs"]
    return cells[2:]  # after the header and its rule


def _equations(cell: str) -> list[tuple[int, int]]:
    """'2.3–2.4' -> [(2, 3), (2, 4)]; '4.13–4.14' and '2.5' alike."""
    bounds = [tuple(int(x) for x in part.split(".")) for part in cell.split("–")]
    if len(bounds) == 1:
        return [bounds[0]]
    (c0, a), (c1, b) = bounds
    assert c0 == c1, cell
    return [(c0, k) for k in range(a, b + 1)]


def _resolve(reference: str) -> object:
    module_name, _, path = reference.partition(":")
    obj: object = importlib.import_module(module_name)
    for name in path.split("."):
        if hasattr(obj, name):
            obj = getattr(obj, name)
            continue
        # A field of a dataclass or a pydantic model is not a class attribute.
        fields = {**getattr(obj, "__dataclass_fields__", {}), **getattr(obj, "model_fields", {})}
        assert name in fields, f"{reference}: {name!r} not found"
        obj = fields[name]
    return obj


def test_every_equation_of_chapters_2_to_5_has_one_row():
    listed = [eq for row in _table_rows() for eq in _equations(row[0])]
    expected = [(c, k) for c, n in EQUATIONS_PER_CHAPTER.items() for k in range(1, n + 1)]
    assert sorted(listed) == expected  # each exactly once, none missing, none invented


def test_every_reference_in_the_equation_table_resolves():
    references = {ref for row in _table_rows() for cell in row for ref in REFERENCE.findall(cell)}
    assert len(references) > 40
    for reference in sorted(references):
        _resolve(reference)


def test_every_row_names_code_or_says_why_not():
    for row in _table_rows():
        code, why = row[2], row[4]
        assert REFERENCE.search(code) or (code == "—" and why), row


def _headings(page: str) -> set[str]:
    return _headings_of(DOCS / page)


def _headings_of(path: Path) -> set[str]:
    text = path.read_text(encoding="utf-8")
    return {line.lstrip("#").strip() for line in text.splitlines() if line.startswith("#")}


def _cited_files() -> list[Path]:
    files = [ROOT / "README.md", ROOT / "CHANGELOG.md", *DOCS.glob("*.md")]
    for folder in ("src", "tests", "bench", "examples"):
        files += [p for p in (ROOT / folder).rglob("*") if p.suffix in (".py", ".toml", ".md")]
    return [p for p in files if p != Path(__file__).resolve()]


@pytest.mark.parametrize("path", _cited_files(), ids=lambda p: str(p.relative_to(ROOT)))
def test_docs_citations_name_existing_sections(path):
    text = path.read_text(encoding="utf-8")
    # Every decision the code relies on lives in docs/: nothing cites notes kept
    # outside the repository.
    assert "DESIGN.md" not in text and "../shared" not in text, path
    # A citation may wrap: join comment continuation lines first.
    flat = re.sub(r"\n\s*(#\s*)?", " ", text)
    for page, single, double in CITATION.findall(flat):
        heading = single or double
        assert (DOCS / page).is_file(), f"{path}: docs/{page} does not exist"
        assert heading in _headings(page), f"{path}: no section {heading!r} in docs/{page}"
    changelog = _headings_of(ROOT / "CHANGELOG.md")
    for single, double in CHANGELOG_CITATION.findall(flat):
        heading = single or double
        assert heading in changelog, f"{path}: no entry {heading!r} in CHANGELOG.md"


def _mapped_modules() -> set[str]:
    """The modules docs/architecture.md's module map lists, as dotted names."""
    text = (DOCS / "architecture.md").read_text(encoding="utf-8")
    section = text.split("\n## Module map\n", 1)[1].split("\n## ", 1)[0]
    listed, package = set(), None
    for line in section.splitlines():
        if match := re.fullmatch(r"### `([\w.]+)`", line):
            package = match.group(1)
        elif match := re.match(r"- `([\w.]+)`: \S", line):
            listed.add(f"{package}.{match.group(1)}")
    return listed


def test_the_module_map_lists_every_module_once():
    source = ROOT / "src"
    modules = set()
    for path in (source / "flexsat").rglob("*.py"):
        if "presets" in path.parts:
            continue
        parts = path.with_suffix("").relative_to(source).parts
        # a subpackage's modules are listed under their top-level package
        package = ".".join(parts[:2]) if len(parts) > 2 else "flexsat"
        modules.add(f"{package}.{'.'.join(parts[len(package.split('.')) :])}")
    assert _mapped_modules() == modules
