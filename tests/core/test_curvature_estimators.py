"""Principal-curvature estimators side by side: one sign convention, k1 ≥ k2, directions.

Tier 1: hand cases (a sphere of radius 2, a cylinder, the sign flip of reversed faces). Tier 2:
invariants (k1 ≥ k2 everywhere, unit orthogonal tangent directions). Tier 3: the exact curvature
of the parametric surfaces at the same points (every shipped surface, convergence orders under
refinement, direction angles away from umbilics), libigl's ``principal_curvature`` after its
convention is mapped, and the noisy torus against the numbers of pymeshlab's scale-dependent
quadric (H relative L2 error 0.17 at 0.1 % and 0.63 at 1 % normal noise).
"""

from __future__ import annotations

import igl
import numpy as np
import pytest

from meshlap_core import primitives
from meshlap_core.curvature import estimators as ce
from meshlap_core.curvature.jet_fit import default_jet_radius, estimate_normal_noise, jet_curvatures
from meshlap_core.curvature.study import perturbed_mesh
from meshlap_core.errors import MeshError
from meshlap_core.noise import add_noise, bbox_diagonal
from meshlap_core.options import CURVATURE_ESTIMATORS
from meshlap_core.surfaces import (
    SURFACES,
    ParametricSurface,
    get_surface,
    mesh_surface,
    point_geometry,
    surface_curvature_fields,
    surface_derivatives,
)

ALL = list(CURVATURE_ESTIMATORS)


def ellipsoid(a: float = 1.0, b: float = 1.5, c: float = 2.0) -> ParametricSurface:
    def p(u: np.ndarray, v: np.ndarray) -> np.ndarray:
        x, y, z = a * np.sin(u) * np.cos(v), b * np.sin(u) * np.sin(v), c * np.cos(u)
        return np.stack(np.broadcast_arrays(x, y, z), -1)

    return ParametricSurface("ellipsoid", p, (0, np.pi, 0, 2 * np.pi), True, False, ("u0", "u1"))


def _interior(m, s: ParametricSurface, margin: float = 0.15) -> np.ndarray:
    """Vertices away from the boundary (one-sided stencils) and the poles."""
    u, v = m.uv[:, 0], m.uv[:, 1]
    u0, u1, v0, v1 = s.domain
    keep = ~m.pole & ~m.boundary
    if not s.closed_u:
        keep &= np.minimum(u - u0, u1 - u) > margin * (u1 - u0)
    if not s.closed_v:
        keep &= np.minimum(v - v0, v1 - v) > margin * (v1 - v0)
    if s.poles:  # the lat-long cells next to a pole are slivers
        keep &= np.minimum(u - u0, u1 - u) > margin * (u1 - u0)
    return keep


def _res(s: ParametricSurface, n: int) -> tuple[int, int]:
    return (2 * n, n) if s.name == "torus" else (n, n)


# ---------------------------------------------------------------- tier 1: hand cases


@pytest.mark.parametrize("name", ALL)
def test_sphere_of_radius_two_is_positive_half(name: str) -> None:
    V, F = primitives.icosphere(4, radius=2.0)
    r = ce.estimate_curvature(V, F, name)
    # outward normal, the sphere bends away from it: k1 = k2 = H = 1/2, K = 1/4
    # at an umbilic, k1 - k2 = 2√(H² - K) magnifies small tensor errors: 2.4 % measured for the
    # per-face tensors; libigl's 5-ring fit is biased at this size (its H is 1.097 on the unit
    # level-3 icosphere)
    # the normal cycle splits k1, k2 by 5.8 % next to the 12 valence-5 vertices (the paper's
    # convergence needs a regular enough triangulation)
    tol = {"cotan": 0.02, "quadric": 0.1, "normal_cycle": 0.06}.get(name, 0.05)
    np.testing.assert_allclose(r.k1, 0.5, rtol=tol)
    np.testing.assert_allclose(r.k2, 0.5, rtol=tol)
    np.testing.assert_allclose(r.H, 0.5, rtol=tol)
    assert np.all(np.sum(r.normal * V, axis=1) > 0)  # the normal points outwards


