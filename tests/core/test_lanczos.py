"""Tests of the eigensolver's building blocks in meshlap_core.linalg.

The pieces: block Lanczos with delayed classical Gram–Schmidt (DCGS2), Cholesky QR, the QDLDL
``LDLᵀ`` with its inertia (and the SuperLU fallback), the Löwdin orthonormalization (on two
cores), and the slice plan for two workers. Each is checked against an independent reference:
exact eigenvalues of a diagonal operator, dense LAPACK (``eigvalsh``, ``qr``, ``svd``),
Sylvester's law of inertia counted from dense eigenvalues.
"""

from __future__ import annotations

import concurrent.futures as cf

import numpy as np
import pytest
import scipy.sparse as sp

from meshlap_core import spectral as S
from meshlap_core.linalg import factor
from meshlap_core.linalg.blas import gemm_update, right_solve
from meshlap_core.linalg.eigsolve import lowdin
from meshlap_core.linalg.factor import QDLDLFactor, ShiftInvert, SuperLUFactor, qdldl_inertia
from meshlap_core.linalg.lanczos import BlockLanczos, chol_qr
from meshlap_core.primitives import bumpy_sphere, icosphere


def _diag_lanczos(theta, *, delayed, X=None, steps, block=4, seed=0):
    """Block Lanczos on the diagonal operator ``diag(theta)``."""
    n = len(theta)

    def op(Y, out):
        out[...] = theta[:, None] * Y

    rng = np.random.default_rng(seed)
    lz = BlockLanczos(op, n, block, X, rng, capacity=steps * block + 2 * block)
    lz.delayed = delayed
    for _ in range(steps):
        lz.step()
    return lz


# ------------------------------------------------------------------ block Lanczos, DCGS2


def test_delayed_gram_schmidt_keeps_the_basis_orthonormal_and_the_lanczos_relation():
    n, steps = 3000, 40
    theta = 1.0 / np.linspace(1.0, 50.0, n)  # shift-invert-like: a few large, many small
    lz = _diag_lanczos(theta, delayed=True, steps=0)
    start = lz.passes  # (the random first block is orthogonalized in full)
    for _ in range(steps):
        lz.step()
    j = lz.j
    Q = lz.Q[:, :j]
    assert np.abs(Q.T @ Q - np.eye(j)).max() < 1e-12
    # A Q_j = Q_j T_j + q̃ B Eᵀ: T's lower triangle (what the Ritz values use) is the
    # projection QᵀAQ
    T = np.tril(lz.T[:j, :j]) + np.tril(lz.T[:j, :j], -1).T
    np.testing.assert_allclose(T, Q.T @ (theta[:, None] * Q), atol=1e-12)
    assert lz.passes - start == steps  # one pass over the basis per block


def test_delayed_and_classical_gram_schmidt_give_the_same_ritz_values():
    n = 2000
    rng = np.random.default_rng(3)
    lam = np.sort(rng.uniform(0.5, 40.0, n))
    theta = 1.0 / (lam + 0.1)
    want = 12
    exact = np.sort(theta)[::-1][:want]
    vals = []
    for delayed in (True, False):
        lz = _diag_lanczos(theta, delayed=delayed, steps=30)
        th, _, res, _ = lz.ritz(want)
        assert np.all(res / np.abs(th) < 1e-8)
        vals.append(np.sort(th)[::-1])
    np.testing.assert_allclose(vals[0], exact, rtol=1e-12)
    np.testing.assert_allclose(vals[1], exact, rtol=1e-12)


def test_invariant_subspace_breakdown_continues_with_orthonormal_random_blocks():
    # three distinct eigenvalues: the Krylov space is exhausted after one block of 4
    theta = np.repeat([3.0, 2.0, 1.0], [100, 200, 200])
    lz = _diag_lanczos(theta, delayed=True, steps=6)
    Q = lz.Q[:, : lz.j]
    assert np.abs(Q.T @ Q - np.eye(lz.j)).max() < 1e-12
    th, _, _, _ = lz.ritz(lz.j)
    # every Ritz value is one of the three eigenvalues (to round-off)
    assert np.abs(th[:, None] - np.array([3.0, 2.0, 1.0])[None, :]).min(axis=1).max() < 1e-10


