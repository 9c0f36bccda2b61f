"""One definition of every option and tolerance: ``meshlap_core.options``."""

import ast
from pathlib import Path

import pytest

from meshlap_core import options

ROOT = Path(__file__).resolve().parents[1]
SHARED = {
    name
    for name in vars(options)
    if not name.startswith("_") and name not in {"annotations", "Literal", "get_args"}
}
SOURCES = sorted((ROOT / "meshlap_core").rglob("*.py")) + sorted((ROOT / "app").rglob("*.py"))


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


def test_choices_match_their_literal_types():
    from typing import get_args

    assert options.AREA_KINDS == get_args(options.AreaKind) == ("barycentric", "voronoi")
    assert options.LAPLACIAN_KINDS == get_args(options.LaplacianKind) == ("uniform", "cotan")
    assert options.BOUNDARY_RULES == get_args(options.BoundaryRule) == ("pi", "2pi", "zero")
    assert options.DEFAULT_AREA in options.AREA_KINDS
    assert options.MASS_AREA in options.AREA_KINDS
    assert options.DEFAULT_BOUNDARY in options.BOUNDARY_RULES


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
