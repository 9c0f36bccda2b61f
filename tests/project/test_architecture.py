"""The shape of the code: an acyclic import graph pointing one way, small modules, short functions.

- ``meshlap_core`` never imports the viewer (``meshlap_app`` / ``app``) nor polyscope, not even
  inside a function: the viewer adds its commands and the report's screenshots through entry
  points the core's CLI reads;
- ``meshlap_core.linalg`` is mesh-free: it imports only itself and ``meshlap_core.errors``;
- the module import graph has no cycle, counting imports inside functions (a package's
  ``__init__`` re-exporting its submodules excepted);
- the viewer wing: panels never import the viewer (they type against the host protocol), and
  no module of ``app/`` but a panel's own two files and the registry names a panel in a string;
- no module is longer than ``MAX_MODULE_LINES`` and no function longer than
  ``MAX_FUNCTION_LINES`` (docstring excluded) unless its docstring says why (``Long because``).
"""

from __future__ import annotations

import ast
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
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
    assert not bad, f"{module} imports {sorted(bad)}"


def test_the_core_has_no_viewer_import_at_all():
    """Not even in a string: no ``import meshlap_app`` / ``from meshlap_app`` anywhere."""
    found = [
        m
        for m, p in SOURCES.items()
        if m.startswith("meshlap_core")
        and any(s in p.read_text() for s in ("import meshlap_app", "from meshlap_app"))
    ]
    assert not found


def _panel_names() -> set[str]:
    from meshlap_app.registry import REGISTRY

    return {e.name for e in REGISTRY}


def _strings(tree: ast.AST) -> list[tuple[int, str]]:
    """String constants of a module that are not docstrings, with their line."""
    docs = set()
    for node in ast.walk(tree):
        if isinstance(node, (ast.Module, ast.ClassDef, ast.FunctionDef, ast.AsyncFunctionDef)):
            body = node.body
            if body and isinstance(body[0], ast.Expr) and isinstance(body[0].value, ast.Constant):
                docs.add(id(body[0].value))
    out = []
    for node in ast.walk(tree):
        if isinstance(node, ast.Constant) and isinstance(node.value, str) and id(node) not in docs:
            out.append((node.lineno, node.value))
    return out


@pytest.mark.parametrize("module", [m for m in SOURCES if m.startswith("meshlap_app")])
def test_only_a_panels_own_files_name_it(module):
    """Adding a panel touches its own files and one registry line: no other module of the
    viewer wing names a panel (in a string: a key, a comparison, a default)."""
    names = _panel_names()
    parts = module.split(".")
    own = {parts[-1]} if parts[1:2] in (["panels"], ["state"]) else set()
    if module == "meshlap_app.registry":
        return
    tree = ast.parse(SOURCES[module].read_text())
    bad = [(line, s) for line, s in _strings(tree) if s in names - own]
    assert not bad, f"{module} names panels: {bad}"


@pytest.mark.parametrize("module", [m for m in SOURCES if m.startswith("meshlap_app.panels")])
def test_panels_never_import_the_viewer(module):
    """Not even for type hints: a panel types against ``panels.base.Host``."""
    imported = _imports(module, top_level_only=False)
    bad = {n for n in imported if n.startswith(("meshlap_app.viewer", "meshlap_app.animate"))}
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
    """Counting the imports inside functions (a lazy import is still a dependency)."""
    graph = {m: _internal(_imports(m, top_level_only=False)) - {m} for m in SOURCES}
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
