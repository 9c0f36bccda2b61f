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
    "make_deformer": lambda V, F, t: mc.make_deformer("biharmonic", V, F, [0], [5]),
    "deform_mesh": lambda V, F, t: mc.deform_mesh(V, F, [0], V0[[0]], "harmonic", [5]),
    "HarmonicDeformer": lambda V, F, t: mc.HarmonicDeformer(V, F, [0], [5], k=3),
    "LaplacianCoordinates": lambda V, F, t: mc.LaplacianCoordinates(V, F, [0], [5]),
    "ArapDeformer": lambda V, F, t: mc.ArapDeformer(V, F, [0, 5]),
    "grow_handles": lambda V, F, t: mc.grow_handles(V, F, [0], 0.5),
    "rotation_error": lambda V, F, t: mc.rotation_error(V, F, V0),
    "Flattener": lambda V, F, t: mc.Flattener(V, F).map("lscm"),
    "make_disk": lambda V, F, t: mc.make_disk(V, F),
    "measure_distortion": lambda V, F, t: mc.measure_distortion(V, F, V0[:, :2]),
    "show": lambda V, F, t: mc.show(V, F, renderer="matplotlib", size=(160, 120)),
    "show_side_by_side": lambda V, F, t: mc.show_side_by_side(
        V, F, V0[:, 0], V0[:, 1], renderer="matplotlib", size=(200, 100)
    ),
    "turntable": lambda V, F, t: mc.turntable(
        V, F, frames=2, renderer="matplotlib", size=(120, 90)
    ),
    "open_viewer": lambda V, F, t: mc.open_viewer(V, F, environ={}),  # no display: not opened
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
    "load_mesh",  # a file: the other tests of tests/robustness/
    "icosphere",
    "torus_mesh",
    "grid",
    "cube",
    "get_surface",
    "mesh_surface",
    "point_geometry",
    "SpectralFilter",  # built from a SpectralBasis (tests/core/test_diffusion.py)
    "heat_spectral",  # a SpectralBasis and a field
    "heat_kernel_signature",  # a SpectralBasis and times
    "transfer_function",  # eigenvalues only
    "save_polylines",  # a file of curves: tests/app/test_isolines.py
    "UVMap",  # a record built by Flattener.map
    "MeshPicture",  # a record built by show
    "Turntable",  # a record built by turntable
    "ViewerWindow",  # a record built by open_viewer
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


# ------------------------------------------------------------------ the new API (round 4)
# Every public function of ``meshlap_core.diffusion`` and the curvature estimators, each of
# its arguments other than the mesh given every bad value of its kind: a MeshError that names
# the argument, never a wrapped index, a truncated 2.5, True taken for 1, a complex number's
# real part, NaN computed through, or numpy's own IndexError / shape error.

from meshlap_core import diffusion as dif  # noqa: E402
from meshlap_core.curvature import estimators as ce  # noqa: E402

V1, F1 = primitives.icosphere(1)
N1 = len(V1)  # 42
NAN, INF = float("nan"), float("inf")

BAD: dict[str, list[tuple[str, Any]]] = {
    "index": [
        ("bool", True),
        ("fraction", 2.5),
        ("negative", -1),
        ("n", N1),
        ("2^63", 2**63),
        ("1e20 int", 10**20),
        ("uint64 max", np.uint64(2**64 - 1)),
        ("nan", NAN),
        ("complex", 1j),
        ("string", "3"),
        ("a list", [0, 1]),
    ],
    "indices": [
        ("bool", [True]),
        ("fraction", [2.5]),
        ("negative", [-1]),
        ("n", [N1]),
        ("2^63", [2**63]),
        ("1e20 int", [10**20]),
        ("nan", [NAN]),
        ("complex", [1j]),
        ("string", ["0"]),
        ("empty", []),
    ],
    "count": [
        ("bool", True),
        ("fraction", 2.5),
        ("negative", -1),
        ("1e20 int", 10**20),
        ("nan", NAN),
        ("complex", 1j),
        ("string", "3"),
        ("an array", np.array([3, 4])),
    ],
    "positive": [
        ("nan", NAN),
        ("inf", INF),
        ("negative", -1.0),
        ("zero", 0.0),
        ("bool", True),
        ("complex", 1j),
        ("string", "1"),
    ],
    "real": [("nan", NAN), ("inf", INF), ("bool", True), ("complex", 1j), ("string", "1")],
    "field": [
        ("complex", np.ones(N1) + 1j),
        ("nan", np.r_[np.ones(N1 - 1), NAN]),
        ("bool", np.ones(N1, dtype=bool)),
        ("wrong length", np.ones(N1 + 1)),
        ("strings", np.array(["1"] * N1)),
    ],
    "eigenvalues": [
        ("complex", np.arange(6) + 1j),
        ("nan", np.r_[0.0, 1.0, NAN, 3.0]),
        ("bool", np.ones(4, dtype=bool)),
        ("2-D", np.ones((3, 2))),
        ("empty", np.zeros(0)),
        ("strings", np.array(["1", "2"])),
    ],
    "vector": [  # 1-D values of any length (masses: their count is the mesh's)
        ("complex", np.ones(N1) + 1j),
        ("nan", np.r_[np.ones(N1 - 1), NAN]),
        ("bool", np.ones(N1, dtype=bool)),
        ("strings", np.array(["1"] * N1)),
        ("2-D", np.ones((N1, 2))),
    ],
    "reals": [  # finite numbers, any shape
        ("complex", [1j]),
        ("nan", [NAN]),
        ("inf", [INF]),
        ("bool", [True]),
        ("strings", ["1"]),
    ],
    "points": [
        ("complex", np.ones((3, 3)) + 1j),
        ("nan", np.r_[np.ones((2, 3)), [[NAN, 0, 0]]]),
        ("bool", np.ones((3, 3), dtype=bool)),
        ("wrong shape", np.ones((3, 2))),
    ],
}


