"""Hostile round 3, the library API: every public function of ``meshlap_core`` that takes mesh
arrays refuses odd dtypes and out-of-range indices with a :class:`MeshError` naming the problem,
never a silent (truncated, wrapped, real-part-only) answer, a ``ComplexWarning`` or a raw numpy
error.

The table below lists how each public name is called; a name added to ``meshlap_core.__all__``
must be put in the table or in ``NO_MESH_ARRAYS``, so a new entry point cannot skip the test.
"""

from __future__ import annotations

import warnings
from collections.abc import Callable
from typing import Any

import numpy as np
import pytest

import meshlap_core as mc
from meshlap_core import MeshError, primitives

V0, F0 = primitives.icosphere(0)
N0 = len(V0)

# name -> call(V, F, tmp_path)
CALLS: dict[str, Callable[[Any, Any, Any], Any]] = {
    "save_mesh": lambda V, F, t: mc.save_mesh(t / "out.ply", V, F),
    "save_scalars": lambda V, F, t: mc.save_scalars(t / "s.ply", np.ones(N0), V=V, F=F),
    "validate_mesh": lambda V, F, t: mc.validate_mesh(V, F),
    "mesh_info": lambda V, F, t: mc.mesh_info(V, F),
    "inspect_vertex": lambda V, F, t: mc.inspect_vertex(V, F, 0),
    "one_ring": lambda V, F, t: mc.one_ring(F, N0),
    "boundary_loops": lambda V, F, t: mc.boundary_loops(F),
    "cotan_stiffness": lambda V, F, t: mc.cotan_stiffness(V, F),
    "uniform_laplacian": lambda V, F, t: mc.uniform_laplacian(F, N0),
    "mass_matrix": lambda V, F, t: mc.mass_matrix(V, F),
    "vertex_areas": lambda V, F, t: mc.vertex_areas(V, F),
    "laplace_beltrami": lambda V, F, t: mc.laplace_beltrami(V, F),
    "curvature_field": lambda V, F, t: mc.curvature_field(V, F, "cotan"),
    "all_curvature_fields": lambda V, F, t: mc.all_curvature_fields(V, F),
    "vertex_normals": lambda V, F, t: mc.vertex_normals(V, F),
    "estimate_curvature": lambda V, F, t: mc.estimate_curvature(V, F, "rusinkiewicz"),
    "principal_curvature_quadric": lambda V, F, t: mc.principal_curvature_quadric(V, F),
    # (an explicit radius: the automatic one, 3 edges, covers most of a 12-vertex mesh)
    "jet_curvatures": lambda V, F, t: mc.jet_curvatures(V, F, 1.2),
    "SpectralBasis": lambda V, F, t: mc.SpectralBasis.compute(V, F, 3, cache=False),
    "Smoother": lambda V, F, t: mc.Smoother(V, F),
    "smooth": lambda V, F, t: mc.smooth(V, F, iters=1),
    "add_noise": lambda V, F, t: mc.add_noise(V, F, 0.01, mode="normal"),
    "rmse": lambda V, F, t: mc.rmse(V, V0),
    "HeatDiffusion": lambda V, F, t: mc.HeatDiffusion(V, F),
    "HeatGeodesic": lambda V, F, t: mc.HeatGeodesic(V, F),
    "exact_distance": lambda V, F, t: mc.exact_distance(V, F, [0]),
    "isolines": lambda V, F, t: mc.isolines(V, F, np.linspace(0.0, 1.0, len(V0)), [0.5]),
}
# names that take no vertex / face arrays (files, generators, surfaces, records, the errors)
NO_MESH_ARRAYS = {
    "MeshError",
    "MeshWarning",
    "__version__",
    "Mesh",  # a record built by validate_mesh (tested there)
    "PrincipalCurvatures",  # a record built by the curvature estimators
    "MeshReport",
    "OneRing",  # built by one_ring
    "EdgeTable",  # built by the topology functions
    "load_mesh",  # a file: tests/test_robustness*.py
    "icosphere",
    "torus_mesh",
    "grid",
    "cube",
    "get_surface",
    "mesh_surface",
    "point_geometry",
    "SpectralFilter",  # built from a SpectralBasis (tests/test_diffusion.py)
    "heat_spectral",  # a SpectralBasis and a field
    "heat_kernel_signature",  # a SpectralBasis and times
    "transfer_function",  # eigenvalues only
    "save_polylines",  # a file of curves: tests/test_isolines.py
}
USES_V = {"rmse", "add_noise"} | {
    n for n in CALLS if n not in ("one_ring", "boundary_loops", "uniform_laplacian")
}
USES_F = set(CALLS) - {"rmse"}


