"""Deformation (meshlap_core.deform): hand-computed cases, invariants, libigl, bad input."""

import doctest
import importlib
import threading

import igl
import numpy as np
import pytest
import scipy.sparse.linalg as sla

from meshlap_core import primitives
from meshlap_core.deform import (
    ArapDeformer,
    HarmonicDeformer,
    LaplacianCoordinates,
    deform_mesh,
    edge_graph,
    farthest_region,
    fit_rotations,
    grow_handles,
    make_deformer,
    rigid_targets,
    rotation_error,
    rotation_matrix,
)
from meshlap_core.deform.rotations import fit_rotations_igl
from meshlap_core.errors import Cancelled, MeshError, MeshWarning


@pytest.fixture(scope="module")
def bumpy():
    V, F = primitives.bumpy_sphere(2)
    return V * np.array([1.0, 0.7, 1.3]), F


def diagonal(V):
    return float(np.linalg.norm(np.ptp(V, axis=0)))


def svd_rotations_reference(S):
    """The textbook fit, matrix by matrix: R = V diag(1, 1, det(V Uᵀ)) Uᵀ."""
    out = np.empty_like(S)
    for i, s in enumerate(S):
        U, _, Vt = np.linalg.svd(s)
        D = np.diag([1.0, 1.0, np.sign(np.linalg.det(Vt.T @ U.T))])
        out[i] = Vt.T @ D @ U.T
    return out


# ---------------------------------------------------------------- rotations (local step)


def test_a_mirror_fits_the_identity_with_the_fix_and_the_mirror_without():
    """S = diag(3, 2, −1): tr(RS) over rotations is largest at R = I (value 4); the
    orthogonal polar factor is the mirror diag(1, 1, −1) (value 6, det −1)."""
    S = np.diag([3.0, 2.0, -1.0])[None]
    np.testing.assert_allclose(fit_rotations(S)[0], np.eye(3), atol=1e-15)
    np.testing.assert_allclose(fit_rotations(S, reflection_fix=False)[0], np.diag([1, 1, -1.0]))


def test_a_rotated_ring_gives_back_its_rotation():
    """e' = Q e for every spoke: S = Σ w e eᵀ Qᵀ = A Qᵀ (A positive definite), so R = Q."""
    rng = np.random.default_rng(0)
    Q = np.array([rotation_matrix(rng.standard_normal(3), d) for d in rng.uniform(-180, 180, 50)])
    E = rng.standard_normal((50, 6, 3))  # six spokes per vertex
    w = rng.uniform(0.1, 1.0, (50, 6))
    S = np.einsum("nk,nka,nkb->nab", w, E, E @ Q.transpose(0, 2, 1))
    np.testing.assert_allclose(fit_rotations(S), Q, atol=1e-12)


def test_rotations_equal_the_textbook_svd_also_for_planar_and_mirrored_rings():
    rng = np.random.default_rng(1)
    S = rng.standard_normal((500, 3, 3))
    S[:100, :, 2] = 0.0  # planar one-rings: σ₃ = 0
    S[100:200] = S[100:200] @ np.diag([1.0, 1.0, -1.0])  # some mirrored
    R = fit_rotations(S)
    np.testing.assert_allclose(R, svd_rotations_reference(S), atol=1e-9)
    np.testing.assert_allclose(np.linalg.det(R), 1.0, atol=1e-12)
    np.testing.assert_allclose(
        R @ R.transpose(0, 2, 1), np.broadcast_to(np.eye(3), R.shape), atol=1e-13
    )


def test_rank_one_and_zero_covariances_still_give_rotations():
    a, b = np.array([1.0, 2.0, 3.0]), np.array([0.0, 1.0, 0.0])
    S = np.stack([np.zeros((3, 3)), np.outer(a, b)])
    R = fit_rotations(S)
    np.testing.assert_allclose(R[0], np.eye(3))
    np.testing.assert_allclose(np.linalg.det(R), 1.0)
    np.testing.assert_allclose(R[1] @ (a / np.linalg.norm(a)), b, atol=1e-14)