def test_deflated_vectors_stay_out_of_the_basis():
    n = 1000
    theta = 1.0 / np.linspace(1.0, 20.0, n)
    X = np.zeros((n, 2))
    X[0, 0] = X[1, 1] = 1.0  # the two largest eigenvectors of diag(theta)
    lz = _diag_lanczos(theta, delayed=True, X=X, steps=40)
    Q = lz.Q[:, : lz.j]
    assert np.abs(X.T @ Q).max() < 1e-13
    th, _, res, _ = lz.ritz(1)
    assert res[0] < 1e-8
    assert th[0] == pytest.approx(theta[2], rel=1e-12)  # the largest one not deflated


# ------------------------------------------------------------------ small dense kernels


def test_cholesky_qr_orthonormalizes_and_refuses_ill_conditioned_blocks():
    rng = np.random.default_rng(1)
    W = np.asfortranarray(rng.standard_normal((5000, 4)))
    W0 = W.copy()
    R = chol_qr(W, 2, 1e-4)
    assert R is not None and np.allclose(R, np.triu(R))
    np.testing.assert_allclose(W.T @ W, np.eye(4), atol=1e-14)
    np.testing.assert_allclose(W @ R, W0, atol=1e-12)
    # the same R as Householder QR (up to the signs of its rows)
    _, Rh = np.linalg.qr(W0)
    np.testing.assert_allclose(np.abs(R), np.abs(Rh), rtol=1e-10)
    bad = np.asfortranarray(W0.copy())
    bad[:, 3] = bad[:, 0] + 1e-9 * bad[:, 1]  # nearly dependent: Cholesky QR would be wrong
    keep = bad.copy()
    assert chol_qr(bad, 2, 1e-4) is None
    np.testing.assert_array_equal(bad, keep)  # untouched when refused


def test_gemm_update_and_right_solve_in_place():
    rng = np.random.default_rng(2)
    C = np.asfortranarray(rng.standard_normal((300, 4)))
    A = np.asfortranarray(rng.standard_normal((300, 1)))  # inner dimension 1
    B = rng.standard_normal((1, 4))
    expect = C - A @ B
    gemm_update(C, A, B)
    np.testing.assert_allclose(C, expect, atol=1e-13)
    R = np.triu(rng.standard_normal((4, 4))) + 4 * np.eye(4)
    expect = C @ np.linalg.inv(R)
    right_solve(C, R)
    np.testing.assert_allclose(C, expect, atol=1e-12)


@pytest.mark.parametrize("perturbation", [1e-9, 1e-3])
@pytest.mark.parametrize("threads", [1, 2])
def test_lowdin_orthonormalizes_with_the_smallest_change(perturbation, threads):
    # small perturbations take the series G^-1/2 = I − E/2 + 3E²/8, large ones eigh
    rng = np.random.default_rng(5)
    Q, _ = np.linalg.qr(rng.standard_normal((9000, 70)))
    Y = np.asfortranarray(Q + perturbation * rng.standard_normal(Q.shape))
    Y0 = Y.copy()
    helper = cf.ThreadPoolExecutor(max_workers=1) if threads == 2 else None
    try:
        err = lowdin(Y, helper)
    finally:
        if helper is not None:
            helper.shutdown()
    assert err == pytest.approx(np.abs(Y0.T @ Y0 - np.eye(70)).max())
    assert np.abs(Y.T @ Y - np.eye(70)).max() < 1e-13
    # Löwdin is Y0 (Y0ᵀY0)^-1/2, the orthonormal matrix closest to Y0 (polar factor)
    Uo, _, Vt = np.linalg.svd(Y0, full_matrices=False)
    np.testing.assert_allclose(Y, Uo @ Vt, atol=1e-12)


# ------------------------------------------------------------------ LDLᵀ and inertia


