"""The local step of as-rigid-as-possible: the rotation closest to each of many 3×3 matrices.

Given a covariance ``S = Σ_j w_j e_j e'_jᵀ`` (rest edges ``e``, deformed edges ``e'``), the
rotation minimizing ``Σ_j w_j ‖e'_j − R e_j‖²`` maximizes ``tr(R S)``. With the singular value
decomposition ``S = U Σ Vᵀ`` it is ``R = V Uᵀ`` (Sorkine & Alexa 2007, eq. 6) — unless
``det(V Uᵀ) = −1``: then ``V Uᵀ`` is a *reflection* (a one-ring folded through itself fits
one best), and the closest rotation flips the singular vector of the smallest singular value:
``R = V diag(1, 1, det(V Uᵀ)) Uᵀ`` (the *reflection fix*).

The SVD is computed for all vertices at once, vectorized over them (no Python loop per
vertex), in double precision:

1. ``SᵀS = V Λ Vᵀ`` by cyclic Jacobi rotations (each zeroes one off-diagonal entry; repeated
   sweeps converge quadratically, to round-off in 3–5 sweeps), ``V`` a product of rotations,
   so ``det V = +1``; the eigenvalues are sorted ``λ₁ ≥ λ₂ ≥ λ₃`` (``σᵢ = √λᵢ``), each column
   swap paired with a sign change to keep ``det V = +1``;
2. ``u₁ = S v₁ / ‖S v₁‖``, ``u₂`` the unit part of ``S v₂`` orthogonal to ``u₁``, and
   ``u₃ = u₁ × u₂``, so that ``det U = +1`` too. Then ``S V = U diag(σ₁, σ₂, ±σ₃)`` with the
   sign of ``det S`` on the smallest singular value, and ``R = V Uᵀ`` *is* the reflection fix
   (``reflection_fix=False`` returns the orthogonal factor of the polar decomposition instead,
   ``u₃ = S v₃ / ‖S v₃‖``, which may be a reflection). Building ``u₃`` from ``u₁, u₂`` also
   keeps it exact when ``σ₃ = 0``: a planar one-ring, the most common case.

libigl's ``fit_rotations`` (:func:`fit_rotations_igl`) does the same in single precision
(McAdams et al. 2011, four Jacobi sweeps in ``float``): rotations good to about 1e-5, which
``igl.arap_solve`` uses.
"""

from __future__ import annotations

from typing import Any

import igl
import numpy as np

from ..errors import MeshError
from ..types import FloatArray, real_array

EPS = float(np.finfo(float).eps)
TINY = float(np.finfo(float).tiny)
MAX_SWEEPS = 30
"""Jacobi sweeps at most (round-off is reached in 3–5; the bound only stops NaN input)."""
COMPACT = 0.5
"""When fewer than this share of the matrices still need sweeps, they are swept alone."""
CHUNK = 8192
"""Matrices fitted together: the ~40 arrays of a chunk (64 kB each) stay in the processor's
cache through the ~600 vectorized operations of a fit (at 692k vertices a fit over all at
once streams them from memory, several times slower)."""
_PAIRS = ((0, 1, 2), (0, 2, 1), (1, 2, 0))
"""Each Jacobi rotation ``(p, q)`` in a sweep, and the third index ``r``."""

Columns = list[list[np.ndarray]]
"""A field of 3×3 matrices as ``M[i][j]``, each an ``(n,)`` array (vectorized arithmetic)."""


def _jacobi(a: dict[tuple[int, int], np.ndarray], v: Columns, tol: np.ndarray) -> None:
    """Diagonalize symmetric 3×3 matrices by cyclic Jacobi rotations, in place: ``a`` (the
    upper triangle ``a[p, q]``, ``p ≤ q``, each ``(n,)``) becomes diagonal (the eigenvalues)
    and the columns of ``v`` (``v[i][k]``, coordinate ``i`` of column ``k``) are multiplied by
    the same rotations, so they stay in SO(3). A matrix is done when the squares of its
    off-diagonal entries sum to at most ``tol`` ``(n,)``; once fewer than
    :data:`COMPACT` of them are left, those are finished on their own (gathered, swept,
    scattered back)."""
    for _ in range(MAX_SWEEPS):
        off = a[0, 1] * a[0, 1] + a[0, 2] * a[0, 2] + a[1, 2] * a[1, 2]
        left = off > tol
        count = int(np.count_nonzero(left))
        if count == 0:
            return
        if count < COMPACT * len(tol):
            idx = np.flatnonzero(left)
            sub = {key: x[idx] for key, x in a.items()}
            vs = [[v[i][k][idx] for k in range(3)] for i in range(3)]
            _jacobi(sub, vs, tol[idx])
            for key in a:
                a[key] = a[key].copy()
                a[key][idx] = sub[key]
            for i in range(3):
                for k in range(3):
                    v[i][k] = v[i][k].copy()
                    v[i][k][idx] = vs[i][k]
            return
        _sweep(a, v)