def _faces(values: Any, dtype: Any) -> np.ndarray:
    F = np.array(F0, dtype=dtype)
    F[0, 0] = values
    return F


BAD_F: dict[str, tuple[Any, str]] = {
    "object 13.5": (_faces(13.5, object), "must be integers, got 13.5"),
    "float 13.5": (_faces(13.5, np.float64), "(must be integers, got |non-integer index.*)13.5"),
    "complex": (F0 + 0j, "must be real numbers"),
    "boolean": (F0 > 3, "boolean"),
    "uint64 2^64-1": (_faces(2**64 - 1, np.uint64), "index 18446744073709551615"),
    "float 1e20": (_faces(1e20, np.float64), r"index 1e\+20"),
    "index -1": (_faces(-1, np.int64), "index -1"),
    "strings": (F0.astype(str), "must be numbers"),
}
BAD_V: dict[str, tuple[Any, str]] = {
    "complex": (V0 + 1j, "must be real numbers"),
    "boolean": (V0 > 0, "boolean"),
    "strings": (V0.astype(str), "must be numbers"),
    "object complex": (np.array(V0, dtype=object) + 1j, "must be real numbers"),
}


def test_every_public_name_is_classified():
    names = set(mc.__all__)
    assert names == set(CALLS) | NO_MESH_ARRAYS, "classify the new public name in this file"


@pytest.mark.parametrize("name", sorted(CALLS))
def test_good_arrays_work(name, tmp_path):
    with warnings.catch_warnings():
        warnings.simplefilter("error", np.exceptions.ComplexWarning)
        CALLS[name](V0, F0, tmp_path)


def _refused(call: Callable[[], Any], expect: str) -> None:
    with warnings.catch_warnings():
        warnings.simplefilter("error", np.exceptions.ComplexWarning)
        with pytest.raises(MeshError, match=expect):
            call()


@pytest.mark.parametrize("case", sorted(BAD_F))
@pytest.mark.parametrize("name", sorted(USES_F))
def test_bad_faces_are_refused_by_every_entry_point(name, case, tmp_path):
    F, expect = BAD_F[case]
    _refused(lambda: CALLS[name](V0, F, tmp_path), expect)
    assert not list(tmp_path.iterdir())  # nothing written


@pytest.mark.parametrize("case", sorted(BAD_V))
@pytest.mark.parametrize("name", sorted(USES_V))
def test_bad_vertices_are_refused_by_every_entry_point(name, case, tmp_path):
    V, expect = BAD_V[case]
    _refused(lambda: CALLS[name](V, F0, tmp_path), expect)


@pytest.mark.parametrize("name", sorted(CALLS))
def test_empty_arrays_give_a_mesh_error_or_an_answer(name, tmp_path):
    """Empty V and F: a MeshError (``mesh_info``: "no vertices") or a result, never a raw
    numpy ``ValueError`` from a reduction over nothing."""
    V, F = np.zeros((0, 3)), np.zeros((0, 3), dtype=np.int64)
    try:
        CALLS[name](V, F, tmp_path)
    except MeshError:
        pass


def test_mesh_info_of_empty_arrays():
    with pytest.raises(MeshError, match="no vertices"):
        mc.mesh_info(np.zeros((0, 3)), np.zeros((0, 3), dtype=np.int64))


def test_boundary_loops_refuses_a_negative_index():
    F = np.array([[0, 1, 2], [0, 2, -1]])
    with pytest.raises(MeshError, match="index -1"):
        mc.boundary_loops(F)
