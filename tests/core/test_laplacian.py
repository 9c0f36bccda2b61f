"""Laplacians: hand-computed triangle, invariants, agreement with libigl."""

import igl
import numpy as np
import pytest

from meshlap_core import laplacian as lap
from meshlap_core import primitives
from meshlap_core.errors import MeshError

RIGHT_V = np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 0]])
RIGHT_F = np.array([[0, 1, 2]])


def random_mesh(seed: int = 0):
    """An icosphere with every vertex jittered: irregular, but still a valid closed mesh."""
    V, F = primitives.icosphere(2)
    rng = np.random.default_rng(seed)
    return V + 0.05 * rng.standard_normal(V.shape), F


def test_right_triangle_by_hand():
    # angles: pi/2 at corner 0, pi/4 at corners 1 and 2 -> cot = 0, 1, 1
    C = lap.cotan_stiffness(RIGHT_V, RIGHT_F).toarray()
    expected = np.array([[-1.0, 0.5, 0.5], [0.5, -0.5, 0.0], [0.5, 0.0, -0.5]])
    np.testing.assert_allclose(C, expected, atol=1e-15)
    np.testing.assert_allclose(lap.vertex_areas(RIGHT_V, RIGHT_F, "barycentric"), [1 / 6] * 3)
    # Voronoi cells of a right triangle (Meyer et al.): (|e|^2 cot) / 8 per vertex
    np.testing.assert_allclose(lap.vertex_areas(RIGHT_V, RIGHT_F, "voronoi"), [1 / 4, 1 / 8, 1 / 8])
    np.testing.assert_allclose(lap.squared_edge_lengths(RIGHT_V, RIGHT_F), [[2.0, 1.0, 1.0]])


def test_uniform_laplacian_by_hand_on_octahedron():
    V = np.array([[1.0, 0, 0], [-1, 0, 0], [0, 1, 0], [0, -1, 0], [0, 0, 1], [0, 0, -1]])
    F = np.array(
        [[0, 2, 4], [2, 1, 4], [1, 3, 4], [3, 0, 4], [2, 0, 5], [1, 2, 5], [3, 1, 5], [0, 3, 5]]
    )
    L = lap.uniform_laplacian(F, 6)
    # each vertex has 4 neighbours whose mean is the origin: L x = -x
    np.testing.assert_allclose(L @ V, -V, atol=1e-15)
    np.testing.assert_allclose(lap.adjacency_matrix(F, 6).sum(axis=1).A1, 4)


@pytest.mark.parametrize(
    "make", [lambda: primitives.icosphere(2), primitives.torus_mesh, primitives.grid, random_mesh]
)
def test_invariants(make):
    V, F = make()
    n = len(V)
    C = lap.cotan_stiffness(V, F)
    assert C.shape == (n, n) and C.format == "csr"
    np.testing.assert_allclose(C @ np.ones(n), 0, atol=1e-10)
    assert abs(C - C.T).max() < 1e-12
    # negative semidefinite: x^T C x <= 0 for random x
    x = np.random.default_rng(1).standard_normal((n, 5))
    assert np.all(np.einsum("ij,ij->j", x, C @ x) <= 1e-10)
    L = lap.uniform_laplacian(F, n)
    np.testing.assert_allclose(L @ np.ones(n), 0, atol=1e-12)
    A = lap.face_areas(V, F).sum()
    for area in lap.AREA_KINDS:
        np.testing.assert_allclose(lap.vertex_areas(V, F, area).sum(), A, rtol=1e-12)
        LB = lap.laplace_beltrami(V, F, area)
        np.testing.assert_allclose(LB @ np.ones(n), 0, atol=1e-8)


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_hand_written_cotan_matches_libigl(seed):
    V, F = random_mesh(seed)
    mine = lap.cotan_stiffness_intrinsic(lap.squared_edge_lengths(V, F), F, len(V))
    ref = igl.cotmatrix(V, F)
    assert abs(mine - ref).max() < 1e-12
    bary = igl.massmatrix(V, F, igl.MASSMATRIX_TYPE_BARYCENTRIC).diagonal()
    np.testing.assert_allclose(lap.vertex_areas(V, F, "barycentric"), bary, rtol=1e-12)


def test_unreferenced_trailing_vertex_keeps_its_row():
    V = np.vstack([RIGHT_V, [[5.0, 5, 5]]])
    assert lap.cotan_stiffness(V, RIGHT_F).shape == (4, 4)
    assert lap.uniform_laplacian(RIGHT_F, 4).shape == (4, 4)
    assert lap.vertex_areas(V, RIGHT_F, "voronoi")[3] == 0


def test_degenerate_face_gives_finite_weights():
    V = np.array([[0.0, 0, 0], [1, 0, 0], [2, 0, 0], [0, 1, 0]])  # 0,1,2 collinear
    F = np.array([[0, 1, 2], [0, 1, 3]])
    C = lap.cotan_stiffness_intrinsic(lap.squared_edge_lengths(V, F), F, 4)
    assert np.isfinite(C.data).all()
    assert np.isfinite(lap.cotan_stiffness(V, F).data).all()
    assert np.isfinite(lap.vertex_areas(V, F, "voronoi")).all()


def test_inputs_not_modified_and_bad_area_rejected():
    V, F = primitives.icosphere(1)
    V0, F0 = V.copy(), F.copy()
    lap.cotan_stiffness(V, F)
    lap.mass_matrix(V, F, "voronoi")
    np.testing.assert_array_equal(V, V0)
    np.testing.assert_array_equal(F, F0)
    with pytest.raises(MeshError, match="area"):
        lap.vertex_areas(V, F, "circumcentric")


def test_mean_edge_length_counts_each_edge_once():
    """By hand: the right triangle's edges 1, 1, √2; two triangles sharing the diagonal of the
    unit square have five edges 1, 1, 1, 1, √2 (a mean over half-edges would count the shared
    diagonal twice: (4 + 2√2)/6). Against libigl on a closed and an open mesh; a mesh's own
    edge list gives the same number; no faces: 0."""
    assert lap.mean_edge_length(RIGHT_V, RIGHT_F) == pytest.approx((2 + np.sqrt(2)) / 3)
    V = np.array([[0.0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]])
    F = np.array([[0, 1, 2], [0, 2, 3]])
    assert lap.mean_edge_length(V, F) == pytest.approx((4 + np.sqrt(2)) / 5)
    for V, F in (primitives.icosphere(2), primitives.grid(7, 5)):
        h = lap.mean_edge_length(V, F)
        assert h == pytest.approx(igl.avg_edge_length(V, F), rel=1e-12)
        E = np.sort(np.concatenate([F[:, [0, 1]], F[:, [1, 2]], F[:, [2, 0]]]), axis=1)
        assert lap.mean_edge_length(V, F, np.unique(E, axis=0)) == pytest.approx(h, rel=1e-15)
    assert lap.mean_edge_length(RIGHT_V, np.zeros((0, 3), dtype=np.int64)) == 0.0
