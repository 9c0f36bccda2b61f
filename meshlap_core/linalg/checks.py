"""Checks of computed eigenpairs of ``K u = λ M u``: residuals of every pair, ``M``-orthonormality.

Mesh-free.
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from ..errors import MeshError
from .common import FloatArray, IntArray
from .components import component_scales
from .factor import ShiftInvert

RESIDUAL_TOL = 1e-5
"""Largest relative residual ``||K u − λ M u||_{M⁻¹} / max(λ, λ_ref)`` accepted for any pair
(the solver aims at 1e-6 on its own estimate; its results measure 1e-12 to 1e-7)."""


#: elements (n × columns) of one temporary of :func:`pair_residuals` (96 MB of float64)
CHUNK_ELEMENTS = 12 * 2**20


def pair_residuals(
    K: sp.csr_matrix,
    m: FloatArray,
    lam: FloatArray,
    U: FloatArray,
    labels: IntArray | None = None,
    chunk: int | None = None,
) -> FloatArray:
    """Relative residual of every pair, ``(k,)``:
    ``||K u_i − λ_i M u_i||_{M⁻¹} / max(λ_i, λ_ref,i)`` for ``M``-normalized ``u_i``.

    ``λ_ref,i = s_c``: the frequency scale of the component ``c`` that holds the largest share
    ``||u_i||²_{M,c}`` of the vector (:func:`~meshlap_core.linalg.components.component_scales`,
    given ``labels``; else one component, ``λ_ref = tr(K)/(n·tr(M))``), so a zero mode of a
    tiny component is measured against its own scale, while a vector that leaks round-off
    onto a component of a much larger scale is not excused by it. One sparse product ``K U``
    in column chunks: ``O(nnz(K)·k)`` time, ``O(n·chunk)`` memory (three temporaries of
    ``n × chunk``; default chunk: up to 128 columns, fewer on large meshes so that each
    temporary stays near 96 MB: 18 columns at 692k vertices). SciPy's sparse × dense
    product loops over the chunk's columns innermost, so wide chunks run it several times
    faster per column than narrow ones (at 692k vertices and k = 100: 1.4 s of CPU in
    chunks of 16 columns, 2.5 s in chunks of 6).
    """
    n, kk = U.shape
    if chunk is None:
        chunk = int(min(128, max(4, CHUNK_ELEMENTS // max(n, 1))))
    if kk:  # equal chunks (no thin last one)
        chunk = -(-kk // -(-kk // chunk))
    out = np.zeros(kk)
    if labels is None:
        labels = np.zeros(n, dtype=np.int64)
    ncomp = int(labels.max(initial=-1)) + 1
    scales = component_scales(K, m, labels, ncomp)
    P = sp.csr_matrix((np.ones(n), (labels, np.arange(n))), shape=(ncomp, n)) if ncomp > 1 else None
    w = 1.0 / np.sqrt(m)[:, None]
    for j0 in range(0, kk, chunk):
        j1 = min(kk, j0 + chunk)
        Uc = U[:, j0:j1]
        R = K @ Uc
        MU = m[:, None] * Uc
        ref = np.full(j1 - j0, scales[0]) if P is None else scales[np.argmax(P @ (MU * Uc), axis=0)]
        MU *= lam[None, j0:j1]
        R -= MU
        del MU
        R *= w  # ||r||_{M⁻¹} = ||M^-½ r||
        r = np.sqrt(np.einsum("ij,ij->j", R, R))
        out[j0:j1] = r / np.maximum(lam[j0:j1], ref)
    return out


def max_residual(
    K: sp.csr_matrix, m: FloatArray, lam: FloatArray, U: FloatArray, labels: IntArray | None = None
) -> float:
    """The largest of :func:`pair_residuals` (0 for no pairs)."""
    return float(pair_residuals(K, m, lam, U, labels).max(initial=0.0))


def orthogonality(U: FloatArray, m: FloatArray) -> float:
    """``max|UᵀMU − I|`` over the rows of a sample of columns (first, last, thirds and 4 more
    at random, each against all) and the ``M``-norms of every column: ``O(nk)``."""
    kk = U.shape[1]
    if kk == 0:
        return 0.0
    idx = np.unique(
        np.r_[0, kk // 3, (2 * kk) // 3, kk - 1, np.random.default_rng(kk).integers(0, kk, 4)]
    )
    G = (U[:, idx] * m[:, None]).T @ U  # (no n × k temporary: M applied to the sample)
    E = np.zeros_like(G)
    E[np.arange(len(idx)), idx] = 1.0
    norms = np.einsum("ij,ij,i->j", U, U, m)
    return float(max(np.abs(G - E).max(), np.abs(norms - 1.0).max()))


def orthonormality_probe(
    U: FloatArray, m: FloatArray, rng: np.random.Generator, probes: int = 4
) -> float:
    """``max_z ||(UᵀMU − I) z|| / ||z||`` over ``probes`` Gaussian vectors ``z``: a check of
    the whole ``UᵀMU = I`` in ``O(nk)`` (not ``O(nk²)``). Any departure ``E = UᵀMU − I`` shows
    with ``E[||Ez||²] = ||E||_F² ||z||²/k``: a column replaced by a copy of another gives
    about ``√(2/k)``; an orthonormal basis gives round-off (~1e-12)."""
    kk = U.shape[1]
    if kk == 0:
        return 0.0
    Z = rng.standard_normal((kk, probes))
    E = U.T @ (m[:, None] * (U @ Z)) - Z
    return float((np.linalg.norm(E, axis=0) / np.linalg.norm(Z, axis=0)).max())


def inertia_check(K: sp.csr_matrix, m: FloatArray, lam: FloatArray, k: int) -> None:
    """Sylvester's law of inertia on computed eigenvalues ``lam`` (ascending, the smallest of
    ``K u = λ M u``, ``k`` of them asked for).

    The ``LDLᵀ`` of ``A − τI`` (``A = M^-½KM^-½``) at a shift ``τ`` in a gap of ``lam`` (the
    first above ``λ_k``, else the highest below) counts the eigenvalues below ``τ``, which must
    all be in ``lam``: dense ``eigh`` on a badly scaled pencil can return accurate pairs yet
    skip the smallest ones, and a cached basis may have lost a pair; no residual shows that.
    Nothing to check when every eigenvalue was computed or no gap is seen. One sparse
    factorization.

    Raises
    ------
    MeshError
        The count differs, or ``A − τI`` cannot be factored.
    """
    n = len(m)
    if len(lam) >= n:
        return
    scale = float(K.diagonal().sum() / (n * m.sum()))
    gaps = np.flatnonzero(np.diff(lam) > 1e-7 * np.maximum(np.abs(lam[1:]), scale))
    if not len(gaps):
        return
    above = gaps[gaps >= k - 1]
    j = int(above[0] if len(above) else gaps[-1])
    inv = sp.diags(1.0 / np.sqrt(m))
    try:
        op = ShiftInvert(
            (inv @ K @ inv).tocsr(),
            0.5 * (lam[j] + lam[j + 1]),
            rng=np.random.default_rng(0),
            spacing=lam[j + 1] - lam[j],
        )
    except RuntimeError as exc:
        raise MeshError(f"eigensolver: inertia check: {exc}", "K") from None
    have = int(np.count_nonzero(lam < op.sigma))
    if op.n_below != have:
        raise MeshError(
            f"{have} eigenvalues were found below {op.sigma:.6g} but "
            f"Sylvester's inertia counts {op.n_below}: eigenvalues are missing (the "
            "eigenproblem is too badly conditioned to solve accurately), so no basis is given",
            "K",
        )