def _sweep(a: dict[tuple[int, int], np.ndarray], v: Columns) -> None:
    """One cyclic sweep: a rotation in each plane ``(p, q)`` zeroes ``a[p, q]``."""
    zero = np.zeros(len(a[0, 0]))
    for p, q, r in _PAIRS:
        apq = a[p, q]
        d = a[q, q] - a[p, p]
        # t = tan θ of the rotation that zeroes a_pq (the smaller root: |θ| ≤ π/4)
        t = (2.0 * apq) * np.copysign(1.0, d) / (np.abs(d) + np.hypot(d, 2.0 * apq) + TINY)
        c = 1.0 / np.sqrt(1.0 + t * t)
        s = t * c
        ta = t * apq
        a[p, p] = a[p, p] - ta
        a[q, q] = a[q, q] + ta
        a[p, q] = zero
        rp, rq = (min(r, p), max(r, p)), (min(r, q), max(r, q))
        arp, arq = a[rp], a[rq]
        a[rp] = c * arp - s * arq
        a[rq] = s * arp + c * arq
        for i in range(3):
            vp, vq = v[i][p], v[i][q]
            v[i][p] = c * vp - s * vq
            v[i][q] = s * vp + c * vq


def _sort_descending(lam: list[np.ndarray], v: Columns) -> None:
    """Sort eigenpairs by decreasing eigenvalue in place; a swap negates one column so that
    ``det V`` stays ``+1``."""
    for p, q in ((0, 1), (1, 2), (0, 1)):
        swap = lam[q] > lam[p]
        lam[p], lam[q] = np.where(swap, lam[q], lam[p]), np.where(swap, lam[p], lam[q])
        for i in range(3):
            vp, vq = v[i][p], v[i][q]
            v[i][p] = np.where(swap, vq, vp)
            v[i][q] = np.where(swap, -vp, vq)


def _apply(s: Columns, v: Columns, k: int) -> list[np.ndarray]:
    """``S v_k`` (3 arrays)."""
    return [s[i][0] * v[0][k] + s[i][1] * v[1][k] + s[i][2] * v[2][k] for i in range(3)]


def _unit_or(w: list[np.ndarray], norm: np.ndarray, ok: np.ndarray, other: list[np.ndarray]):
    """``w / norm`` where ``ok``, else ``other``."""
    inv = 1.0 / np.where(ok, norm, 1.0)
    return [np.where(ok, w[i] * inv, other[i]) for i in range(3)]


def _cross(a: list[np.ndarray], b: list[np.ndarray]) -> list[np.ndarray]:
    return [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]


def _perpendicular(u: list[np.ndarray]) -> list[np.ndarray]:
    """A unit vector perpendicular to each unit ``u``: ``u × e`` for the axis ``e`` along which
    ``u`` is shortest."""
    ax = np.argmin(np.abs(np.stack(u)), axis=0)
    e = [(ax == i).astype(float) for i in range(3)]
    w = _cross(u, e)
    return _unit_or(w, np.sqrt(w[0] ** 2 + w[1] ** 2 + w[2] ** 2), np.ones(len(ax), bool), w)


def _left_vectors(s: Columns, v: Columns, reflection_fix: bool) -> Columns:
    """``U`` ``[u₁, u₂, u₃]`` (``U[k][i]``) from ``S`` and the sorted ``V``."""
    b0, b1 = _apply(s, v, 0), _apply(s, v, 1)
    n0 = np.sqrt(b0[0] ** 2 + b0[1] ** 2 + b0[2] ** 2)
    u0 = _unit_or(b0, n0, n0 > TINY, [v[i][0] for i in range(3)])  # S = 0: U = V, so R = I
    dot = u0[0] * b1[0] + u0[1] * b1[1] + u0[2] * b1[2]
    w = [b1[i] - dot * u0[i] for i in range(3)]
    n1 = np.sqrt(w[0] ** 2 + w[1] ** 2 + w[2] ** 2)
    ok = n1 > EPS * n0
    u1 = _unit_or(w, n1, ok, [v[i][1] for i in range(3)])
    flat = np.flatnonzero(~ok & (n0 > TINY))  # rank 1: any unit vector perpendicular to u₁
    if len(flat):
        other = _perpendicular([x[flat] for x in u0])
        for i in range(3):
            u1[i][flat] = other[i]
    u2 = _cross(u0, u1)
    if not reflection_fix:
        b2 = _apply(s, v, 2)
        sign = np.where(u2[0] * b2[0] + u2[1] * b2[1] + u2[2] * b2[2] < 0, -1.0, 1.0)
        u2 = [sign * x for x in u2]
    return [u0, u1, u2]


