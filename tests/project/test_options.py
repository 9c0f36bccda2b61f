"""One definition of every option and tolerance: ``meshlap_core.options``."""

import ast
from pathlib import Path

import pytest

from meshlap_core import options

ROOT = Path(__file__).resolve().parents[2]
SHARED = {
    name
    for name in vars(options)
    if not name.startswith("_")
    and name not in {"annotations", "Literal", "get_args", "MeshError", "check_choice"}
}
SOURCES = sorted((ROOT / "meshlap_core").rglob("*.py")) + sorted((ROOT / "app").rglob("*.py"))
CHOICE_SETS = {
    name: set(value)
    for name, value in vars(options).items()
    if name.isupper()
    and isinstance(value, tuple)
    and value
    and all(isinstance(v, str) for v in value)
}
"""Every choice tuple of ``options`` (AREA_KINDS, SMOOTHING_METHODS, CURVATURE_FIELDS, ...)."""

APP_TODO: set[str] = set()
"""Files that still spell out a tuple of choice names; each entry is removed as its file imports
the tuple from ``meshlap_core.options`` instead (the list only shrinks)."""


def _assigned_names(tree: ast.AST) -> set[str]:
    names: set[str] = set()
    for node in ast.walk(tree):
        targets = []
        if isinstance(node, ast.Assign):
            targets = node.targets
        elif isinstance(node, ast.AnnAssign):
            targets = [node.target]
        for t in targets:
            if isinstance(t, ast.Name):
                names.add(t.id)
    return names


@pytest.mark.parametrize("path", SOURCES, ids=lambda p: str(p.relative_to(ROOT)))
def test_no_module_redefines_an_option(path):
    if path.name == "options.py" and path.parent.name == "meshlap_core":
        return
    again = _assigned_names(ast.parse(path.read_text())) & SHARED
    assert not again, f"{path.name} defines {sorted(again)} again: import them from options"


def _choice_tuples(tree: ast.AST) -> list[tuple[int, str, list[str]]]:
    """``(line, options name, the strings)`` of every tuple, list or set literal whose string
    elements are two or more names of one choice set and nothing else (``("explicit", "implicit")``;
    a table header ``("u", "v", "k1", "k2")`` is not one)."""
    found = []
    for node in ast.walk(tree):
        if not isinstance(node, ast.Tuple | ast.List | ast.Set):
            continue
        strings = [e.value for e in node.elts if isinstance(e, ast.Constant)]
        strings = [s for s in strings if isinstance(s, str)]
        if len(set(strings)) < 2:
            continue
        for name, choices in CHOICE_SETS.items():
            if set(strings) <= choices:
                found.append((node.lineno, name, strings))
                break
    return found


@pytest.mark.parametrize("path", SOURCES, ids=lambda p: str(p.relative_to(ROOT)))
def test_no_module_spells_out_a_choice_tuple(path):
    rel = path.relative_to(ROOT).as_posix()
    if rel == "meshlap_core/options.py":
        return
    found = _choice_tuples(ast.parse(path.read_text()))
    if rel in APP_TODO:
        assert found, f"{rel} no longer spells out a choice tuple: remove it from APP_TODO"
        return
    where = "; ".join(f"line {line}: {strings} (options.{name})" for line, name, strings in found)
    assert not found, f"{rel} spells out choices again: {where}; import them from options"


def test_the_choice_tuple_check_catches_literals():
    tree = ast.parse(
        'M = ("explicit", "implicit", "taubin")\nfor a in ["barycentric", "voronoi"]: pass\n'
        'x = {"frozen", "recompute"}\nheader = ("u", "v", "k1", "k2")\none = ("cotan",)\n'
    )
    assert [line for line, _, _ in _choice_tuples(tree)] == [1, 2, 3]


def test_check_choice_gives_the_one_message():
    from meshlap_core.errors import MeshError

    assert options.check_choice("cotan", options.LAPLACIAN_KINDS, "Laplacian") == "cotan"
    with pytest.raises(MeshError) as e:
        options.check_choice("mixed", options.AREA_KINDS, "area")
    assert str(e.value) == "area: unknown area 'mixed'; choose one of barycentric, voronoi"
    with pytest.raises(MeshError) as e:
        options.check_choice("3pi", options.BOUNDARY_RULES, "boundary rule", "boundary")
    assert e.value.source == "boundary"
    assert e.value.problem == "unknown boundary rule '3pi'; choose one of pi, 2pi, zero"


def test_choices_match_their_literal_types():
    from typing import get_args

    assert options.AREA_KINDS == get_args(options.AreaKind) == ("barycentric", "voronoi")
    assert options.LAPLACIAN_KINDS == get_args(options.LaplacianKind) == ("uniform", "cotan")
    assert options.BOUNDARY_RULES == get_args(options.BoundaryRule) == ("pi", "2pi", "zero")
    assert options.DEFAULT_AREA in options.AREA_KINDS
    assert options.MASS_AREA in options.AREA_KINDS
    assert options.DEFAULT_BOUNDARY in options.BOUNDARY_RULES
    literal = {
        "CURVATURE_METHODS": options.CurvatureMethod,
        "CURVATURE_FIELDS": options.CurvatureField,
        "SMOOTHING_METHODS": options.SmoothingMethod,
        "MASS_UPDATES": options.MassUpdate,
        "NOISE_MODES": options.NoiseMode,
        "DERIVATIVE_METHODS": options.DerivativeMethod,
        "MESHERS": options.Mesher,
        "UP_AXES": options.UpAxis,
    }
    for name, kind in literal.items():
        assert getattr(options, name) == get_args(kind), name
    assert options.CURVATURE_FIELDS == (*options.CURVATURE_METHODS, "difference")
    assert tuple(options.CURVATURE_FIELD_LABELS) == options.CURVATURE_FIELDS
    assert options.DEFAULT_CURVATURE_FIELD in options.CURVATURE_FIELDS
    assert options.DEFAULT_SMOOTHING_METHOD in options.SMOOTHING_METHODS
    assert set(options.EULER_METHODS) < set(options.SMOOTHING_METHODS)
    assert options.DEFAULT_MASS_UPDATE in options.MASS_UPDATES
    assert options.DEFAULT_NOISE_MODE in options.NOISE_MODES
    assert options.DEFAULT_UP in options.UP_AXES


def test_the_two_forms_of_the_degeneracy_threshold_agree():
    """|e1×e2| ≤ d·Σl² (validator) ⟺ 16A² ≤ (2d)²(Σl²)² (cotangent weights)."""
    import numpy as np

    from meshlap_core import laplacian
    from meshlap_core.validate import degenerate_faces

    assert laplacian._DEGENERATE_REL16 == (2 * options.DEGENERATE_REL) ** 2
    F = np.array([[0, 1, 2]])
    for h, degenerate in ((0.0, True), (1e-14, True), (1e-6, False), (0.5, False)):
        V = np.array([[0, 0, 0], [1, 0, 0], [0.5, h, 0]], float)
        assert bool(degenerate_faces(V, F)[1][0]) == degenerate
        cot = laplacian.cotangents_intrinsic(laplacian.squared_edge_lengths(V, F))
        assert bool(np.all(cot == 0)) == degenerate
