"""Tests of meshlap_core.spectral and the ``spectral`` command.

Sign convention: C (cotan stiffness) is negative semidefinite; the eigenproblem is
K u = λ M u with K = −C positive semidefinite, so the eigenvalues are the frequencies λ >= 0 of
−Δ. Tiers: hand-computed tiny cases; invariants (M-orthonormality, zero modes per component,
monotone projection error, scale covariance); references (dense LAPACK, scipy's eigsh, the
sphere's l(l+1), the Neumann square's π²(a² + b²)).
"""

from __future__ import annotations

import json
import threading

import numpy as np
import pytest
import scipy.linalg
import scipy.sparse as sp
import scipy.sparse.linalg as spla
from threadpoolctl import threadpool_limits

from meshlap_core import spectral as S
from meshlap_core.cli import main
from meshlap_core.errors import MeshError
from meshlap_core.options import AREA_KINDS
from meshlap_core.primitives import bumpy_sphere, grid, icosphere, torus_mesh

# every test under each plan of the eigensolver (one slice worker and two, forced): the machine's
# load must not pick which one a test sees
pytestmark = pytest.mark.usefixtures("slice_plan")


@pytest.fixture(autouse=True)
def _cache_in_tmp(tmp_path, monkeypatch):
    """Every test gets its own cache directory (never the user's)."""
    monkeypatch.setenv("MESHLAP_CACHE_DIR", str(tmp_path / "cache"))


def _orth(U, m):
    return np.abs(U.T @ (m[:, None] * U) - np.eye(U.shape[1])).max()


def _sign_entries(U):
    """Per column, the entry the sign rule makes positive: the first of those within 1e-6 of
    the largest magnitude (a symmetric mesh reaches it at mirror vertices, ± by round-off)."""
    a = np.abs(U)
    return U[np.argmax(a >= (1 - 1e-6) * a.max(axis=0), axis=0), np.arange(U.shape[1])]


def _dense_reference(V, F, k, **kw):
    """Generalized eigenvalues of (K, M) straight from LAPACK (no code of ours but the pencil)."""
    K, m = S.spectral_operators(V, F, **kw)
    with threadpool_limits(1):  # threaded LAPACK crawls on a loaded 2-core machine
        return scipy.linalg.eigh(
            K.toarray(), np.diag(m), eigvals_only=True, subset_by_index=(0, k - 1)
        )


def _eigsh_reference(V, F, k):
    """scipy's ARPACK shift-invert on the same pencil (shift scaled to the mesh)."""
    K, m = S.spectral_operators(V, F)
    lam = spla.eigsh(
        K,
        k,
        M=sp.diags(m).tocsc(),
        sigma=-1e-3 * K.diagonal().mean() / m.mean(),
        which="LM",
        return_eigenvectors=False,
    )
    return np.sort(lam)


def _two_components():
    V1, F1 = icosphere(3)
    V2, F2 = torus_mesh(40, 20)
    return np.vstack([V1, V2 + np.array([6.0, 0.0, 0.0])]), np.vstack([F1, F2 + len(V1)])


# ------------------------------------------------------------------ hand-computed tiny cases


def test_equilateral_triangle_by_hand():
    # side 1: cot 60° = 1/√3, so K = (1/(2√3)) [[2,-1,-1],[-1,2,-1],[-1,-1,2]] with eigenvalues
    # 0, √3/2, √3/2; every vertex has mass (√3/4)/3 = √3/12, hence λ = 0, 6, 6.
    V = np.array([[0.0, 0, 0], [1, 0, 0], [0.5, np.sqrt(3) / 2, 0]])
    F = np.array([[0, 1, 2]])
    for mass in AREA_KINDS:
        lam, U, _ = S.laplacian_eigenpairs(V, F, 3, area=mass)
        np.testing.assert_allclose(lam, [0.0, 6.0, 6.0], atol=1e-12)
        np.testing.assert_allclose(U[:, 0], 1 / np.sqrt(np.sqrt(3) / 4), rtol=1e-12)


def test_two_separate_triangles_have_two_zero_modes():
    V = np.array([[0.0, 0, 0], [1, 0, 0], [0.5, np.sqrt(3) / 2, 0]])
    V = np.vstack([V, V + 5.0])
    F = np.array([[0, 1, 2], [3, 4, 5]])
    lam, U, info = S.laplacian_eigenpairs(V, F, 6)
    np.testing.assert_allclose(lam, [0, 0, 6, 6, 6, 6], atol=1e-12)
    assert info.n_components == 2
    # the zero modes are the normalized component indicators
    ind = U[:, :2] * np.sqrt(np.sqrt(3) / 4)
    np.testing.assert_allclose(np.sort(np.abs(ind), axis=None), [0] * 6 + [1] * 6, atol=1e-12)


# ----------------------------------------------------------------------------- invariants


def test_full_basis_reconstructs_the_vertices():
    V, F = bumpy_sphere(2)  # 162 vertices: k = n, dense solver
    basis = S.SpectralBasis.compute(V, F, len(V), cache=False)
    assert basis.info.method == "dense"
    np.testing.assert_allclose(basis.reconstruct(len(V)), V, atol=1e-9)
    assert _orth(basis.vectors, basis.mass) < 1e-10


