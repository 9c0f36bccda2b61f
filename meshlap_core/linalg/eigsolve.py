"""The generalized symmetric eigensolver: the ``k`` smallest eigenpairs of ``K u = λ M u``.

``K`` symmetric positive semidefinite and sparse, ``M = diag(m) > 0``. The solver works on the
symmetric scaled pencil ``A = M^-½ K M^-½`` (same eigenvalues, ``y = M^½ u``):

* one eigenvalue 0 per connected component of the sparsity graph of ``K``, with the normalized
  indicator as eigenvector, deflated exactly (:func:`null_space`);
* small problems (or ``k`` close to ``n``): dense ``eigh`` (:func:`dense_eigenpairs`);
* otherwise shift-invert block Lanczos with spectrum slicing
  (:class:`~meshlap_core.linalg.slicing.SlicedLanczos`): ``[0, λ_k]`` is cut into consecutive
  intervals holding ~64 eigenvalues each (~128 for the lowest with one worker; equal slices, an
  even number of them, with two), planned with Weyl's law ``N(λ) ≈ area·λ/4π`` and then with
  the density the inertia counts at the shifts measure; slices run in two threads when two
  cores are idle. Every interval gets a shift in its middle and an ``LDLᵀ`` factor without
  pivoting (QDLDL, AMD ordering; SuperLU in symmetric mode as fallback,
  :mod:`~meshlap_core.linalg.factor`); a singular matrix is never factored. Block Lanczos
  (block 4) with delayed classical Gram–Schmidt against the slice's own basis (DCGS2,
  :mod:`~meshlap_core.linalg.lanczos`) runs until every Ritz value in the interval has a
  relative residual below 1e-8 and the nearest ones outside are resolved. Orthogonalizing only
  within a slice is what makes large ``k`` cheap: ``O(n·k·s)`` vector work instead of the
  ``O(n·k²)`` of a single Lanczos run, for slices of ``s`` eigenvalues.
* Sylvester's law of inertia checks the result: the signs of ``D`` at every shift, and at one
  more shift in a gap just above ``λ_k``, count the eigenvalues below it, which must equal the
  number found; a deficit is searched for again with the found vectors deflated. Slices are
  finally orthonormalized together (Löwdin, :func:`lowdin`).
* Every pair's residual in the pencil is then measured; pairs above the promised 1e-8
  (:data:`~meshlap_core.linalg.refine.PROMISED_RESIDUAL`) are refined by inverse iteration
  and Rayleigh–Ritz (:mod:`~meshlap_core.linalg.refine`), and a result that still misses it
  is refused. So the accuracy does not depend on the slice plan, which depends on the
  number of workers, which depends on how busy the machine is.

Mesh-free: the mesh pencil is assembled by :mod:`meshlap_core.spectral.operators`.

References
----------
Grimes, Lewis & Simon, "A shifted block Lanczos algorithm for solving sparse symmetric
generalized eigenproblems", 1994 (shifts, inertia, slicing). Vallet & Lévy, "Spectral geometry
processing with manifold harmonics", 2008 (band-by-band shift-invert).
"""

from __future__ import annotations

import time
from typing import Any, Literal

import numpy as np
import scipy.linalg as sla
import scipy.sparse as sp
from scipy.linalg import blas

from ..errors import MeshError, check_cancel
from .blas import blas_threads as limit_blas_threads
from .checks import RESIDUAL_TOL, inertia_check, orthogonality, pair_residuals
from .common import (
    CancellableProgress,
    FloatArray,
    IntArray,
    ProgressCallback,
    SolveInfo,
    report_progress,
    with_cancel,
)
from .components import component_scales, components, null_space, scale_groups, solve_by_groups
from .factor import ldl_backend
from .refine import PROMISED_RESIDUAL, ScaledPencil, refine_pairs
from .slicing import SlicedLanczos, default_workers

# Dense solver below this many vertices (or when k is a large fraction of n).
DENSE_MAX_N = 1500
# Sparse solver refuses k above this fraction of n on problems too big for the dense solver.
SPARSE_MAX_FRACTION = 0.5
DENSE_HARD_MAX_N = 8000