def test_libigl_single_precision_fit_is_what_igl_fit_rotations_returns():
    rng = np.random.default_rng(2)
    S = rng.standard_normal((3, 3, 40))
    stacked = S.transpose(0, 2, 1).reshape(120, 3)
    expected = igl.fit_rotations(stacked / np.abs(S).max(), True).reshape(3, 40, 3)
    np.testing.assert_allclose(fit_rotations_igl(S), expected.transpose(0, 2, 1))


# ---------------------------------------------------------------- hand-computed deformations


def test_harmonic_displacement_of_a_strip_is_linear():
    """Left column up by 1, right column fixed: d = 1 − x is harmonic and the cotangent
    Laplacian is exact on linear functions of a flat mesh (natural boundary elsewhere)."""
    V, F = primitives.grid(6, 4)
    left, right = np.flatnonzero(V[:, 0] == 0), np.flatnonzero(V[:, 0] == 1)
    h = HarmonicDeformer(V, F, left, right, k=1)
    U = h.update(V[left] + [0.0, 0.0, 1.0])
    np.testing.assert_allclose(U[:, 2], 1.0 - V[:, 0], atol=1e-14)
    np.testing.assert_allclose(U[:, :2], V[:, :2], atol=1e-15)
    # the Dirichlet energy of d = 1 − x over the unit square: ∫|∇d|² = 1
    assert h.energy() == pytest.approx(1.0, rel=1e-12)


def test_a_single_free_vertex_moves_to_its_weighted_neighbour_average():
    """A fan of 4 triangles around the centre of a square; corners held (one moved by 1 in
    z): the harmonic centre is the cotangent average (right isosceles: all weights ½·cot 45°·2
    = 1 for the spokes), so it rises by 1/4."""
    V = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0], [0.5, 0.5, 0]], dtype=float)
    F = np.array([[0, 1, 4], [1, 2, 4], [2, 3, 4], [3, 0, 4]])
    h = HarmonicDeformer(V, F, [0], [1, 2, 3], k=1)
    U = h.update([[0.0, 0.0, 1.0]])
    assert U[4, 2] == pytest.approx(0.25, abs=1e-15)


# ---------------------------------------------------------------- invariants


@pytest.mark.parametrize("method", ["laplacian", "harmonic", "biharmonic", "triharmonic"])
def test_zero_move_reproduces_the_rest_pose_exactly(bumpy, method):
    V, F = bumpy
    solver = make_deformer(method, V, F, [0, 40], [100, 101])
    assert np.array_equal(solver.update(V[[0, 40]]), V)
    assert solver.energy() == 0.0


def test_arap_zero_move_stays_at_rest(bumpy):
    V, F = bumpy
    arap = ArapDeformer(V, F, [0, 40], [100])
    np.testing.assert_allclose(arap.run(5), V, atol=1e-13)


@pytest.mark.parametrize("method", ["laplacian", "harmonic", "biharmonic", "triharmonic"])
def test_a_translation_of_every_handle_translates_the_mesh(bumpy, method):
    """K·1 = 0: a constant displacement costs nothing, so it is the solution."""
    V, F = bumpy
    t = np.array([0.3, -0.1, 0.2])
    U = make_deformer(method, V, F, [0, 40, 90]).update(V[[0, 40, 90]] + t)
    np.testing.assert_allclose(U, V + t, atol=1e-10)


def test_handles_reach_their_targets_and_the_fixed_region_stays(bumpy):
    V, F = bumpy
    targets = V[[0, 5]] + [[0.3, 0.1, 0.0], [0.0, -0.2, 0.1]]
    for method in ("harmonic", "biharmonic", "triharmonic", "arap"):
        s = make_deformer(method, V, F, [0, 5], [100, 150])
        U = s.update(targets)
        np.testing.assert_allclose(U[[0, 5]], targets, atol=1e-15)
        np.testing.assert_array_equal(U[[100, 150]], V[[100, 150]])
        assert s.handle_error() < 1e-15