def test_sparse_solver_is_m_orthonormal_and_matches_dense():
    V, F = bumpy_sphere(3)  # 642 vertices, the sparse path forced
    lam, U, info = S.laplacian_eigenpairs(V, F, 60, method="sparse")
    assert info.method.startswith("shift-invert")
    K, m = S.spectral_operators(V, F)
    assert _orth(U, m) <= 1e-10
    ref = _dense_reference(V, F, 60)
    np.testing.assert_allclose(lam, ref, rtol=1e-9, atol=1e-9 * ref.max())
    np.testing.assert_allclose(K @ U, (m[:, None] * U) * lam, atol=1e-6 * lam.max())
    assert np.all(np.diff(lam) >= 0) and lam[0] == 0.0 and info.n_clipped == 0


def test_many_slices_in_two_threads_match_dense():
    V, F = icosphere(3)  # exact multiplicities 3, 4, 5 of the icosahedral group
    lam, U, info = S.laplacian_eigenpairs(
        V, F, 150, method="sparse", slice_size=30, first_slice=30, workers=2
    )
    assert len(info.shifts) >= 5
    _, m = S.spectral_operators(V, F)
    assert _orth(U, m) <= 1e-10
    # the reported orthogonality is that of the result, after the slices were orthonormalized
    # together (their departure before is reported as a message)
    assert info.orthogonality_error <= 1e-12
    assert any("orthonormalized together" in msg for msg in info.messages)
    ref = _dense_reference(V, F, 150)
    np.testing.assert_allclose(lam, ref, rtol=1e-9, atol=1e-9 * ref.max())


def test_signs_are_deterministic():
    V, F = bumpy_sphere(3)
    U1 = S.laplacian_eigenpairs(V, F, 20, method="sparse", workers=1)[1]
    U2 = S.laplacian_eigenpairs(V, F, 20, method="sparse", workers=2)[1]
    assert np.all(_sign_entries(U1) > 0)
    # same eigenvalues, non-degenerate here: the same vectors, signs included
    np.testing.assert_allclose(U1, U2, atol=1e-6)


def test_two_components_give_two_zero_eigenvalues_sparse():
    V, F = _two_components()
    lam, _, info = S.laplacian_eigenpairs(V, F, 12, method="sparse")
    assert info.n_components == 2
    assert np.count_nonzero(lam == 0.0) == 2 and lam[2] > 1e-3
    ref = _dense_reference(V, F, 12)
    np.testing.assert_allclose(lam[2:], ref[2:], rtol=1e-9)


def test_open_mesh_neumann_eigenvalues_of_the_unit_square():
    V, F = grid(45, 45)  # unit square, open: natural (Neumann) boundary conditions
    lam = S.laplacian_eigenpairs(V, F, 6, method="sparse")[0]
    pi2 = np.pi**2
    np.testing.assert_allclose(lam, [0, pi2, pi2, 2 * pi2, 4 * pi2, 4 * pi2], rtol=1e-2, atol=1e-12)


def test_scale_covariance_tiny_and_huge_meshes():
    # λ scales like 1/length²; the shift scales with the mesh, so a total area of 1e-6 or 1e6
    # (the dragon is 0.07, nefertiti 3.6e5) is solved as well as area 4π
    V, F = bumpy_sphere(4)
    lam = S.laplacian_eigenpairs(V, F, 30, method="sparse")[0]
    for s in (1e-3, 1e3):
        lam_s = S.laplacian_eigenpairs(V * s, F, 30, method="sparse")[0]
        np.testing.assert_allclose(lam_s * s**2, lam, rtol=1e-8, atol=1e-10 * lam.max())


def test_every_pair_has_a_small_relative_residual_on_a_mesh_of_slivers():
    # a 1 × 0.002 strip of a 120 × 8 grid: the lowest modes vary along the strip only, so
    # λ_max/λ_1 ~ 1e9 (as on the scanned dragon). A residual small relative to the shifted
    # operator alone would leave them with pencil residuals ~ tol·λ_max/λ: each pair must
    # have ||K u − λ M u||_{M⁻¹} <= 1e-6 λ (the solver's pencil criterion, with room).
    V, F = grid(120, 8)
    V = V * np.array([1.0, 0.002, 1.0])
    K, m = S.spectral_operators(V, F)
    lam, U, _ = S.laplacian_eigenpairs(V, F, 40, method="sparse", workers=1)
    assert (K.diagonal() / m).max() / lam[1] > 1e6  # (a lower bound of λ_max / λ_1)
    R = K @ U - (m[:, None] * U) * lam[None, :]
    r = np.sqrt(np.sum(R * R / m[:, None], axis=0))
    assert np.all(r[1:] <= 5e-6 * lam[1:])
    # and the low modes are those of a 1-D Neumann rod of length 1: λ_j ≈ (jπ)²
    np.testing.assert_allclose(lam[1:6], (np.arange(1, 6) * np.pi) ** 2, rtol=2e-3)


def test_uniform_laplacian_is_the_graph_laplacian():
    V, F = bumpy_sphere(3)
    lam, U, _ = S.laplacian_eigenpairs(V, F, 25, laplacian="uniform", method="sparse")
    K, m = S.spectral_operators(V, F, laplacian="uniform")
    np.testing.assert_array_equal(m, 1.0)
    A = K.toarray()
    np.testing.assert_allclose(
        np.diag(A), [len(set(F[np.any(F == i, 1)].ravel())) - 1 for i in range(len(V))]
    )
    with threadpool_limits(1):
        ref = np.linalg.eigvalsh(A)[:25]
    np.testing.assert_allclose(lam, ref, rtol=1e-9, atol=1e-12)
    assert _orth(U, m) < 1e-10