# Lanczos parameters.
BLOCK = 4  # block size (handles eigenvalue multiplicities up to 4 without relying on round-off)
TOL = 1e-8  # relative residual of the shift-inverted Ritz pairs: ||Op y − θ y|| <= tol |θ|
SLICE = 64  # eigenpairs per slice with an interior shift (LDLᵀ solves)
FIRST_SLICE = 128  # eigenpairs in the lowest slice (one worker; one-sided: no neighbour below)


def dense_eigenpairs(
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


def lowdin(Y: FloatArray, helper: Any | None = None) -> float:
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


SIGN_TIE = 1e-6
"""Entries within this relative distance of a column's largest magnitude count as tied for
the sign rule (:func:`fix_signs`)."""


def fix_signs(U: FloatArray) -> None:
    """Deterministic sign: the entry of largest magnitude of each column is positive; among
    entries tied with it (within :data:`SIGN_TIE`, as on a symmetric mesh, where the largest
    magnitude is reached at mirror vertices with opposite signs), the first one.

    The tie rule makes the sign independent of round-off: two solves whose vectors differ by
    1e-12 (another slice plan, a refined pair) would otherwise pick different vertices of a
    tie and opposite signs. Column by column on an F-ordered ``U`` (no ``n × k`` temporary:
    550 MB at 692k vertices and k = 100), and only the columns that change sign are
    rewritten."""
    k = U.shape[1]
    if k == 0:
        return
    if U.flags.f_contiguous:
        idx = np.empty(k, dtype=np.int64)
        for j in range(k):
            a = np.abs(U[:, j])
            idx[j] = int(np.argmax(a >= (1.0 - SIGN_TIE) * a.max()))
    else:
        a = np.abs(U)
        idx = np.argmax(a >= (1.0 - SIGN_TIE) * a.max(axis=0)[None, :], axis=0)
    for j in np.flatnonzero(U[idx, np.arange(k)] < 0):
        U[:, j] *= -1.0


def pencil_eigenpairs(
    K: sp.spmatrix,
    m: FloatArray,
    k: int,
    *,
    progress: ProgressCallback | None = None,
    cancel: Any = None,
    known: tuple[FloatArray, FloatArray] | None = None,
    method: Literal["auto", "dense", "sparse"] = "auto",
    tol: float = TOL,
    block: int = BLOCK,
    slice_size: int = SLICE,
    first_slice: int = FIRST_SLICE,
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
    cancel : threading.Event or callable, optional
        Checked between Lanczos blocks (and at every report): once set (or returning
        ``True``) the solve stops with :class:`~meshlap_core.errors.Cancelled`.
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

    Components whose frequency scales differ by more than
    :data:`~meshlap_core.linalg.components.SCALE_GAP` are solved group by group, each with its
    own shifts. Every result is checked before it is returned: the residual of every pair
    (at most :data:`~meshlap_core.linalg.refine.PROMISED_RESIDUAL` for the sparse solver,
    after refining the pairs above it; :data:`~meshlap_core.linalg.checks.RESIDUAL_TOL` for
    the dense one) and, for the dense solver, Sylvester's inertia at a gap; a result that
    fails raises :class:`MeshError`.

    (Over 80 lines only because of this docstring: the body is ~35 lines.)
    """
    t0 = time.perf_counter()
    progress = with_cancel(progress, cancel, "eigensolve")
    if cancel is not None:
        check_cancel(cancel, "eigensolve")
    K, m, k = _checked_pencil(K, m, k)
    ncomp, labels = components(K)
    groups = scale_groups(component_scales(K, m, labels, ncomp)) if ncomp > 1 else []
    tuning = {"tol": tol, "block": block, "slice_size": slice_size, "first_slice": first_slice}
    refine, pencil = False, None  # (each group refines its own sparse result)
    if len(groups) > 1:
        _use_dense(method, len(m), k)  # (checks the method's name)
        lam, U, info = _grouped_eigenpairs(
            K,
            m,
            k,
            labels,
            groups,
            method=method,
            progress=progress,
            tuning=tuning,
            workers=workers,
            blas_threads_=blas_threads,
        )
    else:
        lam, U, info, pencil = _solve(
            K,
            m,
            k,
            labels,
            ncomp,
            method=method,
            progress=progress,
            known=known,
            tuning=tuning,
            workers=workers,
            blas_threads_=blas_threads,
            density=density,
        )
        refine = not _use_dense(method, len(m), k)
    info.timings["eigensolve"] = time.perf_counter() - t0
    # (one BLAS thread, as in the solve: OpenBLAS's threads on these n × k products doubled
    # the check's time at 43k vertices on a busy machine, 0.35 s against 0.19 s)
    with limit_blas_threads(1 if blas_threads is None else max(1, int(blas_threads))):
        lam, U = _check_result(K, m, lam, U, labels, info, refine=refine, pencil=pencil)
    return lam, U, info


def _grouped_eigenpairs(
    K: sp.csr_matrix,
    m: FloatArray,
    k: int,
    labels: IntArray,
    groups: list[IntArray],
    *,
    method: str,
    progress: ProgressCallback | None,
    tuning: dict[str, Any],
    workers: int | None,
    blas_threads_: int | None,
) -> tuple[FloatArray, FloatArray, SolveInfo]:
    """:func:`pencil_eigenpairs` group by group (components of very different scale, see
    :func:`~meshlap_core.linalg.components.solve_by_groups`): each group's sub-pencil gets its
    own solve, shifts and checks; known pairs are not reused."""

    def solve(Kg: sp.csr_matrix, mg: FloatArray, kg: int, g: int) -> Any:
        sub = method if method != "sparse" or kg <= SPARSE_MAX_FRACTION * len(mg) else "auto"
        return pencil_eigenpairs(
            Kg,
            mg,
            kg,
            method=sub,  # type: ignore[arg-type]
            progress=_group_progress(progress, g, len(groups)),
            workers=workers,
            blas_threads=blas_threads_,
            **tuning,
        )

    lam, U, info = solve_by_groups(K, m, k, labels, groups, solve)
    info.messages.insert(
        0,
        f"components of very different scale: solved in {len(groups)} groups, each with "
        "its own shifts (one solve would lose the small eigenvalues to round-off)",
    )
    return lam, U, info


def _group_progress(
    progress: ProgressCallback | None, g: int, count: int
) -> ProgressCallback | None:
    """``progress`` for group ``g`` of ``count``: its fractions mapped into ``[g, g+1]/count``."""
    if progress is None:
        return None
    outer = progress

    def inner(f: float, msg: str) -> None:
        outer((g + f) / count, f"group {g + 1}/{count}: {msg}")

    if isinstance(progress, CancellableProgress):  # the slices keep polling the same cancel
        return CancellableProgress(inner, progress.cancel, progress.what)
    return inner


def _check_result(
    K: sp.csr_matrix,
    m: FloatArray,
    lam: FloatArray,
    U: FloatArray,
    labels: IntArray,
    info: SolveInfo,
    *,
    refine: bool,
    pencil: ScaledPencil | None = None,
) -> tuple[FloatArray, FloatArray]:
    """Measure every pair's residual (one sparse product) and the orthonormality into
    ``info``. With ``refine`` (a result of the sparse solver), pairs above
    :data:`PROMISED_RESIDUAL` are refined (:func:`~meshlap_core.linalg.refine.refine_pairs`)
    and a result still above it is refused; any result with a pair above
    :data:`RESIDUAL_TOL` is refused (:class:`MeshError`). Returns ``(lam, U)`` (refined or not)."""
    t1 = time.perf_counter()
    res = pair_residuals(K, m, lam, U, labels)
    promised = refine
    if promised and not np.all(res <= PROMISED_RESIDUAL):
        before = float(np.nanmax(res))
        lam, U, res, done = refine_pairs(K, m, lam, U, labels, res, pencil=pencil)
        sub = U[:, done.columns]  # (the sign rule on the changed columns only)
        fix_signs(sub)
        U[:, done.columns] = sub
        info.messages.append(
            f"{done.pairs} eigenpair(s) refined in {done.rounds} round(s) (inverse iteration, "
            f"Rayleigh-Ritz): max relative residual {before:.1e} -> {float(np.nanmax(res)):.1e}"
        )
        info.timings["refinement"] = time.perf_counter() - t1
    info.max_residual = float(res.max(initial=0.0))
    info.orthogonality_error = orthogonality(U, m)
    info.timings["residual_check"] = time.perf_counter() - t1
    limit = PROMISED_RESIDUAL if promised else RESIDUAL_TOL
    bad = np.flatnonzero(~(res <= limit))
    if len(bad):
        j = int(bad[np.argmax(np.where(np.isfinite(res[bad]), res[bad], np.inf))])
        raise MeshError(
            f"the eigensolver's result fails its check: {len(bad)} of {len(lam)} eigenpairs "
            f"have a relative residual above {limit:.0e} (pair {j}, lambda = "
            f"{lam[j]:.6g}: {res[j]:.1e}){' after refinement' if promised else ''}; the "
            "eigenproblem is too badly conditioned to solve accurately, so no basis is given",
            "K",
        )
    return lam, U


def _solve(
    K: sp.csr_matrix,
    m: FloatArray,
    k: int,
    labels: IntArray,
    ncomp: int,
    *,
    method: str,
    progress: ProgressCallback | None,
    known: tuple[FloatArray, FloatArray] | None,
    tuning: dict[str, Any],
    workers: int | None,
    blas_threads_: int | None,
    density: float | None,
) -> tuple[FloatArray, FloatArray, SolveInfo, ScaledPencil | None]:
    """:func:`pencil_eigenpairs` on a pencil whose components have comparable scales: the
    exact null space, then the dense or the sparse solver; ``(lam, U, info, pencil)``
    (``pencil``: that of the sparse solver's slices, else ``None``)."""
    n = len(m)
    info = SolveInfo(n_vertices=n, k=k)
    Z = null_space(m, labels, ncomp)
    info.n_components = ncomp
    pencil = None
    if _use_dense(method, n, k):
        info.method = "dense"
        report_progress(progress, 0.0, f"eigensolver: dense, {n} vertices")
        with limit_blas_threads(1):
            lam, Y = dense_eigenpairs(K, m, min(n, k + 2 + k // 50), Z)
            inertia_check(K, m, lam, k)
            info.n_factorizations += 1
            lam, Y = lam[:k], np.asfortranarray(Y[:, :k])
            lowdin(Y)
        report_progress(progress, 1.0, "eigensolver: done")
    else:
        lam, Y, pencil = _sparse_eigenpairs(
            K,
            m,
            k,
            Z,
            info,
            progress=progress,
            known=known,
            tuning=tuning,
            workers=workers,
            blas_threads_=blas_threads_,
            density=density,
        )
    lam, U = _finish(K, m, lam, Y, info)
    return lam, U, info, pencil


def _use_dense(method: str, n: int, k: int) -> bool:
    """Whether ``method`` asks for the dense solver on ``n`` unknowns and ``k`` pairs
    (``"auto"``: ``n <= DENSE_MAX_N`` or ``k > SPARSE_MAX_FRACTION·n``); refuses an unknown
    method and a dense solve above ``DENSE_HARD_MAX_N``."""
    if method not in ("auto", "dense", "sparse"):
        raise MeshError(f"unknown method {method!r}; choose auto, dense or sparse", "method")
    use_dense = method == "dense" or (
        method == "auto" and (n <= DENSE_MAX_N or k > SPARSE_MAX_FRACTION * n)
    )
    if use_dense and n > DENSE_HARD_MAX_N:
        raise MeshError(
            f"k = {k} is more than {SPARSE_MAX_FRACTION:.0%} of the {n} vertices; a basis that "
            f"large needs the dense solver, which is limited to {DENSE_HARD_MAX_N} vertices "
            f"(ask for at most {int(SPARSE_MAX_FRACTION * n)} modes)",
            "k",
        )
    return use_dense


def _checked_pencil(K: Any, m: Any, k: Any) -> tuple[sp.csr_matrix, FloatArray, int]:
    """``K`` as CSR float64 and ``m`` as a flat float64 array, checked (shapes, finite,
    positive masses), and ``k`` checked against ``n``."""
    K = sp.csr_matrix(K, dtype=np.float64)
    m = np.asarray(m, dtype=np.float64).ravel()
    n = len(m)
    if K.shape != (n, n):
        raise MeshError(f"should be ({n},{n}) to match the masses; shape is {K.shape}", "K")
    if not (np.all(np.isfinite(m)) and np.all(m > 0)):
        raise MeshError("masses must be finite and positive", "m")
    if not np.all(np.isfinite(K.data)):
        raise MeshError("has NaN or infinite entries", "K")
    return K, m, check_k(k, n, "k")


def _sparse_eigenpairs(
    K: sp.csr_matrix,
    m: FloatArray,
    k: int,
    Z: FloatArray,
    info: SolveInfo,
    *,
    progress: ProgressCallback | None,
    known: tuple[FloatArray, FloatArray] | None,
    tuning: dict[str, Any],
    workers: int | None,
    blas_threads_: int | None,
    density: float | None,
) -> tuple[FloatArray, FloatArray, ScaledPencil | None]:
    """The sparse path of :func:`pencil_eigenpairs`: sliced shift-invert block Lanczos (or
    the known pairs / the null space alone when they suffice), then Löwdin across slices.
    Returns ``(lam, Y, pencil)`` with ``Y = M^½ U`` and the slices' scaled pencil and
    ordering (for the refinement; ``None`` when no slice ran)."""
    n, ncomp = len(m), Z.shape[1]
    d = np.sqrt(m)
    info.method = "shift-invert block Lanczos, spectrum slicing"
    nw = 1  # slice workers (also the cores the final orthonormalization may use)
    kn = None
    pencil = None
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
        slice_size, first_slice = tuning["slice_size"], tuning["first_slice"]
        if workers is not None:
            nw = max(1, int(workers))
        else:  # (one slice below ~60 modes: no need to sample the machine's load)
            nw = 1 if k < 60 else default_workers(n, max(slice_size, first_slice))
        nb = 1 if blas_threads_ is None else max(1, int(blas_threads_))
        info.messages.append(f"{nw} slice worker(s), {nb} BLAS thread(s), LDLT by {ldl_backend(n)}")
        rho = float(density) if density else float(m.sum() / (4 * np.pi))
        try:
            with limit_blas_threads(nb):
                solver = SlicedLanczos(
                    K,
                    m,
                    k,
                    Z,
                    info,
                    known=kn,
                    progress=progress,
                    workers=nw,
                    weyl_density=rho,
                    **tuning,
                )
                lam, Y = solver.solve()
                pencil = ScaledPencil(solver.ctx.A, solver.ctx.ordering)
        except RuntimeError as exc:  # (inertia counts that cannot be reconciled, no factor)
            raise MeshError(
                f"{exc}; the eigenproblem is too badly conditioned for the solver, so no "
                "basis is given",
                "K",
            ) from None
    t1 = time.perf_counter()
    with limit_blas_threads(1):
        if nw >= 2:
            import concurrent.futures as cf

            with cf.ThreadPoolExecutor(max_workers=1) as helper:
                before = lowdin(Y, helper)
        else:
            before = lowdin(Y)
    if before > 1e-11:
        info.messages.append(
            f"slices orthonormalized together (Lowdin; max|U^T M U - I| was {before:.1e})"
        )
    info.timings["orthonormalization"] = time.perf_counter() - t1
    return lam, Y, pencil


def _finish(
    K: sp.csr_matrix, m: FloatArray, lam: FloatArray, Y: FloatArray, info: SolveInfo
) -> tuple[FloatArray, FloatArray]:
    """Clip round-off below 0 (counted in ``info``), sort, map ``Y = M^½ U`` back to ``U`` (in
    place) and fix the signs; returns ``(lam, U)``."""
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
    U /= np.sqrt(m)[:, None]
    fix_signs(U)
    return lam, U


def check_k(k: Any, n: int, name: str) -> int:
    """``k`` as an int in ``[1, n]``, else :class:`MeshError` naming ``name``."""
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
