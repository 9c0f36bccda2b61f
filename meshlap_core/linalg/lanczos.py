"""Block Lanczos with full reorthogonalization (DCGS2) and Cholesky QR.

Mesh-free: the operator is any symmetric ``op(Y, out)`` on ``n × b`` blocks.
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np
import scipy.linalg as sla
from scipy.linalg import lapack

from .blas import gemm_update, right_solve
from .common import FloatArray

ORTH_LEVEL = 1e-10  # orthogonality kept in the Lanczos basis (classical Gram–Schmidt bound)


def column_sq_norms(W: FloatArray) -> FloatArray:
    """The squared norms of the columns of ``W`` (``(b,)``), without an ``n × b`` temporary."""
    return np.einsum("ij,ij->j", W, W)


def orthonormal_columns(X: FloatArray) -> FloatArray | None:
    """An orthonormal basis (F-ordered) of the span of ``X``; dependent columns dropped."""
    Qx, R, _ = sla.qr(X, mode="economic", pivoting=True, check_finite=False)
    dR = np.abs(np.diag(R))
    r = int(np.count_nonzero(dR > 1e-8 * max(dR.max(initial=0.0), 1e-300)))
    return np.asfortranarray(Qx[:, :r]) if r else None


def chol_qr(
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
        right_solve(W, R)
        Rtot = R @ Rtot
    return Rtot


class BlockLanczos:
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
        self.X = None if X is None or X.shape[1] == 0 else orthonormal_columns(X)
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
        # (preallocated: a fresh n × b array per step costs its page faults again, about a
        # tenth of the solve's CPU time at 692k vertices, where each block is 22 MB)
        self._work = (
            np.empty((n, 2 * block), order="F"),
            np.empty((n, 2 * block), order="F"),
            np.empty((n, block), order="F"),
            np.empty((n, block), order="F"),
        )
        self.Q[:, :block] = self._random_orthonormal(block, 0, None)

    def _project(self, W: FloatArray, ncols: int) -> tuple[FloatArray, FloatArray]:
        """Classical Gram–Schmidt against ``X`` and ``Q[:, :ncols]``; returns
        ``(W, Q_aᵀ W_original)``.

        A pass maps ``e = ||Qᵀw|| / ||w||`` to at most ``κ(δe + ε)`` with ``δ = ||I − QᵀQ||``
        and ``κ = ||w|| / ||w'||`` (``e = 1`` before the first pass). A second pass is
        made only when that estimate would exceed ``ORTH_LEVEL`` (so the basis stays
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
            if est <= ORTH_LEVEL:
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
            gemm_update(W, self.X, self.X.T @ W)
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
            S = chol_qr(q, 1, 0.5)
            if S is None:  # pragma: no cover - see the rank test in _finish_step
                raise RuntimeError("Lanczos: lost orthogonality")
            gemm_update(W, Qt, Rc)
            W -= D[:, b:]
            right_solve(W, S)
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
        gemm_update(V, q, g)
        if self.X is not None:
            # (what the projections against Q cancelled can leave ε·‖W‖/‖V‖ along X; the
            # delayed pass of the next step covers Q only)
            gemm_update(V, self.X, self.X.T @ V)
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
        W = self._work[3]  # (not kept: _finish_step copies the new block into Q)
        self.op(self.Q[:, j0:j1], W)
        self.n_applied += b
        return b, j0, j1, W, float(np.sqrt(column_sq_norms(W).max(initial=0.0)))

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
        elif (R := chol_qr(W, 2, 1e-4, 1e-8 * size)) is not None:
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

    def vectors(self, S: FloatArray, out: FloatArray | None = None) -> FloatArray:
        """Ritz vectors ``Q S`` (``n × S.shape[1]``, F-ordered), written into the leading
        columns of ``out`` (``n × >= S.shape[1]``, F-ordered: the caller's store, so that the
        vectors are not copied there afterwards) when given, else into a new array."""
        s = S.shape[1]
        if out is None or out.shape[0] != self.n or out.shape[1] < s or not out.flags.f_contiguous:
            out = np.empty((self.n, s), order="F")
        else:
            out = out[:, :s]
        np.matmul(self.Q[:, : self.j], np.ascontiguousarray(S), out=out)
        return out


# --------------------------------------------------------------------------------------------
# The eigensolver
# --------------------------------------------------------------------------------------------