def test_reconstruction_error_is_non_increasing_and_matches_direct():
    V, F = bumpy_sphere(3)
    basis = S.SpectralBasis.compute(V, F, 200, cache=False)
    errs = basis.errors()
    assert errs.k[0] == 0 and len(errs.l2) == 201
    # the M-weighted error of an M-orthogonal projection never increases
    assert np.all(np.diff(errs.l2) <= 1e-12)
    m = basis.mass
    for k in (0, 1, 7, 64, 200):
        Uk = basis.vectors[:, :k]
        direct = Uk @ (Uk.T @ (m[:, None] * V))
        e = np.linalg.norm(V - direct, axis=1)
        assert errs.mean[k] == pytest.approx(e.mean(), rel=1e-9, abs=1e-14)
        assert errs.max[k] == pytest.approx(e.max(), rel=1e-9, abs=1e-14)
        assert errs.rms[k] == pytest.approx(np.sqrt(np.mean(e**2)), rel=1e-9, abs=1e-14)
        assert errs.l2[k] == pytest.approx(np.sqrt(m @ e**2 / m.sum()), rel=1e-9, abs=1e-14)
        np.testing.assert_allclose(basis.vertex_error(k), e, atol=1e-12)
    diag = np.linalg.norm(V.max(0) - V.min(0))
    assert errs.relative_mean[5] == pytest.approx(errs.mean[5] / diag)
    # projecting with the wrong inner product (U_kᵀ X) is not a projection: it is worse
    Uk = basis.vectors[:, :50]
    wrong = Uk @ (Uk.T @ V)
    assert np.mean(np.linalg.norm(V - wrong, axis=1)) > 10 * errs.mean[50]


def test_errors_at_chosen_k_match_the_direct_projection_and_the_full_table():
    V, F = bumpy_sphere(3)
    basis = S.SpectralBasis.compute(V, F, 120, cache=False)
    m = basis.mass
    ks = [120, 0, 7, 64, 7]
    errs = basis.errors_at(ks)
    assert errs.k.tolist() == [0, 7, 64, 120]  # sorted, unique
    full = basis.errors(k_max=120)
    for i, k in enumerate(errs.k):
        Uk = basis.vectors[:, :k]
        e = np.linalg.norm(V - Uk @ (Uk.T @ (m[:, None] * V)), axis=1)
        assert errs.mean[i] == pytest.approx(e.mean(), rel=1e-9, abs=1e-14)
        assert errs.max[i] == pytest.approx(e.max(), rel=1e-9, abs=1e-14)
        assert errs.rms[i] == pytest.approx(np.sqrt(np.mean(e**2)), rel=1e-9, abs=1e-14)
        assert errs.l2[i] == pytest.approx(np.sqrt(m @ e**2 / m.sum()), rel=1e-9, abs=1e-14)
        assert errs.row(int(k)) == pytest.approx(full.row(int(k)), rel=1e-9, abs=1e-14)
    with pytest.raises(MeshError, match="k = 8"):
        errs.row(8)
    # another field than the vertices: a single column
    X = V[:, 2] ** 2
    one = basis.errors_at([3, 50], X)
    U3 = basis.vectors[:, :3]
    assert one.max[0] == pytest.approx(np.abs(X - U3 @ (U3.T @ (m * X))).max(), rel=1e-9)
    with pytest.raises(MeshError):
        basis.errors_at([-1, 4])


def test_incremental_reconstruction_equals_the_direct_product():
    V, F = bumpy_sphere(3)
    basis = S.SpectralBasis.compute(V, F, 120, cache=False)
    m = basis.mass
    for k in [5, 6, 120, 0, 37, 36, 99, 1, 64, 120, 3]:
        Uk = basis.vectors[:, :k]
        np.testing.assert_allclose(basis.reconstruct(k), Uk @ (Uk.T @ (m[:, None] * V)), atol=1e-12)
    out = basis.reconstruct(10)
    out[:] = 0.0  # the caller owns the returned array
    assert np.abs(basis.reconstruct(10)).max() > 0.5
    X = np.random.default_rng(1).standard_normal(len(V))
    Uk = basis.vectors[:, :30]
    np.testing.assert_allclose(basis.reconstruct(30, X), Uk @ (Uk.T @ (m * X)), atol=1e-12)
    np.testing.assert_allclose(basis.coefficients(k=30), Uk.T @ (m[:, None] * V), atol=1e-12)


def test_asking_for_more_modes_extends_the_basis():
    V, F = bumpy_sphere(4)  # 2562 vertices: the sparse solver, which extends incrementally
    basis = S.SpectralBasis.compute(V, F, 20, cache=False)
    u = basis.eigenfunction(45)  # beyond k_max: extends
    assert basis.k_max == 46 and u.shape == (len(V),)
    ref = _eigsh_reference(V, F, 46)
    np.testing.assert_allclose(basis.eigenvalues, ref, rtol=1e-9, atol=1e-9 * ref.max())
    assert _orth(basis.vectors, basis.mass) <= 1e-10
    direct = S.laplacian_eigenpairs(V, F, 46, method="sparse")[1]
    overlap = np.abs(np.sum(direct * (basis.mass[:, None] * basis.vectors), axis=0))
    assert overlap.min() > 1 - 1e-6  # the same (non-degenerate) eigenvectors


def test_progress_callback_worker_thread_and_cancel():
    V, F = bumpy_sphere(4)
    seen: list[tuple[float, str]] = []
    result = {}

    def work():
        result["basis"] = S.SpectralBasis.compute(
            V, F, 40, cache=False, progress=lambda f, msg: seen.append((f, msg))
        )

    t = threading.Thread(target=work)
    t.start()
    t.join()
    assert result["basis"].k_max == 40
    assert seen and all(0.0 <= f <= 1.0 for f, _ in seen)
    assert all(isinstance(msg, str) and msg for _, msg in seen)

    class Stop(Exception):
        pass

    def cancel(fraction, message):
        raise Stop

    with pytest.raises(Stop):
        S.laplacian_eigenpairs(V, F, 40, method="sparse", progress=cancel)


