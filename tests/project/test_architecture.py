"""The shape of the code: an acyclic import graph pointing one way, small modules, short functions.

- ``meshlap_core`` never imports the viewer (``meshlap_app`` / ``app``) nor polyscope, not even
  inside a function: the viewer adds its commands and the report's screenshots through entry
  points the core's CLI reads;
- ``meshlap_core.linalg`` is mesh-free: it imports only itself and ``meshlap_core.errors``;
- the module import graph has no cycle, counting imports inside functions (a package's
  ``__init__`` re-exporting its submodules excepted);
- the viewer wing: panels never import the viewer (they type against the host protocol), and
  no module of ``app/`` but a panel's own two files and the registry names a panel in a string;
- no module imports a private name (``_x``) of another module, nor a private module from outside
  the package that holds it;
- the layers: the components (a top-level module, or a sub-package with everything in it; a
  module of a shelf in ``SHELVES`` on its own) import each other at run time without a cycle,
  and a type-only import (under ``if TYPE_CHECKING:``) never points up to a component that
  imports the importer's at run time (it would hide a cycle of the layers);
- sizes are a concept's, not a target: a module over ``WARN_MODULE_LINES`` lines or a function
  over ``WARN_FUNCTION_LINES`` (docstring excluded, unless its docstring says why: ``Long
  because``) is reported as a warning, never a failure.
"""

from __future__ import annotations

import ast
import functools
import warnings
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
WARN_MODULE_LINES = 1200
WARN_FUNCTION_LINES = 150
REASON = "Long because"


class SizeWarning(UserWarning):
    """A module or function long enough to ask whether it holds more than one concept."""


PRIVATE_ALLOWED: dict[str, set[str]] = {
    # The curvature package (issue 32) moved the modules, not yet these helpers: the estimators
    # and the jet fit reuse the fields' per-face pass until it is a shared module of its own.
    "meshlap_core.curvature.estimators": {
        "meshlap_core.curvature.fields._areas_from",
        "meshlap_core.curvature.fields._cotan_Cx",
        "meshlap_core.curvature.fields._cotan_H",
        "meshlap_core.curvature.fields._deficit_from",
        "meshlap_core.curvature.fields._face_frame",
        "meshlap_core.curvature.fields._face_geometry",
        "meshlap_core.curvature.fields._geometry_of",
        "meshlap_core.curvature.fields._mixed_corner_areas",
        "meshlap_core.curvature.fields._normals_from",
    },
    "meshlap_core.curvature.jet_fit": {
        "meshlap_core.curvature.fields._face_geometry",
        "meshlap_core.curvature.fields._normals_from",
    },
}
"""Private imports that are known and being removed (the list only shrinks; an entry that no
longer happens fails ``test_the_allowlists_hold_only_what_still_happens``)."""

TYPE_ONLY_ALLOWED: set[tuple[str, str]] = set()
"""Type-only imports up the layers that are known and being removed (the list only shrinks)."""


SHELVES: dict[str, str] = {
    "meshlap_core.curvature": "fields and principal sit under noise (normal-direction noise) "
    "and surfaces.geometry (the exact principal frame); refinement, convergence, study and the "
    "jet fit's noise model sit above noise and surfaces",
    "meshlap_app.state": "settings and animation sit under panel_spec, which each panel's state "
    "module uses to declare its spec; app and session sit above the registry, which lists the "
    "specs",
}
"""Packages that are a shelf of modules by subject rather than one layer: each of their modules
is a component of the layers on its own (the import graph of modules still has no cycle).
A shelf that would no longer close a cycle as one component leaves the list
(``test_each_shelf_spans_more_than_one_layer``)."""


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


@functools.cache
def _tree(module: str) -> ast.Module:
    """The parsed source of ``module`` (parsed once for every rule)."""
    return ast.parse(SOURCES[module].read_text())


def _absolute(module: str, is_package: bool, node: ast.ImportFrom) -> str:
    """The absolute name of the module a ``from ... import ...`` statement imports from."""
    if node.level:
        base = module.split(".") if is_package else module.split(".")[:-1]
        base = base[: len(base) - (node.level - 1)]
        return ".".join(base + ([node.module] if node.module else []))
    return node.module or ""


