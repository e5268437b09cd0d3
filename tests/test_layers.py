"""flexsat's import structure: no import circle, and no import from a layer to one above it.

docs/architecture.md, 'Layers'. The module graph is built statically: every ``import``
and ``from ... import`` statement in ``src/flexsat`` (at module level, inside a
function, under ``if TYPE_CHECKING:`` alike: a deferred import that goes up a layer
is still an upward dependency), ``from x import y`` resolved to the module ``x.y``
when there is one, else to ``x``. A plug-in found by name (an entry point, the
figure package :meth:`flexsat.simulate.Result.plot` imports through its registry)
is not an import statement and is not an edge.
"""

from __future__ import annotations

import ast
import itertools
import re
from collections import deque
from pathlib import Path

import flexsat

SRC = Path(flexsat.__file__).parent
ARCHITECTURE = Path(__file__).parents[1] / "docs" / "architecture.md"

LAYERS: tuple[tuple[str, tuple[str, ...]], ...] = (
    # Top to bottom: a module imports modules of its own layer or of the layers below.
    ("entry point", ("flexsat.__main__",)),
    ("command line", ("flexsat.cli",)),
    ("study", ("flexsat.study",)),
    ("figures", ("flexsat.plots",)),
    ("campaigns", ("flexsat.campaigns",)),
    ("real time", ("flexsat.realtime",)),
    ("simulation", ("flexsat.simulate",)),
    ("linear analysis", ("flexsat.linear",)),
    ("control", ("flexsat.control",)),
    ("analysis", ("flexsat.analysis",)),
    ("finite elements", ("flexsat.fe",)),
    ("environment", ("flexsat.environment",)),
    ("orbit", ("flexsat.orbit",)),
    # The package itself: its version and the physics' public names, the compiled cache.
    ("package", ("flexsat", "flexsat._compiled_cache")),
    ("physics", ("flexsat.dynamics",)),
    ("configuration", ("flexsat.config",)),
    ("compiled toolkit", ("flexsat.compiled",)),
    ("shared", ("flexsat._lazy", "flexsat.errors", "flexsat.files", "flexsat.parallel",
                "flexsat.pool", "flexsat.processes", "flexsat.strict_json", "flexsat._version")),
)  # fmt: skip


def module_names(root: Path) -> dict[str, Path]:
    """Every module of the package at ``root``, by dotted name (a package by its own)."""
    modules = {}
    for path in sorted(root.rglob("*.py")):
        parts = path.relative_to(root.parent).with_suffix("").parts
        modules[".".join(parts[:-1] if parts[-1] == "__init__" else parts)] = path
    return modules


def import_graph(root: Path) -> dict[str, dict[str, int]]:
    """``{module: {imported module: line of the first such import}}``, within the package."""
    modules = module_names(root)

    def known(name: str) -> str | None:
        while name and name not in modules:
            name = name.rpartition(".")[0]
        return name or None

    graph: dict[str, dict[str, int]] = {}
    for name, path in modules.items():
        package = name if path.name == "__init__.py" else name.rpartition(".")[0]
        edges = graph.setdefault(name, {})
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"), str(path))):
            targets = []
            if isinstance(node, ast.Import):
                targets = [known(alias.name) for alias in node.names]
            elif isinstance(node, ast.ImportFrom):
                if node.level:
                    base = package.split(".")[: len(package.split(".")) - node.level + 1]
                    source = ".".join([*base, *([node.module] if node.module else [])])
                else:
                    source = node.module or ""
                targets = [f"{source}.{alias.name}" if f"{source}.{alias.name}" in modules
                           else known(source) for alias in node.names]  # fmt: skip
            for target in targets:
                if target is not None and target != name:
                    edges.setdefault(target, node.lineno)
    return graph


def components(graph: dict[str, dict[str, int]]) -> list[list[str]]:
    """The strongly connected components of more than one module (Tarjan), sorted."""
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on_stack: set[str] = set()
    found = []
    for start in sorted(graph):  # iterative: no recursion limit
        if start in index:
            continue
        work = [(start, iter(sorted(graph[start])))]
        index[start] = low[start] = len(index)
        stack.append(start)
        on_stack.add(start)
        while work:
            node, children = work[-1]
            child = next(children, None)
            if child is not None:
                if child not in index:
                    index[child] = low[child] = len(index)
                    stack.append(child)
                    on_stack.add(child)
                    work.append((child, iter(sorted(graph[child]))))
                elif child in on_stack:
                    low[node] = min(low[node], index[child])
                continue
            work.pop()
            if work:
                low[work[-1][0]] = min(low[work[-1][0]], low[node])
            if low[node] == index[node]:
                component = []
                while not component or component[-1] != node:
                    component.append(stack.pop())
                    on_stack.discard(component[-1])
                if len(component) > 1:
                    found.append(sorted(component))
    return sorted(found)


