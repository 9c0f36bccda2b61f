"""Property-based tests (hypothesis) on random valid meshes: closed ones from convex hulls of
random points on a sphere, open ones from randomly lifted grids."""

import itertools

import numpy as np
import scipy.sparse as sp
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from scipy.spatial import ConvexHull

from meshlap_core import curvature, laplacian, primitives, topology
from meshlap_core.smoothing import Smoother

SETTINGS = settings(max_examples=25, deadline=None, suppress_health_check=[HealthCheck.too_slow])


def closed_mesh(seed: int, n: int):
    """Convex hull of n random points on an ellipsoid, faces oriented outward (genus 0)."""
    rng = np.random.default_rng(seed)
    P = rng.standard_normal((n, 3))
    P /= np.linalg.norm(P, axis=1, keepdims=True)
    P *= rng.uniform(0.5, 2.0, size=3)
    F = ConvexHull(P).simplices.astype(np.int64)
    c = P[F].mean(axis=1)
    nrm = np.cross(P[F[:, 1]] - P[F[:, 0]], P[F[:, 2]] - P[F[:, 0]])
    flip = np.einsum("ij,ij->i", nrm, c - P.mean(axis=0)) < 0
    F[flip] = F[flip][:, ::-1]
    return P, F


def open_mesh(seed: int, nx: int, ny: int):
    """A grid with random heights and jittered x, y: a disk (chi = 1)."""
    rng = np.random.default_rng(seed)
    V, F = primitives.grid(nx, ny)
    V = V.copy()
    V[:, :2] += rng.uniform(-0.2, 0.2, (len(V), 2)) / max(nx, ny)
    V[:, 2] = 0.3 * rng.standard_normal(len(V)) / max(nx, ny)
    return V, F


meshes = st.one_of(
    st.builds(closed_mesh, st.integers(0, 10_000), st.integers(12, 200)),
    st.builds(open_mesh, st.integers(0, 10_000), st.integers(3, 12), st.integers(3, 12)),
)


@SETTINGS
@given(meshes)
def test_operators_finite_symmetric_rows_sum_to_zero(mesh):
    V, F = mesh
    n = len(V)
    C = laplacian.cotan_stiffness(V, F)
    assert np.isfinite(C.data).all()
    assert abs(C - C.T).max() <= 1e-10 * max(1.0, abs(C).max())
    np.testing.assert_allclose(C @ np.ones(n), 0, atol=1e-9 * max(1.0, abs(C).max()))
    L = laplacian.uniform_laplacian(F, n)
    np.testing.assert_allclose(L @ np.ones(n), 0, atol=1e-12)
    for area in laplacian.AREA_KINDS:
        a = laplacian.vertex_areas(V, F, area)
        assert np.isfinite(a).all() and (a >= 0).all()
        np.testing.assert_allclose(a.sum(), laplacian.face_areas(V, F).sum(), rtol=1e-10)
    for values in curvature.curvature_fields(V, F).values():
        assert np.isfinite(values).all()


@SETTINGS
@given(meshes)
def test_gauss_bonnet_with_boundary_term(mesh):
    V, F = mesh
    chi = topology.euler_characteristic(F)
    total = curvature.angle_deficit(V, F, "pi").sum()
    np.testing.assert_allclose(total, 2 * np.pi * chi, atol=1e-8)


@SETTINGS
@given(meshes)
def test_one_ring_consistent_with_faces(mesh):
    V, F = mesh
    n = len(V)
    ring = topology.one_ring(F, n)
    assert ring.regular.all()
    faces = {tuple(np.roll(f, -int(np.argmin(f)))) for f in F.tolist()}
    bmask = topology.boundary_vertex_mask(F, n)
    for i in range(n):
        r = ring[i].tolist()
        pairs = itertools.pairwise(r + r[:1] if not bmask[i] else r)
        for a, b in pairs:
            t = [i, a, b]
            k = t.index(min(t))
            assert tuple(t[k:] + t[:k]) in faces


@SETTINGS
@given(meshes, st.floats(1e-3, 10.0), st.sampled_from(["uniform", "cotan"]))
def test_implicit_smoothing_never_increases_dirichlet_energy(mesh, lam, kind):
    """The implicit step minimises |x' - x|^2_W / 2 + lam E(x'), so E(x') <= E(x), with
    E(x) = 1/2 x^T K x for the operator's own stiffness K (cotan: -C; uniform: D - A)."""
    V, F = mesh
    n = len(V)
    if kind == "cotan":
        K = -laplacian.cotan_stiffness(V, F)
        lam *= float(np.mean(laplacian.face_areas(V, F)))  # lambda has units of length^2
    else:
        A = laplacian.adjacency_matrix(F, n)
        K = sp.diags(np.asarray(A.sum(axis=1)).ravel()) - A

    def energy(X):
        return 0.5 * float(np.einsum("ij,ij->", X, K @ X))

    s = Smoother(V, F, "implicit", kind, lam, warn=False, track_history=False)
    e = [energy(s.V)]
    for _ in range(3):
        s.step()
        e.append(energy(s.V))
    assert all(b <= a * (1 + 1e-9) + 1e-12 for a, b in itertools.pairwise(e))
    assert np.isfinite(s.V).all()
