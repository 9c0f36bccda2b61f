"""Heat, geodesic distance, spectral filters and the heat kernel signature (meshlap_core.diffusion).

Three tiers: hand-computed tiny cases, invariants, and references (the Legendre series of the
sphere's heat kernel, great-circle and Euclidean distance, ``expm_multiply``, libigl).
"""

import importlib.util

import igl
import numpy as np
import pytest
import scipy.sparse as sp
import scipy.sparse.linalg as spla
from scipy.special import eval_legendre

from meshlap_core.diffusion import (
    HeatDiffusion,
    HeatGeodesic,
    SpectralFilter,
    boundary_vertices,
    curve_gain,
    exact_distance,
    geodesic,
    heat_kernel_column,
    heat_kernel_signature,
    heat_spectral,
    hks_distance,
    hks_times,
    igl_heat_distance,
    isoline_values,
    isolines,
    mean_edge_length,
    save_polylines,
    smoother_transfer,
    transfer,
    truncation_bound,
    unit_heat,
)
from meshlap_core.diffusion.geodesic import face_gradients, far_levels, gradient_stiffness
from meshlap_core.errors import MeshError
from meshlap_core.linalg.factor import CholmodSPDFactor, SharedAnalysis, pinned_data
from meshlap_core.primitives import bumpy_sphere, grid, icosphere
from meshlap_core.spectral.basis import SpectralBasis


def two_spheres():
    V, F = icosphere(2)
    return np.vstack([V, V + np.array([5.0, 0, 0])]), np.vstack([F, F + len(V)])


@pytest.fixture(scope="module")
def full_basis():
    V, F = bumpy_sphere(2)
    return SpectralBasis.compute(V, F, len(V), cache=False)


def sphere_heat_kernel(cos_gamma, t, terms=200):
    """Σ (2l+1)/(4π) e^{−l(l+1)t} P_l(cos γ): the heat kernel of the unit sphere."""
    ell = np.arange(terms)
    w = (2 * ell + 1) / (4 * np.pi) * np.exp(-ell * (ell + 1) * t)
    return eval_legendre(ell[None, :], cos_gamma[:, None]) @ w


# ---------------------------------------------------------------- hand-computed tiny cases


def test_exact_distance_on_one_right_triangle_is_the_edge_lengths():
    V = np.array([[0.0, 0, 0], [3, 0, 0], [0, 4, 0]])
    F = np.array([[0, 1, 2]])
    np.testing.assert_allclose(exact_distance(V, F, [1]), [3.0, 0.0, 5.0], atol=1e-12)


def test_heat_distance_on_a_regular_tetrahedron_is_symmetric():
    V = np.array([[1.0, 1, 1], [1, -1, -1], [-1, 1, -1], [-1, -1, 1]])
    F = np.array([[0, 1, 2], [0, 3, 1], [0, 2, 3], [1, 3, 2]])
    d = HeatGeodesic(V, F).distance([0])
    assert d[0] == 0.0
    np.testing.assert_allclose(d[1:], d[1], rtol=1e-12)
    assert d[1] > 0


def test_one_euler_step_on_two_triangles_by_hand():
    # unit square split along its diagonal: K = −C by hand, M = diag(areas) (voronoi)
    V = np.array([[0.0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]])
    F = np.array([[0, 1, 2], [0, 2, 3]])
    hd = HeatDiffusion(V, F)
    u0 = np.array([1.0, 0, 0, 0])
    u = hd.euler(u0, 0.3)
    A = np.diag(hd.mass) + 0.3 * hd.K.toarray()
    np.testing.assert_allclose(A @ u, hd.mass * u0, atol=1e-14)
    # the right angles at 1 and 3: edge 0–2 has weight ½(cot 90° + cot 90°) = 0, 0–1 has ½
    np.testing.assert_allclose(hd.K.toarray()[0], [1.0, -0.5, 0.0, -0.5], atol=1e-14)


# ---------------------------------------------------------------- heat: invariants and references


