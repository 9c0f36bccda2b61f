"""One slice of spectrum slicing: factor at a shift, run block Lanczos until the interval's
eigenpairs have converged, count the inertia.

The pencil is the symmetric scaled ``A = M^-½ K M^-½`` of ``K u = λ M u``; vectors are in
``y = M^½ u`` coordinates. Mesh-free.
"""

from __future__ import annotations

import threading
import time
from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp

from .common import FloatArray, ProgressCallback, cancel_check
from .factor import ShiftInvert, SymbolicOrdering
from .lanczos import BlockLanczos

LAMBDA_TOL = 1e-6  # relative residual ||K u − λ M u||_{M⁻¹} / λ of every pair
EDGE_TOL = 1e-4  # residual of the nearest Ritz value outside a slice's interval
CHECK_EVERY = 8  # convergence checks at least every j/CHECK_EVERY Lanczos vectors


@dataclass
class SliceSpec:
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
    # columns of the caller's store the Ritz vectors are written into when they fit (the
    # lowest slice: 575 MB not copied, nor faulted in twice, at 692k vertices and k = 100)
    out: FloatArray | None = None


@dataclass
class SliceResult:
    spec: SliceSpec
    sigma: float
    n_below: int  # eigenvalues below sigma (inertia)
    lam: FloatArray
    Y: FloatArray
    krylov_dim: int
    n_applied: int
    seconds: float
    check: tuple[float, int] | None = None  # (shift, eigenvalues below it) near the top


class SliceCancelled(Exception):
    """The solve was cancelled (by the progress callback or another slice's error)."""


class SliceContext:
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
        self.A = scaled_pencil(K, 1.0 / self.d)  # M^-1/2 K M^-1/2
        self.ordering = SymbolicOrdering(self.n)
        self.Zy = Zy if Zy.shape[1] else None
        self.tol, self.block, self.target = tol, block, target
        self.base_count = base_count
        self.scale = float(K.diagonal().sum() / (self.n * m.sum()))
        self._progress = progress
        self._check = cancel_check(progress)  # the caller's cancel, polled between blocks
        self._lock = threading.Lock()
        self._converged: dict[int, int] = {}
        self._done_count = 0
        self.cancel = threading.Event()
        self.error: BaseException | None = None
        self.local = threading.local()  # per worker thread: a spare factorization to reuse
        self.inertia: dict[int, tuple[float, int]] = {}  # slice -> (shift, eigenvalues below)

    def poll(self) -> bool:
        """Whether to stop: another slice failed, or the caller's ``cancel`` was set (then
        :attr:`error` is its :class:`~meshlap_core.errors.Cancelled`)."""
        if self.cancel.is_set():
            return True
        if self._check is not None:
            try:
                self._check()
            except BaseException as exc:
                with self._lock:
                    if self.error is None:
                        self.error = exc
                self.cancel.set()
                return True
        return False

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


def scaled_pencil(K: sp.csr_matrix, s: FloatArray) -> sp.csr_matrix:
    """``diag(s) K diag(s)`` (CSR, the pattern of ``K``) by scaling the stored entries: one
    pass over them instead of two sparse products (about 1 s at 692k vertices)."""
    K = sp.csr_matrix(K)
    rows = np.repeat(np.arange(K.shape[0]), np.diff(K.indptr))
    data = K.data * s[rows] * s[K.indices]
    return sp.csr_matrix((data, K.indices.copy(), K.indptr.copy()), shape=K.shape)


def _convergence(
    ctx: SliceContext, spec: SliceSpec, lz: BlockLanczos, sigma: float
) -> tuple[FloatArray, FloatArray, FloatArray, FloatArray, float]:
    """Ritz pairs of the slice's Lanczos basis and how far they are from converged.

    Returns ``(lam, S, inside, conv, worst)``: the Ritz values ``λ = σ + 1/θ``, their
    ``T``-eigenvectors, the mask of those in the slice's interval, the mask of converged pairs,
    and the decades of residual still missing (``<= 0``: done).
    """
    b = ctx.block
    th, S, res, C = lz.ritz(lz.j)
    with np.errstate(divide="ignore"):
        lam = sigma + 1.0 / th
    # Two residuals. Of the shift-inverted pair, relative to |θ|. And in the pencil: with
    # μ = σ + 1/θ, (A − μ)y = −(A − σ)(Op y − θy)/θ = −(A − σ)q̃ C/θ, exactly and cheaply
    # (one sparse product with the next block). The first alone lets eigenvalues far
    # from the shift (λ ≪ σ in the lowest slice) keep λ-relative residuals up to
    # tol·λ_max/λ (1e-3 on meshes of slivers); the second asks for LAMBDA_TOL relative
    # to λ. (It is an estimate from the Lanczos relation, so it keeps falling as Lanczos
    # converges: no round-off floor can stall it.)
    Qn = lz.Q[:, lz.j : lz.j + b]
    Z = ctx.A @ Qn - sigma * Qn
    G = Z.T @ Z
    ath = np.maximum(np.abs(th), 1e-300)
    rlam = np.sqrt(np.maximum(np.einsum("ij,ij->j", C, G @ C), 0.0)) / ath
    # each pair's residual over its tolerance (converged at <= 1)
    ratio = np.maximum(res / ath / ctx.tol, rlam / np.maximum(LAMBDA_TOL * np.abs(lam), 1e-300))
    conv = ratio <= 1.0
    if spec.count is None:
        hi = spec.hi
    else:  # the `count` lowest Ritz values >= lo
        cand = np.sort(lam[lam >= spec.lo])
        hi = cand[spec.count] if len(cand) > spec.count else np.inf
    inside = (lam >= spec.lo) & (lam < hi)
    # decades still missing: every inside Ritz pair to `tol`, and the nearest Ritz value
    # outside on each bounded side to `EDGE_TOL` (resolved well enough to be sure it is
    # outside, so nothing inside is still undiscovered)
    worst = float(np.log10(np.maximum(ratio[inside], 1e-300)).max(initial=-1.0))
    for side in ("above", "below"):
        if side == "below" and not spec.check_below:
            continue
        out = np.flatnonzero(lam >= hi if side == "above" else lam < spec.lo)
        if len(out) == 0 or not np.isfinite(hi):
            worst = max(worst, 3.0)  # not even approximated yet
            continue
        nearest = out[np.argmin(np.abs(lam[out] - sigma))]
        worst = max(worst, float(np.log10(max(ratio[nearest] * ctx.tol, 1e-300) / EDGE_TOL)))
    return lam, S, inside, conv, worst


