"""Checks of computed eigenpairs of ``K u = λ M u``: residuals of every pair, ``M``-orthonormality.

Mesh-free.
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp

from .common import FloatArray


def max_residual(
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


def orthogonality(U: FloatArray, m: FloatArray) -> float:
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