def circle(graph: dict[str, dict[str, int]], component: list[str]) -> list[str]:
    """The shortest circle ``[a, ..., a]`` through the component's first module."""
    first = component[0]
    parent: dict[str, str | None] = {first: None}
    queue = deque([first])
    while queue:
        node = queue.popleft()
        if first in graph[node]:
            path = [node]
            while parent[path[-1]] is not None:
                path.append(parent[path[-1]])
            return [*reversed(path), first]
        for child in sorted(graph[node]):
            if child in component and child not in parent:
                parent[child] = node
                queue.append(child)
    raise AssertionError(f"{component} is not strongly connected")


def folder(module: str) -> str:
    return module if module in _PACKAGES else module.rpartition(".")[0]


def layer_of(module: str) -> int:
    """Index in :data:`LAYERS` (0 at the top) of the longest package prefix of ``module``."""
    best = max((p for _, ps in LAYERS for p in ps if module == p or module.startswith(p + ".")),
               key=len, default=None)  # fmt: skip
    assert best is not None, f"{module} is in no layer: add it to LAYERS (tests/test_layers.py)"
    return next(i for i, (_, ps) in enumerate(LAYERS) if best in ps)


GRAPH = import_graph(SRC)
_PACKAGES = {name for name, path in module_names(SRC).items() if path.name == "__init__.py"}


def _describe(component: list[str]) -> str:
    path = circle(GRAPH, component)
    steps = [f"{a} (line {GRAPH[a][b]})" for a, b in itertools.pairwise(path)]
    return f"{len(component)} modules ({', '.join(component)}), e.g. " + " -> ".join(
        [*steps, path[-1]]
    )


def test_the_graph_finds_deferred_relative_and_module_imports(tmp_path):
    # A package whose only circle goes through a deferred, relative import; the
    # package `sub` is in it too (pkg.a imports it, it imports pkg.sub.b).
    pkg = tmp_path / "pkg"
    (pkg / "sub").mkdir(parents=True)
    (pkg / "__init__.py").write_text("")
    (pkg / "sub" / "__init__.py").write_text("from pkg.sub.b import B\n")
    (pkg / "a.py").write_text("from pkg import sub\nimport pkg.sub.b\n")
    (pkg / "sub" / "b.py").write_text("B = 1\ndef f():\n    from .. import a\n")
    graph = import_graph(pkg)
    assert graph == {"pkg": {}, "pkg.a": {"pkg.sub": 1, "pkg.sub.b": 2},
                     "pkg.sub": {"pkg.sub.b": 1}, "pkg.sub.b": {"pkg.a": 3}}  # fmt: skip
    assert components(graph) == [["pkg.a", "pkg.sub", "pkg.sub.b"]]
    assert circle(graph, ["pkg.a", "pkg.sub", "pkg.sub.b"]) == ["pkg.a", "pkg.sub.b", "pkg.a"]


def test_every_module_has_a_layer():
    assert [layer_of(m) for m in GRAPH]


def test_no_import_circle_across_folders():
    across = [c for c in components(GRAPH) if len({folder(m) for m in c}) > 1]
    assert not across, "import circles across folders:\n" + "\n".join(map(_describe, across))


def test_no_import_circle_inside_a_folder():
    inside = [c for c in components(GRAPH) if len({folder(m) for m in c}) == 1]
    assert not inside, "import circles inside a folder:\n" + "\n".join(map(_describe, inside))


def test_no_import_goes_up_a_layer():
    upward = [f"{src} (line {line}, layer {LAYERS[layer_of(src)][0]!r}) -> {dst} "
              f"(layer {LAYERS[layer_of(dst)][0]!r})"
              for src, edges in sorted(GRAPH.items()) for dst, line in sorted(edges.items())
              if layer_of(dst) < layer_of(src)]  # fmt: skip
    assert not upward, "imports from a layer to one above it:\n" + "\n".join(upward)


def test_the_docs_list_the_layers_in_this_order():
    # docs/architecture.md, 'Layers': each row's packages, top to bottom, as above.
    text = ARCHITECTURE.read_text(encoding="utf-8").split("## Layers", 1)[1].split("\n## ", 1)[0]
    rows = re.findall(r"^\| [^|]+ \| (`flexsat[^|]*) \|", text, re.M)
    layers = [sorted({layer_of(p) for p in re.findall(r"`(flexsat[\w.]*)`", row)}) for row in rows]
    assert len(rows) >= 10 and all(len(row) == 1 for row in layers), rows
    assert [row[0] for row in layers] == sorted(row[0] for row in layers), rows