@pytest.fixture(scope="module")
def basis():
    return mc.SpectralBasis.compute(V1, F1, 12, cache=False)


EIG = np.array([0.0, 1.0, 2.0, 3.0, 5.0, 8.0])
# name -> (call(basis, **arguments), the good arguments, {argument: kind})
API: dict[str, tuple[Callable[..., Any], dict[str, Any], dict[str, str]]] = {
    "check_sources": (lambda b, **a: dif.check_sources(n=N1, **a), {"sources": [3]},
                      {"sources": "indices"}),
    "unit_heat": (lambda b, **a: dif.unit_heat(**a), {"sources": [3], "mass": np.ones(N1)},
                  {"sources": "indices", "mass": "vector"}),
    "HeatDiffusion.euler": (lambda b, **a: dif.HeatDiffusion(V1, F1).euler(**a),
                            {"u0": np.ones(N1), "t": 0.1, "steps": 2},
                            {"u0": "field", "t": "positive", "steps": "count"}),
    "HeatDiffusion.exact": (lambda b, **a: dif.HeatDiffusion(V1, F1).exact(**a),
                            {"u0": np.ones(N1), "t": 0.1}, {"u0": "field", "t": "positive"}),
    "HeatGeodesic": (lambda b, **a: dif.HeatGeodesic(V1, F1, **a), {"m": 1.0}, {"m": "positive"}),
    "HeatGeodesic.distance": (lambda b, **a: dif.HeatGeodesic(V1, F1).distance(**a),
                              {"sources": [3]}, {"sources": "indices"}),
    "exact_distance": (lambda b, **a: dif.exact_distance(V1, F1, **a), {"sources": [3]},
                       {"sources": "indices"}),
    "igl_heat_distance": (lambda b, **a: dif.igl_heat_distance(V1, F1, **a),
                          {"sources": [3], "t": 0.1}, {"sources": "indices", "t": "positive"}),
    "heat_spectral": (lambda b, **a: dif.heat_spectral(b, **a),
                      {"u0": np.ones(N1), "t": 0.1, "k": 5},
                      {"u0": "field", "t": "positive", "k": "count"}),
    "heat_kernel_column": (lambda b, **a: dif.heat_kernel_column(b, **a),
                           {"source": 3, "t": 0.1, "k": 5},
                           {"source": "index", "t": "positive", "k": "count"}),
    "truncation_bound": (lambda b, **a: dif.truncation_bound(**a),
                         {"eigenvalues": EIG, "t": 0.1, "k": 3},
                         {"eigenvalues": "eigenvalues", "t": "positive", "k": "count"}),
    "hks_times": (lambda b, **a: dif.hks_times(**a), {"eigenvalues": EIG, "count": 4},
                  {"eigenvalues": "eigenvalues", "count": "count"}),
    "heat_kernel_signature": (lambda b, **a: dif.heat_kernel_signature(b, **a),
                              {"times": [0.1, 1.0], "k": 5},
                              {"times": "eigenvalues", "k": "count"}),
    "hks_distance": (lambda b, **a: dif.hks_distance(**a),
                     {"H": np.ones((N1, 2)), "vertex": 3}, {"vertex": "index"}),
    "isoline_values": (lambda b, **a: dif.isoline_values(**a),
                       {"values": np.arange(N1, dtype=float), "count": 3}, {"count": "count"}),
    "isolines": (lambda b, **a: dif.isolines(V1, F1, **a),
                 {"values": np.arange(N1, dtype=float), "levels": [3.0]},
                 {"values": "field", "levels": "reals"}),
    "save_polylines": (lambda b, path, **a: dif.save_polylines(path, **a),
                       {"P": np.eye(3), "E": np.array([[0, 1]])}, {"P": "points"}),
    "low_pass": (lambda b, **a: dif.low_pass(**a), {"eigenvalues": EIG, "keep": 3},
                 {"eigenvalues": "eigenvalues", "keep": "count"}),
    "band_gain": (lambda b, **a: dif.band_gain(**a),
                  {"eigenvalues": EIG, "lo": 1, "hi": 3, "gain": 2.0},
                  {"eigenvalues": "eigenvalues", "lo": "count", "hi": "count", "gain": "real"}),
    "transfer": (lambda b, **a: dif.transfer("taubin", **a),
                 {"eigenvalues": EIG, "step": 0.1, "iters": 2, "nu": -0.2},
                 {"eigenvalues": "eigenvalues", "step": "positive", "iters": "count",
                  "nu": "real"}),
    "SpectralFilter": (lambda b, **a: dif.SpectralFilter(b, **a), {"X": V1, "k": 5},
                       {"X": "field", "k": "count"}),
    "SpectralFilter.apply": (lambda b, **a: dif.SpectralFilter(b, k=5).apply(**a),
                             {"h": np.ones(5)}, {"h": "eigenvalues"}),
    "measured_amplification": (lambda b, **a: dif.measured_amplification(b, **a),
                               {"X_before": V1, "X_after": V1, "k": 5},
                               {"X_before": "field", "X_after": "field", "k": "count"}),
    "smoother_transfer": (lambda b, **a: dif.smoother_transfer(b, "explicit", **a),
                          {"step": 0.1, "iters": 2}, {"step": "positive", "iters": "count"}),
    "boundary_vertices": (lambda b, **a: dif.boundary_vertices(F1, **a), {"n": N1},
                          {"n": "count"}),
    "curvature_at_vertex": (lambda b, **a: ce.curvature_at_vertex(V1, F1, **a), {"vertex": 3},
                            {"vertex": "index"}),
    "quadric_curvatures": (lambda b, **a: ce.quadric_curvatures(V1, F1, **a), {"radius": 2},
                           {"radius": "count"}),
    "jet_curvatures": (lambda b, **a: ce.jet_curvatures(V1, F1, **a), {"radius": 0.8},
                       {"radius": "positive"}),
}  # fmt: skip
CASES = [
    (name, arg, label)
    for name, (_, _, args) in API.items()
    for arg, kind in args.items()
    for label, _ in BAD[kind]
]


