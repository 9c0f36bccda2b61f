"""``meshlap curvature``'s field computed while the mesh is validated
(:func:`meshlap_core.cli.curvature.load_with_field`): the same field as from the validated
mesh, also when the validation repairs the file (the field is then computed again)."""

from __future__ import annotations

import numpy as np
import pytest

from meshlap_core.cli.curvature import load_with_field
from meshlap_core.curvature import curvature_field
from meshlap_core.io import load_mesh, save_mesh
from meshlap_core.primitives import bumpy_sphere


@pytest.mark.parametrize("method", ["cotan", "uniform", "gaussian", "k1"])
def test_field_of_a_clean_mesh_is_the_validated_meshs(tmp_path, method):
    path = tmp_path / "bumpy.obj"
    save_mesh(path, *bumpy_sphere(2))
    mesh, values = load_with_field(str(path), method, "voronoi", "pi")
    want = curvature_field(mesh.V, mesh.F, method, "voronoi", "pi")
    np.testing.assert_array_equal(values, want)


def test_field_of_a_repaired_mesh_is_computed_again(tmp_path):
    """A duplicated face and an unreferenced vertex: the validation drops them, so the
    parsed arrays (one more vertex) are not the mesh's: the field is the validated mesh's."""
    V, F = bumpy_sphere(1)
    V = np.vstack([V, [[5.0, 5.0, 5.0]]])  # unreferenced
    F = np.vstack([F, F[:1]])  # duplicated
    path = tmp_path / "repaired.obj"
    with open(path, "w") as fh:
        fh.writelines(f"v {x} {y} {z}\n" for x, y, z in V)
        fh.writelines(f"f {a + 1} {b + 1} {c + 1}\n" for a, b, c in F)
    mesh, values = load_with_field(str(path), "cotan", "voronoi", "pi")
    assert mesh.report.repairs and len(values) == len(mesh.V) == len(V) - 1
    np.testing.assert_array_equal(values, curvature_field(mesh.V, mesh.F, "cotan"))
    assert len(load_mesh(path).V) == len(values)