# ----------------------------------------------------------------------------- references


def test_unit_sphere_eigenvalues_cluster_at_l_l_plus_1():
    V, F = icosphere(4)
    lam = S.laplacian_eigenpairs(V, F, 16, method="sparse")[0]
    assert lam[0] == 0.0
    for deg, rtol in ((1, 0.005), (2, 0.005), (3, 0.01)):
        block = lam[deg * deg : (deg + 1) ** 2]  # multiplicity 2l + 1
        np.testing.assert_allclose(block, deg * (deg + 1), rtol=rtol)
    # and the clusters are separated: 3, 5, 7 values, not more
    assert lam[4] - lam[3] > 3.0 and lam[9] - lam[8] > 5.0


def test_agrees_with_scipy_eigsh():
    V, F = torus_mesh(64, 24)
    K, m = S.spectral_operators(V, F)
    ref, Uref = spla.eigsh(K, 40, M=sp.diags(m).tocsc(), sigma=-1e-3, which="LM")
    o = np.argsort(ref)
    ref, Uref = ref[o], Uref[:, o]
    lam, U, _ = S.pencil_eigenpairs(K, m, 40, method="sparse")
    np.testing.assert_allclose(lam[1:], ref[1:], rtol=1e-9)
    # eigenspaces agree (the torus has 2-fold degenerate pairs: compare projectors)
    P = U.T @ (m[:, None] * Uref)
    sv = np.linalg.svd(P[:39, :39], compute_uv=False)
    assert sv.min() > 1 - 1e-6


@pytest.mark.parametrize("gil_free", [False, True])
def test_both_ldl_back_ends_give_the_eigsh_pairs(spd_backend, gil_free, monkeypatch):
    """CHOLMOD (scikit-sparse) and QDLDL (the pure-wheel fallback, also the one a thread of
    the window uses: ``prefer_gil_free``) give the same eigenpairs as scipy's eigsh: equal
    eigenvalues, M-orthonormal vectors with small residuals ``‖Ku − λMu‖``."""
    from meshlap_core.linalg import spd

    monkeypatch.setattr(spd, "_GIL_FREE", {"eigen": gil_free})
    V, F = torus_mesh(48, 20)
    K, m = S.spectral_operators(V, F)
    ref = np.sort(spla.eigsh(K, 30, M=sp.diags(m).tocsc(), sigma=-1e-3, which="LM")[0])
    lam, U, info = S.pencil_eigenpairs(K, m, 30, method="sparse", workers=1)
    want = "CHOLMOD" if spd_backend == "cholmod" and not gil_free else "QDLDL"
    assert any(f"LDLT by {want}" in msg for msg in info.messages), info.messages
    np.testing.assert_allclose(lam[1:], ref[1:], rtol=1e-9)
    assert abs(lam[0]) < 1e-12
    np.testing.assert_allclose(U.T @ (m[:, None] * U), np.eye(30), atol=1e-10)
    R = K @ U - (m[:, None] * U) * lam
    assert np.linalg.norm(R / np.sqrt(m)[:, None], axis=0).max() <= 1e-6 * lam.max()
    assert np.all(_sign_entries(U) > 0)


def test_fix_signs_makes_the_largest_entry_positive_in_any_layout():
    from meshlap_core.linalg.eigsolve import fix_signs

    A = np.array([[1.0, -3.0, 0.0], [-2.0, 1.0, 0.0], [0.5, 2.0, 0.0]])
    want = np.array([[-1.0, 3.0, 0.0], [2.0, -1.0, 0.0], [-0.5, -2.0, 0.0]])
    for order in "CF":
        X = np.array(A, order=order)
        fix_signs(X)
        np.testing.assert_array_equal(X, want)
    # ties (mirror vertices of a symmetric mesh): the first of the tied entries decides,
    # whichever is larger by round-off
    for eps in (0.0, 1e-13, -1e-13):
        T = np.array([[0.3, -0.5], [-0.3 * (1 + eps), 0.5 * (1 + eps)], [0.1, 0.0]])
        for order in "CF":
            X = np.array(T, order=order)
            fix_signs(X)
            np.testing.assert_array_equal(np.sign(X[:2]), [[1.0, 1.0], [-1.0, -1.0]])


# ----------------------------------------------------------------------------- bad input


def test_k_out_of_range_and_bad_meshes():
    V, F = icosphere(1)
    with pytest.raises(MeshError, match="only 42 vertices"):
        S.laplacian_eigenpairs(V, F, 43)
    with pytest.raises(MeshError, match="positive"):
        S.laplacian_eigenpairs(V, F, 0)
    with pytest.raises(MeshError, match="unreferenced"):
        S.laplacian_eigenpairs(np.vstack([V, [[5.0, 5, 5]]]), F, 3)
    with pytest.raises(MeshError, match="no faces"):
        S.laplacian_eigenpairs(V, np.zeros((0, 3), dtype=np.int64), 3)
    with pytest.raises(MeshError, match="laplacian"):
        S.laplacian_eigenpairs(V, F, 3, laplacian="graph")
    basis = S.SpectralBasis.compute(V, F, 42, cache=False)  # k = n works
    assert basis.k_max == 42


# ----------------------------------------------------------------------------- cache