def _resolve(module: str, is_package: bool, node: ast.ImportFrom) -> list[str]:
    """Absolute names of the modules a ``from ... import ...`` statement loads."""
    target = _absolute(module, is_package, node)
    names = [f"{target}.{a.name}" for a in node.names]
    found = [n for n in names if n in SOURCES]
    return found or [target]


def _imports(module: str, *, top_level_only: bool) -> set[str]:
    path = SOURCES[module]
    tree = _tree(module)
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
    tree = _tree(module)
    bad = [(line, s) for line, s in _strings(tree) if s in names - own]
    assert not bad, f"{module} names panels: {bad}"


@pytest.mark.parametrize("module", [m for m in SOURCES if m.startswith("meshlap_app.panels")])
def test_panels_never_import_the_viewer(module):
    """Not even for type hints: a panel types against ``host.Host``."""
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


def _long_functions(module: str) -> list[str]:
    """Functions of ``module`` over ``WARN_FUNCTION_LINES`` (docstring excluded) whose
    docstring does not say why."""
    tree = _tree(module)
    long = []
    for node in ast.walk(tree):
        if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
            n = node.end_lineno - node.lineno + 1
            doc = ast.get_docstring(node) or ""
            first = node.body[0]
            if doc and isinstance(first, ast.Expr):  # the docstring does not count
                n -= first.end_lineno - first.lineno + 1
            if n > WARN_FUNCTION_LINES and REASON not in doc:
                long.append(f"{node.name} ({n} lines)")
    return long


def test_long_code_is_a_warning_not_a_failure():
    """A module is sized by its concept: one over ``WARN_MODULE_LINES`` lines, or a function
    over ``WARN_FUNCTION_LINES`` that does not say why, is reported (pytest's warnings
    summary) for a reader to judge, and never fails the suite."""
    sizes = {m: len(p.read_text().splitlines()) for m, p in SOURCES.items()}
    reported = []
    for module in sorted(SOURCES):
        if sizes[module] > WARN_MODULE_LINES:
            reported.append(f"{module} has {sizes[module]} lines (one concept?)")
        long = _long_functions(module)
        if long:
            reported.append(f"{module}: {', '.join(long)} (split, or say '{REASON} ...')")
    for line in reported:
        warnings.warn(line, SizeWarning, stacklevel=1)
    assert len(sizes) == len(SOURCES) and all(n >= 0 for n in sizes.values())


# ---------------------------------------------------------------- private names
def _private(name: str) -> bool:
    """``_x`` is private to its module (``__x__`` is not)."""
    return name.startswith("_") and not (name.startswith("__") and name.endswith("__"))


def _inside(module: str, package: str) -> bool:
    return module == package or module.startswith(package + ".")


@functools.cache
def _private_imports(module: str) -> frozenset[str]:
    """The private names of other modules that ``module`` imports: ``from m import _x`` (a
    function, class or value of ``m``), or a private module (``io/_scan.py``) imported from
    outside the package that holds it (its own package's modules may)."""
    path = SOURCES[module]
    found = set()
    for node in ast.walk(_tree(module)):
        if isinstance(node, ast.ImportFrom):
            target = _absolute(module, path.name == "__init__.py", node)
            names = [f"{target}.{a.name}" for a in node.names]
        elif isinstance(node, ast.Import):
            names = [a.name for a in node.names]
        else:
            continue
        for full in names:
            parts = full.split(".")
            if parts[0] not in ("meshlap_core", "meshlap_app"):
                continue
            for i in range(1, len(parts)):
                if not _private(parts[i]):
                    continue
                if ".".join(parts[: i + 1]) not in SOURCES:  # a private name of a module
                    found.add(full)
                    break
                if not _inside(module, ".".join(parts[:i])):  # a private module, from outside
                    found.add(full)
                    break
    return frozenset(found)


@pytest.mark.parametrize("module", sorted(SOURCES))
def test_no_module_imports_a_private_name_of_another(module):
    """Shared means public: a name another module needs loses its underscore (or moves to the
    module both import); ``_x`` stays its own module's business."""
    bad = _private_imports(module) - PRIVATE_ALLOWED.get(module, set())
    assert not bad, f"{module} imports private names {sorted(bad)}"