def test_hard_laplacian_coordinates_are_the_biharmonic_displacement(bumpy):
    """‖Δx − δ‖²_M = ‖Δ(x − p)‖²_M: keeping δ with exact constraints is Δ²d = 0."""
    V, F = bumpy
    t = V[[0, 5]] + [[0.3, 0.1, 0.0], [0.0, -0.2, 0.1]]
    hard = LaplacianCoordinates(V, F, [0, 5], [100], constraints="hard").update(t)
    np.testing.assert_allclose(
        hard, HarmonicDeformer(V, F, [0, 5], [100], k=2).update(t), atol=1e-13
    )


def test_soft_laplacian_coordinates_lag_and_less_with_a_larger_weight(bumpy):
    V, F = bumpy
    t = V[[0]] + [0.0, 0.0, 0.3]
    lags = []
    for w in (1.0, 100.0, 1e4):
        lc = LaplacianCoordinates(V, F, [0], [100], weight=w)
        lc.update(t)
        lags.append(lc.handle_error())
        shape, penalty = lc.energy_parts()
        assert shape > 0 and penalty > 0 and lc.energy() == pytest.approx(shape + penalty)
    assert 0 < lags[2] < lags[1] < lags[0] < 0.3


def test_arap_energy_never_increases_and_matches_its_vertex_shares(bumpy):
    V, F = bumpy
    arap = ArapDeformer(V, F, [0, 5, 40], [100, 150])
    arap.set_targets(rigid_targets(V, arap.handles, rotation_matrix([1, 0, 1], 50), [0.2, 0, 0]))
    arap.run(60)
    e = np.array(arap.energies)
    scale = arap.terms.rest  # μ tr(pᵀKp): the size of the round-off in E
    assert np.all(np.diff(e) <= 1e-13 * scale), np.diff(e).max()
    assert e[-1] < 0.5 * e[0]
    assert arap.vertex_energy().sum() == pytest.approx(arap.energy(), rel=1e-9, abs=1e-12 * scale)


