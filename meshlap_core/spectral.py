"""Spectral mesh processing: the Laplace–Beltrami eigenbasis, reconstruction from k modes, caching.

Sign convention: the Laplacians of this project are negative semidefinite (``Δx = −2Hn``,
:mod:`meshlap_core.laplacian`). The eigenproblem solved here is the generalized symmetric one

    K u = λ M u,      K = −C  (symmetric positive semidefinite),  M = diag(m) > 0,

whose eigenvalues ``0 = λ₀ ≤ λ₁ ≤ …`` are the non-negative frequencies of ``−Δ = −M⁻¹C``. ``C``
is the cotangent stiffness (libigl ``cotmatrix``) and ``M`` the lumped Voronoi (default) or
barycentric mass; with ``laplacian="uniform"`` it is the combinatorial graph Laplacian
``K = D − A`` (the symmetric form ``−D·L`` of the uniform Laplacian ``L = D⁻¹A − I``) with the
identity as mass. Eigenvectors are ``M``-orthonormal (``UᵀMU = I``) and the spectral
reconstruction of a per-vertex field ``X`` from the first ``k`` modes is the ``M``-orthogonal
projection ``U_k U_kᵀ M X`` (projecting with ``U_kᵀ X`` instead is the classic bug: it is not a
projection unless ``M = I``, and the error stops decreasing with ``k``).

Open meshes get natural (Neumann) boundary conditions (nothing to do: ``C`` assembled from the
faces is the Neumann stiffness), and every connected component contributes one zero eigenvalue
whose eigenvector is the normalized indicator of the component (deflated exactly).

The eigensolver (:func:`pencil_eigenpairs`, :func:`laplacian_eigenpairs`) is shift-invert block
Lanczos with spectrum slicing, on the symmetric scaled pencil ``A = M^-½ K M^-½``:

* ``[0, λ_k]`` is cut into consecutive intervals holding ~64 eigenvalues each (~128 for the
  lowest with one worker; equal slices, an even number of them, with two), planned with Weyl's
  law ``N(λ) ≈ area·λ/4π`` and then with the density that the inertia counts at the shifts
  measure (known as soon as a slice is factored); slices run in two threads when two cores
  are idle.
* Every interval gets a shift in its middle and an ``LDLᵀ`` factor without pivoting (QDLDL,
  AMD ordering; SuperLU in symmetric mode as fallback). The lowest interval too: the null
  space (one indicator per component) is deflated exactly, so nothing below 0 needs resolving,
  and a middle shift converges it in ~30 % fewer steps than a shift below the spectrum. A
  singular matrix is never factored: a shift that lands on an eigenvalue is moved.
* Block Lanczos (block 4) with delayed classical Gram–Schmidt against the slice's own basis
  (DCGS2: each block's second orthogonalization pass rides along with the next block's first,
  one pass over the basis per block), until every Ritz value in the interval has a relative
  residual below 1e-8 and the nearest ones outside are resolved. Orthogonalizing only within
  a slice is what makes large ``k`` cheap: ``O(n·k·s)`` memory-bound vector work instead of the
  ``O(n·k²)`` of a single Lanczos run (ARPACK's restarts), for slices of ``s`` eigenvalues.
* Sylvester's law of inertia checks the result: the signs of ``D`` at every shift, and at one
  more shift in a gap just above ``λ_k`` (factored by the top slice as soon as it is done),
  count the eigenvalues below it, which must equal the number found; a deficit is searched
  for again with the found vectors deflated. Slices are finally orthonormalized together
  (Löwdin: ``O(n·k²)`` products at BLAS-3 speed, on two cores when two workers ran).

Small meshes (or ``k`` close to ``n``) use a dense solver.

:class:`SpectralBasis` is computed once (and cached on disk, keyed by a hash of the mesh and the
options) and then answers reconstructions for any ``k`` quickly: the coefficients ``UᵀMX`` are
kept and ``reconstruct(k)`` moves incrementally from the previous ``k`` or from a stored
checkpoint, so a slider move costs ``O(n·|Δk|)``.

References
----------
Lévy, "Laplace-Beltrami eigenfunctions towards an algorithm that understands geometry", 2006.
Vallet & Lévy, "Spectral geometry processing with manifold harmonics", 2008 (band-by-band
shift-invert). Grimes, Lewis & Simon, "A shifted block Lanczos algorithm for solving sparse
symmetric generalized eigenproblems", 1994 (shifts, inertia, slicing).
"""

from __future__ import annotations

import hashlib
import json
import os
import threading
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Literal

import numpy as np
import scipy.linalg as sla
import scipy.sparse as sp
import scipy.sparse.linalg as spla
from scipy.linalg import blas, lapack
from scipy.sparse.csgraph import connected_components

from . import laplacian as _lap
from .errors import MeshError
from .linalg.blas import blas_threads as _blas_threads
from .linalg.blas import thread_controller as _thread_controller
from .options import AREA_KINDS, LAPLACIAN_KINDS, MASS_AREA, AreaKind, LaplacianKind
from .types import FloatArray, IntArray, as_mesh

MASS_KINDS = AREA_KINDS  # the lumped mass of the pencil is a vertex area

ProgressCallback = Callable[[float, str], None]
"""``progress(fraction, message)``: ``fraction`` in ``[0, 1]``; raise from it to cancel."""

CACHE_FORMAT = 1

# Dense solver below this many vertices (or when k is a large fraction of n).
_DENSE_MAX_N = 1500
# Sparse solver refuses k above this fraction of n on meshes too big for the dense solver.
_SPARSE_MAX_FRACTION = 0.5
_DENSE_HARD_MAX_N = 8000

# Lanczos parameters.
_BLOCK = 4  # block size (handles eigenvalue multiplicities up to 4 without relying on round-off)
_TOL = 1e-8  # relative residual of the shift-inverted Ritz pairs: ||Op y − θ y|| <= tol |θ|
_SLICE = 64  # eigenpairs per slice with an interior shift (LDLᵀ solves)
_FIRST_SLICE = 128  # eigenpairs in the lowest slice (one worker; one-sided: no neighbour below)
_ORTH_LEVEL = 1e-10  # orthogonality kept in the Lanczos basis
_CHECK_EVERY = 8  # convergence checks at least every j/_CHECK_EVERY Lanczos vectors
_LAMBDA_TOL = 1e-6  # relative residual ||K u − λ M u||_{M⁻¹} / λ of every pair
_EDGE_TOL = 1e-4  # residual of the nearest Ritz value outside a slice's interval
_SPLIT = 0.42  # share of the interior slice when two workers split <= _FIRST_SLICE pairs


# --------------------------------------------------------------------------------------------
# Operators
# --------------------------------------------------------------------------------------------


def _check_options(laplacian: str, mass: str) -> None:
    if laplacian not in LAPLACIAN_KINDS:
        raise MeshError(
            f"unknown Laplacian {laplacian!r}; choose one of {', '.join(LAPLACIAN_KINDS)}",
            "laplacian",
        )
    if mass not in MASS_KINDS:
        raise MeshError(f"unknown mass {mass!r}; choose one of {', '.join(MASS_KINDS)}", "mass")


def _options(laplacian: str, mass: str) -> dict[str, str]:
    """The options that define the eigenproblem (the uniform Laplacian always uses M = I)."""
    _check_options(laplacian, mass)
    return {"laplacian": laplacian, "mass": "identity" if laplacian == "uniform" else mass}


def spectral_operators(
    V: FloatArray,
    F: IntArray,
    laplacian: LaplacianKind = "cotan",
    mass: AreaKind = MASS_AREA,
) -> tuple[sp.csr_matrix, FloatArray]:
    """The pencil ``(K, m)`` of the eigenproblem ``K u = λ diag(m) u``.

    Parameters
    ----------
    V : (n,3) float
    F : (m,3) int
    laplacian : {"cotan", "uniform"}
        ``"cotan"``: ``K = −C`` with ``C`` the (negative semidefinite) cotangent stiffness.
        ``"uniform"``: ``K = D − A``, the graph Laplacian (``−D·L`` for the uniform Laplacian
        ``L = D⁻¹A − I``), with ``m = 1``.
    mass : {"voronoi", "barycentric"}
        Lumped vertex areas used as ``m`` for ``"cotan"`` (ignored for ``"uniform"``).

    Returns
    -------
    K : (n,n) scipy.sparse.csr_matrix
        Symmetric positive semidefinite, rows summing to 0.
    m : (n,) float
        Positive masses.

    Raises
    ------
    MeshError
        No faces, or a vertex with zero mass (unreferenced, or only in degenerate faces): the
        mass matrix would be singular. :func:`meshlap_core.io.load_mesh` removes unreferenced
        vertices.
    """
    _check_options(laplacian, mass)
    V, F = as_mesh(V, F)
    n = len(V)
    if n == 0 or len(F) == 0:
        raise MeshError("the mesh has no faces; spectral processing needs a surface", "F")
    if laplacian == "uniform":
        A = _lap.adjacency_matrix(F, n)
        deg = np.asarray(A.sum(axis=1)).ravel()
        K = (sp.diags(deg) - A).tocsr()
        m = np.ones(n)
    else:
        K = (-_lap.cotan_stiffness(V, F)).tocsr()
        m = _lap.vertex_areas(V, F, mass)
    bad = np.flatnonzero(~(m > 0))
    if len(bad):
        raise MeshError(
            f"vertex {int(bad[0])} (and {len(bad) - 1} more) has zero area: it is unreferenced "
            "or only in degenerate faces, so the mass matrix is singular; remove unreferenced "
            "vertices and degenerate faces first (meshlap's load_mesh does)",
            "V",
        )
    K.sum_duplicates()
    K.sort_indices()
    return K, m


def _components(K: sp.csr_matrix) -> tuple[int, IntArray]:
    """Connected components of the sparsity graph of ``K`` (= mesh components)."""
    ncomp, labels = connected_components(K, directed=False)
    return int(ncomp), labels.astype(np.int64)


def _null_space(m: FloatArray, labels: IntArray, ncomp: int) -> FloatArray:
    """``M``-orthonormal indicators of the components, ``(n, ncomp)``, F-ordered."""
    n = len(m)
    Z = np.zeros((n, ncomp), order="F")
    Z[np.arange(n), labels] = 1.0
    area = np.bincount(labels, weights=m, minlength=ncomp)
    Z /= np.sqrt(area)[None, :]
    return Z


# --------------------------------------------------------------------------------------------
# Shift-invert operators
# --------------------------------------------------------------------------------------------


class _Unstable(Exception):
    """An LDLᵀ factorization that cannot be trusted (zero or tiny pivot)."""


class _Ordering:
    """The fill-reducing symmetric ordering shared by every ``LDLᵀ`` of one pencil.

    All shifted matrices ``A − σI`` have the same pattern, and SuperLU's minimum degree
    ordering depends on the pattern only, so it is computed once (on a fixed random
    relabelling: on the very regular numbering of subdivided meshes MMD takes 20× longer)
    and later factorizations skip it. Thread-safe.
    """

    def __init__(self, n: int) -> None:
        self.n = n
        self.perm: IntArray | None = None
        self.lock = threading.Lock()


class _LDL:
    """SuperLU ``LDLᵀ`` of a symmetric matrix, with its inertia; see :func:`_ldl_inertia`."""

    def __init__(self, lu: Any, perm: IntArray) -> None:
        self.lu, self.perm = lu, perm

    def solve(self, B: FloatArray) -> FloatArray:
        Y = self.lu.solve(np.ascontiguousarray(B[self.perm]))
        X = np.empty_like(Y)
        X[self.perm] = Y
        return X