@pytest.mark.parametrize("name", ALL)
def test_reversed_faces_negate_and_swap(name: str) -> None:
    s = ellipsoid()
    m = mesh_surface(s, 24)
    a = ce.estimate_curvature(m.V, m.F, name)
    b = ce.estimate_curvature(m.V, m.F[:, ::-1], name)
    # the inward normal: every curvature changes sign, so the max becomes minus the min
    np.testing.assert_allclose(b.k1, -a.k2, atol=1e-8)
    np.testing.assert_allclose(b.k2, -a.k1, atol=1e-8)
    keep = _interior(m, s)
    assert np.all(a.k2[keep] > 0) and np.all(a.H[keep] > 0)  # convex, outward faces


@pytest.mark.parametrize("name", ["cotan", "rusinkiewicz", "jet"])
def test_cylinder_directions(name: str) -> None:
    # r = 0.5: around the axis κ = 2 (bends away from the outward normal), along it 0
    s = get_surface("cylinder", r=0.5)
    m = mesh_surface(s, 48)
    r = ce.estimate_curvature(m.V, m.F, name)
    keep = _interior(m, s)
    tol = 0.05 if name == "jet" else 0.02  # the jet's bias ~ (radius κ)²: 1.7 % measured
    np.testing.assert_allclose(r.k1[keep], 2.0, atol=tol)
    np.testing.assert_allclose(r.k2[keep], 0.0, atol=tol)
    axis = np.array([0.0, 0.0, 1.0])
    axis_of_cylinder = point_geometry(s, 1.0, 0.5).dir2  # exact direction of k2 = 0
    np.testing.assert_allclose(np.abs(axis_of_cylinder), axis, atol=1e-12)
    assert np.all(np.abs(r.d2[keep] @ axis) > np.cos(np.radians(1.0)))


# ---------------------------------------------------------------- tier 2: invariants


@pytest.mark.parametrize("name", ALL)
def test_k1_ge_k2_and_orthonormal_tangent_directions(name: str) -> None:
    V, F = primitives.bumpy_sphere(3)
    r = ce.estimate_curvature(V, F, name)
    assert np.all(r.k1 >= r.k2)
    for d in (r.d1, r.d2):
        np.testing.assert_allclose(np.linalg.norm(d, axis=1), 1, atol=1e-6)
    np.testing.assert_allclose(np.sum(r.d1 * r.d2, axis=1), 0, atol=1e-6)
    if name != "quadric":  # libigl's directions are tangent to its own fitted normal
        np.testing.assert_allclose(np.sum(r.d1 * r.normal, axis=1), 0, atol=1e-6)
    np.testing.assert_allclose(r.H, (r.k1 + r.k2) / 2)
    assert r.field("abs_max") == pytest.approx(np.maximum(np.abs(r.k1), np.abs(r.k2)))


def test_bad_options_are_mesh_errors() -> None:
    V, F = primitives.icosphere(1)
    with pytest.raises(MeshError, match="estimator"):
        ce.estimate_curvature(V, F, "nonsense")  # type: ignore[arg-type]
    with pytest.raises(MeshError, match="radius"):
        jet_curvatures(V, F, radius=-1.0)
    with pytest.raises(MeshError, match="does not take"):
        ce.estimate_curvature(V, F, "rusinkiewicz", radius=2)
    with pytest.raises(MeshError, match="field"):
        ce.estimate_curvature(V, F).field("k3")


def test_disagreement_is_the_max_pairwise_difference() -> None:
    V, F = primitives.bumpy_sphere(2)
    rs = [ce.estimate_curvature(V, F, n) for n in ("cotan", "rusinkiewicz")]
    np.testing.assert_allclose(ce.disagreement(rs, "H"), np.abs(rs[0].H - rs[1].H), atol=1e-14)
    assert np.all(ce.disagreement(rs[:1]) == 0)


# ---------------------------------------------------------------- tier 3: exact surfaces


