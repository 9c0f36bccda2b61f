"""Symmetric positive definite sparse systems: factorize once, solve many right-hand sides.

``A = LLᵀ`` by CHOLMOD's supernodal Cholesky (through ``cholespy``), reused for every
``solve``; SciPy's SuperLU when cholespy is unavailable. Used by implicit smoothing, whose
system ``W − λK`` is factorized once per ``λ`` and solved once per step.
"""

from __future__ import annotations

import contextlib

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as sla

from .quiet import quiet_c_stdout


def surely_positive_definite(A: sp.csr_matrix, margin: float = 1e-8) -> bool:
    """True when the Jacobi-scaled ``D^-1/2 A D^-1/2`` is diagonally dominant by ``margin``.

    Then all its eigenvalues are at least ``margin`` (Gershgorin) and a Cholesky factorization
    cannot fail; ``False`` means "not proven" (the factorization may still succeed).

    Parameters
    ----------
    A : (n,n) scipy.sparse matrix
        Symmetric.
    margin : float

    Returns
    -------
    bool
    """
    d = A.diagonal()
    if len(d) == 0:
        return True
    if not np.all(d > 0):
        return False
    s = 1.0 / np.sqrt(d)
    B = abs(A).tocsr()
    off = np.asarray((sp.diags(s) @ B @ sp.diags(s)).sum(axis=1)).ravel() - 1.0
    return bool(np.all(off <= 1.0 - margin))


class SPDSolver:
    """Sparse Cholesky factorization of a symmetric positive definite matrix, reused per solve.

    Uses ``cholespy`` (CHOLMOD); falls back to SciPy's SuperLU when cholespy is unavailable.
    A matrix that is not provably positive definite (:func:`surely_positive_definite`) is
    factorized with the C standard output silenced
    (:func:`~meshlap_core.linalg.quiet.quiet_c_stdout`), so CHOLMOD's complaint never reaches
    the user's output.

    Parameters
    ----------
    A : (n,n) scipy.sparse matrix
        Symmetric positive definite (both triangles stored).

    Raises
    ------
    numpy.linalg.LinAlgError
        When the factorization finds ``A`` not numerically positive definite.
    """

    def __init__(self, A: sp.spmatrix) -> None:
        A = sp.csr_matrix(A)
        A.sum_duplicates()
        A.sort_indices()
        self.n = A.shape[0]
        try:
            from cholespy import CholeskySolverD, MatrixType
        except ImportError:  # pragma: no cover - cholespy is a dependency
            self._lu = sla.splu(A.tocsc())
            self._chol = None
            return
        self._lu = None
        quiet = contextlib.nullcontext() if surely_positive_definite(A) else quiet_c_stdout()
        try:
            with quiet:
                self._chol = CholeskySolverD(
                    self.n,
                    np.ascontiguousarray(A.indptr, dtype=np.int32),
                    np.ascontiguousarray(A.indices, dtype=np.int32),
                    np.ascontiguousarray(A.data, dtype=np.float64),
                    MatrixType.CSR,
                )
        except ValueError:
            raise np.linalg.LinAlgError("the matrix is not numerically positive definite") from None

    def solve(self, B: np.ndarray) -> np.ndarray:
        """``X = A⁻¹ B`` for ``B`` of shape ``(n,)`` or ``(n,k)`` (``B`` is not modified)."""
        B = np.ascontiguousarray(B, dtype=np.float64)
        if self._chol is None:
            return self._lu.solve(B)  # type: ignore[union-attr]
        X = np.empty_like(B)
        self._chol.solve(B, X)
        return X
