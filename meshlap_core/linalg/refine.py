"""Refinement of computed eigenpairs of ``K u = λ M u`` whose residual misses the promised
accuracy: block inverse iteration at one shift below them, then Rayleigh–Ritz.

The sliced Lanczos solver stops each slice on its own residual estimate; pairs far from their
slice's shift, or mixed a little by the final orthonormalization, can end above
:data:`PROMISED_RESIDUAL`. How far above depends on how the spectrum was cut into slices, and
the cut depends on the number of slice workers (two when two cores are idle, else one): the
same mesh gave ``max_residual`` 1.1e-7 with one worker and 4e-9 with two. Refining what misses
the tolerance makes the result's accuracy the same under every plan.

Mesh-free; vectors in ``y = M^½ u`` coordinates of the scaled pencil ``A = M^-½ K M^-½``.

References
----------
Parlett, *The Symmetric Eigenvalue Problem*, 1998, §4.2 (inverse iteration), §11.4
(Rayleigh–Ritz on a subspace).
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
import scipy.sparse as sp

from .checks import pair_residuals
from .common import FloatArray, IntArray
from .factor import ShiftInvert, SymbolicOrdering
from .slice_worker import scaled_pencil

PROMISED_RESIDUAL = 1e-8
"""Largest relative residual (:func:`~meshlap_core.linalg.checks.pair_residuals`) of any pair
the sparse solver returns: pairs above it are refined (:func:`refine_pairs`) and a result
still above it after :data:`ROUNDS` rounds is refused."""

ROUNDS = 3  # refinement rounds (each: one factorization, ITERATIONS solves of the bad block)
ITERATIONS = 2  # inverse iterations per round
OVERSAMPLING = 8  # random vectors iterated with the bad ones
NEIGHBOURS = 2  # pairs on each side refined with a run of bad pairs in the later rounds
MAX_SHIFTS = 6  # runs of bad pairs refined each with its own shift, in a round after the first


class ScaledPencil(NamedTuple):
    """``A = M^-½ K M^-½`` and its symbolic ordering, as the slices of the solve built them
    (reused: the scaling is a pass over ``K``, the ordering a CHOLMOD analysis)."""

    A: sp.csr_matrix
    ordering: SymbolicOrdering


class Refinement(NamedTuple):
    """What :func:`refine_pairs` did: how many pairs were refined (each counted once), in
    how many rounds, and every column it changed (the refined ones and those Rayleigh–Ritz
    took along; positions after the final sort)."""

    pairs: int
    rounds: int
    columns: IntArray = np.zeros(0, dtype=np.int64)


def refine_pairs(
    K: sp.csr_matrix,
    m: FloatArray,
    lam: FloatArray,
    U: FloatArray,
    labels: IntArray,
    res: FloatArray,
    *,
    tol: float = PROMISED_RESIDUAL,
    rounds: int = ROUNDS,
    pencil: ScaledPencil | None = None,
) -> tuple[FloatArray, FloatArray, FloatArray, Refinement]:
    """Refine the pairs whose residual ``res`` is above ``tol`` until none is (or ``rounds``
    rounds have run).

    The first round factors ``A − σI`` at one shift below every bad eigenvalue
    (``σ = −½ min λ_bad``: positive definite) and iterates the bad vectors (with a few random
    ones) :data:`ITERATIONS` times: a component along the eigenvector of ``λ_j`` shrinks by
    ``(λ_i − σ)/(λ_j − σ)`` against that of ``λ_i``, so the high-frequency round-off that
    dominates a residual is damped by orders of magnitude in one factorization. The later
    rounds take each run of consecutive bad pairs with a shift just below it
    (a tenth of the way to the eigenvalue below), where the nearer eigenvalues above are
    damped too (at most :data:`MAX_SHIFTS` runs a round; more share one shift). Every
    iterate is kept orthogonal to the null space and to the other pairs (eigenvectors
    too), orthonormalized (QR), and the bad pairs are replaced by the lowest Ritz pairs of
    ``A`` on the iterated block (Rayleigh–Ritz). ``A = M^-½ K M^-½``, vectors ``M^½ u``.

    Parameters
    ----------
    K : (n,n) sparse CSR
        Stiffness (symmetric positive semidefinite).
    m : (n,) float
        Masses (``M = diag(m)``).
    lam : (k,) float
        Ascending eigenvalues.
    U : (n,k) float
        ``M``-orthonormal eigenvectors; refined **in place** (a float64 writeable array: no
        ``n × k`` copy, 140 MB at 173k vertices and k = 100) and returned.
    labels : (n,) int
        Component labels (the null space, and the residuals' reference scales).
    res : (k,) float
        The pairs' residuals (:func:`~meshlap_core.linalg.checks.pair_residuals`).
    tol : float
    rounds : int
    pencil : ScaledPencil, optional
        ``A`` and its ordering when the solve has them already.

    Returns
    -------
    lam : (k,) float
        Ascending.
    U : (n,k) float
        ``M``-orthonormal, the input array; each changed column with the sign of the
        column it replaces.
    res : (k,) float
        The residuals of the returned pairs.
    refinement : Refinement
        How many pairs were refined (counted once however many rounds they took), in how
        many rounds.
    """
    bad = np.flatnonzero(~(res <= tol))
    if not len(bad):
        return lam, U, res, Refinement(0, 0)
    d = np.sqrt(m)
    if pencil is None:
        pencil = ScaledPencil(scaled_pencil(K, 1.0 / d), SymbolicOrdering(len(m)))
    A = pencil.A
    n = len(m)
    ncomp = int(labels.max(initial=-1)) + 1
    Zy = np.zeros((n, ncomp), order="F")
    Zy[np.arange(n), labels] = d
    Zy /= np.linalg.norm(Zy, axis=0)[None, :]
    writable = isinstance(U, np.ndarray) and U.dtype == np.float64 and U.flags.writeable
    Y = U if writable else np.array(U, dtype=np.float64)
    Y *= d[:, None]  # (y = M^½ u, in place)
    lam = np.array(lam, dtype=np.float64)
    res = np.array(res, dtype=np.float64)
    was = np.zeros(len(lam), dtype=bool)
    zero = np.flatnonzero(lam <= 0)
    if len(zero) == min(ncomp, len(lam)):  # the null space: the exact indicators
        was[zero[~(res[zero] <= tol)]] = True
        Y[:, zero] = Zy[:, : len(zero)]
        lam[zero] = 0.0
        res[zero] = pair_residuals(K, m, lam[zero], Y[:, zero] / d[:, None], labels)
        bad = np.flatnonzero(~(res <= tol))
    rng = np.random.default_rng(20240611)
    done = 0
    ever = np.zeros(len(lam), dtype=bool)  # columns changed in any round
    ever[zero] = len(zero) == min(ncomp, len(lam))
    for r in range(rounds):
        if not len(bad):
            break
        done += 1
        was[bad] = True
        runs = _runs(bad, int(np.count_nonzero(lam <= 0)), len(lam))
        if r == 0 or len(runs) > MAX_SHIFTS:
            pos = lam[bad][lam[bad] > 0]
            low = float(pos.min()) if len(pos) else float(np.abs(lam).max(initial=1.0)) or 1.0
            plan = [(bad, -0.5 * low, 0.5 * low)]
        else:  # a shift a tenth of the way from each run's lowest pair to the pair below
            plan = []
            for run in runs:
                a = lam[run[0]]
                below = lam[run[0] - 1] if run[0] > 0 else 0.0
                gap = a - below if a > below else max(abs(a), 1e-300)
                plan.append((run, a - 0.1 * gap, 0.1 * gap))
        changed = np.zeros(len(lam), dtype=bool)
        for idx, sigma, spacing in plan:
            theta, X = _iterate(pencil, Y, Zy, lam, idx, sigma, spacing, rng)
            _replace(Y, idx, X)
            lam[idx] = theta
            changed[idx] = True
            changed[_rayleigh_ritz_coupled(A, Y, lam, idx)] = True
        order = np.argsort(lam, kind="stable")
        moved = np.flatnonzero(order != np.arange(len(order)))
        if len(moved):  # (only the columns that move are copied)
            Y[:, moved] = Y[:, order[moved]]
            lam, was, changed, res = lam[order], was[order], changed[order], res[order]
        sel = np.flatnonzero(changed)
        ever[sel] = True
        ever[moved] |= True
        res[sel] = pair_residuals(K, m, lam[sel], Y[:, sel] / d[:, None], labels)
        bad = np.flatnonzero(~(res <= tol))
    Y /= d[:, None]  # (back to u, in place)
    return lam, Y, res, Refinement(int(np.count_nonzero(was)), done, np.flatnonzero(ever))


def _replace(Y: FloatArray, cols: IntArray, X: FloatArray) -> None:
    """``Y[:, cols] = X``, each new column's sign that of the column it replaces (Rayleigh–Ritz
    picks signs at random: a clean pair taken along comes back as it was)."""
    flip = np.einsum("ij,ij->j", X, Y[:, cols]) < 0
    X[:, flip] *= -1.0
    Y[:, cols] = X


def _runs(bad: IntArray, first: int, k: int) -> list[IntArray]:
    """Runs of consecutive bad pairs, each with :data:`NEIGHBOURS` pairs on either side (a
    neighbour whose vector holds a little of a bad pair's eigenvector would keep it out of
    the deflated block), not below ``first`` (the null space is exact), overlaps merged."""
    runs: list[list[int]] = []
    for run in np.split(bad, np.flatnonzero(np.diff(bad) > 1) + 1):
        lo, hi = max(int(run[0]) - NEIGHBOURS, first), min(int(run[-1]) + NEIGHBOURS, k - 1)
        if runs and lo <= runs[-1][1] + 1:
            runs[-1][1] = max(runs[-1][1], hi)
        else:
            runs.append([lo, hi])
    return [np.arange(lo, hi + 1) for lo, hi in runs]


def _iterate(
    pencil: ScaledPencil,
    Y: FloatArray,
    Zy: FloatArray,
    lam: FloatArray,
    idx: IntArray,
    sigma: float,
    spacing: float,
    rng: np.random.Generator,
) -> tuple[FloatArray, FloatArray]:
    """Inverse iteration of the columns ``idx`` of ``Y`` (and :data:`OVERSAMPLING` random
    vectors) at the shift ``sigma``, orthogonal to ``Zy`` and to the other columns with
    ``λ > 0``; returns the ``len(idx)`` lowest Ritz pairs ``(θ, X)`` of ``A`` on the block."""
    A = pencil.A
    n = A.shape[0]
    op = ShiftInvert(A, sigma, rng=rng, spacing=spacing, ordering=pencil.ordering)
    # (projections against Zy and the kept columns of Y, without copying them)
    keep = (lam > 0).astype(np.float64)
    keep[idx] = 0.0
    guard = max(min(OVERSAMPLING, n - Zy.shape[1] - int(keep.sum()) - len(idx)), 0)
    X = np.hstack([Y[:, idx], rng.standard_normal((n, guard))])
    for _ in range(ITERATIONS):
        X = op.factor.solve(X)
        for _ in range(2):  # classical Gram–Schmidt, twice
            X -= Zy @ (Zy.T @ X)
            X -= Y @ (keep[:, None] * (Y.T @ X))
        X, _ = np.linalg.qr(X)
    H = X.T @ (A @ X)
    theta, C = np.linalg.eigh(0.5 * (H + H.T))
    return theta[: len(idx)], X @ C[:, : len(idx)]


def _rayleigh_ritz_coupled(
    A: sp.csr_matrix, Y: FloatArray, lam: FloatArray, idx: IntArray
) -> IntArray:
    """Rayleigh–Ritz of the columns ``idx`` of ``Y`` together with the other columns they
    couple to through ``A`` (in place in ``Y`` and ``lam``).

    A refined vector is orthogonal to the other pairs' vectors; when one of those holds a
    little of the refined pair's eigenvector (``y_j = v_j + ε v_i``), the refined one must
    hold ``−ε v_j`` and keeps a residual ``ε (λ_j − λ_i)`` that no inverse iteration
    removes. Both errors lie in the span of the two columns, which Rayleigh–Ritz on that
    span removes: the coupling ``y_jᵀ A y_i`` (``≈ ε (λ_j − λ_i)``) says which columns to
    take along. Returns the columns taken along (changed too)."""
    k = Y.shape[1]
    W = A @ Y[:, idx]
    G = Y.T @ W  # (k, len(idx)): y_jᵀ A y_i
    rest = np.setdiff1d(np.arange(k), idx)
    if not len(rest):
        return rest
    # a coupling matters when it gives the refined pair a residual near the tolerance
    # (relative to its λ: the residuals' reference scale is at least that), and when it is
    # above round-off
    floor = 1e-13 * float(np.abs(lam).max(initial=0.0))
    mask = np.abs(G[rest]) > np.maximum(0.1 * PROMISED_RESIDUAL * np.abs(lam[idx])[None, :], floor)
    coupled = rest[mask.any(axis=1)]
    if not len(coupled):
        return coupled
    S = np.r_[idx, coupled]
    Ws = np.hstack([W, A @ Y[:, coupled]])
    H = Y[:, S].T @ Ws
    theta, C = np.linalg.eigh(0.5 * (H + H.T))
    order = np.argsort(S)
    _replace(Y, S[order], Y[:, S] @ C)
    lam[S[order]] = theta
    return coupled
