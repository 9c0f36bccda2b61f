"""A quadratic energy with some rows known: factorized once per handle set, solved per drag.

Minimizing ``½ xᵀQx − xᵀb`` over the free rows ``f`` with the known rows ``k`` given is the
linear system ``Q_ff x_f = b_f − Q_fk x_k`` (libigl's ``min_quad_with_fixed`` without equality
constraints). ``Q_ff`` is symmetric positive definite when every connected component holds a
known row (:class:`~meshlap_core.deform.constraints.Constraints`), so it is factorized once by
sparse Cholesky (CHOLMOD through :class:`~meshlap_core.linalg.factor.SharedAnalysis`, or
the bundled fallback of :class:`~meshlap_core.linalg.spd.SPDSolver`) and each drag is one
back-substitution with the three coordinates as right-hand sides.
"""

from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np
import scipy.sparse as sp

from ..errors import MeshError
from ..linalg.factor import SharedAnalysis
from ..linalg.spd import solver_backend
from ..types import FloatArray, IntArray

SIMPLICIAL_MAX_N = 200_000
"""Below this many unknowns CHOLMOD factorizes simplicially (``LDLᵀ``), from it
supernodally, as the heat method does (:mod:`meshlap_core.diffusion.geodesic`)..."""
SIMPLICIAL_MAX_ROW = 10.0
"""...unless the matrix has more than this many entries per row (the triharmonic ``K(M⁻¹K)²``,
about 37): its factor is dense enough for supernodes to pay (measured at 43k vertices,
2 cores: ``K`` 0.14 s simplicial against 0.24 s supernodal, ``KM⁻¹K`` 0.67 s against 0.88 s,
``K(M⁻¹K)²`` 2.3 s against 0.68 s)."""


def factor_mode(n: int, nnz: int) -> str:
    """CHOLMOD's factorization for a system of ``n`` unknowns and ``nnz`` entries."""
    dense = nnz > SIMPLICIAL_MAX_ROW * max(n, 1)
    return "supernodal" if n >= SIMPLICIAL_MAX_N or dense else "simplicial"


@dataclass(frozen=True)
class SystemStats:
    """What a teacher shows of a factorized system.

    Attributes
    ----------
    n_unknowns : int
        Rows of ``Q_ff`` (per coordinate; the three coordinates share the factor).
    nnz : int
        Stored entries of ``Q_ff``.
    factor_seconds : float
        Wall time of the Cholesky factorization.
    backend : str
        ``"cholmod"``, ``"cholespy"`` or ``"superlu"``.
    """

    n_unknowns: int
    nnz: int
    factor_seconds: float
    backend: str


class PinnedSystem:
    """``Q_ff x_f = b_f − Q_fk x_k``, factorized once.

    Parameters
    ----------
    Q : (n,n) scipy.sparse matrix
        Symmetric positive semidefinite.
    free, known : (f,) int, (k,) int
        The unknown rows and the given ones (sorted, disjoint, together ``0 … n−1``;
        :attr:`Constraints.free` and :attr:`Constraints.known`).

    Raises
    ------
    MeshError
        When the factorization finds ``Q_ff`` not numerically positive definite.
    """

    def __init__(self, Q: sp.spmatrix, free: IntArray, known: IntArray) -> None:
        Q = sp.csr_matrix(Q)
        self.free, self.known = free, known
        rows = Q[self.free]
        self._Qff = rows[:, self.free].tocsr()
        self._Qff.sort_indices()
        self._Qfk = rows[:, self.known].tocsr()
        n = len(self.free)
        backend = solver_backend()  # CHOLMOD whenever installed: simplicial wins below 200k
        t0 = time.perf_counter()
        self._solver = None
        if n:
            shared = SharedAnalysis(
                self._Qff.indptr, self._Qff.indices, backend, factor_mode(n, self._Qff.nnz)
            )
            try:
                self._solver = shared.factor(self._Qff.data)
            except np.linalg.LinAlgError:
                raise MeshError(
                    f"the deformation's {n}-unknown system is not numerically positive "
                    "definite (degenerate faces?)",
                    "F",
                ) from None
            backend = self._solver.backend
        self.stats = SystemStats(n, self._Qff.nnz, time.perf_counter() - t0, backend)

    def solve(self, known: FloatArray, b: FloatArray | None = None) -> FloatArray:
        """The minimizer ``x`` ``(n,3)`` with ``x[known_rows] = known``.

        Parameters
        ----------
        known : (k,3) float
            Values of the known rows, in the order of ``constraints.known``.
        b : (n,3) float, optional
            The linear term (zero when not given).
        """
        x = np.empty((len(self.free) + len(self.known), known.shape[1]))
        x[self.known] = known
        if self._solver is None:
            return x
        rhs = -(self._Qfk @ known)
        if b is not None:
            rhs += b[self.free]
        x[self.free] = self._solver.solve(rhs)
        return x
