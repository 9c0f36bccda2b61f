"""The shape of the code: an acyclic import graph pointing one way, small modules, short functions.

- ``meshlap_core`` never imports the viewer (``meshlap_app`` / ``app``) nor polyscope; only the
  CLI (the top layer) reads the viewer's pure-data names (``meshlap_app.state``) and imports the
  viewer lazily, inside the commands that open or render it;
- ``meshlap_core.linalg`` is mesh-free: it imports only itself and ``meshlap_core.errors``;
- the module import graph (module-level imports) has no cycle;
- no module is longer than ``MAX_MODULE_LINES`` and no function longer than
  ``MAX_FUNCTION_LINES`` (docstring excluded) unless its docstring says why (``Long because``).
"""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
MAX_MODULE_LINES = 650
MAX_FUNCTION_LINES = 80
REASON = "Long because"


def _module_name(path: Path) -> str:
    rel = path.relative_to(ROOT).with_suffix("")
    parts = list(rel.parts)
    if parts[0] == "app":
        parts[0] = "meshlap_app"
    if parts[-1] == "__init__":
        parts = parts[:-1]
    return ".".join(parts)


SOURCES = {
    _module_name(p): p
    for folder in ("meshlap_core", "app")
    for p in sorted((ROOT / folder).rglob("*.py"))
}


def _resolve(module: str, is_package: bool, node: ast.ImportFrom) -> list[str]:
    """Absolute names of the modules a ``from ... import ...`` statement loads."""
    if node.level:
        base = module.split(".") if is_package else module.split(".")[:-1]
        base = base[: len(base) - (node.level - 1)]
        target = ".".join(base + ([node.module] if node.module else []))
    else:
        target = node.module or ""
    names = [f"{target}.{a.name}" for a in node.names]
    found = [n for n in names if n in SOURCES]
    return found or [target]


def _imports(module: str, *, top_level_only: bool) -> set[str]:
    path = SOURCES[module]
    tree = ast.parse(path.read_text())
    nodes = tree.body if top_level_only else list(ast.walk(tree))
    if top_level_only:  # include imports under `if TYPE_CHECKING:` only if not guarded
        nodes = [n for n in nodes if isinstance(n, (ast.Import, ast.ImportFrom))]
    out: set[str] = set()
    for node in nodes:
        if isinstance(node, ast.Import):
            out.update(a.name for a in node.names)
        elif isinstance(node, ast.ImportFrom):
            out.update(_resolve(module, path.name == "__init__.py", node))
    return out


def _internal(names: set[str]) -> set[str]:
    out = set()
    for n in names:
        while n and n not in SOURCES:
            n = n.rpartition(".")[0]
        if n:
            out.add(n)
    return out


def test_the_sources_were_found():
    assert "meshlap_core.options" in SOURCES and "meshlap_app" in SOURCES


@pytest.mark.parametrize("module", [m for m in SOURCES if m.startswith("meshlap_core")])
def test_core_never_imports_the_viewer(module):
    imported = _imports(module, top_level_only=False)
    bad = {n for n in imported if n.split(".")[0] in {"polyscope", "meshlap_app", "app"}}
    if module.startswith("meshlap_core.cli"):
        # the CLI is the top layer: it may read the viewer's pure-data names (panels, fields)
        # at import time and import the viewer itself lazily, inside the command that runs it
        bad &= _imports(module, top_level_only=True)
        bad = {n for n in bad if not n.startswith("meshlap_app.state")}
    assert not bad, f"{module} imports {sorted(bad)}"


@pytest.mark.parametrize("module", [m for m in SOURCES if m.startswith("meshlap_core.linalg")])
def test_linalg_is_mesh_free(module):
    internal = _internal(_imports(module, top_level_only=False))
    bad = {
        n
        for n in internal
        if not n.startswith("meshlap_core.linalg") and n != "meshlap_core.errors"
    }
    assert not bad, f"{module} imports mesh-specific {sorted(bad)}"


def test_import_graph_has_no_cycle():
    graph = {m: _internal(_imports(m, top_level_only=True)) - {m} for m in SOURCES}
    # a package's __init__ re-exporting its submodules is not a cycle with them
    for m, deps in graph.items():
        graph[m] = {
            d for d in deps if not (m.startswith(d + ".") and SOURCES[d].name == "__init__.py")
        }
    state: dict[str, int] = {}
    stack: list[str] = []

    def visit(m: str) -> None:
        state[m] = 1
        stack.append(m)
        for d in sorted(graph[m]):
            if state.get(d) == 1:
                cycle = [*stack[stack.index(d) :], d]
                pytest.fail("import cycle: " + " -> ".join(cycle))
            if d not in state:
                visit(d)
        stack.pop()
        state[m] = 2

    for m in sorted(graph):
        if m not in state:
            visit(m)


@pytest.mark.parametrize("module", sorted(SOURCES))
def test_modules_are_small(module):
    n = len(SOURCES[module].read_text().splitlines())
    assert n <= MAX_MODULE_LINES, f"{module} has {n} lines (one concept per module)"


@pytest.mark.parametrize("module", sorted(SOURCES))
def test_long_functions_say_why(module):
    tree = ast.parse(SOURCES[module].read_text())
    long = []
    for node in ast.walk(tree):
        if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
            n = node.end_lineno - node.lineno + 1
            doc = ast.get_docstring(node) or ""
            first = node.body[0]
            if doc and isinstance(first, ast.Expr):  # the docstring does not count
                n -= first.end_lineno - first.lineno + 1
            if n > MAX_FUNCTION_LINES and REASON not in doc:
                long.append(f"{node.name} ({n} lines)")
    assert not long, f"{module}: {', '.join(long)} (split, or say '{REASON} ...' in the docstring)"