def _indefinite(n=400, seed=6):
    rng = np.random.default_rng(seed)
    A = sp.random(n, n, density=0.01, random_state=seed)
    A = (A + A.T + sp.diags(rng.uniform(-3.0, 5.0, n))).tocsr()
    return A


def test_qdldl_inertia_counts_the_negative_eigenvalues_and_solves():
    A = _indefinite()
    rng = np.random.default_rng(0)
    ldl, neg = qdldl_inertia(A, rng)
    assert neg == np.count_nonzero(np.linalg.eigvalsh(A.toarray()) < 0)
    b = rng.standard_normal((A.shape[0], 3))
    np.testing.assert_allclose(A @ ldl.solve(b), b, atol=1e-9)


def test_shift_invert_falls_back_to_superlu_without_qdldl(monkeypatch):
    monkeypatch.setenv("MESHLAP_SOLVER", "fallback")  # (QDLDL, not CHOLMOD, first)
    A = _indefinite()
    rng = np.random.default_rng(0)
    op_q = ShiftInvert(A, 0.25, rng=rng, spacing=1.0)

    def unavailable(*args):
        raise ImportError("no qdldl")

    monkeypatch.setattr(factor, "qdldl_inertia", unavailable)
    op_s = ShiftInvert(A, 0.25, rng=rng, spacing=1.0)
    assert isinstance(op_q.factor, QDLDLFactor) and isinstance(op_s.factor, SuperLUFactor)
    assert (
        op_q.n_below
        == op_s.n_below
        == np.count_nonzero(np.linalg.eigvalsh(A.toarray()) < op_q.sigma)
    )
    Y = np.asfortranarray(rng.standard_normal((A.shape[0], 4)))
    out_q, out_s = np.empty_like(Y), np.empty_like(Y)
    op_q(Y, out_q)
    op_s(Y, out_s)
    np.testing.assert_allclose(out_q, out_s, rtol=1e-8, atol=1e-10)


def test_a_shift_on_an_eigenvalue_is_moved_not_factored():
    # A − σI exactly singular at σ = 2: QDLDL hits a zero pivot and the shift moves
    A = sp.diags([1.0, 2.0, 3.0, 4.0]).tocsr()
    op = ShiftInvert(A, 2.0, rng=np.random.default_rng(0), spacing=1.0)
    assert op.sigma != 2.0 and abs(op.sigma - 2.0) < 0.1
    assert op.n_below == (1 if op.sigma > 2.0 else 0) + 1


# ------------------------------------------------------------------ the slice plan


def test_two_workers_get_an_even_number_of_equal_slices():
    V, F = bumpy_sphere(3)  # (no exact multiplicities: no repair slice)
    lam, _, info = S.laplacian_eigenpairs(V, F, 200, method="sparse", slice_size=40, workers=2)
    n_slices = len(info.krylov_dims)
    assert n_slices >= 4 and n_slices % 2 == 0, info.messages
    K, m = S.spectral_operators(V, F)
    ref = np.linalg.eigvalsh(K.toarray() / np.sqrt(m)[:, None] / np.sqrt(m)[None, :])[:200]
    np.testing.assert_allclose(lam, ref, rtol=1e-9, atol=1e-9 * ref.max())