def test_default_cache_dir_respects_the_environment(monkeypatch, tmp_path):
    monkeypatch.setenv("MESHLAP_CACHE_DIR", str(tmp_path / "a"))
    assert S.default_cache_dir() == tmp_path / "a"
    monkeypatch.delenv("MESHLAP_CACHE_DIR")
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "x"))
    assert S.default_cache_dir() == tmp_path / "x" / "meshlap"
    monkeypatch.delenv("XDG_CACHE_HOME")
    monkeypatch.setenv("HOME", str(tmp_path / "h"))
    assert S.default_cache_dir() == tmp_path / "h" / ".cache" / "meshlap"


def test_cache_returns_the_same_basis_and_survives_corruption(tmp_path):
    V, F = bumpy_sphere(4)
    cache = tmp_path / "cache"
    b1 = S.SpectralBasis.compute(V, F, 30)
    files = list(cache.glob("*.npz"))
    assert len(files) == 1 and not b1.info.from_cache
    assert not [p for p in cache.iterdir() if p.suffix != ".npz"]  # no temporary left over
    b2 = S.SpectralBasis.compute(V, F, 30)
    assert b2.info.from_cache
    np.testing.assert_array_equal(b2.eigenvalues, b1.eigenvalues)
    np.testing.assert_array_equal(b2.vectors, b1.vectors)
    b3 = S.SpectralBasis.compute(V, F, 10)  # fewer modes: truncated from the cache
    assert b3.info.from_cache and b3.k_max == 10

    files[0].write_bytes(b"this is not a zip file")
    b4 = S.SpectralBasis.compute(V, F, 30)
    assert not b4.info.from_cache and any("ignored cache" in m for m in b4.info.messages)
    np.testing.assert_allclose(b4.eigenvalues, b1.eigenvalues, rtol=1e-12)
    assert S.SpectralBasis.compute(V, F, 30).info.from_cache  # rebuilt file is good again


def test_cache_rejects_tampered_and_stale_files(tmp_path):
    V, F = bumpy_sphere(4)
    b = S.SpectralBasis.compute(V, F, 20)
    path = next((tmp_path / "cache").glob("*.npz"))
    data = dict(np.load(path))
    data["vectors"] = data["vectors"].copy()
    data["vectors"][:, 7] *= 1.01  # no longer M-orthonormal
    np.savez(path, **data)
    again = S.SpectralBasis.compute(V, F, 20)
    assert not again.info.from_cache and any("M-orthonormal" in m for m in again.info.messages)
    # a file of another mesh under this mesh's name: the stored hash differs
    V2 = V * 1.0001
    other = S.SpectralBasis.compute(V2, F, 20)
    path2 = next(p for p in (tmp_path / "cache").glob("*.npz") if p != path)
    path.write_bytes(path2.read_bytes())
    stale = S.SpectralBasis.compute(V, F, 20)
    assert not stale.info.from_cache and any("stale" in m for m in stale.info.messages)
    assert other.eigenvalues[5] != b.eigenvalues[5]


def test_cache_extends_a_smaller_basis(tmp_path):
    V, F = bumpy_sphere(4)  # sparse path
    S.SpectralBasis.compute(V, F, 15)
    big = S.SpectralBasis.compute(V, F, 40)
    assert not big.info.from_cache and big.k_max == 40
    ref = _eigsh_reference(V, F, 40)
    np.testing.assert_allclose(big.eigenvalues, ref, rtol=1e-9, atol=1e-9 * ref.max())
    assert S.SpectralBasis.compute(V, F, 40).info.from_cache


def test_extension_reads_the_cache_first(tmp_path):
    V, F = bumpy_sphere(4)
    b40 = S.SpectralBasis.compute(V, F, 40)  # the cache now holds 40 modes
    small = S.SpectralBasis.compute(V, F, 10)
    assert small.info.from_cache and small.k_max == 10
    small.ensure(30)  # no solve: the cached modes are enough
    assert small.info.from_cache and small.k_max == 30
    np.testing.assert_array_equal(small.vectors, b40.vectors[:, :30])
    small.ensure(50)  # solves the 10 missing ones and stores all 50
    assert not small.info.from_cache and small.k_max == 50
    assert S.SpectralBasis.compute(V, F, 50).info.from_cache


def test_no_cache_writes_nothing(tmp_path):
    V, F = icosphere(2)
    S.SpectralBasis.compute(V, F, 10, cache=False)
    assert not (tmp_path / "cache").exists()


def test_save_and_load_roundtrip(tmp_path):
    V, F = bumpy_sphere(3)
    b = S.SpectralBasis.compute(V, F, 25, cache=False)
    b.save(tmp_path / "b.npz")
    c = S.SpectralBasis.load(tmp_path / "b.npz", V, F)
    np.testing.assert_array_equal(c.vectors, b.vectors)
    with pytest.raises(MeshError, match="stale"):
        S.SpectralBasis.load(tmp_path / "b.npz", V, F, area="barycentric")


# ----------------------------------------------------------------------------- CLI


@pytest.fixture
def sphere_obj(tmp_path):
    from meshlap_core.io import save_mesh

    path = tmp_path / "bumpy.obj"
    save_mesh(path, *bumpy_sphere(3))
    return path


