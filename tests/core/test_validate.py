"""Tests of meshlap_core.validate: every fatal branch, every repair, topology detection.

Tier 1: hand-made tiny meshes (three triangles on one edge, a bowtie, a flipped cube face).
Tier 2: invariants on primitives (Euler characteristic, boundary counts).
Tier 3: libigl's is_edge_manifold / is_vertex_manifold / unique_simplices as references.
"""

from __future__ import annotations

import igl
import numpy as np
import pytest

from meshlap_core import primitives
from meshlap_core.errors import MeshError
from meshlap_core.validate import (
    MAX_COORDINATE,
    Mesh,
    MeshReport,
    Polygons,
    degenerate_faces,
    duplicate_faces,
    require_manifold,
    topology_report,
    validate_mesh,
)

TRI_V = np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 0]])


def square():
    """Unit square as two CCW triangles (+z normals); 4 boundary edges, 1 interior edge."""
    V = np.array([[0.0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]])
    F = np.array([[0, 1, 2], [0, 2, 3]])
    return V, F


# ---------------------------------------------------------------------------- tier 1: basics


def test_single_triangle_report():
    mesh = validate_mesh(TRI_V, [[0, 1, 2]], "tri")
    assert isinstance(mesh, Mesh) and isinstance(mesh.report, MeshReport)
    assert mesh.V.dtype == np.float64 and mesh.F.dtype == np.int64
    assert mesh.n_vertices == 3 and mesh.n_faces == 1
    r = mesh.report
    assert (r.n_edges, r.n_boundary_edges, r.n_nonmanifold_edges) == (3, 3, 0)
    assert r.is_manifold and r.consistently_oriented and not r.is_closed
    assert r.n_components == 1
    assert r.repairs == [] and r.warnings == []
    V, F = mesh  # unpacks like a (V, F) pair
    assert np.array_equal(V, TRI_V) and np.array_equal(F, [[0, 1, 2]])


def test_inputs_not_modified():
    V, F = square()
    V0, F0 = V.copy(), F.copy()
    mesh = validate_mesh(V, F)
    mesh.V[0, 0] = 99.0
    mesh.F[0, 0] = 3
    assert np.array_equal(V, V0) and np.array_equal(F, F0)


# ---------------------------------------------------------------------------- fatal branches


@pytest.mark.parametrize(
    ("V", "F", "needle"),
    [
        (np.zeros((0, 3)), [[0, 1, 2]], "no vertices"),
        (TRI_V, np.zeros((0, 3), dtype=int), "no faces"),
        (TRI_V, [], "no faces"),
        (np.zeros((3, 2)), [[0, 1, 2]], "shape (n,3)"),
        (TRI_V, [[0, 1, 3]], "face 0 has index 3 but the mesh has 3 vertices"),
        (TRI_V, [[0, 1, 2], [0, -1, 2]], "face 1 has index -1"),
        (TRI_V, [[0, 1, 2], [0, 1]], "face 1 has 2 corners; a face needs at least 3"),
        (TRI_V, [[0, 1.5, 2]], "non-integer"),
        (TRI_V, [0, 1, 2], "shape (m,k)"),
    ],
)
def test_fatal_problems_name_source_and_problem(V, F, needle):
    with pytest.raises(MeshError) as info:
        validate_mesh(V, F, "bad.obj")
    assert needle in str(info.value)
    assert str(info.value).startswith("bad.obj: ")


def test_nan_and_inf_name_the_vertex():
    V = np.vstack([TRI_V, [np.nan, 0, 0]])
    with pytest.raises(MeshError, match=r"m\.off: vertex 3 has a NaN or infinite coordinate"):
        validate_mesh(V, [[0, 1, 2]], "m.off")
    V = np.vstack([[0, 0, np.inf], TRI_V])
    with pytest.raises(MeshError, match="vertex 0 has a NaN or infinite"):
        validate_mesh(V, [[1, 2, 3]], "m.off")


def test_vertex_map_used_in_messages():
    V = np.vstack([TRI_V, [np.nan, 0, 0]])
    with pytest.raises(MeshError, match="vertex 17 has a NaN"):
        validate_mesh(V, [[0, 1, 2]], "m.stl", vertex_map=[5, 6, 7, 17])