@pytest.mark.parametrize("surface", list(SURFACES))
@pytest.mark.parametrize("name", ALL)
def test_surface_and_mesh_agree_at_the_same_points(surface: str, name: str) -> None:
    """`meshlap surface` (point_geometry) and every mesh estimator, same sign and size."""
    s = get_surface(surface)
    m = mesh_surface(s, _res(s, 48))
    keep = _interior(m, s)
    r = ce.estimate_curvature(m.V, m.F, name)
    scale = max(1.0, float(np.nanmax(np.abs(surface_curvature_fields(s, *m.uv[keep].T).k1))))
    # a wrong sign or order would miss by 2|κ|; libigl's fit is off by up to 0.26 on the helicoid
    tol = 0.4 * scale if name == "quadric" else 0.06 * scale
    for i in np.flatnonzero(keep)[:: max(1, keep.sum() // 40)]:
        g = point_geometry(s, *m.uv[i])
        assert r.k1[i] == pytest.approx(g.k1, abs=tol), (i, g.k1, g.k2)
        assert r.k2[i] == pytest.approx(g.k2, abs=tol), (i, g.k1, g.k2)


def _l2_errors(s: ParametricSurface, name: str, levels: tuple[int, ...]) -> np.ndarray:
    out = []
    for n in levels:
        m = mesh_surface(s, _res(s, n))
        keep = _interior(m, s)
        cf = surface_curvature_fields(s, m.uv[:, 0], m.uv[:, 1])
        r = ce.estimate_curvature(m.V, m.F, name)
        out.append(
            [np.sqrt(np.mean((r.H - cf.H)[keep] ** 2)), np.sqrt(np.mean((r.K - cf.K)[keep] ** 2))]
        )
    return np.array(out)


@pytest.mark.parametrize(
    "surface, name, order",
    [
        ("torus", "cotan", 1.9),  # Meyer et al.: order 2 on regular meshes (measured 2.0)
        ("saddle", "cotan", 1.9),
        ("helicoid", "cotan", 1.9),
        ("torus", "rusinkiewicz", 1.9),  # measured 2.0
        ("ellipsoid", "rusinkiewicz", 1.3),  # measured 1.5 (lat-long cells away from poles)
        ("torus", "quadric", 1.8),  # measured 2.0 between the finer levels
        ("torus", "normal_cycle", 1.9),  # measured 2.0 on these regular grids
        ("helicoid", "normal_cycle", 1.9),
        ("saddle", "jet", 1.6),  # automatic radius ∝ h^0.6 on clean meshes: measured 1.8-1.9
    ],
)
def test_convergence_orders(surface: str, name: str, order: float) -> None:
    s = ellipsoid() if surface == "ellipsoid" else get_surface(surface)
    err = _l2_errors(s, name, (32, 64))
    observed = np.log2(err[0] / err[1])  # h halves between the levels
    assert np.all(observed > order), observed


@pytest.mark.parametrize("surface", ["torus", "saddle", "helicoid"])
@pytest.mark.parametrize("name", ALL)
def test_directions_within_stated_angle_away_from_umbilics(surface: str, name: str) -> None:
    s = get_surface(surface)
    m = mesh_surface(s, _res(s, 64))
    u, v = m.uv[:, 0], m.uv[:, 1]
    cf = surface_curvature_fields(s, u, v)
    D = surface_derivatives(s, u, v)
    d1 = cf.w1[:, :1] * D.p_u + cf.w1[:, 1:] * D.p_v
    d1 /= np.linalg.norm(d1, axis=1, keepdims=True)
    gap = np.abs(cf.k1 - cf.k2) > 0.1 * np.maximum(np.abs(cf.k1), np.abs(cf.k2))
    keep = _interior(m, s) & gap
    r = ce.estimate_curvature(m.V, m.F, name)
    angle = np.degrees(np.arccos(np.clip(np.abs(np.sum(r.d1 * d1, axis=1)), 0, 1)))[keep]
    limit = 5.0 if name == "quadric" else 1.0  # measured max: quadric 3.9° (helicoid), others 0.4°
    assert angle.max() < limit


def test_quadric_is_libigls_principal_curvature_with_pv1_the_max() -> None:
    V, F = primitives.torus_mesh(96, 48)
    PD1, _, PV1, PV2, _ = igl.principal_curvature(V, F, 5)
    # libigl: PV1 is the max, measured against the face orientation's normal (positive on the
    # outside of the torus, where it is convex), so it maps one to one
    assert np.all(PV1 >= PV2)
    outside = np.hypot(V[:, 0], V[:, 1]) > 3.5
    assert np.all(PV2[outside] > 0)
    r = ce.estimate_curvature(V, F, "quadric")
    np.testing.assert_allclose(r.k1, PV1, atol=1e-12)
    np.testing.assert_allclose(r.k2, PV2, atol=1e-12)
    np.testing.assert_allclose(np.abs(np.sum(r.d1 * PD1, axis=1)), 1, atol=1e-9)
    # and it agrees in sign and shape with the other estimators
    rus = ce.estimate_curvature(V, F, "rusinkiewicz")
    assert np.corrcoef(r.H, rus.H)[0, 1] > 0.95
    assert np.all(np.sign(r.K) == np.sign(rus.K))


def test_quadric_sign_does_not_come_from_the_data_on_a_helicoid() -> None:
    """The old wrapper took the sign from Σ H·(PV1+PV2), negative on every helicoid level, and
    negated the result; now it follows the face orientation like the exact surface."""
    s = get_surface("helicoid")
    m = mesh_surface(s, 64)
    keep = _interior(m, s)
    cf = surface_curvature_fields(s, m.uv[:, 0], m.uv[:, 1])
    r = ce.estimate_curvature(m.V, m.F, "quadric")
    # k1 = 1/(1+u²) along one ruling-diagonal; check the directions agree with the exact ones
    D = surface_derivatives(s, m.uv[:, 0], m.uv[:, 1])
    d1 = cf.w1[:, :1] * D.p_u + cf.w1[:, 1:] * D.p_v
    d1 /= np.linalg.norm(d1, axis=1, keepdims=True)
    assert np.median(np.abs(np.sum(r.d1 * d1, axis=1))[keep]) > np.cos(np.radians(5))


# ---------------------------------------------------------------- noise (the scan case)


@pytest.fixture(scope="module")
def torus32k():
    V, F = primitives.torus_mesh(256, 128)  # 32768 vertices, R = 3, r = 1
    v = np.arctan2(V[:, 2], np.hypot(V[:, 0], V[:, 1]) - 3.0)
    H = 0.5 * (1.0 + np.cos(v) / (3.0 + np.cos(v)))
    return V, F, H


@pytest.mark.parametrize("alpha, bound", [(0.001, 0.17), (0.01, 0.63)])
def test_jet_meets_pymeshlab_on_the_noisy_torus(torus32k, alpha: float, bound: float) -> None:
    """Normal noise N(0, (α·diag)²): pymeshlab's scale-dependent quadric has H relative L2
    error 0.17 / 0.63 (issue 25); the jet with its automatic radius must not do worse (measured
    0.084 / 0.25), while every fixed-stencil estimator is far off (cotan 13, quadric 0.9 / 4)."""
    V0, F, H = torus32k
    V = add_noise(V0, F, alpha, mode="normal", seed=0)
    r = jet_curvatures(V, F)
    rel = np.linalg.norm(r.H - H) / np.linalg.norm(H)
    assert rel <= bound
    cot = ce.estimate_curvature(V, F, "cotan")
    assert np.linalg.norm(cot.H - H) / np.linalg.norm(H) > 3 * bound


def test_noise_estimate_and_radius_follow_the_noise(torus32k) -> None:
    V0, F, _ = torus32k
    sigma = 0.001 * bbox_diagonal(V0)
    V = add_noise(V0, F, 0.001, mode="normal", seed=1)
    assert estimate_normal_noise(V, F) == pytest.approx(sigma, rel=0.15)
    assert estimate_normal_noise(V0, F) < 0.2 * sigma  # clean: only the h²κ offsets
    assert default_jet_radius(V, F) > default_jet_radius(V0, F)


def test_mixed_voronoi_areas_from_the_face_frame_equal_libigls_massmatrix() -> None:
    """The cotan and normal-cycle estimators take the mixed Voronoi areas from their one pass
    over the faces (obtuse triangles included: a jittered, flipped saddle)."""
    from meshlap_core.curvature.fields import _areas_from, _face_frame

    m, V = perturbed_mesh("saddle", 20, 0.0, jitter=0.4, flips=0.3)
    theta = igl.internal_angles(V, m.F)
    assert (theta > np.pi / 2).any()  # the obtuse rule is exercised
    ref = igl.massmatrix(V, m.F, igl.MASSMATRIX_TYPE_VORONOI).diagonal()
    np.testing.assert_allclose(_areas_from(V, m.F, _face_frame(V, m.F), "voronoi"), ref, rtol=1e-12)


@pytest.mark.parametrize("name", ["cotan", "rusinkiewicz", "normal_cycle", "quadric"])
def test_curvature_at_vertex_is_the_whole_meshs_value_there(name: str) -> None:
    m, V = perturbed_mesh("torus", (48, 24), 0.002, jitter=0.3)
    whole = ce.estimate_curvature(V, m.F, name)
    for i in (0, 100, 250):
        p, j = ce.curvature_at_vertex(V, m.F, i, name)
        assert len(p.k1) < len(V) / 2  # a patch, not the mesh
        np.testing.assert_allclose([p.k1[j], p.k2[j]], [whole.k1[i], whole.k2[i]], atol=1e-9)
        S, _, _ = p.shape_operator(j)
        Sw, _, _ = whole.shape_operator(i)
        np.testing.assert_allclose(S, Sw, atol=1e-9)
    with pytest.raises(MeshError, match="whole mesh"):
        ce.curvature_at_vertex(V, m.F, 0, "jet")
    with pytest.raises(MeshError, match="out of range"):
        ce.curvature_at_vertex(V, m.F, len(V), name)


def test_shape_operator_has_the_principal_pairs_as_eigenpairs() -> None:
    V, F = primitives.torus_mesh(32, 16)
    p = ce.estimate_curvature(V, F, "cotan")
    for i in (0, 7, 300):
        S, t1, t2 = p.shape_operator(i)
        np.testing.assert_allclose(np.cross(t1, t2), p.normal[i], atol=1e-12)
        c1 = np.array([p.d1[i] @ t1, p.d1[i] @ t2])
        np.testing.assert_allclose(S @ c1, p.k1[i] * c1, atol=1e-12)
        np.testing.assert_allclose(np.linalg.eigvalsh(S)[::-1], [p.k1[i], p.k2[i]], atol=1e-12)


def test_ellipsoid_exact_curvature_is_the_closed_form() -> None:
    """The catalogue's ellipsoid (its curvature from the fundamental forms) against
    K = 1/(a²b²c² h⁴), H = (a²+b²+c²−|x|²)/(2a²b²c² h³), and k1 = k2 at an umbilic."""
    from meshlap_core.surfaces import ellipsoid_curvature, get_surface
    from meshlap_core.surfaces.geometry import surface_curvature_fields

    a, b, c = 2.0, 1.2, 0.7
    s = get_surface("ellipsoid", a=a, b=b, c=c)
    rng = np.random.default_rng(1)
    u, v = rng.uniform(0.05, np.pi - 0.05, 50), rng.uniform(0, 2 * np.pi, 50)
    X = s(u, v)
    np.testing.assert_allclose(X[:, 0] ** 2 / a**2 + X[:, 1] ** 2 / b**2 + X[:, 2] ** 2 / c**2, 1)
    cf = surface_curvature_fields(s, u, v)
    H, K = ellipsoid_curvature(a, b, c, X)
    np.testing.assert_allclose(cf.H, H, rtol=1e-10)
    np.testing.assert_allclose(cf.K, K, rtol=1e-10)
    assert np.all(cf.k1 >= cf.k2) and np.all(cf.k2 > 0)  # outward normal: convex, H > 0
    # the umbilic in the xz-plane: x² = a²(a²−b²)/(a²−c²), z² = c²(b²−c²)/(a²−c²)
    x = a * np.sqrt((a * a - b * b) / (a * a - c * c))
    z = c * np.sqrt((b * b - c * c) / (a * a - c * c))
    um = surface_curvature_fields(s, np.array([np.arctan2(x / a, z / c)]), np.array([0.0]))
    assert um.k1[0] == pytest.approx(um.k2[0], rel=1e-6)
    # a sphere is the ellipsoid with equal axes
    H1, K1 = ellipsoid_curvature(2.0, 2.0, 2.0, get_surface("sphere", r=2.0)(u, v))
    np.testing.assert_allclose(H1, 0.5)
    np.testing.assert_allclose(K1, 0.25)


@pytest.mark.parametrize("name", ["cotan", "rusinkiewicz", "normal_cycle", "quadric", "jet"])
def test_mesh_estimators_converge_to_the_exact_ellipsoid(name: str) -> None:
    """Refinement 16 -> 32 -> 64 cells: the relative RMS error of H and K (away from the
    poles) shrinks at order about 2 for every estimator (measured 1.8-2.2)."""
    from meshlap_core.curvature.study import curvature_study

    rows = curvature_study(["ellipsoid"], [name], (16, 32, 64))
    assert rows[-1]["H_rel"] < 0.015 and rows[-1]["K_rel"] < 0.025
    for q in ("H", "K"):
        errs = [r[f"{q}_rel"] for r in rows]
        assert errs[0] > errs[1] > errs[2]
        assert rows[-1][f"{q}_order"] > 1.6


def test_a_kept_topology_gives_the_same_estimate_for_new_positions() -> None:
    """The faces' edges built once (CurvatureTopology) and reused as the vertices move: the same
    values as without it; a topology of other faces is refused, as is one for the quadric."""
    from meshlap_core.curvature.topology import CurvatureTopology

    m, V0 = perturbed_mesh("torus", (24, 12), 0.0, jitter=0.3, flips=0.2)
    topo = CurvatureTopology.of(m.F, len(V0))
    for alpha in (0.001, 0.004):
        V = add_noise(V0, m.F, alpha, mode="normal", seed=3)
        for name in ce.TOPOLOGY_ESTIMATORS:
            plain, kept = (
                ce.estimate_curvature(V, m.F, name),
                ce.estimate_curvature(V, m.F, name, topology=topo),
            )
            for f in ("k1", "k2", "d1", "d2", "normal"):
                np.testing.assert_array_equal(getattr(plain, f), getattr(kept, f))
    other = CurvatureTopology.of(np.roll(m.F, 1, axis=0), len(V0))
    for name in ce.TOPOLOGY_ESTIMATORS:
        with pytest.raises(MeshError, match="another mesh"):
            ce.estimate_curvature(V0, m.F, name, topology=other)
    with pytest.raises(MeshError, match="does not take"):
        ce.estimate_curvature(V0, m.F, "quadric", topology=topo)


def test_topology_adjacency_is_the_brute_force_one() -> None:
    """Interior edges (two consistently oriented faces) and the vertex–face CSR against loops
    over a hand-checkable mesh (an open strip of 4 triangles, a boundary everywhere)."""
    from meshlap_core.curvature.topology import CurvatureTopology

    F = np.array([[0, 1, 2], [1, 3, 2], [2, 3, 4], [3, 5, 4]])
    topo = CurvatureTopology.of(F, 6)
    a, b, f1, f2 = topo.interior
    assert sorted(zip(a.tolist(), b.tolist(), f1.tolist(), f2.tolist(), strict=True)) == [
        (1, 2, 0, 1),
        (2, 3, 2, 1),
        (3, 4, 2, 3),
    ]
    ptr, faces = topo.vertex_faces
    for i in range(6):
        assert faces[ptr[i] : ptr[i + 1]].tolist() == [f for f in range(4) if i in F[f]]
    assert topo.faces_around(np.array([0, 5])).tolist() == [0, 3]
    assert topo.on_boundary.all()
    src, dst = topo.directed
    assert np.all(np.diff(src) >= 0) and len(src) == 2 * len(topo.table.edges)
    pairs = set(zip(src.tolist(), dst.tolist(), strict=True))
    assert pairs == {(j, i) for i, j in pairs} and (0, 1) in pairs and (0, 3) not in pairs


def test_curvature_at_vertex_takes_a_kept_topology() -> None:
    from meshlap_core.curvature.topology import CurvatureTopology

    m, V = perturbed_mesh("torus", (48, 24), 0.002, jitter=0.3)
    topo = CurvatureTopology.of(m.F, len(V))
    whole = ce.estimate_curvature(V, m.F, "rusinkiewicz")
    for i in (7, 500):
        p, j = ce.curvature_at_vertex(V, m.F, i, "rusinkiewicz", topology=topo)
        np.testing.assert_allclose([p.k1[j], p.k2[j]], [whole.k1[i], whole.k2[i]], atol=1e-9)