def svd_rotations(
    S: FloatArray, reflection_fix: bool = True, basis: FloatArray | None = None
) -> tuple[FloatArray, FloatArray]:
    """:func:`fit_rotations` on matrices stored component-major, ``S[i, j]`` an ``(n,)`` array
    (the layout the ARAP solver keeps, no transposes), with the right singular vectors.

    Parameters
    ----------
    S : (3,3,n) float
    reflection_fix : bool
    basis : (3,3,n) float, optional
        Right singular vectors of nearby matrices (the last iteration's): the sweeps start
        from ``basisᵀ SᵀS basis``, nearly diagonal already, and need fewer of them.

    Returns
    -------
    R : (3,3,n) float
    V : (3,3,n) float
        The right singular vectors (columns, ``det = +1``), sorted by decreasing singular value.
    """
    R = np.empty(S.shape)
    V = np.empty(S.shape)
    for lo in range(0, S.shape[2], CHUNK):
        part = slice(lo, lo + CHUNK)
        guess = None if basis is None else basis[:, :, part]
        _svd_chunk(S[:, :, part], reflection_fix, guess, R[:, :, part], V[:, :, part])
    return R, V


def _svd_chunk(
    S: FloatArray, reflection_fix: bool, basis: FloatArray | None, R: FloatArray, V: FloatArray
) -> None:
    """:func:`svd_rotations` of one chunk of matrices, written into ``R`` and ``V``."""
    # each matrix divided by its largest entry (the rotation does not change): SᵀS neither
    # overflows (coordinates up to 1e75) nor underflows (down to 1e-60)
    big = np.abs(S).max(axis=(0, 1))
    inv = 1.0 / np.where(big > 0, big, 1.0)
    s = [[S[i, j] * inv for j in range(3)] for i in range(3)]
    if basis is None:
        n = S.shape[2]
        one, zero = np.ones(n), np.zeros(n)
        v = [[one if i == k else zero for k in range(3)] for i in range(3)]
        b = [[s[i][k] for k in range(3)] for i in range(3)]
    else:
        v = [[basis[i, k] for k in range(3)] for i in range(3)]
        b = [_apply(s, v, k) for k in range(3)]
        b = [[b[k][i] for k in range(3)] for i in range(3)]  # b[i][k] = (S V)_ik
    a = {
        (p, q): b[0][p] * b[0][q] + b[1][p] * b[1][q] + b[2][p] * b[2][q]
        for p in range(3)
        for q in range(p, 3)
    }
    _jacobi(a, v, (EPS * np.abs(a[0, 0] + a[1, 1] + a[2, 2])) ** 2)
    lam = [a[0, 0], a[1, 1], a[2, 2]]
    _sort_descending(lam, v)
    u = _left_vectors(s, v, reflection_fix)
    for i in range(3):
        for j in range(3):
            R[i, j] = v[i][0] * u[0][j] + v[i][1] * u[1][j] + v[i][2] * u[2][j]
            V[i, j] = v[i][j]


def fit_rotations_stacked(S: FloatArray, reflection_fix: bool = True) -> FloatArray:
    """:func:`fit_rotations` on component-major ``(3,3,n)`` matrices; ``(3,3,n)`` out."""
    return svd_rotations(S, reflection_fix)[0]


def check_covariances(S: Any, name: str = "S") -> FloatArray:
    """``S`` as a finite ``(n,3,3)`` float64 array."""
    raw = real_array(S, name, "matrix entries")
    arr = np.asarray(raw, dtype=np.float64)
    if arr.ndim != 3 or arr.shape[1:] != (3, 3):
        raise MeshError(f"should have shape (n,3,3); shape is {arr.shape}", name)
    if not np.isfinite(arr).all():
        raise MeshError("has a NaN or infinite entry", name)
    return arr


def fit_rotations(S: Any, reflection_fix: bool = True) -> FloatArray:
    """The rotation ``R`` maximizing ``tr(R S)`` for each 3×3 ``S`` (see the module docstring).

    Parameters
    ----------
    S : (n,3,3) float
        Covariances ``Σ_j w_j e_j e'_jᵀ`` (rest edges times deformed edges).
    reflection_fix : bool
        ``False`` returns the orthogonal polar factor ``V Uᵀ``, a reflection where
        ``det S < 0`` (what ARAP without the fix would use).

    Returns
    -------
    R : (n,3,3) float
        ``det R = +1`` with the fix; ``R e ≈ e'``.

    Examples
    --------
    >>> S = np.diag([1.0, 1.0, -1.0])[None]  # a mirror: the best rotation is not a reflection
    >>> np.round(np.linalg.det(fit_rotations(S)), 12).tolist()
    [1.0]
    """
    arr = check_covariances(S)
    stacked = np.ascontiguousarray(arr.transpose(1, 2, 0))
    return fit_rotations_stacked(stacked, reflection_fix).transpose(2, 0, 1).copy()


def fit_rotations_igl(S: FloatArray) -> FloatArray:
    """libigl's single-precision fit (``igl.fit_rotations(S, True)``, the one ``igl.arap_solve``
    calls, after dividing all ``S`` by their largest entry as it does), on component-major
    ``(3,3,n)`` matrices; ``(3,3,n)`` out."""
    n = S.shape[2]
    scale = float(np.abs(S).max()) if S.size else 0.0
    stacked = S.transpose(0, 2, 1).reshape(3 * n, 3) / (scale if scale > 0 else 1.0)
    R = igl.fit_rotations(np.ascontiguousarray(stacked), True)  # (3, 3n): block r is R_r
    return np.ascontiguousarray(R.reshape(3, n, 3).transpose(0, 2, 1))