def test_cli_json(sphere_obj, tmp_path, capsys):
    code = main(
        [
            "spectral",
            str(sphere_obj),
            "--k",
            "60",
            "--reconstruct",
            "5,15,60",
            "--save-reconstruction",
            str(tmp_path / "rec"),
            "--out",
            str(tmp_path / "basis.npz"),
            "--json",
        ]
    )
    assert code == 0
    r = json.loads(capsys.readouterr().out)
    assert r["n_vertices"] == 642 and r["k"] == 60 and len(r["eigenvalues"]) == 60
    assert "eigensolve" in r["timings"]
    assert [row["k"] for row in r["reconstruction"]] == [5, 15, 60]
    for row in r["reconstruction"]:
        assert {"k", "mean_error", "max_error", "rms_error", "relative_mean_error"} <= set(row)
    l2 = [row["l2_error"] for row in r["reconstruction"]]  # area-weighted: monotone in k
    assert l2[0] >= l2[1] >= l2[2] > 0
    from meshlap_core.io import load_mesh

    V, F = bumpy_sphere(3)
    rec = load_mesh(tmp_path / "rec" / "bumpy_k15.obj")
    basis = S.SpectralBasis.load(tmp_path / "basis.npz", V, F)
    np.testing.assert_allclose(rec.V, basis.reconstruct(15), atol=1e-12)
    assert list((tmp_path / "cache").glob("*.npz"))


def test_cli_errors_and_no_cache(sphere_obj, tmp_path, capsys):
    assert main(["spectral", str(sphere_obj), "--k", "700"]) == 2
    err = capsys.readouterr().err
    assert "--k" in err and "642 vertices" in err
    assert main(["spectral", str(sphere_obj), "--k", "10", "--reconstruct", "20"]) == 2
    assert "--reconstruct" in capsys.readouterr().err
    assert main(["spectral", str(sphere_obj), "--k", "10", "--out", str(sphere_obj)]) == 2
    assert (
        main(["spectral", str(sphere_obj), "--k", "12", "--no-cache", "--laplacian", "uniform"])
        == 0
    )
    out = capsys.readouterr().out
    assert "uniform" in out and "reconstruction error" in out
    assert not (tmp_path / "cache").exists()


# ----------------------------------------------------------------------------- real mesh


@pytest.mark.shared
def test_cleaned_dragon_nonmanifold_seven_components(shared_mesh):
    from meshlap_core.io import load_mesh

    mesh = load_mesh(shared_mesh("dragon.obj"))  # repairs duplicates / unreferenced vertices
    lam, U, info = S.laplacian_eigenpairs(mesh.V, mesh.F, 12)
    assert info.n_components == 7 and np.count_nonzero(lam == 0.0) == 7 and lam[7] > 0
    _, m = S.spectral_operators(mesh.V, mesh.F)
    # (relative residuals in the original pencil are amplified by λ_max/λ, ~1e9 on this mesh
    # of slivers; 1e-3 means the vectors are eigenvectors, the eigenvalues far better)
    assert _orth(U, m) <= 1e-10 and info.max_residual < 1e-3


def test_the_pencil_is_assembled_once_per_cache_miss(monkeypatch, tmp_path):
    from meshlap_core import laplacian

    calls = {"stiffness": 0, "areas": 0}
    stiffness, areas = laplacian.cotan_stiffness, laplacian.vertex_areas

    def counted_stiffness(*args, **kw):
        calls["stiffness"] += 1
        return stiffness(*args, **kw)

    def counted_areas(*args, **kw):
        calls["areas"] += 1
        return areas(*args, **kw)

    monkeypatch.setattr(laplacian, "cotan_stiffness", counted_stiffness)
    monkeypatch.setattr(laplacian, "vertex_areas", counted_areas)
    V, F = icosphere(2)
    basis = S.SpectralBasis.compute(V, F, 4, cache_dir=tmp_path)
    assert not basis.info.from_cache
    assert calls == {"stiffness": 1, "areas": 1}
    # an extension beyond the cached modes: once more
    basis.ensure(10)
    assert calls == {"stiffness": 2, "areas": 2}
    # the result is the sphere's spectrum: 0, then l(l+1) = 2 three times
    np.testing.assert_allclose(basis.eigenvalues[1:4], 2.0, rtol=0.02)


# ------------------------------------------------------------------ badly scaled input (issue 14)


def _two_spheres(small: float, big: float):
    """A fine icosphere of radius ``small`` beside a coarse one of radius ``big``."""
    Vs, Fs = icosphere(3)  # 642 vertices
    Vb, Fb = icosphere(1)  # 42 vertices
    V = np.vstack([Vs * small, Vb * big + [3.0 * big, 0.0, 0.0]])
    F = np.vstack([Fs, Fb + len(Vs)])
    return V, F, (Vs * small, Fs), (Vb * big, Fb)


@pytest.mark.parametrize("radii", [(1e-6, 1e6), (1e-12, 1.0)], ids=["1e-6,1e6", "1e-12,1"])
@pytest.mark.parametrize("method", ["dense", "sparse"])
def test_two_spheres_of_very_different_size_give_each_spectrum(radii, method):
    """0, 0, then the l(l+1)/r² series of each sphere: the coarse big sphere's 41 non-zero
    eigenvalues lie far below the small sphere's first, 2/r_small²; each as when the sphere
    is solved alone."""
    small, big = radii
    V, F, alone_small, alone_big = _two_spheres(small, big)
    k = 60
    lam, U, info = S.laplacian_eigenpairs(V, F, k, method=method)
    assert info.n_components == 2 and "per scale group" in info.method
    if method == "sparse":
        assert "Lanczos" in info.method
    lam_s, _, _ = S.laplacian_eigenpairs(*alone_small, k, method="dense")
    lam_b, _, _ = S.laplacian_eigenpairs(*alone_big, 42, method="dense")
    ref = np.sort(np.r_[lam_s, lam_b])[:k]
    assert lam[0] == lam[1] == 0.0
    np.testing.assert_allclose(lam[2:], ref[2:], rtol=1e-8)
    # the series: l(l+1)/r², l = 1 three times, for each sphere (as the meshes allow)
    np.testing.assert_allclose(lam[2:5], 2.0 / big**2, rtol=0.15)
    np.testing.assert_allclose(lam[43:46], 2.0 / small**2, rtol=1e-3)
    assert lam[42] < 1e-6 * lam[43]  # every big-sphere mode before the small sphere's first
    # M-orthonormal; every non-zero mode lives on one sphere
    _, m = S.spectral_operators(V, F)
    assert _orth(U, m) < 1e-10
    n_small = len(alone_small[0])
    on_small = np.sum(m[:n_small, None] * U[:n_small] ** 2, axis=0)
    assert np.all((on_small < 1e-12) | (on_small > 1 - 1e-12))
    assert info.max_residual <= 1e-8