def test_huge_coordinates_are_an_error_not_nans_later():
    V = TRI_V * 1e300
    # the squared edge length really would overflow in float64
    with np.errstate(over="ignore"):
        assert not np.isfinite(np.sum((V[1] - V[0]) ** 2) ** 2)
    with pytest.raises(MeshError, match=r"vertex 1 has coordinate 1e\+300.*rescale"):
        validate_mesh(V, [[0, 1, 2]], "huge.obj")
    # just below the limit is accepted
    ok = validate_mesh(TRI_V * MAX_COORDINATE / 2, [[0, 1, 2]])
    assert ok.n_faces == 1


def test_all_faces_degenerate_is_fatal():
    V = np.array([[0.0, 0, 0], [1, 0, 0], [2, 0, 0], [3, 0, 0]])  # collinear
    with pytest.raises(
        MeshError,
        match=r"flat\.obj: all 3 faces are degenerate \(1 with a "
        r"repeated vertex, 2 with zero area\)",
    ):
        validate_mesh(V, [[0, 1, 2], [1, 2, 3], [0, 0, 1]], "flat.obj")


def test_no_source_uses_argument_names():
    with pytest.raises(MeshError, match=r"^F: face 0 has index 9"):
        validate_mesh(TRI_V, [[0, 1, 9]])
    with pytest.raises(MeshError, match=r"^V: the mesh has no vertices"):
        validate_mesh(np.zeros((0, 3)), [[0, 1, 2]])


# ---------------------------------------------------------------------------- repairs


def test_polygons_fan_triangulated_and_reported():
    V = np.array([[0.0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0], [2, 0.5, 0]])
    mesh = validate_mesh(V, [[0, 1, 2, 3], [1, 4, 2]], "quad.obj")
    assert mesh.F.tolist() == [[0, 1, 2], [0, 2, 3], [1, 4, 2]]
    assert mesh.face_map.tolist() == [0, 0, 1]
    assert mesh.report.repairs == [
        "triangulated 1 polygon with more than 3 corners into 2 triangles (fan triangulation)"
    ]
    assert mesh.report.n_input_faces == 2
    # same via an (m,4) array and via Polygons
    m2 = validate_mesh(V[:4], np.array([[0, 1, 2, 3]]))
    assert m2.F.tolist() == [[0, 1, 2], [0, 2, 3]]
    pent = Polygons(np.array([0, 1, 4, 2, 3]), np.array([5]))
    m3 = validate_mesh(V, pent)
    assert m3.F.tolist() == [[0, 1, 4], [0, 4, 2], [0, 2, 3]]
    assert "into 3 triangles" in m3.report.repairs[0]
    # the fan covers the polygon: total area of the convex pentagon (shoelace formula)
    P = V[[0, 1, 4, 2, 3], :2]
    x, y = P[:, 0], P[:, 1]
    shoelace = 0.5 * abs(np.dot(x, np.roll(y, -1)) - np.dot(y, np.roll(x, -1)))
    areas = 0.5 * igl.doublearea(m3.V, m3.F).sum()
    assert areas == pytest.approx(shoelace)


def test_degenerate_faces_removed_and_reported():
    V, F = square()
    V = np.vstack([V, [2, 0, 0]])  # vertex 4 collinear with 0 and 1
    F = np.vstack([F, [0, 0, 1], [0, 1, 4]])
    mesh = validate_mesh(V, F, "deg.obj")
    assert mesh.F.tolist() == [[0, 1, 2], [0, 2, 3]]
    assert mesh.report.repairs == [
        "removed 2 degenerate faces (1 with a repeated vertex, 1 with zero area)",
        "removed 1 unreferenced vertex (1 of them used only by removed faces)",
    ]
    assert mesh.vertex_map.tolist() == [0, 1, 2, 3]


def test_repair_false_keeps_and_warns():
    V, F = square()
    V = np.vstack([V, [5, 5, 5]])
    F = np.vstack([F, [2, 0, 1], [0, 0, 1]])
    mesh = validate_mesh(V, F, repair=False)
    assert mesh.n_faces == 4 and mesh.n_vertices == 5
    assert mesh.report.repairs == []
    w = " | ".join(mesh.report.warnings)
    assert "1 degenerate face" in w and "1 duplicate face" in w
    assert "1 unreferenced vertex (not removed: repair=False)" in w


def test_duplicate_faces_any_order_removed_first_kept():
    V, F = square()
    F = np.vstack([F, [2, 1, 0], [1, 2, 0], [3, 0, 2]])  # reversed, rotated, rotated
    mesh = validate_mesh(V, F, "dup.obj")
    assert mesh.F.tolist() == [[0, 1, 2], [0, 2, 3]]
    assert mesh.face_map.tolist() == [0, 1]
    assert mesh.report.repairs == [
        "removed 3 duplicate faces (same three vertices as an earlier face, in any order)"
    ]
    # reference: libigl's unique_simplices finds the same number of distinct faces
    FF = igl.unique_simplices(F)[0]
    assert len(FF) == len(F) - int(duplicate_faces(F, len(V)).sum())