def test_the_new_api_table_covers_every_public_function():
    """Every name of ``meshlap_core.diffusion.__all__`` (a function or class taking more than
    the mesh) and the estimators' entry points are in the table, or said why not."""
    elsewhere = {
        "HeatDiffusion",  # its methods are in the table
        "HeatGeodesic",  # the constructor and .distance are
        "SpectralFilter",  # the constructor and .apply are
        "curve_gain",  # tests/test_diffusion.py: bad knots
        "mean_edge_length",  # V and F only: the mesh table above
    }
    names = {n.split(".")[0] for n in API} | elsewhere
    assert set(dif.__all__) <= names, sorted(set(dif.__all__) - names)


@pytest.mark.parametrize("name", sorted(API))
def test_the_new_api_takes_good_arguments(name, basis, tmp_path):
    call, good, _ = API[name]
    extra = {"path": tmp_path / "c.obj"} if name == "save_polylines" else {}
    call(basis, **extra, **good)


@pytest.mark.parametrize(("name", "arg", "case"), CASES)
def test_the_new_api_refuses_bad_arguments_naming_them(name, arg, case, basis, tmp_path):
    call, good, kinds = API[name]
    value = dict(BAD[kinds[arg]])[case]
    extra = {"path": tmp_path / "c.obj"} if name == "save_polylines" else {}
    if name == "SpectralFilter.apply" and case == "2-D":
        value = np.ones((5, 1))
    with warnings.catch_warnings():
        warnings.simplefilter("error", np.exceptions.ComplexWarning)
        warnings.simplefilter("error", RuntimeWarning)
        with pytest.raises(MeshError) as err:
            call(basis, **extra, **{**good, arg: value})
    assert str(err.value).startswith(f"{arg}: "), str(err.value)
    assert not list(tmp_path.iterdir())  # nothing written