def _relative_residuals(K, m, lam, U):
    """``||K u − λ M u||_{M⁻¹} / max(λ, λ_ref)`` per pair, ``λ_ref = tr(K)/(n·Σm)`` (one
    component), written out here rather than taken from the solver's check."""
    R = K @ U - (m[:, None] * U) * lam[None, :]
    ref = K.diagonal().sum() / (len(m) * m.sum())
    return np.sqrt(np.sum(R * R / m[:, None], axis=0)) / np.maximum(lam, ref)


def test_an_inaccurate_result_is_refined_to_the_promised_residual(monkeypatch):
    """Three of the Lanczos pairs spoiled by 1e-7 of noise (what an early stop or the mixing
    of slices leaves: residuals ~1e-5) are refined (inverse iteration, Rayleigh–Ritz) to the
    promised residual and agree with LAPACK; without the refinement the same result is
    refused, never returned as if converged."""
    from meshlap_core.linalg import eigsolve, slicing
    from meshlap_core.linalg.refine import PROMISED_RESIDUAL, Refinement

    solve = slicing.SlicedLanczos.solve

    def spoiled(self):
        lam, Y = solve(self)
        Y = np.array(Y, order="F")
        Y[:, [10, 30, 50]] += 1e-7 * np.random.default_rng(1).standard_normal((len(Y), 3))
        return lam, Y

    monkeypatch.setattr(slicing.SlicedLanczos, "solve", spoiled)
    V, F = bumpy_sphere(4)  # 2562 vertices: the sparse solver
    K, m = S.spectral_operators(V, F)
    lam, U, info = S.pencil_eigenpairs(K, m, 64, method="sparse")
    assert any("refined" in msg for msg in info.messages), info.messages
    r = _relative_residuals(K, m, lam, U)
    assert r.max() <= PROMISED_RESIDUAL and info.max_residual <= PROMISED_RESIDUAL
    np.testing.assert_allclose(lam, _dense_reference(V, F, 64), rtol=1e-9, atol=1e-12)
    assert _orth(U, m) < 1e-10

    # the refinement switched off: the spoiled result is refused
    def no_refinement(K, m, lam, U, labels, res, **kw):
        return lam, U, res, Refinement(0, 0)

    monkeypatch.setattr(eigsolve, "refine_pairs", no_refinement)
    with pytest.raises(MeshError, match="after refinement"):
        S.pencil_eigenpairs(K, m, 64, method="sparse")


def test_refinement_removes_high_frequency_round_off_from_a_pair():
    """Hand-made: exact pairs (LAPACK) with 1e-6 of the highest mode added to three of them
    (residual ~1e-6·λ_max/λ_ref): :func:`refine_pairs` brings them back to the exact pairs
    and leaves the clean ones as they were."""
    from meshlap_core.linalg.checks import pair_residuals
    from meshlap_core.linalg.refine import PROMISED_RESIDUAL, refine_pairs

    V, F = bumpy_sphere(2)
    K, m = S.spectral_operators(V, F)
    with threadpool_limits(1):
        lam_all, U_all = scipy.linalg.eigh(K.toarray(), np.diag(m))
    lam, U = lam_all[:20].copy(), U_all[:, :20].copy()
    lam[0] = 0.0
    U[:, 0] = 1.0 / np.sqrt(m.sum())
    dirty = U.copy()
    dirty[:, [3, 7, 12]] += 1e-6 * U_all[:, [-1]]
    dirty[:, [3, 7, 12]] /= np.sqrt(np.sum(m[:, None] * dirty[:, [3, 7, 12]] ** 2, axis=0))
    labels = np.zeros(len(m), dtype=np.int64)
    res = pair_residuals(K, m, lam, dirty, labels)
    assert np.flatnonzero(res > PROMISED_RESIDUAL).tolist() == [3, 7, 12]
    lam2, U2, res2, done = refine_pairs(K, m, lam, dirty, labels, res)
    assert done.pairs == 3 and res2.max() <= PROMISED_RESIDUAL
    np.testing.assert_allclose(res2, _relative_residuals(K, m, lam2, U2), rtol=1e-6, atol=1e-15)
    np.testing.assert_allclose(lam2, lam_all[:20], rtol=1e-10, atol=1e-12)
    overlap = np.abs(np.sum(m[:, None] * U2 * U, axis=0))  # each column still its own mode
    np.testing.assert_allclose(overlap[[3, 7, 12]], 1.0, atol=1e-8)
    np.testing.assert_allclose(U2[:, 5], U[:, 5], atol=1e-10)  # (a clean pair stays)
    assert _orth(U2, m) < 1e-12