def test_a_rigid_motion_is_reproduced_by_arap_and_not_by_laplacian_coordinates():
    """Three handles moved by one rigid motion, nothing fixed: ARAP's energy has its minimum 0
    there and reaches it (within 1e-4 of the diagonal after 500 iterations, as libigl does);
    Laplacian coordinates keep δ unrotated, so they miss it by a fraction of the size."""
    V, F = primitives.bumpy_sphere(2)
    handles = np.array([0, len(V) // 3, 2 * len(V) // 3])
    rigid = V @ rotation_matrix([1, 2, 3], 40).T + [0.3, -0.2, 0.5]
    size = diagonal(V)
    arap = ArapDeformer(V, F, handles)
    arap.set_targets(rigid[handles])
    arap.run(500)
    assert np.abs(arap.positions - rigid).max() < 1e-4 * size
    assert arap.rotation_error().max() < 1e-3
    lc = LaplacianCoordinates(V, F, handles, constraints="hard")
    miss = np.abs(lc.update(rigid[handles]) - rigid).max()
    assert miss > 0.05 * size  # the error the test shows: 0.19 of the diagonal here
    assert lc.rotation_error().max() > 0.1


def test_a_component_without_a_handle_stays_put():
    V1, F1 = primitives.icosphere(1)
    V = np.concatenate([V1, V1 + np.array([5.0, 0, 0])])
    F = np.concatenate([F1, F1 + len(V1)])
    for method in ("biharmonic", "laplacian", "arap"):
        s = make_deformer(method, V, F, [0])
        U = s.update(V[[0]] + [0.0, 0.0, 0.5])
        assert s.constraints.n_components == 2
        np.testing.assert_array_equal(s.constraints.still, np.arange(len(V1), len(V)))
        np.testing.assert_array_equal(U[len(V1) :], V[len(V1) :])


@pytest.mark.parametrize("method", ["biharmonic", "laplacian", "arap"])
def test_a_vertex_only_in_a_degenerate_face_is_held(method):
    """libigl's cotangents divide by zero on a zero-area face: the guarded ones give it zero
    weights, and its lone vertex (no area, a component of its own) stays put."""
    V1, F1 = primitives.icosphere(1)
    a, b = F1[0, 0], F1[0, 1]
    V = np.concatenate([V1, [(V1[a] + V1[b]) / 2]])
    F = np.concatenate([F1, [[a, b, len(V1)]]])
    s = make_deformer(method, V, F, [5])
    U = s.update(V[[5]] + [0.0, 0.0, 0.3])
    assert len(V1) in s.constraints.still and np.isfinite(U).all()
    np.testing.assert_array_equal(U[len(V1)], V[len(V1)])
    assert U[5, 2] == pytest.approx(V[5, 2] + 0.3)


@pytest.mark.parametrize("method", ["laplacian", "harmonic", "biharmonic", "triharmonic", "arap"])
def test_a_handle_in_no_face_goes_to_its_target_and_faceless_meshes_work(bumpy, method):
    """An unreferenced handle vertex has no stiffness: the soft penalty weighed by it would be
    0 and the system singular (the bundled Cholesky then crashed); it is held exactly."""
    V, F = bumpy
    W = np.concatenate([V, [[3.0, 3.0, 3.0]]])
    s = make_deformer(method, W, F, [0, len(V)])
    U = s.update([V[0] + 0.1, [4.0, 4.0, 4.0]])
    np.testing.assert_array_equal(U[len(V)], [4.0, 4.0, 4.0])
    none = make_deformer(method, V[:4], np.zeros((0, 3), dtype=np.int64), [1])
    U = none.update([[1.0, 2.0, 3.0]])
    np.testing.assert_array_equal(U[1], [1.0, 2.0, 3.0])
    np.testing.assert_array_equal(np.delete(U, 1, axis=0), np.delete(V[:4], 1, axis=0))


@pytest.mark.parametrize("scale", [1e70, 1e-55])
@pytest.mark.parametrize("method", ["triharmonic", "laplacian", "arap"])
def test_results_scale_with_the_mesh_to_the_edges_of_the_coordinate_range(bumpy, scale, method):
    """The rotations, the powers of M⁻¹ and the energies at coordinates 1e70 and 1e-55 (where
    SᵀS of a one-ring would overflow or underflow unnormalized)."""
    V, F = bumpy
    t = V[[0, 40]] + [[0.3, 0.1, 0.0], [0.0, 0.0, -0.2]]
    one = make_deformer(method, V, F, [0, 40], [100])
    big = make_deformer(method, V * scale, F, [0, 40], [100])
    np.testing.assert_allclose(big.update(t * scale) / scale, one.update(t), atol=1e-9)
    assert np.isfinite(big.energy()) and np.isfinite(big.rotation_error()).all()


def test_targets_beyond_the_coordinate_range_are_refused(bumpy):
    V, F = bumpy
    s = make_deformer("biharmonic", V, F, [0])
    with pytest.raises(MeshError, match="beyond") as info:
        s.update([[1e300, 0.0, 0.0]])
    assert info.value.source == "targets"


def test_rotation_error_is_zero_for_a_rigid_motion_and_grows_with_a_stretch(bumpy):
    V, F = bumpy
    rigid = V @ rotation_matrix([0, 1, 1], 70).T + 2.0
    err, _ = rotation_error(V, F, rigid)
    assert err.max() < 1e-12
    err, _ = rotation_error(V, F, V * [1.1, 1.0, 1.0])
    assert 0.0 < err.max() <= 0.1 + 1e-12 and np.median(err) > 0.01


# ---------------------------------------------------------------- against libigl


@pytest.mark.parametrize("k", [1, 2, 3])
@pytest.mark.parametrize("mesh", ["bumpy", "grid"])
def test_k_harmonic_displacement_equals_igl_harmonic(bumpy, k, mesh, spd_backend):
    if mesh == "bumpy":
        V, F = bumpy
        handles, fixed = np.array([0, 5, 40]), np.array([100, 101, 150])
    else:
        V, F = primitives.grid(15, 12)
        V = V + np.c_[0 * V[:, :2], 0.1 * np.sin(5 * V[:, 0])]
        handles, fixed = np.arange(12), np.arange(len(V) - 12, len(V))
    targets = V[handles] + np.random.default_rng(k).normal(0.0, 0.2, (len(handles), 3))
    U = HarmonicDeformer(V, F, handles, fixed, k=k).update(targets)
    b = np.concatenate([handles, fixed])
    bc = np.concatenate([targets - V[handles], np.zeros((len(fixed), 3))])
    np.testing.assert_allclose(U - V, igl.harmonic(V, F, b, bc, k), atol=1e-8)


@pytest.mark.parametrize("energy", ["spokes", "spokes-and-rims"])
def test_arap_with_libigls_rotations_equals_igl_arap_solve(bumpy, energy, spd_backend):
    V, F = bumpy
    handles, fixed = np.array([0, 5, 40]), np.array([100])
    targets = V[handles] + [[0.3, 0.1, 0.0], [0.0, 0.0, 0.0], [-0.2, 0.0, 0.1]]
    kind = {
        "spokes": igl.ARAP_ENERGY_TYPE_SPOKES,
        "spokes-and-rims": igl.ARAP_ENERGY_TYPE_SPOKES_AND_RIMS,
    }
    arap = ArapDeformer(V, F, handles, fixed, energy=energy, rotations="igl")
    arap.set_targets(targets)
    done = 0
    for iters in (1, 10, 30):
        arap.run(iters - done)
        done = iters
        data = igl.ARAPData()
        data.energy = kind[energy]
        data.max_iter = iters
        igl.arap_precomputation(V, F, 3, np.concatenate([handles, fixed]).astype(np.int32), data)
        expected = igl.arap_solve(np.concatenate([targets, V[fixed]]), data, V)
        np.testing.assert_allclose(arap.positions, expected, atol=1e-6)


def dense_arap_reference(V, F, handles, targets, iters):
    """ARAP spokes written out vertex by vertex (np.linalg.svd, a sparse direct solve)."""
    n = len(V)
    C = igl.cotmatrix(V, F).tocsr()
    K = -C
    free = np.setdiff1d(np.arange(n), handles)
    Kff = K[free][:, free].tocsc()
    U = V.copy()
    U[handles] = targets
    for _ in range(iters):
        S = np.zeros((n, 3, 3))
        for i in range(n):
            for j in C[i].indices:
                if j != i:
                    S[i] += C[i, j] * np.outer(V[i] - V[j], U[i] - U[j])
        R = svd_rotations_reference(S)
        b = np.zeros((n, 3))
        for i in range(n):
            for j in C[i].indices:
                if j != i:
                    b[i] += 0.5 * C[i, j] * (R[i] + R[j]) @ (V[i] - V[j])
        U[free] = sla.spsolve(Kff, b[free] - K[free][:, handles] @ targets)
    return U


def test_arap_equals_a_vertex_by_vertex_reference_and_libigl_within_its_precision(spd_backend):
    V, F = primitives.icosphere(2)
    V = V * [1.0, 0.8, 1.2]
    handles = np.array([0, 30, 90])
    targets = V[handles] + [[0.2, 0.0, 0.1], [0.0, 0.0, 0.0], [0.0, -0.3, 0.0]]
    arap = ArapDeformer(V, F, handles)
    arap.set_targets(targets)
    arap.run(8)
    np.testing.assert_allclose(
        arap.positions, dense_arap_reference(V, F, handles, targets, 8), atol=1e-10
    )
    data = igl.ARAPData()
    data.energy = igl.ARAP_ENERGY_TYPE_SPOKES
    data.max_iter = 8
    igl.arap_precomputation(V, F, 3, handles.astype(np.int32), data)
    # libigl fits its rotations in single precision: about 1e-5 of the size apart
    assert np.abs(igl.arap_solve(targets, data, V) - arap.positions).max() < 1e-3 * diagonal(V)


# ---------------------------------------------------------------- handle regions


def test_discs_are_the_exact_geodesic_discs(bumpy):
    V, F = bumpy
    exact = igl.exact_geodesic(V, F, VS=np.array([7]), VT=np.arange(len(V))).ravel()
    for radius in (0.1, 0.3, 0.9):
        regions = grow_handles(V, F, [7], radius)
        np.testing.assert_array_equal(regions.vertices, np.flatnonzero(exact <= radius))
        np.testing.assert_allclose(regions.distance, exact[regions.vertices], atol=1e-12)
        graph = grow_handles(V, F, [7], radius, distance="graph")
        assert set(graph.vertices) <= set(regions.vertices)  # paths along edges are longer
        again = grow_handles(V, F, [7], radius, graph=edge_graph(V, F))  # a cached graph
        np.testing.assert_array_equal(again.vertices, regions.vertices)


def test_overlapping_discs_go_to_the_nearer_seed_and_radius_zero_keeps_the_seeds(bumpy):
    V, F = bumpy
    seeds = [0, 1]
    regions = grow_handles(V, F, seeds, 0.5)
    d = [igl.exact_geodesic(V, F, VS=np.array([s]), VT=regions.vertices).ravel() for s in seeds]
    nearer = np.where(d[0] <= d[1], 0, 1)
    tie = np.isclose(d[0], d[1])
    np.testing.assert_array_equal(regions.region[~tie], nearer[~tie])
    same = grow_handles(V, F, [9, 3], 0.0)
    np.testing.assert_array_equal(same.vertices, [3, 9])


def test_a_disc_over_the_exact_limit_is_measured_along_edges_with_a_warning(bumpy, monkeypatch):
    from meshlap_core.deform import regions

    V, F = bumpy
    monkeypatch.setattr(regions, "MAX_EXACT_PATCH", 50)
    with pytest.warns(MeshWarning, match="along edges"):
        big = grow_handles(V, F, [7], 0.8)
    np.testing.assert_array_equal(
        big.vertices, grow_handles(V, F, [7], 0.8, distance="graph").vertices
    )


def test_the_default_fixed_region_is_far_from_every_handle():
    V, F = primitives.grid(11, 11)
    fixed = farthest_region(V, F, [0], fraction=0.1)  # the handle in one corner
    assert len(fixed) and int(np.argmax(np.linalg.norm(V - V[0], axis=1))) in fixed
    assert np.linalg.norm(V[fixed] - V[0], axis=1).min() > 1.0


# ---------------------------------------------------------------- hooks and the one-shot call


def test_progress_is_reported_and_cancel_stops_the_set_up_and_the_iterations(bumpy):
    V, F = bumpy
    seen = []
    ArapDeformer(V, F, [0], progress=lambda f, m: seen.append(f))
    assert seen[0] == 0.0 and seen[-1] == 1.0 and seen == sorted(seen)
    stop = threading.Event()
    stop.set()
    with pytest.raises(Cancelled):
        HarmonicDeformer(V, F, [0], cancel=stop)
    arap = ArapDeformer(V, F, [0])
    with pytest.raises(Cancelled):
        arap.run(10, cancel=stop)
    assert arap.iteration == 0


def test_deform_mesh_is_the_solver_in_one_call(bumpy):
    V, F = bumpy
    t = V[[0]] + 0.2
    U = deform_mesh(V, F, [0], t, "biharmonic", fixed=[100])
    np.testing.assert_array_equal(U, HarmonicDeformer(V, F, [0], [100]).update(t))
    A = ArapDeformer(V, F, [0], [100])
    A.set_targets(t)
    np.testing.assert_array_equal(deform_mesh(V, F, [0], t, "arap", [100], iters=4), A.run(4))


@pytest.mark.parametrize("module", ["harmonic", "arap", "methods", "rotations", "targets"])
def test_docstring_examples_run(module):
    result = doctest.testmod(importlib.import_module(f"meshlap_core.deform.{module}"))
    assert result.attempted >= 2 and result.failed == 0


# ---------------------------------------------------------------- bad input


BAD_INDICES = [
    ([], "at least one"),
    ([[1, 2]], "flat list"),
    ([1.5], "integers"),
    ([np.nan], "integers"),
    (["a"], "numbers"),
    ([True], "boolean"),
    ([-1], "out of range"),
    ([10**6], "out of range"),
    ([2**70], "out of range"),
]


@pytest.mark.parametrize(("bad", "words"), BAD_INDICES)
def test_bad_handles_and_fixed_are_named(bumpy, bad, words):
    V, F = bumpy
    with pytest.raises(MeshError, match=words) as info:
        HarmonicDeformer(V, F, bad)
    assert info.value.source == "handles"
    if bad == []:
        return  # no fixed vertex is allowed
    with pytest.raises(MeshError, match=words) as info:
        ArapDeformer(V, F, [0], bad)
    assert info.value.source == "fixed"


def test_a_vertex_both_handle_and_fixed_is_refused(bumpy):
    V, F = bumpy
    with pytest.raises(MeshError, match="both a handle and fixed") as info:
        make_deformer("laplacian", V, F, [0, 3], [3, 4])
    assert info.value.source == "fixed"


@pytest.mark.parametrize(
    "bad",
    [
        np.zeros((3, 3)),
        np.zeros((2, 2)),
        [[np.nan, 0, 0], [0, 0, 0]],
        [["a", 0, 0]] * 2,
        np.ones((2, 3), bool),
    ],
)
@pytest.mark.parametrize("method", ["laplacian", "biharmonic", "arap"])
def test_bad_targets_are_named_and_change_nothing(bumpy, bad, method):
    V, F = bumpy
    s = make_deformer(method, V, F, [0, 5])
    before = s.positions.copy()
    with pytest.raises(MeshError) as info:
        s.update(bad)
    assert info.value.source == "targets"
    np.testing.assert_array_equal(s.positions, before)


@pytest.mark.parametrize(
    ("kwargs", "source"),
    [
        ({"k": 0}, "k"),
        ({"k": 4}, "k"),
        ({"k": True}, "k"),
        ({"k": "2"}, "k"),
    ],
)
def test_bad_harmonic_order_is_named(bumpy, kwargs, source):
    V, F = bumpy
    with pytest.raises(MeshError) as info:
        HarmonicDeformer(V, F, [0], **kwargs)
    assert info.value.source == source


@pytest.mark.parametrize(
    ("method", "kwargs", "source"),
    [
        ("nope", {}, "method"),
        ("arap", {"energy": "rims"}, "energy"),
        ("arap", {"rotations": "float"}, "rotations"),
        ("laplacian", {"constraints": "firm"}, "constraints"),
        ("laplacian", {"weight": 0}, "weight"),
        ("laplacian", {"weight": np.nan}, "weight"),
        ("laplacian", {"weight": "x"}, "weight"),
    ],
)
def test_bad_method_options_are_named(bumpy, method, kwargs, source):
    V, F = bumpy
    with pytest.raises(MeshError) as info:
        make_deformer(method, V, F, [0], **kwargs)
    assert info.value.source == source


@pytest.mark.parametrize(
    ("which", "bad"),
    [
        ("V", lambda V, F: V[:, :2]),
        ("V", lambda V, F: V.astype(complex)),
        ("V", lambda V, F: V.astype(str)),
        ("F", lambda V, F: F + 0.5),
        ("F", lambda V, F: F[:, :2]),
        ("F", lambda V, F: -F),
    ],
)
@pytest.mark.parametrize("method", ["laplacian", "biharmonic", "arap"])
def test_bad_mesh_arrays_are_named(bumpy, which, bad, method):
    V, F = bumpy
    args = (bad(V, F), F) if which == "V" else (V, bad(V, F))
    with pytest.raises(MeshError) as info:
        make_deformer(method, *args, [0])
    assert info.value.source == which


def test_bad_meshes_are_named(bumpy):
    V, F = bumpy
    W = V.copy()
    W[3, 1] = np.inf
    with pytest.raises(MeshError, match="vertex 3") as info:
        ArapDeformer(W, F, [0])
    assert info.value.source == "V"
    with pytest.raises(MeshError) as info:
        HarmonicDeformer(V, F + len(V), [0])
    assert info.value.source == "F"


@pytest.mark.parametrize("bad", [-1, np.nan, np.inf, "x", None])
def test_bad_radius_is_named(bumpy, bad):
    V, F = bumpy
    with pytest.raises(MeshError) as info:
        grow_handles(V, F, [0], bad)
    assert info.value.source == "radius"


def test_bad_region_options_are_named(bumpy):
    V, F = bumpy
    with pytest.raises(MeshError) as info:
        grow_handles(V, F, [0], 0.1, distance="heat")
    assert info.value.source == "distance"
    for bad in (0, 1, -0.5, np.nan, "x"):
        with pytest.raises(MeshError) as info:
            farthest_region(V, F, [0], bad)
        assert info.value.source == "fraction"


@pytest.mark.parametrize(
    ("axis", "degrees", "words"),
    [
        ([0, 0, 0], 30, "zero vector"),
        ([0, 0, 1, 2], 30, "3 numbers"),
        ([0, 0, np.nan], 30, "finite"),
        ([0, 0, 1], np.inf, "finite"),
        ([0, 0, 1], "x", "numbers"),
        ([[0, 0, 1]], 30, "3 numbers"),
    ],
)
def test_bad_rotations_are_named(axis, degrees, words):
    with pytest.raises(MeshError, match=words) as info:
        rotation_matrix(axis, degrees)
    assert info.value.source == "rotate"


@pytest.mark.parametrize("bad", [[1, 2], [0, 0, np.nan], ["a", 0, 0], [[0, 0, 1]]])
def test_bad_moves_are_named(bumpy, bad):
    V, _ = bumpy
    with pytest.raises(MeshError) as info:
        rigid_targets(V, np.array([0, 1]), None, bad)
    assert info.value.source == "move"


@pytest.mark.parametrize(
    "bad", [np.zeros((4, 3)), np.zeros((2, 3, 2)), np.full((1, 3, 3), np.nan), "S"]
)
def test_bad_covariances_are_named(bad):
    with pytest.raises(MeshError) as info:
        fit_rotations(bad)
    assert info.value.source == "S"


@pytest.mark.parametrize("bad", [-1, 1.5, True, "3", 10**9])
def test_bad_iteration_counts_are_named(bumpy, bad):
    V, F = bumpy
    arap = ArapDeformer(V, F, [0])
    with pytest.raises(MeshError) as info:
        arap.run(bad)
    assert info.value.source == "iters"


def test_bad_restart_positions_are_named(bumpy):
    V, F = bumpy
    arap = ArapDeformer(V, F, [0])
    arap.reset(V + 0.5)
    for bad in (V[:10], np.full_like(V, np.nan)):
        with pytest.raises(MeshError) as info:
            arap.reset(bad)
        assert info.value.source == "positions"
        np.testing.assert_array_equal(arap.positions, V + 0.5)  # the last good state kept