def _ldl_inertia(
    A: sp.csr_matrix, rng: np.random.Generator, ordering: _Ordering
) -> tuple[_LDL, int]:
    """SuperLU ``LDLᵀ`` of a symmetric matrix and the number of its negative eigenvalues.

    SuperLU in symmetric mode with ``diag_pivot_thresh=0`` permutes rows and columns alike
    and does not pivot, so ``PAPᵀ = L U`` with ``U = D Lᵀ`` and Sylvester's law of inertia
    gives ``#{λ(A) < 0} = #{U_ii < 0}``. A solve with a random right-hand side checks that no
    small pivot spoiled the factor.
    """
    n = A.shape[0]

    def factor(p: IntArray, spec: str) -> Any:
        try:
            return spla.splu(
                A[p][:, p].tocsc(),
                permc_spec=spec,
                diag_pivot_thresh=0.0,
                options={"SymmetricMode": True},
            )
        except RuntimeError as exc:  # exactly singular
            raise _Unstable(str(exc)) from None

    lu = None
    with ordering.lock:  # the first factorization orders; the others wait for its ordering
        perm = ordering.perm
        if perm is None:
            p0 = np.random.default_rng(12345).permutation(n)
            lu = factor(p0, "MMD_AT_PLUS_A")
            if not np.array_equal(lu.perm_r, lu.perm_c):
                raise _Unstable("SuperLU pivoted")
            ordering.perm = p0[np.argsort(lu.perm_c)]
            ldl = _LDL(lu, p0)  # lu.solve applies SuperLU's own permutation
    if lu is None:
        assert perm is not None
        lu = factor(perm, "NATURAL")
        if not (np.array_equal(lu.perm_r, lu.perm_c) and np.array_equal(lu.perm_c, np.arange(n))):
            raise _Unstable("SuperLU pivoted")
        ldl = _LDL(lu, perm)
    return ldl, _checked_inertia(A, ldl, lu.U.diagonal(), rng)


def _checked_inertia(A: sp.csr_matrix, ldl: Any, piv: FloatArray, rng: np.random.Generator) -> int:
    """The number of negative pivots of an ``LDLᵀ`` of ``A`` (its negative eigenvalues, by
    Sylvester's law of inertia), after checking the factor: no zero or non-finite pivot, and a
    solve with a random right-hand side accurate to ``1e-10`` (a tiny pivot spoils it).

    Raises
    ------
    _Unstable
    """
    piv = np.asarray(piv)
    if not np.all(np.isfinite(piv)) or np.any(piv == 0):
        raise _Unstable("zero pivot")
    b = rng.standard_normal(A.shape[0])
    x = ldl.solve(b)
    scale = abs(A).sum(axis=1).max() * np.abs(x).max() + np.abs(b).max()
    if not np.all(np.isfinite(x)) or np.abs(A @ x - b).max() > 1e-10 * scale:
        raise _Unstable("inaccurate solve")
    return int(np.count_nonzero(piv < 0))


class _QDLDL:
    """``LDLᵀ`` of a symmetric matrix by QDLDL (AMD ordering, no pivoting), with its inertia.

    QDLDL (the factorization of the OSQP solver) factors ``PAPᵀ = LDLᵀ`` with ``D`` diagonal
    and no pivoting, so Sylvester's law of inertia gives ``#{λ(A) < 0} = #{D_ii < 0}``. It
    computes its own AMD ordering, factors 2–4× faster than SuperLU's ``LU`` (which does the
    work twice: ``L`` and ``U = DLᵀ``) and its solves release the GIL.
    """

    def __init__(self, solver: Any, pattern: tuple[IntArray, IntArray]) -> None:
        self.solver = solver
        self.pattern = pattern  # (indptr, indices) of the factored upper triangle

    def solve(self, B: FloatArray) -> FloatArray:
        if B.ndim == 1:
            return np.asarray(self.solver.solve(np.ascontiguousarray(B)))
        X = np.empty(B.shape, order="F")
        for c in range(B.shape[1]):
            X[:, c] = self.solver.solve(np.ascontiguousarray(B[:, c]))
        return X


def _qdldl_inertia(
    A: sp.csr_matrix, rng: np.random.Generator, reuse: _QDLDL | None = None
) -> tuple[_QDLDL, int]:
    """QDLDL ``LDLᵀ`` of a symmetric matrix and the number of its negative eigenvalues; a
    solve with a random right-hand side checks that no small pivot spoiled the factor.

    ``reuse``: a factorization no longer needed of a matrix with the same pattern (another
    shift): refactored in place, skipping the AMD ordering and symbolic analysis (0.04 s
    instead of 0.1 s at 40k vertices).

    Raises
    ------
    ImportError
        ``qdldl`` is not installed (the caller falls back to SuperLU).
    _Unstable
        A zero, tiny or non-finite pivot.
    """
    import qdldl

    U = sp.triu(A, format="csc")
    pattern = (U.indptr, U.indices)
    try:
        if (
            reuse is not None
            and np.array_equal(reuse.pattern[0], U.indptr)
            and np.array_equal(reuse.pattern[1], U.indices)
        ):
            solver = reuse.solver
            solver.update(U, upper=True)
        else:
            solver = qdldl.Solver(U, upper=True)
        _, D, _ = solver.factors()
    except (ValueError, RuntimeError) as exc:  # zero pivot
        raise _Unstable(str(exc)) from None
    ldl = _QDLDL(solver, pattern)
    return ldl, _checked_inertia(A, ldl, D, rng)


class _ShiftInvert:
    """``Op(Y) = (A − σI)⁻¹ Y`` for the scaled pencil ``A = M^-½ K M^-½`` (symmetric, same
    eigenvalues ``λ`` as ``K u = λ M u`` with ``y = M^½ u``); ``Op`` has eigenvalues
    ``θ = 1/(λ − σ)``.

    ``LDLᵀ`` without pivoting (QDLDL, else SuperLU in symmetric mode) with its inertia:
    ``n_below`` is the number of eigenvalues ``λ < σ``. A shift that lands (numerically) on an
    eigenvalue (zero or tiny pivot, inaccurate solve) is moved by a small fraction of
    ``spacing``: a singular matrix is never used.
    """

    def __init__(
        self,
        A: sp.csr_matrix,
        sigma: float,
        *,
        rng: np.random.Generator,
        spacing: float,
        ordering: _Ordering | None = None,
        reuse: Any | None = None,
    ) -> None:
        n = A.shape[0]
        eye = sp.identity(n, format="csr")
        if ordering is None:
            ordering = _Ordering(n)
        for attempt in range(6):
            s = sigma + (0.0 if attempt == 0 else (-1) ** attempt * 1e-3 * attempt * spacing)
            S = (A - s * eye).tocsr()
            try:
                try:
                    r, reuse = (reuse if isinstance(reuse, _QDLDL) else None), None
                    self._lu, self.n_below = _qdldl_inertia(S, rng, r)
                except (ImportError, _Unstable):
                    self._lu, self.n_below = _ldl_inertia(S, rng, ordering)
                sigma = s
                break
            except _Unstable:
                continue
        else:
            raise RuntimeError(f"could not factor A - sigma I near sigma = {sigma:.6g}")
        self.sigma = float(sigma)

    def __call__(self, Y: FloatArray, out: FloatArray) -> None:
        out[...] = self._lu.solve(Y)


# --------------------------------------------------------------------------------------------
# Block Lanczos with full reorthogonalization
# --------------------------------------------------------------------------------------------


def _orthonormal_columns(X: FloatArray) -> FloatArray | None:
    """An orthonormal basis (F-ordered) of the span of ``X``; dependent columns dropped."""
    Qx, R, _ = sla.qr(X, mode="economic", pivoting=True, check_finite=False)
    dR = np.abs(np.diag(R))
    r = int(np.count_nonzero(dR > 1e-8 * max(dR.max(initial=0.0), 1e-300)))
    return np.asfortranarray(Qx[:, :r]) if r else None


def _gemm_update(C: FloatArray, A: FloatArray, B: FloatArray, alpha: float = -1.0) -> None:
    """``C += alpha·A B`` in place (``C`` F-ordered ``n × b``): BLAS ``dgemm`` directly, as
    numpy's matmul takes ~15× longer when the inner dimension is 1 and allocates a result."""
    r = blas.dgemm(alpha, A, B, 1.0, C, overwrite_c=True)
    if not np.shares_memory(r, C):  # pragma: no cover - C not F-contiguous
        C[...] = r


def _right_solve(W: FloatArray, R: FloatArray) -> None:
    """``W ← W R⁻¹`` in place, ``R`` upper triangular (``W`` F-ordered)."""
    r = blas.dtrsm(1.0, R, W, side=1, lower=0, overwrite_b=True)
    if not np.shares_memory(r, W):  # pragma: no cover - W not F-contiguous
        W[...] = r


def _chol_qr(
    W: FloatArray, passes: int, min_ratio: float, min_diag: float = 0.0
) -> FloatArray | None:
    """Cholesky QR in place: ``W ← W R⁻¹`` with ``R`` upper triangular, ``passes`` times (the
    second pass restores orthogonality to round-off; Yamamoto et al. 2015, "Roundoff error
    analysis of the CholeskyQR2 algorithm"); returns the accumulated ``R``. ``None`` (and
    ``W`` untouched) when ``R`` is singular, has a diagonal entry ``<= min_diag`` or its
    diagonal spreads more than ``1/min_ratio`` (too ill-conditioned for Cholesky QR: the
    caller uses Householder QR)."""
    b = W.shape[1]
    Rtot = np.eye(b)
    for p in range(passes):
        R, info = lapack.dpotrf(W.T @ W, lower=0, clean=1)
        dR = np.abs(np.diag(R))
        if (
            info != 0
            or not np.all(np.isfinite(dR))
            or dR.min() <= min_ratio * dR.max()
            or (p == 0 and dR.min() <= min_diag)
        ):
            if p:  # pragma: no cover - the first pass succeeded, so W is well conditioned
                raise RuntimeError("Cholesky QR: second pass failed")
            return None
        _right_solve(W, R)
        Rtot = R @ Rtot
    return Rtot