def test_heat_is_conserved_by_euler_and_spectral(full_basis):
    V, F = full_basis.V, full_basis.F
    hd = HeatDiffusion(V, F)
    u0 = unit_heat(np.array([3, 40]), hd.mass)
    for u in (hd.euler(u0, 0.05, steps=3), heat_spectral(full_basis, u0, 0.05)):
        assert np.isclose(hd.mass @ u, 2.0, rtol=1e-10)


def test_full_basis_expansion_equals_expm_multiply(full_basis):
    hd = HeatDiffusion(full_basis.V, full_basis.F)
    u0 = unit_heat(np.array([7]), hd.mass)
    for t in (1e-3, 1e-2, 0.3):
        ref = hd.exact(u0, t)
        got = heat_spectral(full_basis, u0, t)
        assert np.abs(got - ref).max() <= 1e-10 * np.abs(ref).max()
        np.testing.assert_allclose(heat_kernel_column(full_basis, 7, t), got, atol=1e-12)


def test_backward_euler_converges_to_the_exponential_at_first_order(full_basis):
    hd = HeatDiffusion(full_basis.V, full_basis.F)
    u0 = unit_heat(np.array([0]), hd.mass)
    ref = hd.exact(u0, 0.05)
    errs = [np.abs(hd.euler(u0, 0.05, steps=s) - ref).max() for s in (8, 16, 32)]
    orders = np.log2(np.array(errs[:-1]) / np.array(errs[1:]))
    assert np.all((orders > 0.9) & (orders < 1.1)), orders


def test_truncation_error_is_within_the_stated_bound(full_basis):
    t, k, s = 0.05, 40, 5
    U, lam = full_basis.vectors, full_basis.eigenvalues
    err = np.abs(heat_kernel_column(full_basis, s, t, k) - heat_kernel_column(full_basis, s, t))
    bound = truncation_bound(lam, t, k)
    assert bound == pytest.approx(np.exp(-lam[k - 1] * t))
    # each omitted mode i >= k carries e^{−λ_i t} ≤ bound
    assert np.all(err <= bound * (np.abs(U[:, k:]) @ np.abs(U[s, k:])) + 1e-14)


def test_sphere_heat_kernel_matches_the_legendre_series_at_second_order():
    t, errs, hs = 0.1, [], []
    for level in (3, 4, 5):
        V, F = icosphere(level)
        hd = HeatDiffusion(V, F)
        u = hd.exact(unit_heat(np.array([0]), hd.mass), t)
        ref = sphere_heat_kernel(np.clip(V @ V[0], -1, 1), t)
        errs.append(np.abs(u - ref).max() / ref.max())
        hs.append(mean_edge_length(V, F))
    orders = np.log(np.array(errs[:-1]) / errs[1:]) / np.log(np.array(hs[:-1]) / hs[1:])
    # measured: errors 2.6e-2, 6.3e-3, 1.6e-3; orders 2.06, 2.01
    assert np.all(orders > 1.8), orders
    assert errs[-1] < 2e-3


# ---------------------------------------------------------------- geodesic distance


def test_heat_distance_on_the_sphere_converges_to_great_circles():
    errs, hs = [], []
    for level in (3, 4, 5):
        V, F = icosphere(level)
        d = HeatGeodesic(V, F).distance([0])
        errs.append(np.mean(np.abs(d - np.arccos(np.clip(V @ V[0], -1, 1)))))
        hs.append(mean_edge_length(V, F))
    orders = np.log(np.array(errs[:-1]) / errs[1:]) / np.log(np.array(hs[:-1]) / hs[1:])
    # measured with t = h²: mean errors 2.3e-2, 1.3e-2, 8.7e-3 (orders 0.80, 0.61): the
    # heat method with m fixed converges, below first order (its smoothing error is O(√t))
    assert np.all(np.diff(errs) < 0)
    assert np.all(orders > 0.5), orders
    assert errs[-1] < 0.01


