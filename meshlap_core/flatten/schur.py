"""The boundary's Schur complement of the stiffness, and the harmonic extension inside.

For a positive semidefinite ``K`` (``K = −C``) split into interior ``I`` and boundary ``B``
vertices, eliminating the interior gives the dense ``b × b`` matrix

    ``S = K_BB − K_BI K_II⁻¹ K_IB``,

the discrete Dirichlet-to-Neumann map: for boundary values ``u_B``, ``S u_B`` is the flux of
their harmonic extension ``u_I = −K_II⁻¹ K_IB u_B`` (:meth:`BoundaryReduction.extend`). The
spectral conformal map's eigenproblem lives on it (:mod:`.spectral_conformal`).

Two ways to build ``S``, the result the same to round-off:

* with CHOLMOD (scikit-sparse): one Cholesky factorization of ``K`` reordered with the
  interior first (AMD) and the boundary last; its trailing block is ``S = L_BB L_BBᵀ`` (the
  partial factorization of the classical Schur complement method). ``K`` is singular (its
  constants), so ``δ = K_ββ`` is added to the last boundary vertex's diagonal entry before
  factorizing and subtracted from ``S`` afterwards (a change in the ``BB`` block shifts the
  Schur complement by the same amount); the interior solves for the extension reuse the
  factor's leading block (a forward and a back substitution with the boundary rows zero).
  43k vertices, 410 on the boundary: 0.6 s on a loaded machine against 6 s for the next way.
* otherwise: ``K_II`` factorized once and ``S`` built from ``b`` solves in blocks of
  :data:`BLOCK` right-hand sides (progress and ``cancel`` between blocks).
"""

from __future__ import annotations

import warnings
from collections.abc import Callable
from typing import Any

import numpy as np
import scipy.sparse as sp

from ..errors import check_cancel
from ..linalg.common import ProgressCallback, report_progress
from ..linalg.factor import SharedAnalysis
from ..linalg.spd import solver_backend
from ..types import FloatArray, IntArray
from .fixed_boundary import definite, factor_mode, sorted_csr

BLOCK = 64
"""Right-hand sides per solve while ``S`` is built from solves."""

Extend = Callable[[FloatArray], FloatArray]


class BoundaryReduction:
    """``S`` and the harmonic extension of one stiffness matrix and boundary.

    Parameters
    ----------
    K : (n,n) scipy.sparse.csr_matrix
        Symmetric positive semidefinite, ``K·1 = 0``, positive definite on the interior.
    boundary : (b,) int
        The boundary vertices (any order; kept sorted).
    progress, cancel
        As everywhere (:func:`~meshlap_core.linalg.common.report_progress`,
        :func:`~meshlap_core.errors.check_cancel`).

    Attributes
    ----------
    boundary : (b,) int
        Sorted.
    interior : (n−b,) int
    S : (b,b) float
        Symmetric (rows and columns in the order of :attr:`boundary`).
    method : str
        ``"partial factorization"`` or ``"solves"``.
    """

    def __init__(
        self,
        K: sp.csr_matrix,
        boundary: IntArray,
        *,
        progress: ProgressCallback | None = None,
        cancel: Any = None,
    ) -> None:
        check_cancel(cancel, "spectral conformal map")
        n = K.shape[0]
        self.n = n
        self.boundary = np.unique(boundary)
        self.interior = np.setdiff1d(np.arange(n), self.boundary)
        self._K_IB = sp.csr_matrix(K[self.interior][:, self.boundary])
        made = None
        if len(self.interior) and solver_backend() == "cholmod":
            made = _by_factor(K, self.interior, self.boundary)
            self.method = "partial factorization"
        if made is None:
            made = _by_solves(K, self.interior, self.boundary, self._K_IB, progress, cancel)
            self.method = "solves"
        S, self._solve_interior = made
        self.S = 0.5 * (S + S.T)

    def extend(self, xb: FloatArray) -> FloatArray:
        """The harmonic extension ``(n,c)`` of boundary values ``xb`` ``(b,c)``: ``xb`` on
        the boundary, ``−K_II⁻¹ K_IB xb`` inside."""
        out = np.empty((self.n, xb.shape[1]))
        out[self.boundary] = xb
        if len(self.interior):
            out[self.interior] = -self._solve_interior(self._K_IB @ xb)
        return out


def _by_factor(
    K: sp.csr_matrix, interior: IntArray, bnd: IntArray
) -> tuple[FloatArray, Extend] | None:
    """``S`` from one CHOLMOD factorization with the boundary last; ``None`` if CHOLMOD
    refuses (the caller then builds ``S`` from solves)."""
    from sksparse.cholmod import CholmodError, CholmodWarning, analyze

    n_i = len(interior)
    mode = factor_mode(K.shape[0])
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("error", CholmodWarning)
            K_II = sp.csc_matrix(K[interior][:, interior])
            order = analyze(K_II, mode="simplicial", ordering_method="amd").P()
            perm = np.concatenate([interior[order], bnd])
            Kp = sp.csc_matrix(K[perm][:, perm])
            Kp.sum_duplicates()
            last = Kp.indptr[-2] + int(
                np.flatnonzero(Kp.indices[Kp.indptr[-2] :] == len(perm) - 1)[0]
            )
            delta = float(Kp.data[last])
            Kp.data[last] += delta  # definite now; S is shifted back below
            factor = analyze(Kp, mode=mode, ordering_method="natural").cholesky(Kp)
            if not np.array_equal(factor.P(), np.arange(len(perm))):
                return None
            L = factor.L()
    except (CholmodError, CholmodWarning):
        return None
    L_BB = L[n_i:, n_i:].toarray()
    S = L_BB @ L_BB.T
    S[-1, -1] -= delta

    def solve_interior(r: FloatArray) -> FloatArray:
        y = np.zeros((len(perm), r.shape[1]))
        y[:n_i] = r[order]
        y = np.asarray(factor.solve_L(y, use_LDLt_decomposition=False))
        y[n_i:] = 0.0  # (the boundary rows: L_II⁻ᵀ on the interior alone)
        w = np.asarray(factor.solve_Lt(y, use_LDLt_decomposition=False))
        out = np.empty((n_i, r.shape[1]))
        out[order] = w[:n_i]
        return out

    return S, solve_interior


def _by_solves(
    K: sp.csr_matrix,
    interior: IntArray,
    bnd: IntArray,
    K_IB: sp.csr_matrix,
    progress: ProgressCallback | None,
    cancel: Any,
) -> tuple[FloatArray, Extend]:
    """``S`` from a factorization of ``K_II`` and ``b`` solves in blocks."""
    S = K[bnd][:, bnd].toarray()
    n_i, b = len(interior), len(bnd)
    if n_i == 0:  # every vertex on the boundary: nothing to eliminate
        return S, lambda r: np.zeros((0, r.shape[1]))
    K_II = sorted_csr(K[interior][:, interior])
    shared = SharedAnalysis(K_II.indptr, K_II.indices, solver_backend(), factor_mode(n_i))
    factor = definite(lambda: shared.factor(K_II.data))
    cols = sp.csc_matrix(K_IB)
    for c0 in range(0, b, BLOCK):
        check_cancel(cancel, "spectral conformal map")
        report_progress(progress, 0.9 * c0 / b, f"boundary Schur complement, column {c0}/{b}")
        c1 = min(c0 + BLOCK, b)
        X = np.asarray(factor.solve(cols[:, c0:c1].toarray())).reshape(n_i, c1 - c0)
        S[:, c0:c1] -= K_IB.T @ X
    return S, lambda r: np.asarray(factor.solve(r)).reshape(r.shape)