@pytest.mark.parametrize("slow", ["first slice", "planning"])
def test_the_two_worker_plan_does_not_depend_on_which_thread_is_faster(monkeypatch, slow):
    """With two workers the second slice is planned while the first factors. Its plan (and
    so every shift and eigenpair) must not depend on whether that factorization is done:
    a busy machine that slows one thread or the other gives the same slices. Here the first
    slice is held back 0.3 s before it factors, or the planner before it plans slice 1;
    the shifts are those of an undisturbed run (they differed: 4 or 5 slices for this case,
    by the race)."""
    import time

    from meshlap_core.linalg import slicing

    V, F = icosphere(3)
    kw = {"method": "sparse", "slice_size": 30, "first_slice": 30, "workers": 2}
    _, _, calm = S.laplacian_eigenpairs(V, F, 150, **kw)
    if slow == "first slice":
        run = slicing.run_slice

        def held(ctx, spec, seed):
            if spec.index == 0:
                time.sleep(0.3)
            return run(ctx, spec, seed)

        monkeypatch.setattr(slicing, "run_slice", held)
    else:
        plan = slicing.SlicedLanczos.plan

        def late(self, i, *args):
            if i == 1:
                time.sleep(0.3)
            return plan(self, i, *args)

        monkeypatch.setattr(slicing.SlicedLanczos, "plan", late)
    lam, _, info = S.laplacian_eigenpairs(V, F, 150, **kw)
    assert sorted(info.shifts) == sorted(calm.shifts)  # (listed as the slices end)
    K, m = S.spectral_operators(V, F)
    ref = np.linalg.eigvalsh(K.toarray() / np.sqrt(m)[:, None] / np.sqrt(m)[None, :])[:150]
    np.testing.assert_allclose(lam, ref, rtol=1e-9, atol=1e-9 * ref.max())


def test_qdldl_refactors_a_spare_factorization_of_the_same_pattern():
    A = _indefinite()
    eye = sp.identity(A.shape[0], format="csr")
    rng = np.random.default_rng(0)
    first, _ = qdldl_inertia((A - 0.5 * eye).tocsr(), rng)
    again, neg = qdldl_inertia((A - 1.5 * eye).tocsr(), rng, reuse=first)
    assert again.solver is first.solver  # refactored in place
    assert neg == np.count_nonzero(np.linalg.eigvalsh(A.toarray()) < 1.5)
    b = rng.standard_normal(A.shape[0])
    np.testing.assert_allclose((A - 1.5 * eye) @ again.solve(b), b, atol=1e-9)
    # another pattern (one off-diagonal pair fewer): a fresh factorization
    B = A.tolil()
    i, j = B.nonzero()
    off = np.flatnonzero(i != j)[0]
    B[i[off], j[off]] = B[j[off], i[off]] = 0.0
    B = B.tocsr()
    B.eliminate_zeros()
    other, neg_b = qdldl_inertia(B, rng, reuse=again)
    assert other.solver is not again.solver
    assert neg_b == np.count_nonzero(np.linalg.eigvalsh(B.toarray()) < 0)


def test_scaled_pencil_equals_the_two_diagonal_products():
    from meshlap_core.linalg.slice_worker import scaled_pencil

    rng = np.random.default_rng(3)
    K = sp.random(60, 60, density=0.15, random_state=3, format="csr")
    K = (K + K.T).tocsr()
    s = rng.uniform(0.5, 2.0, 60)
    ref = (sp.diags(s) @ K @ sp.diags(s)).toarray()
    A = scaled_pencil(K, s)
    np.testing.assert_allclose(A.toarray(), ref, rtol=1e-15, atol=0)
    assert A.nnz == K.nnz and np.array_equal(A.indices, K.indices)
    np.testing.assert_allclose(A.toarray(), A.toarray().T)  # symmetric stays symmetric


def test_cholmod_analysis_is_done_once_per_pencil_across_threads(spd_backend, monkeypatch):
    """Two slice workers factor shifts of one pencil: CHOLMOD's symbolic analysis (the
    ordering) is computed once and copied by the other thread; every factor still counts
    the inertia right and the eigenvalues are the dense solver's."""
    if spd_backend != "cholmod":
        pytest.skip("CHOLMOD only")
    import sksparse.cholmod as cm

    calls = []
    real = cm.analyze

    def counting(*args, **kwargs):
        calls.append(1)
        return real(*args, **kwargs)

    monkeypatch.setattr(cm, "analyze", counting)
    V, F = bumpy_sphere(3)
    lam, _, info = S.laplacian_eigenpairs(
        V, F, 90, method="sparse", slice_size=24, first_slice=24, workers=2
    )
    assert len(calls) == 1 and len(info.shifts) >= 2 and info.n_factorizations >= 3
    K, m = S.spectral_operators(V, F)
    d = 1 / np.sqrt(m)
    ref = np.linalg.eigvalsh((K.toarray() * d[:, None]) * d[None, :])[:90]
    np.testing.assert_allclose(lam, ref, rtol=1e-9, atol=1e-9 * ref.max())
    # and with a shared ordering, a shift of the same pattern counts its negative eigenvalues
    A = S.spectral_operators(V, F)[0].multiply(d[:, None]).multiply(d[None, :]).tocsr()
    ordering = factor.SymbolicOrdering(A.shape[0])
    eye = sp.identity(A.shape[0], format="csr")
    rng = np.random.default_rng(1)
    first, _ = factor.cholmod_inertia((A - 5.0 * eye).tocsr(), rng, None, ordering)
    second, neg = factor.cholmod_inertia((A - 40.0 * eye).tocsr(), rng, None, ordering)
    assert second.factor is not first.factor and len(calls) == 2
    assert neg == np.count_nonzero(ref < 40.0) + np.count_nonzero(
        np.linalg.eigvalsh(A.toarray())[90:] < 40.0
    )