def test_heat_distance_on_a_flat_grid_approaches_euclidean():
    errs = []
    for n in (11, 21, 41):
        V, F = grid(n, n)
        s = (n // 2) * n + n // 2  # the centre
        d = HeatGeodesic(V, F).distance([s])
        errs.append(np.mean(np.abs(d - np.linalg.norm(V - V[s], axis=1))))
    assert np.all(np.diff(errs) < 0), errs
    assert errs[-1] < 0.01


def test_exact_distance_on_a_grid_is_euclidean():
    V, F = grid(13, 9, size=2.0)
    for s in (0, 50):
        np.testing.assert_allclose(
            exact_distance(V, F, [s]), np.linalg.norm(V - V[s], axis=1), atol=1e-12
        )


@pytest.mark.parametrize("mesh", ["sphere", "grid"])
def test_heat_method_matches_libigl(mesh):
    V, F = icosphere(3) if mesh == "sphere" else grid(21, 21)
    hg = HeatGeodesic(V, F, boundary="average")  # libigl averages on boundaries; t = h²
    for sources in ([220], [3, 220, 400]):
        np.testing.assert_allclose(
            hg.distance(sources), igl_heat_distance(V, F, sources), atol=1e-10
        )


def test_boundary_conditions_differ_and_average_is_their_mean():
    V, F = grid(21, 21)
    s = np.array([220])
    u = {r: HeatGeodesic(V, F, boundary=r).heat(s) for r in ("neumann", "dirichlet", "average")}
    hg = HeatGeodesic(V, F)
    assert np.all(u["dirichlet"][hg.boundary] == 0.0)
    assert np.all(u["neumann"][hg.boundary] > 0.0)
    np.testing.assert_allclose(u["average"], 0.5 * (u["neumann"] + u["dirichlet"]), atol=1e-15)


def test_time_factor_sets_t():
    V, F = icosphere(3)
    a, b = HeatGeodesic(V, F, m=1.0), HeatGeodesic(V, F, m=100.0)
    assert a.t == pytest.approx(mean_edge_length(V, F) ** 2)
    assert b.t == pytest.approx(100 * a.t)
    g = np.arccos(np.clip(V @ V[0], -1, 1))
    da, db = a.distance(0), b.distance(0)
    assert np.abs(da - db).max() > 1e-3  # a different heat, a different field
    # on the round sphere the heat stays radial whatever t: both close to great circles
    assert np.abs(da - g).mean() < 0.03 and np.abs(db - g).mean() < 0.03


def test_components_without_a_source_are_infinite_and_stated():
    V, F = two_spheres()
    n1 = len(V) // 2
    for d in (HeatGeodesic(V, F).distance([0]), exact_distance(V, F, [0])):
        assert np.all(np.isinf(d[n1:])) and np.all(np.isfinite(d[:n1]))
    d = HeatGeodesic(V, F).distance([0, n1 + 5])  # a source in each: both finite, both 0
    assert np.all(np.isfinite(d)) and d[0] == 0 and d[n1 + 5] == 0
    hd = HeatDiffusion(V, F)
    u = hd.euler(unit_heat(np.array([0]), hd.mass), 0.1)
    assert np.abs(u[n1:]).max() < 1e-12 * u.max()  # no heat crosses


@pytest.mark.parametrize(
    "call",
    [
        lambda V, F: HeatGeodesic(V, F).distance([len(V)]),
        lambda V, F: HeatGeodesic(V, F).distance([]),
        lambda V, F: HeatGeodesic(V, F, m=0),
        lambda V, F: HeatGeodesic(V, F, boundary="robin"),
        lambda V, F: HeatDiffusion(V, F).euler(np.zeros(len(V)), -1.0),
        lambda V, F: exact_distance(V, F, [-1]),
    ],
)
def test_bad_arguments_are_mesh_errors(call):
    V, F = icosphere(1)
    with pytest.raises(MeshError):
        call(V, F)


# ---------------------------------------------------------------- isolines


def test_isolines_of_a_linear_field_lie_on_its_level(tmp_path):
    V, F = grid(11, 11)
    levels = isoline_values(V[:, 0], 3)
    np.testing.assert_allclose(levels, [0.25, 0.5, 0.75])
    P, E, which = isolines(V, F, V[:, 0], levels)
    assert len(E) > 0
    np.testing.assert_allclose(P[E[:, 0], 0], levels[which], atol=1e-12)
    path = tmp_path / "curves.obj"
    save_polylines(path, P, E)
    lines = path.read_text().splitlines()
    assert sum(x.startswith("v ") for x in lines) == len(P)
    assert sum(x.startswith("l ") for x in lines) == len(E)


def test_isolines_skip_infinite_values():
    V, F = two_spheres()
    d = HeatGeodesic(V, F).distance([0])
    P, E, _ = isolines(V, F, d, isoline_values(d, 5))
    assert len(E) > 0 and P[:, 0].max() < 2.0  # all on the first sphere


# ---------------------------------------------------------------- filters


def test_filter_with_unit_gain_returns_the_geometry(full_basis):
    f = SpectralFilter(full_basis)
    np.testing.assert_allclose(f.apply(np.ones(f.k)), full_basis.V, atol=1e-10)
    part = SpectralFilter(full_basis, k=20)
    np.testing.assert_allclose(part.apply(np.ones(20), residual=True), full_basis.V, atol=1e-10)


@pytest.mark.parametrize("method", ["explicit", "implicit", "taubin"])
def test_transfer_functions_equal_the_projected_amplification(full_basis, method):
    step = 0.2 / full_basis.eigenvalues[-1] if method != "implicit" else 1e-3
    formula, measured = smoother_transfer(full_basis, method, step, 5)
    assert np.isfinite(measured).sum() > 0.9 * len(measured)
    ok = np.isfinite(measured)
    np.testing.assert_allclose(measured[ok], formula[ok], atol=1e-9)


def test_transfer_shapes():
    lam = np.array([0.0, 1.0, 2.0, 3.0])
    np.testing.assert_array_equal(transfer("low-pass", lam, keep=2), [1, 1, 0, 0])
    np.testing.assert_array_equal(transfer("band", lam, band=(1, 3), gain=2.0), [1, 2, 2, 1])
    np.testing.assert_allclose(transfer("explicit", lam, step=0.1, iters=2), (1 - 0.1 * lam) ** 2)
    np.testing.assert_allclose(transfer("implicit", lam, step=0.1, iters=2), (1 + 0.1 * lam) ** -2)
    with pytest.raises(MeshError):
        transfer("median", lam)


# ---------------------------------------------------------------- heat kernel signature


def test_hks_is_the_heat_kernel_diagonal(full_basis):
    times = hks_times(full_basis.eigenvalues, 4)
    H = heat_kernel_signature(full_basis, times)
    for j, t in enumerate(times):
        col = heat_kernel_column(full_basis, 11, t)
        assert H[11, j] == pytest.approx(col[11], rel=1e-12)
    assert hks_distance(H, 11)[11] == 0.0
    Hs = heat_kernel_signature(full_basis, times, scaled=True)
    # scaled by the heat trace: the M-weighted mean of each column is 1/area
    area = full_basis.mass.sum()
    np.testing.assert_allclose(full_basis.mass @ Hs, 1.0, rtol=1e-10)
    assert area > 0


def test_hks_on_a_round_sphere_is_nearly_constant():
    V, F = icosphere(3)
    basis = SpectralBasis.compute(V, F, 60, cache=False)
    H = heat_kernel_signature(basis, hks_times(basis.eigenvalues, 5)[2:])
    spread = (H.max(axis=0) - H.min(axis=0)) / H.mean(axis=0)
    assert np.all(spread < 0.05), spread


def test_filter_incremental_updates_equal_full_products(full_basis):
    f = SpectralFilter(full_basis, k=80)
    rng = np.random.default_rng(1)
    h = np.ones(80)
    for _ in range(100):  # a drag: a few gains at a time, past a resync
        h[rng.integers(0, 80, size=3)] = rng.uniform(0, 2, size=3)
        got = f.apply(h)
        ref = f.U @ (h[:, None] * f.coefficients)
        np.testing.assert_allclose(got, ref, atol=1e-12)
    got[:] = 0.0  # the caller's copy: the filter's own result is untouched
    np.testing.assert_allclose(f.apply(h), ref, atol=1e-12)


def test_an_euler_step_too_long_for_the_mesh_scale_is_refused():
    V, F = icosphere(2)
    hd = HeatDiffusion(V * 1e-40, F)
    with pytest.raises(MeshError, match="too long"):
        hd.euler(unit_heat(np.array([0]), hd.mass), 1.0)
    u = hd.euler(unit_heat(np.array([0]), hd.mass), 1e-82)  # a step at this scale is fine
    assert hd.mass @ u == pytest.approx(1.0)


@pytest.mark.parametrize("mesh", ["sphere", "grid", "two"])
def test_mean_edge_length_and_boundary_match_libigl(mesh):
    import igl

    V, F = {"sphere": icosphere(2), "grid": grid(7, 5), "two": two_spheres()}[mesh]
    assert mean_edge_length(V, F) == pytest.approx(igl.avg_edge_length(V, F), rel=1e-12)
    expected = np.unique(igl.boundary_facets(F)[0]) if mesh == "grid" else np.zeros(0)
    np.testing.assert_array_equal(boundary_vertices(F, len(V)), expected)


def test_heat_method_survives_underflow_on_a_long_strip():
    """A 2000 × 3 strip of square cells: with t = h² the heat underflows to 0 on more than
    half of it (exp(−d/√t) below 1e-308); those faces take the direction of a longer time's
    heat, so the far end is still at its Euclidean distance (error 0.77 without it)."""
    V, F = grid(2000, 3)
    V = V * np.array([1.0, 2.0 / 1999.0, 1.0])
    hg = HeatGeodesic(V, F)
    assert np.mean(hg.heat(np.array([0])) == 0.0) > 0.5
    d = hg.distance([0])
    assert np.abs(d - np.linalg.norm(V - V[0], axis=1)).max() < 1e-3
    assert len(hg._far) >= 1  # the longer times were used (and are kept)
    V2, F2 = icosphere(3)  # nothing underflows: no extra factorization
    hs = HeatGeodesic(V2, F2)
    hs.distance([0])
    assert hs._far == {}


def test_the_longer_times_a_long_mesh_needs_are_factorized_with_the_precomputation():
    """On the strip the heat of t = h² reaches about 575 √t = 0.29 of its length 1 (exp(−d/√t)
    down to 1e-250), so t·100 (reach 2.9, over twice the diagonal) is factorized up front
    and a click only back-substitutes; on the sphere (reach ≈ 40 radii) none is."""
    V, F = grid(2000, 3)
    V = V * np.array([1.0, 2.0 / 1999.0, 1.0])
    hg = HeatGeodesic(V, F)
    assert far_levels(V, hg.t) == 1 and set(hg._far) == {1}
    built = dict(hg._far)
    hg.distance([0])
    hg.distance([1000])
    assert hg._far == built  # nothing factorized per click
    V2, _ = icosphere(3)
    assert far_levels(V2, mean_edge_length(*icosphere(3)) ** 2) == 0
    assert far_levels(V * 1e6, hg.t) == 4  # at most _FAR_LEVELS


@pytest.mark.parametrize("mesh", ["sphere", "grid", "bumpy"])
def test_face_gradients_are_the_rows_of_igl_grad(mesh):
    import igl

    V, F = {"sphere": icosphere(2), "grid": grid(7, 5), "bumpy": bumpy_sphere(2)}[mesh]
    hat, area = face_gradients(V, F)
    G = igl.grad(V, F).toarray().reshape(3, len(F), len(V))  # rows: x of each face, y, z
    for i in range(3):
        np.testing.assert_allclose(
            hat[i], G[:, np.arange(len(F)), F[:, i]], atol=1e-12 * np.abs(G).max()
        )
    np.testing.assert_allclose(area, 0.5 * igl.doublearea(V, F).ravel(), rtol=1e-14)
    # hand check: the right triangle (0,0), (1,0), (0,1): ∇φ₀ = (−1,−1), ∇φ₁ = (1,0), ∇φ₂ = (0,1)
    hat, area = face_gradients(np.array([[0.0, 0, 0], [1, 0, 0], [0, 1, 0]]), np.array([[0, 1, 2]]))
    np.testing.assert_allclose(hat[:, :, 0], [[-1, -1, 0], [1, 0, 0], [0, 1, 0]], atol=1e-15)
    assert area[0] == 0.5
    hat, area = face_gradients(np.array([[0.0, 0, 0], [1, 0, 0], [2, 0, 0]]), np.array([[0, 1, 2]]))
    assert area[0] == 0 and np.all(hat == 0)  # a face of no area: no gradient


def test_a_drawn_transfer_function_is_linear_between_its_points():
    lam = np.array([0.0, 0.5, 1.0, 1.5, 2.0, 3.0])
    knots = [(0.0, 1.0), (1.0, 0.0), (2.0, 2.0)]
    np.testing.assert_allclose(curve_gain(lam, knots), [1.0, 0.5, 0.0, 1.0, 2.0, 2.0])
    for bad in ([(0.0, 1.0)], [(1.0, 0.0), (0.0, 1.0)], [(0.0, np.nan), (1.0, 1.0)], [1, 2]):
        with pytest.raises(MeshError, match="curve"):
            curve_gain(lam, bad)


def test_the_pieces_of_a_drawn_curve_sum_to_its_filter(full_basis):
    """``Σ_j y_j G_j`` (each hat's filtered geometry, precomputed) equals ``U h(Λ) Uᵀ M X``
    for the curve through the gains ``y``; gains all 1 give X back (the full basis)."""
    f = SpectralFilter(full_basis)
    top = float(full_basis.eigenvalues[-1])
    xs = np.array([0.0, 0.1, 0.3, 1.0]) * top
    G = f.pieces(xs)
    assert G.shape == (4, *full_basis.V.shape)
    y = np.array([1.0, -0.5, 2.0, 0.25])
    h = curve_gain(full_basis.eigenvalues, np.column_stack([xs, y]))
    np.testing.assert_allclose(np.tensordot(y, G, axes=1), f.apply(h), atol=1e-12)
    np.testing.assert_allclose(G.sum(axis=0), full_basis.V, atol=1e-9)
    with pytest.raises(MeshError, match="curve"):
        f.pieces([1.0, 0.0])


def wavy_grid_pair():
    """Two components with boundary: a 15×12 grid lifted into a wave (obtuse and acute
    angles, no symmetry) and a smaller tilted one beside it."""
    V1, F1 = grid(15, 12)
    V1[:, 2] = 0.15 * np.sin(5 * V1[:, 0]) * np.cos(3 * V1[:, 1] + 0.4)
    V1[:, 0] += 0.02 * np.sin(17 * V1[:, 1])
    V2, F2 = grid(6, 7, size=0.5)
    V2 = V2 @ np.array([[1.0, 0, 0.3], [0, 1.0, 0.1], [0, 0, 1.0]]) + np.array([2.0, 0, 0])
    return np.vstack([V1, V2]), np.vstack([F1, F2 + len(V1)])


def test_gradient_stiffness_is_minus_libigl_cotmatrix():
    V, F = wavy_grid_pair()
    hat, area = face_gradients(V, F)
    K = gradient_stiffness(F, hat, area, len(V))
    C = igl.cotmatrix(V, F)
    np.testing.assert_allclose(K.toarray(), -C.toarray(), atol=1e-12 * abs(C).max())
    assert np.all(K.diagonal() > 0) and K.has_canonical_format


def test_pinned_data_decouples_rows_and_keeps_the_pattern():
    A = sp.csr_matrix(np.array([[4.0, 1, 0, 2], [1, 5, 1, 0], [0, 1, 6, 1], [2, 0, 1, 7]]))
    out = pinned_data(A.indptr, A.indices, A.data, np.array([1]))
    P = sp.csr_matrix((out, A.indices, A.indptr), shape=A.shape)
    expected = A.toarray()
    expected[1, [0, 2]] = expected[[0, 2], 1] = 0.0
    np.testing.assert_array_equal(P.toarray(), expected)
    assert P.nnz == A.nnz  # the removed entries are stored zeros
    assert np.array_equal(A.data[:3], [4.0, 1, 2])  # the input is not modified


@pytest.mark.parametrize("solver", ["simplicial", "supernodal", "fallback"])
@pytest.mark.parametrize("rule", ["neumann", "dirichlet", "average"])
def test_shared_analysis_solves_equal_separate_factorizations(solver, rule, monkeypatch):
    """The heat step, the Dirichlet heat step and the pinned Poisson solve of one shared
    symbolic analysis (pinned rows kept as explicit zeros) equal SuperLU solves of the
    separately assembled matrices (libigl's cotmatrix and massmatrix, the restricted
    systems) to round-off, on a mesh with boundary and two components: CHOLMOD's simplicial
    and supernodal factorizations, and the pure-wheel fallback."""
    if solver != "fallback" and importlib.util.find_spec("sksparse") is None:
        pytest.skip("scikit-sparse (CHOLMOD) is not installed")
    monkeypatch.setenv("MESHLAP_SOLVER", "fallback" if solver == "fallback" else "cholmod")
    monkeypatch.setattr(geodesic, "SIMPLICIAL_MAX_N", 0 if solver == "supernodal" else 10**9)
    V, F = wavy_grid_pair()
    n = len(V)
    hg = HeatGeodesic(V, F, boundary=rule)
    backend = "cholespy" if solver == "fallback" else "cholmod"
    factors = [hg._heat, hg._poisson] + ([hg._heat_dirichlet] if rule != "neumann" else [])
    assert all(f.backend == backend for f in factors)
    if solver != "fallback":
        assert hg._shared.mode == solver
        assert all(isinstance(f, CholmodSPDFactor) for f in factors)
        order = hg._shared._base.P()  # one analysis: every factor has its ordering
        assert all(np.array_equal(f.factor.P(), order) for f in factors)
    K = -igl.cotmatrix(V, F).tocsc()
    M = sp.diags(igl.massmatrix(V, F, igl.MASSMATRIX_TYPE_VORONOI).diagonal())
    A = (M + hg.t * K).tocsc()
    boundary = np.unique(igl.boundary_facets(F)[0])
    interior = np.setdiff1d(np.arange(n), boundary)
    rng = np.random.default_rng(5)
    src = np.array([20, 100, n - 3])  # an interior vertex of each component, one more
    delta = np.zeros(n)
    delta[src] = 1.0
    u = spla.spsolve(A, delta)
    ud = np.zeros(n)
    ud[interior] = spla.spsolve(A[interior][:, interior], delta[interior])
    expected = {"neumann": u, "dirichlet": ud, "average": 0.5 * (u + ud)}[rule]
    np.testing.assert_allclose(hg.heat(src), expected, atol=1e-12 * np.abs(expected).max())
    # the Poisson system: one pinned vertex per component (the first), K restricted
    pinned = np.array([0, 15 * 12])
    assert np.array_equal(np.sort(hg._pinned), pinned)
    free = np.setdiff1d(np.arange(n), pinned)
    b = rng.standard_normal(n)
    b[pinned] = 0.0
    phi = np.zeros(n)
    phi[free] = spla.spsolve(K[free][:, free], b[free])
    np.testing.assert_allclose(hg._poisson.solve(b), phi, atol=1e-10 * np.abs(phi).max())


def test_shared_analysis_refuses_an_indefinite_matrix_like_spdsolver(monkeypatch):
    monkeypatch.setenv("MESHLAP_SOLVER", "fallback")
    A = sp.csr_matrix(np.array([[1.0, 2.0], [2.0, 1.0]]))  # eigenvalues 3 and −1
    for backend, mode in [("cholmod", "simplicial"), ("cholmod", "supernodal"), ("cholespy", "")]:
        if backend == "cholmod" and importlib.util.find_spec("sksparse") is None:
            continue
        shared = SharedAnalysis(A.indptr, A.indices, backend, mode or "supernodal")
        if backend == "cholmod":  # its own check refuses it (the LDLᵀ has a negative pivot)
            assert shared._cholmod(shared.matrix(A.data)) is None
        with pytest.raises(np.linalg.LinAlgError):
            shared.factor(A.data)