class _BlockLanczos:
    """Block Lanczos for a symmetric operator, full (CGS2) reorthogonalization, deflation.

    The basis ``Q`` (``n × j``, F-ordered so its leading columns are one BLAS operand) is kept
    orthonormal and orthogonal to the columns of ``X`` (already known eigenvectors). ``T`` is
    the projected block-tridiagonal matrix; Ritz pairs of largest ``|θ|`` are returned with
    the residual estimate ``||B_j S_{last block}||`` (Parlett, *The symmetric eigenvalue
    problem*, ch. 13).
    """

    delayed = True  # DCGS2 (see :meth:`step`); False: classical Gram–Schmidt, 1–2 passes

    def __init__(
        self,
        op: Callable[[FloatArray, FloatArray], None],
        n: int,
        block: int,
        X: FloatArray | None,
        rng: np.random.Generator,
        capacity: int,
    ) -> None:
        self.op = op
        self.n = n
        self.b = block
        self.X = None if X is None or X.shape[1] == 0 else _orthonormal_columns(X)
        self.rng = rng
        self.max_dim = n - (0 if self.X is None else self.X.shape[1])
        cap = max(2 * block, -(-capacity // block) * block) + block
        self.Q = np.empty((n, cap), order="F")
        self.T = np.zeros((cap, cap))
        self.j = 0  # columns of Q whose images are in T
        self.exhausted = False
        self.n_applied = 0
        self.passes = 0
        self.delta = 1e-15  # estimate of ||I − QᵀQ|| (bound, recalibrated by measurement)
        self._measured = 1e-15  # largest orthogonality error measured so far
        self._last_measure = 0
        self.B_last = np.zeros((block, block))
        self._work = (
            np.empty((n, 2 * block), order="F"),
            np.empty((n, 2 * block), order="F"),
            np.empty((n, block), order="F"),
        )
        self.Q[:, :block] = self._random_orthonormal(block, 0, None)

    def _project(self, W: FloatArray, ncols: int) -> tuple[FloatArray, FloatArray]:
        """Classical Gram–Schmidt against ``X`` and ``Q[:, :ncols]``; returns
        ``(W, Q_aᵀ W_original)``.

        A pass maps ``e = ||Qᵀw|| / ||w||`` to at most ``κ(δe + ε)`` with ``δ = ||I − QᵀQ||``
        and ``κ = ||w|| / ||w'||`` (``e = 1`` before the first pass). A second pass is
        made only when that estimate would exceed ``_ORTH_LEVEL`` (so the basis stays
        orthonormal to ~1e-10, far below the semi-orthogonality ``√ε`` that Lanczos needs);
        ``δ`` is re-measured every 16 blocks (:meth:`_measure`), as the bound is pessimistic.
        (Partial reorthogonalization, i.e. skipping the old blocks while their coefficients
        are tiny, was tried: with shift-invert the converged Ritz directions amplify them so
        fast that it still needed 1.9 passes over the basis per block instead of 2.)
        """
        W = np.asfortranarray(W)
        H = np.zeros((ncols, W.shape[1]))
        tmp = np.empty_like(W)
        norm0 = np.linalg.norm(W, axis=0)
        eps = 1e-15 * np.sqrt(ncols + 1.0)
        est = 1.0  # ||Qᵀw|| / ||w|| before the pass (at most 1)
        for _ in range(3):
            # (numpy's matmul releases the GIL, scipy.linalg.blas does not: slices in
            # worker threads would run one at a time)
            if self.X is not None:
                G = self.X.T @ W
                np.matmul(self.X, G, out=tmp)
                W -= tmp
            if ncols:
                Qa = self.Q[:, :ncols]
                G = Qa.T @ W
                np.matmul(Qa, G, out=tmp)
                W -= tmp
                H += G
            norm1 = np.linalg.norm(W, axis=0)
            kappa = min(float(np.max(norm0 / np.maximum(norm1, 1e-300))), 1e16)
            est = kappa * (self.delta * est + eps)
            self.passes += 1
            if est <= _ORTH_LEVEL:
                break
            norm0 = norm1
        self.delta = max(self.delta, est)
        return W, H

    def _random_orthonormal(self, count: int, ncols: int, extra: FloatArray | None) -> FloatArray:
        """``count`` random orthonormal columns orthogonal to ``X``, ``Q[:, :ncols]``, ``extra``."""
        W = np.asfortranarray(self.rng.standard_normal((self.n, count)))
        for _ in range(2):
            W, _ = self._project(W, ncols)
            if extra is not None and extra.shape[1]:
                W -= extra @ (extra.T @ W)
            W, _ = np.linalg.qr(W)
        return W

    def _grow(self) -> None:
        cap = self.Q.shape[1]
        new = cap + max(cap // 2, 4 * self.b) // self.b * self.b
        Q = np.empty((self.n, new), order="F")
        Q[:, :cap] = self.Q
        T = np.zeros((new, new))
        T[:cap, :cap] = self.T
        self.Q, self.T = Q, T

    def step(self) -> None:
        """Apply the operator to the newest block and extend the basis by one block.

        Delayed classical Gram–Schmidt (DCGS2; Świrydowicz, Langou, Ananthan, Yang & Thomas,
        "Low synchronization Gram–Schmidt and GMRES algorithms", 2020, adapted to block
        Lanczos): the newest block ``q̃`` was orthogonalized once when it was made. Its second
        pass is done now, in the same two passes over the basis that orthogonalize
        ``W = Op(q̃)``: one product ``Qᵀ[q̃ W]`` and one ``Q[c P']``, each with ``2b``
        columns. These tall-skinny products are memory bound, so ``2b`` columns cost about as
        much as ``b``: one pass per block instead of up to two. The correction of ``q̃`` to
        ``q = (q̃ − Qc) S⁻¹`` is carried into ``Op(q)`` through the Lanczos relation
        ``Op(Q) = Q T + q̃ R Eᵀ``, without applying the operator again.
        """
        if not self.delayed:
            self._step_classical()
            return
        b, j0, j1, W, size = self._apply_newest()
        Qt = self.Q[:, j0:j1]  # q̃: orthogonalized once (exact for the first block)
        if self.X is not None:  # deflated vectors: a pass now and one at the end
            _gemm_update(W, self.X, self.X.T @ W)
        if j0:
            # (preallocated F-ordered operands: a fresh or C-ordered n × 2b array doubles the
            # time of these products)
            Qa, Y = self.Q[:, :j0], self._work[0]
            Y[:, :b] = Qt
            Y[:, b:] = W
            C = Qa.T @ Y
            c, H1 = C[:, :b], C[:, b:]
            Rp = self.T[j0:j1, j0 - b : j0].copy()  # q̃ Rp = last step's once-orthogonalized W
            Rc = Rp @ c[j0 - b : j0]
            cRc = c @ Rc
            C[:, b:] -= cRc
            D = self._work[1]
            np.matmul(Qa, C, out=D)
            q = self._work[2]
            np.subtract(Qt, D[:, :b], out=q)
            # q̃ − Qc = q S: S is within round-off of I (q̃ was orthogonal to ~1e-8 or better;
            # the rank test in _finish_step sees to it), so one Cholesky QR pass is exact
            S = _chol_qr(q, 1, 0.5)
            if S is None:  # pragma: no cover - see the rank test in _finish_step
                raise RuntimeError("Lanczos: lost orthogonality")
            _gemm_update(W, Qt, Rc)
            W -= D[:, b:]
            _right_solve(W, S)
            V = W
            P = sla.solve_triangular(
                S, (H1 - self.T[:j0, :j0] @ c).T, trans="T", check_finite=False
            ).T  # (H1 holds H1 − cRc now)
            # the previous block's relation Op(q_prev) = Q T + q̃ Rp, rewritten with q
            self.T[:j0, j0 - b : j0] += c @ Rp
            self.T[j0:j1, j0 - b : j0] = S @ Rp
            self.T[:j0, j0:j1] = P
            self.Q[:, j0:j1] = q
        else:
            q, V = Qt, W
        g = q.T @ V
        _gemm_update(V, q, g)
        if self.X is not None:
            # (what the projections against Q cancelled can leave ε·‖W‖/‖V‖ along X; the
            # delayed pass of the next step covers Q only)
            _gemm_update(V, self.X, self.X.T @ V)
        self.T[j0:j1, j0:j1] = 0.5 * (g + g.T)
        self.passes += 1
        self._finish_step(V, size, j0, j1)

    def _apply_newest(self) -> tuple[int, int, int, FloatArray, float]:
        """``W = Op(newest block)``; returns ``(b, j0, j1, W, max column norm of W)`` with the
        newest block in ``Q[:, j0:j1]``."""
        b, j0 = self.b, self.j
        j1 = j0 + b
        if j1 + b > self.max_dim:
            self.exhausted = True
        W = np.empty((self.n, b), order="F")
        self.op(self.Q[:, j0:j1], W)
        self.n_applied += b
        return b, j0, j1, W, float(np.linalg.norm(W, axis=0).max(initial=0.0))

    def _step_classical(self) -> None:
        """:meth:`step` with classical Gram–Schmidt, a second pass when a bound asks for it."""
        _, j0, j1, W, size = self._apply_newest()
        W, H = self._project(W, j1)
        self.T[:j1, j0:j1] = H
        self._finish_step(W, size, j0, j1)

    def _finish_step(self, W: FloatArray, size: float, j0: int, j1: int) -> None:
        """Normalize the orthogonalized block ``W`` (QR; breakdown: continue at random)."""
        b = self.b
        if j1 + b > self.Q.shape[1]:
            self._grow()
        B = np.zeros((b, b))
        if self.exhausted:
            Qn = np.zeros((self.n, b))
        elif (R := _chol_qr(W, 2, 1e-4, 1e-8 * size)) is not None:
            Qn, B = W, R  # (well conditioned, no breakdown: Cholesky QR2 is 4× faster)
        else:
            Qn, R, piv = sla.qr(W, mode="economic", pivoting=True, check_finite=False)
            B[:, piv] = R
            dR = np.abs(np.diag(R))
            # what is left after removing > 1 - 1e-8 of the norm is mostly round-off: treat
            # it as a breakdown (an invariant subspace was found) and continue at random
            rank = int(np.count_nonzero(dR > 1e-8 * max(size, 1e-300)))
            if rank < b:  # (partial) breakdown: an invariant subspace was found
                B[rank:, :] = 0.0
                Qn[:, rank:] = self._random_orthonormal(b - rank, j1, Qn[:, :rank])
        self.Q[:, j1 : j1 + b] = Qn
        self.T[j1 : j1 + b, j0:j1] = B
        self.B_last = B
        self.j = j1
        if not self.delayed and j1 + b - self._last_measure >= 16 * b:
            # (recalibrates the bound that decides classical second passes; DCGS2 always
            # makes its one delayed pass and needs no bound)
            self._measure(j1 + b)

    def _measure(self, ncols: int) -> None:
        """Measure the orthogonality of the blocks added since the last measurement; the
        bound of :meth:`_project` restarts from it (the bound compounds pessimistically)."""
        c0 = self._last_measure
        G = self.Q[:, :ncols].T @ self.Q[:, c0:ncols]
        G[np.arange(c0, ncols), np.arange(ncols - c0)] -= 1.0
        err = float(np.abs(G).max(initial=0.0))
        if self.X is not None:
            err = max(err, float(np.abs(self.X.T @ self.Q[:, c0:ncols]).max(initial=0.0)))
        self._measured = max(self._measured, err)
        self.delta = self._measured
        self._last_measure = ncols

    def ritz(self, want: int) -> tuple[FloatArray, FloatArray, FloatArray, FloatArray]:
        """The ``want`` Ritz values of largest ``|θ|``, their ``T``-eigenvectors, residuals
        ``||Op y − θ y||`` and the coefficients ``C`` (``b × want``) of those residuals on the
        next block: ``Op y − θ y = q̃ C``."""
        j = self.j
        th, S = sla.eigh(self.T[:j, :j], lower=True, check_finite=False)
        order = np.argsort(-np.abs(th), kind="stable")[:want]
        th, S = th[order], S[:, order]
        C = self.B_last @ S[j - self.b : j, :]
        if self.exhausted:
            C[:] = 0.0
        return th, S, np.linalg.norm(C, axis=0), C

    def vectors(self, S: FloatArray) -> FloatArray:
        """Ritz vectors ``Q S`` (``n × S.shape[1]``, F-ordered)."""
        out = np.empty((self.n, S.shape[1]), order="F")
        np.matmul(self.Q[:, : self.j], np.ascontiguousarray(S), out=out)
        return out


# --------------------------------------------------------------------------------------------
# The eigensolver
# --------------------------------------------------------------------------------------------


@dataclass
class SolveInfo:
    """How an eigenbasis was computed (for reports and the benchmark)."""

    method: str = ""
    n_vertices: int = 0
    k: int = 0
    n_components: int = 0
    shifts: list[float] = field(default_factory=list)
    krylov_dims: list[int] = field(default_factory=list)
    n_operator_applications: int = 0
    n_factorizations: int = 0
    n_clipped: int = 0
    min_raw_eigenvalue: float = 0.0
    max_residual: float = float("nan")
    orthogonality_error: float = float("nan")  # max|UᵀMU − I| of the result (sampled rows)
    timings: dict[str, float] = field(default_factory=dict)
    from_cache: bool = False
    cache_path: str | None = None
    messages: list[str] = field(default_factory=list)


class _Found:
    """Accumulates eigenpairs (``y = M^½ u`` coordinates) in a growing F-ordered store."""

    def __init__(self, n: int, capacity: int) -> None:
        self.n = n
        self.Y = np.empty((n, max(capacity, 1)), order="F")
        self.lam = np.empty(0)
        self.count = 0

    def add(self, lam: FloatArray, Y: FloatArray) -> None:
        need = self.count + len(lam)
        if need > self.Y.shape[1]:
            Y2 = np.empty((self.n, max(need, int(self.Y.shape[1] * 1.5))), order="F")
            Y2[:, : self.count] = self.Y[:, : self.count]
            self.Y = Y2
        self.Y[:, self.count : need] = Y
        self.lam = np.concatenate([self.lam, lam])
        self.count = need

    def below(self, x: float) -> int:
        return int(np.count_nonzero(self.lam < x))


def _report(progress: ProgressCallback | None, frac: float, msg: str) -> None:
    if progress is not None:
        progress(float(min(max(frac, 0.0), 1.0)), msg)


def _dense_eigenpairs(
    K: sp.csr_matrix, m: FloatArray, k: int, Z: FloatArray
) -> tuple[FloatArray, FloatArray]:
    """Dense ``eigh`` of ``D⁻¹KD⁻¹``; the null space is replaced by the exact indicators."""
    d = np.sqrt(m)
    A = K.toarray() / d[:, None] / d[None, :]
    A = 0.5 * (A + A.T)
    if k < len(m):
        lam, Y = sla.eigh(A, subset_by_index=(0, k - 1), driver="evr")
    else:
        lam, Y = sla.eigh(A, driver="evd")
    c = min(Z.shape[1], k)
    Zy = Z * d[:, None]
    Y = np.asfortranarray(Y)
    if c:
        # the c lowest eigenvalues are the components' zeros: use the exact indicators
        lam[:c] = 0.0
        Y[:, :c] = Zy[:, :c]
        if k > c:
            rest = Y[:, c:]
            rest -= Zy @ (Zy.T @ rest)
            Y[:, c:] = rest
    return lam, Y


def _lowdin(Y: FloatArray, helper: Any | None = None) -> float:
    """Symmetric (Löwdin) orthonormalization of the columns of ``Y`` in place; returns the
    departure ``max|YᵀY − I|`` before it.

    ``Y ← Y G^-½`` with ``G = YᵀY``. When ``G = I + E`` is that close to ``I`` (as slices
    computed separately are: ``|E| ~ 1e-9``), ``G^-½ = I − E/2 + 3E²/8`` to ``O(‖E‖³)``;
    otherwise from ``eigh(G)``. ``helper`` (an executor with one thread): the two
    ``n × k`` products run on two cores, half of the rows each.
    """
    n, k = Y.shape
    split = helper is not None and n >= 8192 and k >= 64
    h = n // 2
    if split:
        fut = helper.submit(lambda: Y[h:].T @ Y[h:])
        G = Y[:h].T @ Y[:h]
        G += fut.result()
        G = 0.5 * (G + G.T)
    else:
        G = blas.dsyrk(1.0, Y, trans=True, lower=False)
        G = np.triu(G) + np.triu(G, 1).T
    E = G - np.eye(k)
    err = float(np.abs(E).max(initial=0.0))
    if err < 1e-11:  # e.g. a single slice: Q S is orthonormal already
        return err
    if err * k <= 1e-4:  # ‖E‖₂ <= k·max|E|
        S = np.eye(k) - 0.5 * E + 0.375 * (E @ E)
    else:
        w, V = np.linalg.eigh(G)
        S = (V / np.sqrt(w)[None, :]) @ V.T
    chunk = max(1, (1 << 24) // max(1, k))

    def product(r0: int, r1: int) -> None:
        for a in range(r0, r1, chunk):
            b = min(a + chunk, r1)
            Y[a:b] = Y[a:b] @ S

    if split:
        fut = helper.submit(product, h, n)
        product(0, h)
        fut.result()
    else:
        product(0, n)
    return err


def _fix_signs(U: FloatArray) -> None:
    """Deterministic sign: the entry of largest magnitude of each column is positive."""
    if U.shape[1] == 0:
        return
    idx = np.argmax(np.abs(U), axis=0)
    s = np.sign(U[idx, np.arange(U.shape[1])])
    s[s == 0] = 1.0
    U *= s[None, :]


@dataclass
class _SliceSpec:
    """One slice: eigenvalues in ``[lo, hi)`` computed with shift ``sigma``."""

    index: int
    sigma: float
    lo: float
    hi: float
    expected: int
    X: FloatArray | None = None  # extra vectors to deflate (known eigenvectors nearby)
    count: int | None = None  # if set: the `count` lowest eigenvalues >= lo (hi ignored)
    check_below: bool = True  # are there (undeflated) eigenvalues below lo to resolve?
    check_top: bool = False  # the top slice: also factor in a gap below its top eigenvalue


@dataclass
class _SliceResult:
    spec: _SliceSpec
    sigma: float
    n_below: int  # eigenvalues below sigma (inertia)
    lam: FloatArray
    Y: FloatArray
    krylov_dim: int
    n_applied: int
    seconds: float
    check: tuple[float, int] | None = None  # (shift, eigenvalues below it) near the top


class _Cancelled(Exception):
    pass


class _SliceContext:
    """What the slice workers share: the pencil, options, and progress / cancel state."""

    def __init__(
        self,
        K: sp.csr_matrix,
        m: FloatArray,
        Zy: FloatArray,
        *,
        tol: float,
        block: int,
        target: int,
        base_count: int,
        progress: ProgressCallback | None,
    ) -> None:
        self.K, self.m, self.d = K, m, np.sqrt(m)
        self.n = len(m)
        inv = sp.diags(1.0 / self.d)
        self.A = (inv @ K @ inv).tocsr()  # M^-1/2 K M^-1/2
        self.ordering = _Ordering(self.n)
        self.Zy = Zy if Zy.shape[1] else None
        self.tol, self.block, self.target = tol, block, target
        self.base_count = base_count
        self.scale = float(K.diagonal().sum() / (self.n * m.sum()))
        self._progress = progress
        self._lock = threading.Lock()
        self._converged: dict[int, int] = {}
        self._done_count = 0
        self.cancel = threading.Event()
        self.error: BaseException | None = None
        self.local = threading.local()  # per worker thread: a spare factorization to reuse
        self.inertia: dict[int, tuple[float, int]] = {}  # slice -> (shift, eigenvalues below)

    def report(self, index: int, n_conv: int, message: str) -> None:
        if self._progress is None:
            return
        with self._lock:
            if self.cancel.is_set():
                return
            self._converged[index] = n_conv
            count = self.base_count + self._done_count + sum(self._converged.values())
            try:
                self._progress(min(0.99, count / max(self.target, 1)), message)
            except BaseException as exc:  # the caller cancels by raising
                self.error = exc
                self.cancel.set()

    def finished(self, index: int, count: int) -> None:
        with self._lock:
            self._converged.pop(index, None)
            self._done_count += count


def _run_slice(ctx: _SliceContext, spec: _SliceSpec, seed: int) -> _SliceResult:
    """Factor at ``spec.sigma`` and run block Lanczos until every Ritz value in
    ``[lo, hi)`` has converged, and so have the nearest Ritz values outside on each bounded
    side (so nothing inside is still undiscovered); inertia then double-checks the counts."""
    t0 = time.perf_counter()
    rng = np.random.default_rng([seed, spec.index])
    b = ctx.block
    width = spec.hi - max(spec.lo, 0.0)
    # (the factorization of this thread's previous slice, done with, is refactored in place)
    spare, ctx.local.spare = getattr(ctx.local, "spare", None), None
    op = _ShiftInvert(
        ctx.A,
        spec.sigma,
        rng=rng,
        spacing=max(width, ctx.scale) / max(spec.expected, 1),
        ordering=ctx.ordering,
        reuse=spare,
    )
    del spare
    ctx.inertia[spec.index] = (op.sigma, op.n_below)  # (planning of the next slices)
    parts = [x for x in (ctx.Zy, spec.X) if x is not None and x.shape[1]]
    X = np.asfortranarray(np.concatenate(parts, axis=1)) if parts else None
    lz = _BlockLanczos(op, ctx.n, b, X, rng, capacity=int(3.2 * spec.expected) + 16 * b)
    next_check = max(2 * b, int(0.8 * spec.expected) // b * b)
    prev: tuple[int, float] | None = None
    while True:
        if ctx.cancel.is_set():
            raise _Cancelled
        lz.step()
        if lz.j < next_check and not lz.exhausted:
            continue
        th, S, res, C = lz.ritz(lz.j)
        with np.errstate(divide="ignore"):
            lam = op.sigma + 1.0 / th
        # Two residuals. Of the shift-inverted pair, relative to |θ|. And in the pencil: with
        # μ = σ + 1/θ, (A − μ)y = −(A − σ)(Op y − θy)/θ = −(A − σ)q̃ C/θ, exactly and cheaply
        # (one sparse product with the next block). The first alone lets eigenvalues far
        # from the shift (λ ≪ σ in the lowest slice) keep λ-relative residuals up to
        # tol·λ_max/λ (1e-3 on meshes of slivers); the second asks for _LAMBDA_TOL relative
        # to λ. (It is an estimate from the Lanczos relation, so it keeps falling as Lanczos
        # converges: no round-off floor can stall it.)
        Qn = lz.Q[:, lz.j : lz.j + b]
        Z = ctx.A @ Qn - op.sigma * Qn
        G = Z.T @ Z
        ath = np.maximum(np.abs(th), 1e-300)
        rlam = np.sqrt(np.maximum(np.einsum("ij,ij->j", C, G @ C), 0.0)) / ath
        # each pair's residual over its tolerance (converged at <= 1)
        ratio = np.maximum(
            res / ath / ctx.tol, rlam / np.maximum(_LAMBDA_TOL * np.abs(lam), 1e-300)
        )
        conv = ratio <= 1.0
        if spec.count is None:
            hi = spec.hi
        else:  # the `count` lowest Ritz values >= lo
            cand = np.sort(lam[lam >= spec.lo])
            hi = cand[spec.count] if len(cand) > spec.count else np.inf
        inside = (lam >= spec.lo) & (lam < hi)
        # decades still missing: every inside Ritz pair to `tol`, and the nearest Ritz value
        # outside on each bounded side to `_EDGE_TOL` (resolved well enough to be sure it is
        # outside, so nothing inside is still undiscovered)
        worst = float(np.log10(np.maximum(ratio[inside], 1e-300)).max(initial=-1.0))
        for side in ("above", "below"):
            if side == "below" and not spec.check_below:
                continue
            out = np.flatnonzero(lam >= hi if side == "above" else lam < spec.lo)
            if len(out) == 0 or not np.isfinite(hi):
                worst = max(worst, 3.0)  # not even approximated yet
                continue
            nearest = out[np.argmin(np.abs(lam[out] - op.sigma))]
            worst = max(worst, float(np.log10(max(ratio[nearest] * ctx.tol, 1e-300) / _EDGE_TOL)))
        n_in = int(np.count_nonzero(inside & conv))
        ctx.report(
            spec.index,
            n_in,
            f"eigensolver: slice {spec.index} (shift {op.sigma:.4g}): {n_in} eigenpairs, "
            f"Krylov dimension {lz.j}",
        )
        if worst <= 0 or lz.exhausted or lz.j > 8 * spec.expected + 400:
            break  # (the last case is a safeguard; the inertia check catches what is missing)
        # next check: where the convergence rate seen so far says it will be done (residuals
        # fall geometrically with the Krylov dimension), at least one block, at most j/8
        step = max(b, (lz.j // _CHECK_EVERY) // b * b)
        if prev is not None and prev[1] > worst:
            rate = (prev[1] - worst) / (lz.j - prev[0])  # decades per basis vector
            step = int(min(step, max(b, -(-int(np.ceil(worst / rate)) // b) * b)))
        prev = (lz.j, worst)
        next_check = lz.j + step
    sigma_used, n_below, j_used, n_applied = op.sigma, op.n_below, lz.j, lz.n_applied
    sel = np.flatnonzero(inside if lz.exhausted else inside & conv)
    sel = sel[np.argsort(lam[sel], kind="stable")]
    Y = lz.vectors(S[:, sel])
    spare = op._lu
    del lz, op
    check = None
    if spec.check_top and not ctx.cancel.is_set():
        # The inertia check just above λ_k, done here in a gap between the two top
        # eigenvalues of the top slice (everything below them is in this slice or a lower
        # one): with two workers it overlaps the other slice instead of following both.
        ls = lam[sel]
        gaps = np.flatnonzero(np.diff(ls) > 1e-7 * np.maximum(np.abs(ls[1:]), ctx.scale))
        if len(gaps):
            t = int(gaps[-1])
            chk = _ShiftInvert(
                ctx.A,
                0.5 * (ls[t] + ls[t + 1]),
                rng=rng,
                spacing=ls[t + 1] - ls[t],
                ordering=ctx.ordering,
                reuse=spare,
            )
            check = (chk.sigma, chk.n_below)
            spare = chk._lu
    ctx.local.spare = spare
    ctx.finished(spec.index, len(sel))
    return _SliceResult(
        spec=spec,
        sigma=sigma_used,
        n_below=n_below,
        lam=lam[sel],
        Y=Y,
        krylov_dim=j_used,
        n_applied=n_applied,
        seconds=time.perf_counter() - t0,
        check=check,
    )


class _InlinePool:
    """A stand-in for ``ThreadPoolExecutor`` that runs each task at once in the caller."""

    def __enter__(self) -> _InlinePool:
        return self

    def __exit__(self, *exc: object) -> None:
        return None

    def submit(self, fn: Callable[..., Any], *args: Any) -> Any:
        import concurrent.futures as cf

        fut: cf.Future[Any] = cf.Future()
        try:
            fut.set_result(fn(*args))
        except BaseException as exc:
            fut.set_exception(exc)
        return fut


def _idle_cores(window: float = 0.05) -> float:
    """CPU cores not used by other processes right now: ``/proc/stat`` sampled over ``window``
    seconds (Linux), with this process's own CPU time counted as idle (threaded BLAS spins its
    threads for a while after a call: that is not load); else the number of cores minus the
    1-minute load average."""
    cpus = os.cpu_count() or 1

    def sample() -> tuple[float, float, float]:
        with open("/proc/stat") as f:
            vals = [int(x) for x in f.readline().split()[1:8]]
        # idle + iowait, total (user..softirq; guest time is inside user), own CPU seconds
        return vals[3] + vals[4], sum(vals), time.process_time()

    try:
        hz = os.sysconf("SC_CLK_TCK")
        i0, t0, p0 = sample()
        time.sleep(window)
        i1, t1, p1 = sample()
        free = (i1 - i0) + (p1 - p0) * hz
        return float(min(cpus, cpus * free / max(t1 - t0, 1)))
    except (OSError, ValueError, IndexError):
        try:
            return cpus - os.getloadavg()[0]
        except (AttributeError, OSError):  # pragma: no cover
            return float(cpus)


def _default_workers(n: int, slice_size: int) -> int:
    """Two slice workers when two cores are idle, else one (on a busy machine threads only
    compete, and more slices cost more in total); one also when the Krylov bases of two
    slices would need more than ~1 GiB."""
    per = n * 8 * (2.6 * slice_size + 64) + 120 * n
    cpus = os.cpu_count() or 1
    if cpus < 2 or (1 << 30) // max(int(per), 1) < 2:
        return 1
    return 2 if _idle_cores() >= 1.6 else 1


def _sliced_lanczos(
    K: sp.csr_matrix,
    m: FloatArray,
    k: int,
    Z: FloatArray,
    info: SolveInfo,
    *,
    known: tuple[FloatArray, FloatArray] | None,
    progress: ProgressCallback | None,
    tol: float,
    block: int,
    slice_size: int,
    first_slice: int,
    workers: int,
    weyl_density: float,
) -> tuple[FloatArray, FloatArray]:
    """The ``k`` smallest eigenpairs (``y = M^½u`` coordinates) by spectrum slicing.

    The range ``[0, λ_k]`` is cut into consecutive intervals ``[b_{i-1}, b_i)`` holding about
    ``slice_size`` eigenvalues each (widths from Weyl's law ``N(λ) ≈ area·λ/4π`` at first, then
    from the inertia counts at the shifts); each interval is one task for a pool of
    ``workers`` threads (BLAS and the sparse solves release the GIL), with its shift in its
    middle. Afterwards the inertia of every shift, and of one extra shift in a gap just above
    ``λ_k``, is compared with the
    number of eigenvalues found below it; a deficit is searched for again with the known
    eigenvectors deflated.
    """
    n = len(m)
    d = np.sqrt(m)
    extra = 2 + k // 50  # a few beyond k to place the final inertia check in a gap
    target = min(k + extra, n)
    Zy = np.asfortranarray(Z * d[:, None])
    found = _Found(n, target + slice_size)
    if known is None:
        found.add(np.zeros(Z.shape[1]), Zy)
        n_null = Z.shape[1]
    else:
        found.add(known[0], known[1])
        n_null = 0
    base = found.count
    ctx = _SliceContext(
        K, m, Zy, tol=tol, block=block, target=target, base_count=base, progress=progress
    )
    scale = ctx.scale
    seed = 20240611
    checks: list[tuple[float, int]] = []  # (shift, eigenvalues below it) from inertia
    results: dict[int, _SliceResult] = {}
    specs: list[_SliceSpec] = []

    # ---- planning --------------------------------------------------------------------------
    # The lowest slice has no eigenvalues below it to resolve (the null space is deflated):
    # with one worker it takes a larger share (first_slice eigenpairs).
    todo = target - base
    first_big = known is None
    if first_big and (todo <= first_slice and not (workers >= 2 and todo >= 60)):
        sizes = [todo]
    elif first_big and todo <= first_slice:
        # two workers: split, the lowest slice (one-sided) taking a little more
        sizes = [todo - int(_SPLIT * todo), int(_SPLIT * todo)]
    else:
        if workers >= 2:
            # equal slices, as many as a multiple of the workers (the last round keeps every
            # thread busy), of the size nearest to slice_size
            lo_n = max(workers, todo // slice_size // workers * workers)
            cands = [c for c in (lo_n, lo_n + workers) if todo >= 32 * c] or [1]
            n_sl = min(cands, key=lambda c: abs(np.log(todo / c / slice_size)))
            per = -(-todo // n_sl)
            sizes = [per] * n_sl
        else:
            first = min(first_slice, todo) if first_big else 0
            rest = todo - first
            n_int = max(1, -(-rest // slice_size))
            per = -(-rest // n_int)
            sizes = ([first] if first_big else []) + [per] * n_int
    sizes = [max(s_, 4) for s_ in sizes]
    n_total = len(sizes)
    lam_known_hi = float(found.lam.max(initial=0.0)) if known is not None else 0.0
    known_X = None
    near_all = False
    if known is not None and known[0].size:
        # the first new slice must not find the known eigenpairs near its lower end again
        w = sizes[0] / weyl_density
        near = np.flatnonzero(found.lam >= lam_known_hi - w)
        near = near[near >= n_null]
        near_all = len(near) == found.count
        known_X = np.asfortranarray(found.Y[:, near])

    def plannable(i: int) -> bool:
        """Slice ``i`` is planned from the inertia of slice ``i − 1``, known as soon as it is
        factored (so the plan does not depend on which thread finishes first, and no thread
        waits for a long slice to end)."""
        if i < max(workers, 1) or (i - 1) in results:
            return True
        return (i - 1) in ctx.inertia

    def density_before(i: int) -> float:
        """Eigenvalue density for planning slice ``i``: between the last two inertia counts
        at the shifts of slices ``< i`` (the first point is ``(0, base)``), else from the
        finished slices ``<= i - workers``, else Weyl's."""
        pts = [(0.0, base if known is None else n_null)] + [
            ctx.inertia[j] for j in range(i) if j in ctx.inertia
        ]
        if len(pts) >= 2 and pts[-1][0] > pts[-2][0]:
            (s0, n0), (s1, n1) = pts[-2], pts[-1]
            if n1 - n0 >= 4:
                return (n1 - n0) / (s1 - s0)
        j = i - max(workers, 1)
        while j >= 0:
            r = results.get(j)
            if r is not None:
                lo = max(r.spec.lo, 0.0)
                cnt = len(r.lam) + (base if r.spec.index == 0 and known is None else 0)
                if cnt >= 4 and r.spec.hi > lo:
                    return cnt / (r.spec.hi - lo)
            j -= 1
        return weyl_density

    def plan(i: int) -> _SliceSpec:
        # (the lowest slice starts just below 0: round-off can put a zero mode that the
        # component indicators do not cover a hair below 0)
        lo = specs[-1].hi if specs else (lam_known_hi if known is not None else -1e-6 * scale)
        rho = density_before(i)
        start = max(lo, 0.0)
        # the last planned slice reaches a little further: a cut just above lambda_k would
        # need the next slice for a few eigenvalues
        size = sizes[min(i, len(sizes) - 1)]
        count = None
        if i >= n_total - 1 and all(j in results for j in range(i)):
            # the last slice, with every lower eigenvalue known: ask for exactly what is missing
            have = base + sum(len(results[j].lam) for j in range(i))
            count = max(target - have, 1)
            size = count
        hi = start + size * (1.0 if count is not None or i < n_total - 1 else 1.05) / rho
        return _SliceSpec(
            i,
            0.5 * (start + hi),
            lo,
            hi,
            size,
            known_X if (i == 0 and known is not None) else None,
            count,
            check_below=lo > 0 and not (i == 0 and known_X is not None and near_all),
            check_top=workers >= 2 and i == n_total - 1,
        )

    def need_more(i: int) -> bool:
        return i < n_total

    # ---- run the slices (a pool of `workers` threads) ----------------------------------------
    import concurrent.futures as cf

    def absorb(r: _SliceResult) -> None:
        results[r.spec.index] = r
        info.shifts.append(r.sigma)
        info.krylov_dims.append(r.krylov_dim)
        info.n_operator_applications += r.n_applied
        info.n_factorizations += 1
        checks.append((r.sigma, r.n_below))
        if r.check is not None:
            checks.append(r.check)
            info.n_factorizations += 1

    t_slices = time.perf_counter()
    with cf.ThreadPoolExecutor(max_workers=workers) if workers > 1 else _InlinePool() as pool:
        running: dict[cf.Future[_SliceResult], int] = {}
        try:
            while True:
                while len(running) < max(workers, 1):
                    i = len(specs)
                    if not need_more(i) or not plannable(i):
                        break
                    specs.append(plan(i))
                    running[pool.submit(_run_slice, ctx, specs[-1], seed)] = i
                if not running:
                    got = base + sum(len(r.lam) for r in results.values())
                    if got >= target or len(specs) > 4 * n_total + 20:
                        break
                    n_total += 1  # the density estimate was short: one more slice
                    specs.append(plan(len(specs)))
                    running[pool.submit(_run_slice, ctx, specs[-1], seed)] = len(specs) - 1
                    continue
                # (a short timeout while the next slice waits for an inertia count)
                waiting = len(running) < max(workers, 1) and need_more(len(specs))
                done, _ = cf.wait(
                    running, timeout=0.01 if waiting else None, return_when=cf.FIRST_COMPLETED
                )
                for f in sorted(done, key=lambda f: running[f]):
                    del running[f]
                    absorb(f.result())
        except BaseException:
            ctx.cancel.set()
            for f in running:
                f.cancel()
            raise
        finally:
            if ctx.error is not None:
                raise ctx.error
    for i in sorted(results):
        found.add(results[i].lam, results[i].Y)
    results.clear()
    _dedupe(found, base, scale)
    info.timings["slices"] = time.perf_counter() - t_slices

    # ---- verification by inertia; repair deficits --------------------------------------
    t_ver = time.perf_counter()
    rng = np.random.default_rng([seed, 999])
    repair_index = 10_000
    for _attempt in range(6):
        lam_sorted = np.sort(found.lam)
        if not any(s > lam_sorted[min(k, found.count) - 1] for s, _ in checks):
            # an inertia point in a gap just above the k-th eigenvalue
            tau = None
            for j in range(k - 1, found.count - 1):
                lo_, hi_ = lam_sorted[j], lam_sorted[j + 1]
                if hi_ - lo_ > 1e-7 * max(abs(hi_), scale):
                    tau = 0.5 * (lo_ + hi_)
                    break
            if tau is None:
                tau = lam_sorted[-1] * (1 + 1e-6) + 1e-6 * scale
            spare, ctx.local.spare = getattr(ctx.local, "spare", None), None
            op = _ShiftInvert(
                ctx.A,
                tau,
                rng=rng,
                ordering=ctx.ordering,
                reuse=spare,
                spacing=1e-3 * max(lam_sorted[-1] - lam_sorted[k - 1], scale),
            )
            info.n_factorizations += 1
            checks.append((op.sigma, op.n_below))
            del op
        checks.sort()
        bad = None
        prev = -np.inf
        for s, nu in checks:
            have = found.below(s)
            if have > nu:
                raise RuntimeError(
                    f"eigensolver: {have} eigenvalues found below {s:.6g} but inertia counts {nu}"
                )
            if have < nu:
                bad = (prev, s, nu - have)
                break
            prev = s
        if bad is None:
            break
        lo, hi, missing = bad
        lo = max(lo, 0.0) if np.isfinite(lo) else 0.0
        info.messages.append(
            f"inertia check: {missing} eigenvalue(s) in [{lo:.6g}, {hi:.6g}) were missed; "
            "searching again with the found ones deflated"
        )
        near = np.flatnonzero(
            (found.lam >= lo - 0.25 * (hi - lo)) & (found.lam <= hi + 0.25 * (hi - lo))
        )
        near = near[near >= n_null]  # the null space is deflated in every slice already
        below = bool(np.any(found.lam[: found.count] < lo - 0.25 * (hi - lo)))
        spec = _SliceSpec(
            repair_index,
            0.5 * (lo + hi),
            lo,
            hi,
            max(missing, 4),
            np.asfortranarray(found.Y[:, near]),
            check_below=below and lo > 0,
        )
        repair_index += 1
        r = _run_slice(ctx, spec, seed)
        absorb(r)
        old = found.count
        found.add(r.lam, r.Y)
        _dedupe(found, old, scale)
    else:
        raise RuntimeError("eigensolver: could not account for every eigenvalue (inertia)")
    info.timings["verification"] = time.perf_counter() - t_ver
    if found.count < k:
        raise RuntimeError(f"eigensolver: found only {found.count} of {k} eigenpairs")
    o = np.argsort(found.lam, kind="stable")[:k]
    lam = found.lam[o]
    Y = np.asfortranarray(found.Y[:, o])
    info.messages.append(
        f"inertia checks at {len(checks)} shifts: every eigenvalue below "
        f"{max(s for s, _ in checks):.6g} was found"
    )
    return lam, Y


def _dedupe(found: _Found, old_count: int, scale: float) -> None:
    """Remove from the pairs added after ``old_count`` what the earlier ones already span.

    Pairs are compared within clusters of (nearly) equal eigenvalues: a later vector is
    orthogonalized against the cluster's earlier vectors and kept (normalized) only if more
    than half of it is new, so repeated eigenvalues are handled by subspace, not by vector.
    """
    lam = found.lam
    order = np.argsort(lam, kind="stable")
    keep: list[int] = list(range(old_count))
    kept_sorted = np.sort(lam[:old_count])
    kept_idx = np.argsort(lam[:old_count], kind="stable")
    extra: list[int] = []
    for i in order:
        if i < old_count:
            continue
        tol = 1e-6 * max(abs(lam[i]), scale)
        a, b = np.searchsorted(kept_sorted, [lam[i] - tol, lam[i] + tol + 1e-300])
        cl = [int(kept_idx[t]) for t in range(a, b)] + [
            j for j in extra if abs(lam[j] - lam[i]) <= tol
        ]
        if cl:
            Yc = found.Y[:, cl]
            w = found.Y[:, i].copy()
            for _ in range(2):
                w -= Yc @ (Yc.T @ w)
            nw = float(np.linalg.norm(w))
            if nw <= 0.5:
                continue
            if nw < 1.0 - 1e-8:
                found.Y[:, i] = w / nw
        extra.append(int(i))
    keep += sorted(extra)
    if len(keep) < found.count:
        ka = np.asarray(keep, dtype=np.int64)
        found.Y[:, : len(ka)] = found.Y[:, ka]
        found.lam = lam[ka]
        found.count = len(ka)


def laplacian_eigenpairs(
    V: FloatArray,
    F: IntArray,
    k: int,
    *,
    laplacian: LaplacianKind = "cotan",
    mass: AreaKind = MASS_AREA,
    progress: ProgressCallback | None = None,
    known: tuple[FloatArray, FloatArray] | None = None,
    method: Literal["auto", "dense", "sparse"] = "auto",
    **tuning: Any,
) -> tuple[FloatArray, FloatArray, SolveInfo]:
    """The ``k`` smallest eigenpairs of ``K u = λ M u`` for a mesh (``K = −C``, see module).

    Parameters
    ----------
    V : (n,3) float
    F : (m,3) int
    k : int
        Number of eigenpairs, ``1 <= k <= n`` (``k = n`` is the full basis).
    laplacian, mass : str
        See :func:`spectral_operators`.
    progress, known, method, **tuning
        See :func:`pencil_eigenpairs`.

    Returns
    -------
    lam : (k,) float
        Ascending frequencies ``>= 0`` of ``−Δ``.
    U : (n,k) float, F-ordered
        ``UᵀMU = I``.
    info : SolveInfo

    Examples
    --------
    >>> from meshlap_core.primitives import icosphere
    >>> lam, U, info = laplacian_eigenpairs(*icosphere(3), 4)
    >>> [round(float(x), 2) for x in lam]   # 0, then l(l+1) = 2 three times (unit sphere)
    [0.0, 2.0, 2.0, 2.0]
    """
    t_start = time.perf_counter()
    V, F = as_mesh(V, F)
    k = _check_k(k, len(V), "k")
    K, m = spectral_operators(V, F, laplacian, mass)
    t_ops = time.perf_counter() - t_start
    opts = _options(laplacian, mass)
    if "density" not in tuning:
        # Weyl's law N(λ) ≈ area·λ/4π; for the graph Laplacian of a near-equilateral mesh the
        # same count gives λ ≈ 4π√3·N/n
        tuning["density"] = (
            m.sum() / (4 * np.pi)
            if opts["laplacian"] == "cotan"
            else len(m) / (4 * np.pi * np.sqrt(3.0))
        )
    lam, U, info = pencil_eigenpairs(
        K, m, k, progress=progress, known=known, method=method, **tuning
    )
    info.timings["operators"] = t_ops
    info.timings["total"] = time.perf_counter() - t_start
    return lam, U, info


def pencil_eigenpairs(
    K: sp.spmatrix,
    m: FloatArray,
    k: int,
    *,
    progress: ProgressCallback | None = None,
    known: tuple[FloatArray, FloatArray] | None = None,
    method: Literal["auto", "dense", "sparse"] = "auto",
    tol: float = _TOL,
    block: int = _BLOCK,
    slice_size: int = _SLICE,
    first_slice: int = _FIRST_SLICE,
    workers: int | None = None,
    blas_threads: int | None = None,
    density: float | None = None,
) -> tuple[FloatArray, FloatArray, SolveInfo]:
    """The ``k`` smallest eigenpairs of ``K u = λ diag(m) u``, ``K`` symmetric positive
    semidefinite with zero row sums (``K = −C``: the sign convention of the module).

    Parameters
    ----------
    K : (n,n) sparse matrix
        Symmetric positive semidefinite stiffness, e.g. from :func:`spectral_operators`.
    m : (n,) float
        Positive lumped masses.
    k : int
        ``1 <= k <= n``.
    progress : callable, optional
        ``progress(fraction, message)`` during long solves, possibly from the solver's worker
        threads (calls are serialized); raise from it to cancel the solve.
    known : (lam (j,), U (n,j)), optional
        The ``j`` smallest eigenpairs, already computed: only the others are solved for.
    method : {"auto", "dense", "sparse"}
        ``"auto"``: dense ``eigh`` for ``n <= 1500`` or ``k > n/2``, else sliced shift-invert
        block Lanczos.
    tol, block, slice_size, first_slice
        Tuning of the sparse solver: relative residual of the shift-inverted Ritz pairs, block
        size, eigenpairs per interior slice and in the lowest slice (one worker).
    workers : int, optional
        Slices solved concurrently in threads; default 2 when two cores are idle (sampled from
        ``/proc/stat``), else 1 (also when memory would be tight). The Gram–Schmidt products
        use numpy's matmul, which releases the GIL.
    blas_threads : int, optional
        BLAS threads during the solve (default 1, set with ``threadpoolctl``): OpenBLAS's
        own threads on these tall-skinny products gained nothing on 2 cores and collapsed
        (several times slower, spinning) as soon as other processes used the cores.
    density : float, optional
        Expected eigenvalues per unit of ``λ`` (Weyl), used to plan the first slices;
        default ``Σm / 4π``.

    Returns
    -------
    lam : (k,) float
        Ascending, ``>= 0`` (round-off below zero is clipped and counted in ``info``).
    U : (n,k) float, F-ordered
        ``UᵀMU = I``; the entry of largest magnitude of each column is positive.
    info : SolveInfo

    Notes
    -----
    One eigenvalue 0 per connected component of the sparsity graph, with the normalized
    indicator as eigenvector (deflated exactly), so no shift is ever needed at or below 0. The
    shifts are placed from Weyl's law scaled by the mesh's area (so total areas from 10⁻² to
    10⁶ behave alike) and moved off eigenvalues: a singular matrix is never factored.
    Sylvester inertia counts at every shift, plus one in a gap just above ``λ_k``, prove that
    no eigenvalue was skipped.
    """
    t0 = time.perf_counter()
    K = sp.csr_matrix(K, dtype=np.float64)
    m = np.asarray(m, dtype=np.float64).ravel()
    n = len(m)
    if K.shape != (n, n):
        raise MeshError(f"should be ({n},{n}) to match the masses; shape is {K.shape}", "K")
    if not (np.all(np.isfinite(m)) and np.all(m > 0)):
        raise MeshError("masses must be finite and positive", "m")
    if not np.all(np.isfinite(K.data)):
        raise MeshError("has NaN or infinite entries", "K")
    k = _check_k(k, n, "k")
    info = SolveInfo(n_vertices=n, k=k)
    ncomp, labels = _components(K)
    Z = _null_space(m, labels, ncomp)
    info.n_components = ncomp
    if method not in ("auto", "dense", "sparse"):
        raise MeshError(f"unknown method {method!r}; choose auto, dense or sparse", "method")
    use_dense = method == "dense" or (
        method == "auto" and (n <= _DENSE_MAX_N or k > _SPARSE_MAX_FRACTION * n)
    )
    if use_dense and n > _DENSE_HARD_MAX_N:
        raise MeshError(
            f"k = {k} is more than {_SPARSE_MAX_FRACTION:.0%} of the {n} vertices; a basis that "
            f"large needs the dense solver, which is limited to {_DENSE_HARD_MAX_N} vertices "
            f"(ask for at most {int(_SPARSE_MAX_FRACTION * n)} modes)",
            "k",
        )
    d = np.sqrt(m)
    if use_dense:
        info.method = "dense"
        _report(progress, 0.0, f"eigensolver: dense, {n} vertices")
        with _blas_threads(1):
            lam, Y = _dense_eigenpairs(K, m, k, Z)
            _lowdin(Y)
        _report(progress, 1.0, "eigensolver: done")
    else:
        info.method = "shift-invert block Lanczos, spectrum slicing"
        nw = 1  # slice workers (also the cores the final orthonormalization may use)
        kn = None
        if known is not None and len(known[0]):
            lam0 = np.asarray(known[0], dtype=np.float64)
            U0 = np.asarray(known[1], dtype=np.float64)
            if U0.shape != (n, len(lam0)):
                raise MeshError("known eigenvectors have the wrong shape", "known")
            kn = (lam0, np.asfortranarray(U0 * d[:, None]))
        if kn is not None and len(kn[0]) >= k:
            lam, Y = kn[0][:k].copy(), np.asfortranarray(kn[1][:, :k])
        elif k <= ncomp:
            lam, Y = np.zeros(k), np.asfortranarray(Z[:, :k] * d[:, None])
        else:
            if workers is not None:
                nw = max(1, int(workers))
            else:  # (one slice below ~60 modes: no need to sample the machine's load)
                nw = 1 if k < 60 else _default_workers(n, max(slice_size, first_slice))
            nb = 1 if blas_threads is None else max(1, int(blas_threads))
            info.messages.append(f"{nw} slice worker(s), {nb} BLAS thread(s)")
            rho = float(density) if density else float(m.sum() / (4 * np.pi))
            with _blas_threads(nb):
                lam, Y = _sliced_lanczos(
                    K,
                    m,
                    k,
                    Z,
                    info,
                    known=kn,
                    progress=progress,
                    tol=tol,
                    block=block,
                    slice_size=slice_size,
                    first_slice=first_slice,
                    workers=nw,
                    weyl_density=rho,
                )
        t1 = time.perf_counter()
        with _blas_threads(1):
            if nw >= 2:
                import concurrent.futures as cf

                with cf.ThreadPoolExecutor(max_workers=1) as helper:
                    before = _lowdin(Y, helper)
            else:
                before = _lowdin(Y)
        if before > 1e-11:
            info.messages.append(
                f"slices orthonormalized together (Lowdin; max|U^T M U - I| was {before:.1e})"
            )
        info.timings["orthonormalization"] = time.perf_counter() - t1
    info.min_raw_eigenvalue = float(lam.min(initial=0.0))
    neg = lam < 0
    info.n_clipped = int(np.count_nonzero(neg))
    if info.n_clipped:
        info.messages.append(
            f"{info.n_clipped} eigenvalue(s) slightly below 0 (min {info.min_raw_eigenvalue:.3g}) "
            "clipped to 0"
        )
    lam = np.where(neg, 0.0, lam)
    o = np.argsort(lam, kind="stable")
    if np.any(o != np.arange(len(o))):
        lam, Y = lam[o], np.asfortranarray(Y[:, o])
    U = Y
    U /= d[:, None]
    _fix_signs(U)
    info.timings["eigensolve"] = time.perf_counter() - t0
    t1 = time.perf_counter()
    info.max_residual = _max_residual(K, m, lam, U)
    info.orthogonality_error = _orthogonality(U, m)
    info.timings["residual_check"] = time.perf_counter() - t1
    return lam, U, info


def _max_residual(
    K: sp.csr_matrix, m: FloatArray, lam: FloatArray, U: FloatArray, sample: int = 24
) -> float:
    """``max_i ||K u_i − λ_i M u_i||_{M⁻¹} / max(λ_i, λ_ref)`` over ``sample`` columns spread
    evenly (first and last included); ``||u_i||_M = 1``, ``λ_ref = tr(K)/(n·tr(M))``."""
    kk = U.shape[1]
    if kk == 0:
        return 0.0
    idx = np.unique(np.linspace(0, kk - 1, min(kk, sample)).round().astype(np.int64))
    ref = float(K.diagonal().sum() / (len(m) * m.sum()))
    Us = U[:, idx]
    R = K @ Us - (m[:, None] * Us) * lam[None, idx]
    r = np.sqrt(np.sum(R * R / m[:, None], axis=0))
    return float(np.max(r / np.maximum(lam[idx], ref)))


def _orthogonality(U: FloatArray, m: FloatArray) -> float:
    """``max|UᵀMU − I|`` over the rows of a sample of columns (first, last, thirds and 4 more
    at random, each against all) and the ``M``-norms of every column: ``O(nk)``."""
    kk = U.shape[1]
    if kk == 0:
        return 0.0
    idx = np.unique(
        np.r_[0, kk // 3, (2 * kk) // 3, kk - 1, np.random.default_rng(kk).integers(0, kk, 4)]
    )
    G = U[:, idx].T @ (m[:, None] * U)
    E = np.zeros_like(G)
    E[np.arange(len(idx)), idx] = 1.0
    norms = np.einsum("ij,ij,i->j", U, U, m)
    return float(max(np.abs(G - E).max(), np.abs(norms - 1.0).max()))


def _check_k(k: Any, n: int, name: str) -> int:
    try:
        kk = int(k)
    except (TypeError, ValueError):
        raise MeshError(f"must be an integer, got {k!r}", name) from None
    if kk != k or kk < 1:
        raise MeshError(f"must be a positive integer, got {k!r}", name)
    if kk > n:
        raise MeshError(
            f"asks for {kk} eigenmodes but the mesh has only {n} vertices (at most {n} modes "
            "exist; k = n is the full basis)",
            name,
        )
    return kk


# --------------------------------------------------------------------------------------------
# Cache
# --------------------------------------------------------------------------------------------


def default_cache_dir() -> Path:
    """``$MESHLAP_CACHE_DIR``, else ``$XDG_CACHE_HOME/meshlap``, else ``~/.cache/meshlap``."""
    env = os.environ.get("MESHLAP_CACHE_DIR")
    if env:
        return Path(env)
    xdg = os.environ.get("XDG_CACHE_HOME")
    if xdg:
        return Path(xdg) / "meshlap"
    return Path.home() / ".cache" / "meshlap"


def mesh_key(V: FloatArray, F: IntArray, options: dict[str, str]) -> str:
    """SHA-256 of the vertices, faces, options and cache format (hex)."""
    V, F = as_mesh(V, F)
    h = hashlib.sha256()
    h.update(f"meshlap-spectral-{CACHE_FORMAT}".encode())
    h.update(json.dumps(options, sort_keys=True).encode())
    h.update(np.array(V.shape + F.shape, dtype=np.int64).tobytes())
    h.update(V.tobytes())
    h.update(F.tobytes())
    return h.hexdigest()


def _cache_file(cache_dir: Path, key: str) -> Path:
    return Path(cache_dir) / f"spectral-{key[:40]}.npz"


def _write_npz(path: Path, arrays: dict[str, Any], overwrite_inputs: Any = ()) -> None:
    from .io import atomic_write

    with atomic_write(path, "wb", overwrite_inputs=overwrite_inputs) as f:
        np.savez(f, **arrays)


def _validate_arrays(
    data: Any, key: str, options: dict[str, str], K: sp.csr_matrix, m: FloatArray
) -> tuple[FloatArray, FloatArray, float]:
    """Check a loaded basis thoroughly (format, hash, options, shapes, finite values, ascending
    non-negative eigenvalues, the mass, ``M``-orthonormality of a sample of columns against all,
    eigen-residuals of the sample); raise ``ValueError`` with the reason if anything is off.
    Returns the eigenvalues, vectors and the sampled orthogonality error."""
    need = ("format", "key", "options", "eigenvalues", "vectors", "mass")
    missing = [x for x in need if x not in data]
    if missing:
        raise ValueError(f"missing {', '.join(missing)}")
    if int(data["format"]) != CACHE_FORMAT:
        raise ValueError("other cache format")
    if str(data["key"]) != key:
        raise ValueError("stale (the mesh or the options differ)")
    if json.loads(str(data["options"])) != options:
        raise ValueError("options differ")
    lam = np.asarray(data["eigenvalues"], dtype=np.float64)
    U = np.asarray(data["vectors"])
    mm = np.asarray(data["mass"], dtype=np.float64)
    n = len(m)
    if U.dtype != np.float64 or lam.ndim != 1 or U.shape != (n, len(lam)) or mm.shape != (n,):
        raise ValueError("wrong shapes")
    if len(lam) == 0:
        raise ValueError("empty basis")
    if not (np.isfinite(lam).all() and np.isfinite(U).all()):
        raise ValueError("non-finite values")
    if lam.min() < 0 or np.any(np.diff(lam) < 0):
        raise ValueError("eigenvalues not ascending and >= 0")
    if not np.allclose(mm, m, rtol=1e-12, atol=0):
        raise ValueError("mass differs")
    orth = _orthogonality(U, m)
    if orth > 1e-8:
        raise ValueError("vectors are not M-orthonormal")
    if _max_residual(K, m, lam, U) > 1e-5:  # (on up to 64 columns spread evenly)
        raise ValueError("vectors are not eigenvectors")
    return lam, np.asfortranarray(U), orth


def _read_cache(
    path: Path,
    key: str,
    options: dict[str, str],
    K: sp.csr_matrix,
    m: FloatArray,
    messages: list[str],
) -> tuple[FloatArray, FloatArray, float] | None:
    """The validated cached basis, or ``None`` (missing, or unusable: reason in ``messages``)."""
    if not path.is_file():
        return None
    try:
        with np.load(path, allow_pickle=False) as data:
            return _validate_arrays(data, key, options, K, m)
    except Exception as exc:  # any unreadable or inconsistent file is ignored and rebuilt
        messages.append(f"ignored cache file {path}: {exc}")
        return None


# --------------------------------------------------------------------------------------------
# The basis
# --------------------------------------------------------------------------------------------


@dataclass
class ReconstructionErrors:
    """Reconstruction errors ``|x_i − x̂_i|`` for every ``k = 0 … k_max`` (index = ``k``).

    ``mean``, ``max``, ``rms`` are over vertices; ``l2`` is the area-weighted RMS
    ``sqrt(||X − X̂_k||²_M / area)``, which never increases with ``k`` (the reconstruction is
    the ``M``-orthogonal projection). ``diagonal`` is the bounding-box diagonal of ``X`` and
    the ``relative_*`` properties divide by it.
    """

    k: IntArray
    mean: FloatArray
    max: FloatArray
    rms: FloatArray
    l2: FloatArray
    diagonal: float

    @property
    def relative_mean(self) -> FloatArray:
        return self.mean / self.diagonal

    @property
    def relative_max(self) -> FloatArray:
        return self.max / self.diagonal

    @property
    def relative_rms(self) -> FloatArray:
        return self.rms / self.diagonal

    @property
    def relative_l2(self) -> FloatArray:
        return self.l2 / self.diagonal

    def row(self, k: int) -> dict[str, float]:
        """The statistics for one ``k`` (the CLI's JSON object)."""
        return {
            "k": int(k),
            "mean_error": float(self.mean[k]),
            "max_error": float(self.max[k]),
            "rms_error": float(self.rms[k]),
            "l2_error": float(self.l2[k]),
            "relative_mean_error": float(self.mean[k] / self.diagonal),
            "relative_max_error": float(self.max[k] / self.diagonal),
        }


class SpectralBasis:
    """A computed Laplace–Beltrami eigenbasis of a mesh: compute once, reconstruct fast.

    Build it with :meth:`compute` (or :func:`compute_basis`). Attributes are read-only by
    convention; the methods are thread-safe (one lock), so a viewer may extend the basis in a
    worker thread while the UI thread reconstructs.

    Attributes
    ----------
    V : (n,3) float
    F : (m,3) int
    eigenvalues : (k_max,) float
        Ascending frequencies ``λ >= 0`` of ``−Δ`` (``K u = λ M u``).
    vectors : (n,k_max) float
        ``M``-orthonormal eigenvectors (F-ordered: column slices are contiguous).
    mass : (n,) float
        The diagonal of ``M``.
    options : dict
        ``{"laplacian": ..., "mass": ...}``.
    info : SolveInfo

    Examples
    --------
    >>> from meshlap_core.primitives import icosphere
    >>> V, F = icosphere(2)
    >>> basis = SpectralBasis.compute(V, F, 16, cache=False)
    >>> basis.reconstruct(16).shape
    (162, 3)
    """

    def __init__(
        self,
        V: FloatArray,
        F: IntArray,
        eigenvalues: FloatArray,
        vectors: FloatArray,
        mass: FloatArray,
        options: dict[str, str],
        info: SolveInfo | None = None,
    ) -> None:
        self.V, self.F = as_mesh(V, F)
        self.eigenvalues = np.asarray(eigenvalues, dtype=np.float64)
        self.vectors = np.asfortranarray(vectors, dtype=np.float64)
        self.mass = np.asarray(mass, dtype=np.float64)
        self.options = dict(options)
        self.info = info if info is not None else SolveInfo()
        self._lock = threading.RLock()  # guards the arrays and the reconstruction state
        self._extend_lock = threading.Lock()  # one extension at a time
        self._cache_path: Path | None = None  # set by compute(cache=True)
        self._threads = _thread_controller()
        self._reset_reconstruction()

    # ---- construction ------------------------------------------------------------------

    @classmethod
    def compute(
        cls,
        V: FloatArray,
        F: IntArray,
        k: int,
        *,
        laplacian: LaplacianKind = "cotan",
        mass: AreaKind = MASS_AREA,
        cache: bool = True,
        cache_dir: str | os.PathLike | None = None,
        progress: ProgressCallback | None = None,
    ) -> SpectralBasis:
        """Compute (or load from the cache) the ``k`` smallest eigenpairs.

        Parameters
        ----------
        V : (n,3) float
        F : (m,3) int
        k : int
            ``1 <= k <= n``.
        laplacian, mass : str
            See :func:`spectral_operators`.
        cache : bool
            Look up / store the basis in the cache directory (:func:`default_cache_dir`). A
            cached basis with at least ``k`` modes is used (truncated); one with fewer modes is
            extended; a corrupt or stale file is ignored and replaced.
        cache_dir : path, optional
            Overrides :func:`default_cache_dir`.
        progress : callable, optional
            ``progress(fraction, message)``.
        """
        V, F = as_mesh(V, F)
        opts = _options(laplacian, mass)
        k = _check_k(k, len(V), "k")
        t0 = time.perf_counter()
        K, m = spectral_operators(V, F, laplacian, mass)
        known = None
        path = None
        msgs: list[str] = []
        if cache:
            path = _cache_file(
                Path(cache_dir) if cache_dir else default_cache_dir(), mesh_key(V, F, opts)
            )
            known = _read_cache(path, mesh_key(V, F, opts), opts, K, m, msgs)
            if known is not None and len(known[0]) >= k:
                info = SolveInfo(
                    method="cache",
                    n_vertices=len(V),
                    k=k,
                    from_cache=True,
                    cache_path=str(path),
                    messages=msgs,
                    n_components=_components(K)[0],
                    orthogonality_error=known[2],
                )
                info.timings["eigensolve"] = 0.0
                info.timings["cache_load"] = time.perf_counter() - t0
                _report(progress, 1.0, "eigenbasis loaded from the cache")
                basis = cls(V, F, known[0][:k], known[1][:, :k], m, opts, info)
                basis._cache_path = path
                return basis
        lam, U, info = laplacian_eigenpairs(
            V,
            F,
            k,
            laplacian=laplacian,
            mass=mass,
            progress=progress,
            known=None if known is None else known[:2],
        )
        info.messages[:0] = msgs
        basis = cls(V, F, lam, U, m, opts, info)
        basis._cache_path = path
        basis._write_cache()
        return basis

    def _write_cache(self) -> None:
        path = self._cache_path
        if path is None:
            return
        try:
            path.parent.mkdir(parents=True, exist_ok=True)
            self.save(path)
            self.info.cache_path = str(path)
        except (OSError, MeshError) as exc:
            self.info.messages.append(f"could not write the cache file {path}: {exc}")

    def save(self, path: str | os.PathLike, *, overwrite_inputs: Any = ()) -> None:
        """Write the basis as ``.npz`` (atomically: temporary file and ``os.replace``), in the
        cache format; :meth:`load` reads it back for the same mesh and options."""
        _write_npz(
            Path(path),
            {
                "format": np.array(CACHE_FORMAT),
                "key": np.array(mesh_key(self.V, self.F, self.options)),
                "options": np.array(json.dumps(self.options, sort_keys=True)),
                "eigenvalues": self.eigenvalues,
                "vectors": self.vectors,
                "mass": self.mass,
                "n_faces": np.array(len(self.F)),
            },
            overwrite_inputs,
        )

    @classmethod
    def load(
        cls,
        path: str | os.PathLike,
        V: FloatArray,
        F: IntArray,
        *,
        laplacian: LaplacianKind = "cotan",
        mass: AreaKind = MASS_AREA,
    ) -> SpectralBasis:
        """Load a basis written by :meth:`save` for the mesh ``(V, F)``; every check of the
        cache applies (a file for another mesh or options raises :class:`MeshError`)."""
        V, F = as_mesh(V, F)
        opts = _options(laplacian, mass)
        K, m = spectral_operators(V, F, laplacian, mass)
        try:
            with np.load(path, allow_pickle=False) as data:
                lam, U, orth = _validate_arrays(data, mesh_key(V, F, opts), opts, K, m)
        except MeshError:
            raise
        except Exception as exc:
            raise MeshError(f"not a usable spectral basis: {exc}", os.fspath(path)) from None
        info = SolveInfo(
            method="file",
            n_vertices=len(V),
            k=len(lam),
            cache_path=os.fspath(path),
            n_components=_components(K)[0],
            orthogonality_error=orth,
        )
        return cls(V, F, lam, U, m, opts, info)

    # ---- basic accessors -----------------------------------------------------------------

    @property
    def k_max(self) -> int:
        """Number of computed modes."""
        return int(self.vectors.shape[1])

    @property
    def n_vertices(self) -> int:
        return len(self.V)

    def eigenfunction(self, i: int) -> FloatArray:
        """Eigenfunction ``i`` (0-based) as a per-vertex scalar field ``(n,)`` (a copy);
        extends the basis if ``i >= k_max``."""
        i = int(i)
        if i < 0:
            raise MeshError(f"must be >= 0, got {i}", "i")
        self.ensure(i + 1)
        return self.vectors[:, i].copy()

    def coefficients(self, X: FloatArray | None = None, k: int | None = None) -> FloatArray:
        """Spectral coefficients ``U_kᵀ M X`` (``(k, d)``); ``X`` defaults to ``V``."""
        k = self.k_max if k is None else int(k)
        self.ensure(k)
        with self._lock:
            if X is None:
                return self._coeffs[:k].copy()
            Xa = self._field(X)
            return self.vectors[:, :k].T @ (self.mass[:, None] * Xa)

    def _field(self, X: FloatArray) -> FloatArray:
        Xa = np.asarray(X, dtype=np.float64)
        if Xa.ndim == 1:
            Xa = Xa[:, None]
        if Xa.ndim != 2 or len(Xa) != self.n_vertices or not np.isfinite(Xa).all():
            raise MeshError(
                f"should be a finite (n,) or (n,d) per-vertex field with n = {self.n_vertices};"
                f" shape is {np.shape(X)}",
                "X",
            )
        return Xa

    # ---- extension -----------------------------------------------------------------------

    def ensure(self, k: int, progress: ProgressCallback | None = None) -> None:
        """Make at least ``k`` modes available, extending the basis if needed: from the cache
        when it holds enough modes, else by solving for the new modes only (the known ones
        are deflated). The solve runs without holding the reconstruction lock, so another
        thread keeps reconstructing with the modes it already has; call it from a worker
        thread for large extensions (``reconstruct(k)`` beyond ``k_max`` calls it too)."""
        k = _check_k(k, self.n_vertices, "k")
        if k <= self.k_max:
            return
        with self._extend_lock:
            if k <= self.k_max:
                return
            lap = self.options["laplacian"]
            mass = self.options["mass"] if lap == "cotan" else "voronoi"
            K, m = spectral_operators(self.V, self.F, lap, mass)  # type: ignore[arg-type]
            msgs: list[str] = []
            got = None
            if self._cache_path is not None:
                got = _read_cache(
                    self._cache_path,
                    mesh_key(self.V, self.F, self.options),
                    self.options,
                    K,
                    m,
                    msgs,
                )
            if got is not None and len(got[0]) >= k:
                lam, U = got[0][:k], got[1][:, :k]
                info = SolveInfo(
                    method="cache",
                    n_vertices=self.n_vertices,
                    k=k,
                    from_cache=True,
                    cache_path=str(self._cache_path),
                    messages=msgs,
                    n_components=self.info.n_components,
                    orthogonality_error=got[2],
                )
                write = False
            else:
                with self._lock:
                    known = (self.eigenvalues, self.vectors)
                if got is not None and len(got[0]) > len(known[0]):
                    known = (got[0], got[1])
                lam, U, info = laplacian_eigenpairs(
                    self.V,
                    self.F,
                    k,
                    laplacian=lap,
                    mass=mass,  # type: ignore[arg-type]
                    progress=progress,
                    known=known,
                )
                info.messages[:0] = msgs
                write = True
            with self._lock:
                self.eigenvalues, self.vectors, self.info = lam, np.asfortranarray(U), info
                self._reset_reconstruction()
            if write:
                self._write_cache()

    # ---- reconstruction ------------------------------------------------------------------

    def _reset_reconstruction(self) -> None:
        n, kmax = self.vectors.shape
        with _blas_threads(1, self._threads):
            self._coeffs = self.vectors.T @ (self.mass[:, None] * self.V)  # (k_max, 3)
        # checkpoints R_j = U_j c_j every `stride` modes (<= ~64 MB), built on first use
        budget = 64 << 20
        per = max(1, n * 3 * 8)
        self._stride = max(16, -(-kmax // max(1, budget // per)))
        self._checkpoints: dict[int, FloatArray] | None = None
        self._cur_k = 0
        self._cur = np.zeros((n, 3))

    def _build_checkpoints(self) -> None:  # (called with the BLAS threads limited)
        n, kmax = self.vectors.shape
        cps = {0: np.zeros((n, 3))}
        R = np.zeros((n, 3))
        for j0 in range(0, kmax, self._stride):
            j1 = min(j0 + self._stride, kmax)
            R = R + self.vectors[:, j0:j1] @ self._coeffs[j0:j1]
            if j1 % self._stride == 0 or j1 == kmax:
                cps[j1] = R
        self._checkpoints = cps

    def reconstruct(self, k: int, X: FloatArray | None = None) -> FloatArray:
        """Spectral reconstruction ``U_k U_kᵀ M X`` from the first ``k`` modes (``0 <= k``).

        With ``X = None`` (the vertices) the coefficients are cached and the result is updated
        from the previous ``k`` or the nearest stored checkpoint, so any move of ``k`` costs
        ``O(n · min(|Δk|, stride/2))``. Asking for ``k > k_max`` extends the basis.

        Returns
        -------
        Xk : (n,3) float (or ``(n,d)`` for a given ``X``), a new array
        """
        k = int(k)
        if k < 0:
            raise MeshError(f"must be >= 0, got {k}", "k")
        if k > 0:
            self.ensure(k)
        if X is not None:
            Xa = self._field(X)
            Uk = self.vectors[:, :k]
            out = Uk @ (Uk.T @ (self.mass[:, None] * Xa))
            return out if np.ndim(X) == 2 else out[:, 0]
        with self._lock, _blas_threads(1, self._threads):
            if self._checkpoints is None:
                self._build_checkpoints()
            assert self._checkpoints is not None
            cp = min(self._checkpoints, key=lambda j: abs(j - k))
            if abs(cp - k) < abs(self._cur_k - k):
                start, R = cp, self._checkpoints[cp].copy()
            else:
                start, R = self._cur_k, self._cur
            if k > start:
                R += self.vectors[:, start:k] @ self._coeffs[start:k]
            elif k < start:
                R -= self.vectors[:, k:start] @ self._coeffs[k:start]
            self._cur_k, self._cur = k, R
            return R.copy()

    def vertex_error(self, k: int, X: FloatArray | None = None) -> FloatArray:
        """Per-vertex reconstruction error ``|x_i − x̂_i|`` with ``k`` modes, ``(n,)``."""
        Xa = self.V if X is None else self._field(X)
        R = self.reconstruct(k, X)
        return np.linalg.norm(Xa - R.reshape(Xa.shape), axis=1)

    def errors(self, X: FloatArray | None = None, k_max: int | None = None) -> ReconstructionErrors:
        """Error statistics for every ``k = 0 … k_max`` in one pass.

        The reconstructions of all ``k`` are cumulative sums over the modes, evaluated in
        chunks of vertices, so the cost is ``O(n · k_max · d)`` (not ``k_max`` separate
        reconstructions) and the memory ``O(chunk · k_max · d)``.
        """
        kmax = self.k_max if k_max is None else int(k_max)
        self.ensure(max(kmax, 1))
        Xa = self.V if X is None else self._field(X)
        with self._lock:
            U = self.vectors
            c = self._coeffs[:kmax] if X is None else U[:, :kmax].T @ (self.mass[:, None] * Xa)
        n, dim = Xa.shape
        sums = np.zeros(kmax + 1)
        sq = np.zeros(kmax + 1)
        wsq = np.zeros(kmax + 1)
        mx = np.zeros(kmax + 1)
        chunk = max(1, (1 << 20) // max(1, kmax * dim))  # ~8 MB blocks stay in cache
        with _blas_threads(1, self._threads):
            self._error_pass(Xa, U, c, chunk, sums, sq, wsq, mx)
        diag = float(np.linalg.norm(Xa.max(axis=0) - Xa.min(axis=0)))
        return ReconstructionErrors(
            k=np.arange(kmax + 1),
            mean=sums / n,
            max=mx,
            rms=np.sqrt(sq / n),
            l2=np.sqrt(wsq / self.mass.sum()),
            diagonal=diag if diag > 0 else 1.0,
        )

    def _error_pass(
        self,
        Xa: FloatArray,
        U: FloatArray,
        c: FloatArray,
        chunk: int,
        sums: FloatArray,
        sq: FloatArray,
        wsq: FloatArray,
        mx: FloatArray,
    ) -> None:
        n, kmax = len(Xa), len(c)
        for r0 in range(0, n, chunk):
            r1 = min(n, r0 + chunk)
            Xr = Xa[r0:r1]
            P = U[r0:r1, :kmax][:, :, None] * c[None, :, :]  # (rows, k, d)
            np.cumsum(P, axis=1, out=P)
            P -= Xr[:, None, :]
            e = np.empty((r1 - r0, kmax + 1))
            e[:, 0] = np.linalg.norm(Xr, axis=1)
            e[:, 1:] = np.sqrt(np.einsum("rkd,rkd->rk", P, P))
            sums += e.sum(axis=0)
            sq += (e * e).sum(axis=0)
            wsq += self.mass[r0:r1] @ (e * e)
            np.maximum(mx, e.max(axis=0), out=mx)


def compute_basis(
    V: FloatArray,
    F: IntArray,
    k: int,
    *,
    laplacian: LaplacianKind = "cotan",
    mass: AreaKind = MASS_AREA,
    cache: bool = True,
    cache_dir: str | os.PathLike | None = None,
    progress: ProgressCallback | None = None,
) -> SpectralBasis:
    """One-shot wrapper of :meth:`SpectralBasis.compute`."""
    return SpectralBasis.compute(
        V,
        F,
        k,
        laplacian=laplacian,
        mass=mass,
        cache=cache,
        cache_dir=cache_dir,
        progress=progress,
    )


def reconstruct(
    V: FloatArray,
    F: IntArray,
    k: int,
    *,
    laplacian: LaplacianKind = "cotan",
    mass: AreaKind = MASS_AREA,
    cache: bool = False,
) -> FloatArray:
    """Spectral reconstruction of the vertices from their ``k`` lowest modes, ``(n,3)``."""
    return compute_basis(V, F, k, laplacian=laplacian, mass=mass, cache=cache).reconstruct(k)