def _top_check(
    ctx: SliceContext, ls: FloatArray, rng: np.random.Generator, spare: object
) -> tuple[tuple[float, int] | None, object]:
    """The inertia check just above λ_k, done in a gap between the two top eigenvalues ``ls``
    of the top slice (everything below them is in this slice or a lower one): with two
    workers it overlaps the other slice instead of following both. Returns the
    ``(shift, eigenvalues below it)`` (or ``None``: no gap) and the spare factorization."""
    gaps = np.flatnonzero(np.diff(ls) > 1e-7 * np.maximum(np.abs(ls[1:]), ctx.scale))
    if not len(gaps):
        return None, spare
    t = int(gaps[-1])
    chk = ShiftInvert(
        ctx.A,
        0.5 * (ls[t] + ls[t + 1]),
        rng=rng,
        spacing=ls[t + 1] - ls[t],
        ordering=ctx.ordering,
        reuse=spare,
    )
    return (chk.sigma, chk.n_below), chk.factor


def _vectors_and_top_check(
    ctx: SliceContext,
    lz: BlockLanczos,
    S: FloatArray,
    ls: FloatArray,
    rng: np.random.Generator,
    spare: object,
    out: FloatArray | None = None,
) -> tuple[FloatArray, tuple[float, int] | None, object]:
    """The Ritz vectors ``Q S`` of the top slice and its inertia check (:func:`_top_check`)
    at the same time: the ``n × j`` by ``j × s`` product (numpy, without the GIL) in a helper
    thread while this one factors (CHOLMOD holds the GIL). At 692k vertices and k = 100
    they take about 3 s and 4 s of CPU, one after the other before. ``out``: see
    :meth:`BlockLanczos.vectors`. Returns ``(Y, check, spare)``."""
    import concurrent.futures as cf

    started = threading.Event()

    def vectors() -> FloatArray:
        started.set()
        return lz.vectors(S, out)

    with cf.ThreadPoolExecutor(max_workers=1) as helper:
        fut = helper.submit(vectors)
        started.wait(1.0)  # (the helper is in numpy's product, not waiting for the GIL)
        check, spare = _top_check(ctx, ls, rng, spare)
        Y = fut.result()
    return Y, check, spare


def run_slice(ctx: SliceContext, spec: SliceSpec, seed: int) -> SliceResult:
    """Factor at ``spec.sigma`` and run block Lanczos until every Ritz value in
    ``[lo, hi)`` has converged, and so have the nearest Ritz values outside on each bounded
    side (so nothing inside is still undiscovered); inertia then double-checks the counts."""
    t0 = time.perf_counter()
    rng = np.random.default_rng([seed, spec.index])
    b = ctx.block
    width = spec.hi - max(spec.lo, 0.0)
    # (the factorization of this thread's previous slice, done with, is refactored in place)
    spare, ctx.local.spare = getattr(ctx.local, "spare", None), None
    op = ShiftInvert(
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
    lz = BlockLanczos(op, ctx.n, b, X, rng, capacity=int(3.2 * spec.expected) + 16 * b)
    next_check = max(2 * b, int(0.8 * spec.expected) // b * b)
    prev: tuple[int, float] | None = None
    while True:
        if ctx.poll():
            raise SliceCancelled
        lz.step()
        if lz.j < next_check and not lz.exhausted:
            continue
        lam, S, inside, conv, worst = _convergence(ctx, spec, lz, op.sigma)
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
        step = max(b, (lz.j // CHECK_EVERY) // b * b)
        if prev is not None and prev[1] > worst:
            rate = (prev[1] - worst) / (lz.j - prev[0])  # decades per basis vector
            step = int(min(step, max(b, -(-int(np.ceil(worst / rate)) // b) * b)))
        prev = (lz.j, worst)
        next_check = lz.j + step
    sigma_used, n_below, j_used, n_applied = op.sigma, op.n_below, lz.j, lz.n_applied
    sel = np.flatnonzero(inside if lz.exhausted else inside & conv)
    sel = sel[np.argsort(lam[sel], kind="stable")]
    spare: object = op.factor
    check = None
    if spec.check_top and not ctx.cancel.is_set():
        Y, check, spare = _vectors_and_top_check(ctx, lz, S[:, sel], lam[sel], rng, spare, spec.out)
    else:
        Y = lz.vectors(S[:, sel], spec.out)
    del lz, op
    ctx.local.spare = spare
    ctx.finished(spec.index, len(sel))
    return SliceResult(
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