# ---------------------------------------------------------------- layers
def _component(module: str, shelves: frozenset[str] = frozenset(SHELVES)) -> str:
    """The unit of the layers: a top-level module (``meshlap_core.mesh``, ``meshlap_app.jobs``)
    or a sub-package with everything in it (``meshlap_core.io``, ``meshlap_app.panels``); a
    module of one of the ``shelves`` is a unit of its own."""
    package = ".".join(module.split(".")[:2])
    return module if package in shelves else package


@functools.cache
def _split_imports(module: str) -> tuple[frozenset[str], frozenset[str]]:
    """The modules ``module`` imports at run time (in functions too) and those it imports only
    for type checking (under ``if TYPE_CHECKING:``)."""
    path = SOURCES[module]
    tree = _tree(module)
    guarded: set[int] = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.If) and "TYPE_CHECKING" in ast.unparse(node.test):
            guarded.update(id(n) for stmt in node.body for n in ast.walk(stmt))
    runtime, typing = set(), set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            names = {a.name for a in node.names}
        elif isinstance(node, ast.ImportFrom):
            names = set(_resolve(module, path.name == "__init__.py", node))
        else:
            continue
        (typing if id(node) in guarded else runtime).update(_internal(names) - {module})
    return frozenset(runtime), frozenset(typing)


@functools.cache
def _layers(shelves: frozenset[str] = frozenset(SHELVES)) -> dict[str, frozenset[str]]:
    """The components each component imports at run time (a package's ``__init__``
    re-exporting its own submodules excepted)."""
    graph: dict[str, set[str]] = {_component(m, shelves): set() for m in SOURCES}
    for m in SOURCES:
        for d in _split_imports(m)[0]:
            if m.startswith(d + ".") and SOURCES[d].name == "__init__.py":
                continue
            if _component(d, shelves) != _component(m, shelves):
                graph[_component(m, shelves)].add(_component(d, shelves))
    return {c: frozenset(ds) for c, ds in graph.items()}


def _reaches(start: str, goal: str, shelves: frozenset[str] = frozenset(SHELVES)) -> bool:
    graph, seen, todo = _layers(shelves), set(), [start]
    while todo:
        c = todo.pop()
        if c == goal:
            return True
        if c not in seen:
            seen.add(c)
            todo.extend(graph[c])
    return False


def test_the_components_form_layers():
    """No cycle among the components at run time, so "up" is defined: a component is above
    every component it imports."""
    cycles = sorted(f"{a} <-> {b}" for a, ds in _layers().items() for b in ds if _reaches(b, a))
    assert not cycles, f"components importing each other: {cycles}"


@pytest.mark.parametrize("shelf", sorted(SHELVES))
def test_each_shelf_spans_more_than_one_layer(shelf):
    """A shelf is split into its modules only because, as one component, it would sit both
    under and over another component (the list only shrinks)."""
    whole = frozenset(SHELVES) - {shelf}
    assert any(_reaches(d, shelf, whole) for d in _layers(whole)[shelf]), (
        f"{shelf} is one layer: remove it from SHELVES"
    )


def _type_only_up(module: str) -> set[tuple[str, str]]:
    return {
        (module, d)
        for d in _split_imports(module)[1]
        if _component(d) != _component(module) and _reaches(_component(d), _component(module))
    }


@pytest.mark.parametrize("module", sorted(SOURCES))
def test_type_only_imports_never_run_up_the_layers(module):
    """``if TYPE_CHECKING:`` is for an import too costly at run time, not for one that would
    close a cycle of the layers: a type a lower layer needs lives in (or moves to) a lower
    module."""
    bad = _type_only_up(module) - TYPE_ONLY_ALLOWED
    assert not bad, f"{module} imports for types from a layer above it: {sorted(bad)}"


def test_the_allowlists_hold_only_what_still_happens():
    """Each allowlisted private or type-only import still happens (a fixed one leaves its list)."""
    stale = [
        f"{m}: {n}"
        for m, names in PRIVATE_ALLOWED.items()
        for n in sorted(names - _private_imports(m))
    ]
    happening = {pair for m in SOURCES for pair in _type_only_up(m)}
    stale += [f"{a} -> {b}" for a, b in sorted(TYPE_ONLY_ALLOWED - happening)]
    assert not stale, f"remove from the allowlists: {stale}"