def test_duplicate_faces_large_n_path_matches_key_path():
    rng = np.random.default_rng(3)
    F = rng.integers(0, 50, size=(400, 3))
    F = np.vstack([F, F[rng.permutation(400)[:60]][:, ::-1]])
    small = duplicate_faces(F, 50)
    big = duplicate_faces(F, 3_000_000)  # lexicographic np.unique path
    assert np.array_equal(small, big)
    assert int(small.sum()) == len(F) - len({tuple(sorted(f)) for f in F.tolist()})


def test_unreferenced_vertices_removed_with_vertex_map():
    V, F = square()
    V = np.vstack([[9, 9, 9], V[:2], [8, 8, 8], V[2:], [7, 7, 7]])  # originals at 1,2,4,5
    F = np.array([[1, 2, 4], [1, 4, 5]])
    mesh = validate_mesh(V, F, "unref.obj")
    assert mesh.report.repairs == ["removed 3 unreferenced vertices"]
    assert mesh.vertex_map.tolist() == [1, 2, 4, 5]
    assert np.array_equal(mesh.V, V[mesh.vertex_map])
    assert np.array_equal(mesh.V[mesh.F], V[F])  # same triangles geometrically
    assert mesh.report.n_input_vertices == 7


def test_degenerate_faces_threshold():
    V = np.array([[0.0, 0, 0], [1, 0, 0], [0.5, 1e-15, 0], [0.5, 1e-3, 0]])
    rep, zero = degenerate_faces(V, np.array([[0, 1, 2], [0, 1, 3], [0, 0, 3]]))
    assert rep.tolist() == [False, False, True]
    assert zero.tolist() == [True, False, False]


# ---------------------------------------------------------------------------- topology


def test_three_triangles_on_one_edge():
    V = np.array([[0.0, 0, 0], [1, 0, 0], [0.5, 1, 0], [0.5, -1, 0], [0.5, 0, 1]])
    F = np.array([[0, 1, 2], [1, 0, 3], [0, 1, 4]])
    mesh = validate_mesh(V, F, "fin.obj")
    r = mesh.report
    assert r.n_nonmanifold_edges == 1
    assert r.nonmanifold_edges.tolist() == [[0, 1]]
    assert not r.is_manifold
    assert any("1 non-manifold edge " in w for w in r.warnings)
    assert r.n_boundary_edges == 6
    assert not igl.is_edge_manifold(F)[0]  # reference agrees
    with pytest.raises(MeshError) as info:
        require_manifold(mesh, "mean curvature flow")
    assert str(info.value) == (
        "fin.obj: mean curvature flow needs an edge-manifold, consistently oriented mesh; "
        "this one has 1 non-manifold edge"
    )


def test_bowtie_vertex():
    V = np.array([[0.0, 0, 0], [1, 1, 0], [1, -1, 0], [-1, 1, 0], [-1, -1, 0]])
    F = np.array([[0, 2, 1], [0, 3, 4]])
    r = validate_mesh(V, F).report
    assert r.n_nonmanifold_vertices == 1
    assert r.nonmanifold_vertices.tolist() == [0]
    assert r.n_nonmanifold_edges == 0 and not r.is_manifold
    assert r.n_components == 1  # connected through the shared vertex
    assert any("1 non-manifold vertex" in w for w in r.warnings)
    ref = ~igl.is_vertex_manifold(F)
    assert np.flatnonzero(ref).tolist() == [0]
    require_manifold(F, "smoothing")  # edge-manifold and oriented: allowed


def test_two_closed_cones_pinched_at_a_vertex():
    # two tetrahedra sharing vertex 0: every edge has two faces, but vertex 0 has two fans
    V = np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1], [-1, 0, 0], [0, -1, 0], [0, 0, -1]])
    tet = np.array([[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]])
    F = np.vstack([tet, np.where(tet == 0, 0, tet + 3)])
    r = validate_mesh(V, F).report
    assert r.is_closed and r.n_nonmanifold_edges == 0
    assert r.nonmanifold_vertices.tolist() == [0]
    assert np.flatnonzero(~igl.is_vertex_manifold(F)).tolist() == [0]
    assert r.n_edges == 12 and r.n_components == 1