def test_ritz_vectors_written_into_the_callers_store_equal_q_times_s():
    """``BlockLanczos.vectors(S, out)`` writes ``Q S`` into the leading columns of ``out``
    (the store of found pairs) and returns that view; ``FoundPairs.add`` of that view keeps
    it without a copy, and of any other array copies it."""
    from meshlap_core.linalg.slicing import FoundPairs

    theta = np.linspace(1.0, 2.0, 60)
    lz = _diag_lanczos(theta, delayed=True, steps=5)
    S_ = np.random.default_rng(1).standard_normal((lz.j, 7))
    ref = lz.Q[:, : lz.j] @ S_
    found = FoundPairs(60, 20)
    found.add(np.zeros(2), np.eye(60)[:, :2])
    Y = lz.vectors(S_, found.free())
    assert np.shares_memory(Y, found.Y) and Y.shape == (60, 7)
    assert np.allclose(Y, ref, atol=1e-13)
    found.add(np.arange(1.0, 8.0), Y)
    assert found.count == 9
    assert np.allclose(found.Y[:, 2:9], ref, atol=1e-13)
    assert np.array_equal(found.Y[:, :2], np.eye(60)[:, :2])
    other = np.asfortranarray(ref[:, :3] + 1.0)
    found.add(np.ones(3), other)
    assert np.array_equal(found.Y[:, 9:12], other) and not np.shares_memory(other, found.Y)
    # a store without room: a new array
    small = np.empty((60, 3), order="F")
    Y2 = lz.vectors(S_, small)
    assert not np.shares_memory(Y2, small) and np.allclose(Y2, ref, atol=1e-13)


@pytest.mark.parametrize("chunk", [None, 1, 3, 64])
def test_pair_residuals_equal_the_dense_formula_for_any_chunk(chunk):
    """``||K u − λ M u||_{M⁻¹} / max(λ, λ_ref)`` column by column with dense algebra, for
    every chunking of the columns (one component: ``λ_ref = tr(K)/(n·tr(M))``)."""
    from meshlap_core.linalg.checks import pair_residuals

    rng = np.random.default_rng(3)
    n, kk = 40, 7
    Bm = sp.random(n, n, density=0.2, random_state=4)
    L = sp.diags(np.asarray(abs(Bm + Bm.T).sum(axis=1)).ravel()) - abs(Bm + Bm.T)
    K = sp.csr_matrix(L + sp.diags(np.ones(n)))  # connected or not: labels say one component
    m = rng.uniform(0.5, 2.0, n)
    U = np.asfortranarray(rng.standard_normal((n, kk)))
    lam = rng.uniform(0.0, 5.0, kk)
    Kd = K.toarray()
    ref_scale = np.trace(Kd) / (n * m.sum())
    want = [
        np.sqrt(np.sum((Kd @ U[:, j] - lam[j] * m * U[:, j]) ** 2 / m)) / max(lam[j], ref_scale)
        for j in range(kk)
    ]
    got = pair_residuals(K, m, lam, U, None, chunk)
    assert np.allclose(got, want, rtol=1e-12, atol=0)