def _same_two_spheres(small: float, big: float):
    """Two icospheres of 162 vertices, radii ``small`` and ``big``."""
    V, F = icosphere(2)
    return np.vstack([V * small, V * big + [3.0 * big, 0.0, 0.0]]), np.vstack([F, F + len(V)])


@pytest.mark.parametrize("method", ["dense", "sparse"])
def test_a_badly_scaled_pencil_solved_in_one_piece_is_refused(monkeypatch, method):
    """Without the per-scale groups the solvers lose the big sphere's eigenvalues (dense
    ``eigh``: pairs that are accurate but not the smallest; Lanczos: inertia counts that do
    not match): the checks refuse the result instead of returning it."""
    from meshlap_core.linalg import eigsolve

    monkeypatch.setattr(eigsolve, "scale_groups", lambda s, gap=0: [np.arange(len(s))])
    V, F = _same_two_spheres(1e-6, 1e6)
    with pytest.raises(MeshError, match="badly conditioned"):
        S.laplacian_eigenpairs(V, F, 20, method=method)


def test_spectral_command_on_two_scales_is_right_or_refused(capsys, tmp_path, monkeypatch):
    from meshlap_core.io import save_mesh
    from meshlap_core.linalg import eigsolve

    V, F, _, alone_big = _two_spheres(1e-12, 1.0)
    path = tmp_path / "two.obj"
    save_mesh(path, V, F)
    code = main(["spectral", str(path), "--k", "50", "--json", "--no-cache"])
    out, err = capsys.readouterr()
    assert code == 0, err
    r = json.loads(out)
    lam_b, _, _ = S.laplacian_eigenpairs(*alone_big, 42, method="dense")
    np.testing.assert_allclose(r["eigenvalues"][2:43], lam_b[1:], rtol=1e-8)
    assert r["max_residual"] <= 1e-8 and any("very different scale" in x for x in r["messages"])
    # the same solve without the groups: one error line naming the file, exit 2
    monkeypatch.setattr(eigsolve, "scale_groups", lambda s, gap=0: [np.arange(len(s))])
    path = tmp_path / "same.obj"
    save_mesh(path, *_same_two_spheres(1e-12, 1.0))
    code = main(["spectral", str(path), "--k", "20", "--no-cache"])
    out, err = capsys.readouterr()
    assert code == 2 and out == "" and err.count("\n") == 1
    assert err.startswith(f"meshlap: error: {path}: ") and "badly conditioned" in err


# ------------------------------------------------------------------ the cache is verified in full


def _tamper(path, change):
    with np.load(path, allow_pickle=False) as data:
        arrays = {key: data[key] for key in data.files}
    change(arrays)
    with open(path, "wb") as f:
        np.savez(f, **arrays)


def _shift_last(a):
    a["eigenvalues"] = a["eigenvalues"].copy()
    a["eigenvalues"][-1] *= 1.2  # (still ascending; not one of the sampled columns' checks)


def _swap_vector(a):
    U = a["vectors"].copy()
    U[:, 11] = U[:, 12]  # an unsampled column replaced by its neighbour (same λ: l = 3)
    a["vectors"] = U


def _drop_pair(a):
    keep = np.r_[0:5, 6 : len(a["eigenvalues"])]  # pair 5 lost: the rest are genuine
    a["eigenvalues"] = a["eigenvalues"][keep]
    a["vectors"] = np.asfortranarray(a["vectors"][:, keep])


@pytest.mark.parametrize(
    "change, words",
    [(_shift_last, "not eigenpairs"), (_swap_vector, "orthonormal"), (_drop_pair, "inertia")],
    ids=["eigenvalue+20%", "vector", "missing-pair"],
)
def test_an_altered_cache_file_is_refused_and_recomputed(tmp_path, change, words):
    """A cache file whose key and format are right but whose numbers were altered (where the
    old sampled checks did not look) is verified in full, ignored, said so and recomputed."""
    V, F = icosphere(3)
    good = S.SpectralBasis.compute(V, F, 41, cache_dir=tmp_path)
    path = good.info.cache_path
    _tamper(path, change)
    again = S.SpectralBasis.compute(V, F, 40, cache_dir=tmp_path)
    assert not again.info.from_cache
    notes = [x for x in again.info.messages if x.startswith("ignored cache file")]
    assert len(notes) == 1 and words in notes[0], again.info.messages
    np.testing.assert_allclose(again.eigenvalues, good.eigenvalues[:40], rtol=1e-9, atol=1e-12)
    # the rewritten file is trusted again
    third = S.SpectralBasis.compute(V, F, 40, cache_dir=tmp_path)
    assert third.info.from_cache
    np.testing.assert_array_equal(third.eigenvalues, again.eigenvalues)


def test_spectral_command_says_when_it_ignores_an_altered_cache(capsys, tmp_path, monkeypatch):
    from meshlap_core.io import save_mesh

    monkeypatch.setenv("MESHLAP_CACHE_DIR", str(tmp_path / "c"))
    V, F = icosphere(3)
    path = tmp_path / "s.obj"
    save_mesh(path, V, F)
    assert main(["spectral", str(path), "--k", "20", "--json"]) == 0
    first = json.loads(capsys.readouterr().out)
    _tamper(first["cache_file"], _shift_last)
    assert main(["spectral", str(path), "--k", "20", "--json"]) == 0
    out, err = capsys.readouterr()
    r = json.loads(out)
    assert r["from_cache"] is False and r["eigenvalues"] == pytest.approx(first["eigenvalues"])
    assert "ignored cache file" in err and "not eigenpairs" in err