def test_flipped_face_on_cube_is_inconsistent():
    V, F = primitives.cube()
    ok = validate_mesh(V, F).report
    assert ok.consistently_oriented and ok.is_closed and ok.is_manifold
    assert len(V) - ok.n_edges + len(F) == 2  # Euler characteristic of a sphere
    G = F.copy()
    G[5] = G[5, ::-1]
    mesh = validate_mesh(V, G, "cube.obj")
    r = mesh.report
    assert not r.consistently_oriented
    assert r.n_inconsistent_edges == 3  # each edge of the flipped face
    assert any("not consistently oriented: 3 edges" in w for w in r.warnings)
    # libigl agrees: not edge-manifold in its oriented sense, but no edge has > 2 faces
    assert r.n_nonmanifold_edges == 0
    with pytest.raises(MeshError, match="this one has 3 inconsistently oriented edges"):
        require_manifold(mesh, "cotangent smoothing")


@pytest.mark.parametrize(
    ("name", "mesh", "chi", "n_boundary"),
    [
        ("icosphere", primitives.icosphere(2), 2, 0),
        ("torus", primitives.torus_mesh(12, 8), 0, 0),
        ("grid", primitives.grid(6, 4), 1, 2 * 5 + 2 * 3),
        ("cube", primitives.cube(1), 2, 0),
    ],
)
def test_primitives_invariants(name, mesh, chi, n_boundary):
    V, F = mesh
    m = validate_mesh(V, F, name)
    r = m.report
    assert m.n_vertices - r.n_edges + m.n_faces == chi
    assert r.n_boundary_edges == n_boundary
    assert r.is_manifold and r.consistently_oriented and r.n_components == 1
    assert r.repairs == [] and r.warnings == []
    assert 2 * r.n_edges == 3 * m.n_faces + r.n_boundary_edges  # handshake on half-edges


def test_components_count():
    V1, F1 = primitives.icosphere(1)
    V2, F2 = primitives.torus_mesh(8, 6)
    V = np.vstack([V1, V2 + 10])
    F = np.vstack([F1, F2 + len(V1)])
    r = validate_mesh(V, F).report
    assert r.n_components == 2
    assert r.n_components == igl.facet_components(F)[0]  # manifold: same as edge-components


def test_random_soup_against_references():
    """Non-manifold edges, boundary edges and non-manifold vertices of a random soup."""
    rng = np.random.default_rng(7)
    V, F0 = primitives.grid(8, 8)
    n = len(V)
    extra = rng.integers(0, n, size=(25, 3))  # random extra triangles over a manifold grid
    F = np.vstack([F0, extra])
    F = F[(F[:, 0] != F[:, 1]) & (F[:, 1] != F[:, 2]) & (F[:, 0] != F[:, 2])]
    F = F[~duplicate_faces(F, n)]
    r = topology_report(F, n)
    # brute force edge counts with a dictionary
    count: dict[tuple[int, int], int] = {}
    for f in F.tolist():
        for a, b in ((f[0], f[1]), (f[1], f[2]), (f[2], f[0])):
            e = (min(a, b), max(a, b))
            count[e] = count.get(e, 0) + 1
    assert r.n_edges == len(count)
    assert r.n_boundary_edges == sum(c == 1 for c in count.values())
    assert r.n_nonmanifold_edges == sum(c > 2 for c in count.values())
    assert sorted(map(tuple, r.nonmanifold_edges.tolist())) == sorted(
        e for e, c in count.items() if c > 2
    )
    ref = np.flatnonzero(~igl.is_vertex_manifold(F))
    ref = ref[np.isin(ref, F)]  # libigl marks nothing for unreferenced vertices either way
    assert r.nonmanifold_vertices.tolist() == ref.tolist()
    assert 0 < r.n_nonmanifold_vertices < n and 0 < r.n_nonmanifold_edges  # a real mix


def test_require_manifold_accepts_good_mesh_and_F():
    V, F = primitives.icosphere(1)
    require_manifold(validate_mesh(V, F), "spectral basis")
    require_manifold(F, "spectral basis")
    fin = np.array([[0, 1, 2], [1, 0, 3], [0, 1, 4]])
    with pytest.raises(MeshError, match=r"^F: spectral basis needs"):
        require_manifold(fin, "spectral basis", source="F")


def test_report_to_dict_is_plain():
    r = validate_mesh(*square()).report.to_dict()
    assert r["n_boundary_edges"] == 4 and r["is_manifold"] is True
    assert all(not isinstance(v, np.ndarray) for v in r.values())
