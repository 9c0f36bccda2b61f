"""Maps with a fixed boundary: Tutte's (uniform weights) and the harmonic map (cotangent weights).

Both pin the outer boundary loop to a convex curve (:mod:`.boundary`) and ask every other
vertex to be the weighted average of its neighbours, i.e. they solve the Dirichlet problem

    ``K u = 0`` at the free vertices, ``u = u_b`` on the outer loop,

for the two coordinates at once, with ``K`` positive semidefinite (``K·1 = 0``):

* **Tutte** (Tutte 1963, "How to draw a graph"; Floater 1997): ``K = D − A``, the graph
  Laplacian (weight 1 per edge). Every weight is positive, so with the boundary on a convex
  polygon each free vertex is a convex combination of its neighbours and the map is one-to-one
  (Floater 2003, "One-to-one piecewise linear mappings over triangulations"): no face flips.
* **harmonic** (Pinkall & Polthier 1993; Eck et al. 1995): ``K = −C`` (libigl's
  ``−cotmatrix``, :func:`cotan_laplacian`), the Dirichlet energy ``½ uᵀKu = ½∫|∇u|²``;
  closer to conformal, but an
  obtuse angle gives a negative weight and the map may fold.

``K`` is factorized once with the pinned rows and columns decoupled (same pattern, one CHOLMOD
analysis, :class:`~meshlap_core.linalg.factor.SharedAnalysis`); a new boundary shape (circle
or square) is then two back substitutions. Holes (inner boundary loops) stay free: their
rows are the natural (Neumann) ones.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np
import scipy.sparse as sp

from ..diffusion.geodesic import SIMPLICIAL_MAX_N
from ..errors import MeshError
from ..laplacian import cotangents_intrinsic, squared_edge_lengths
from ..linalg.factor import SharedAnalysis, pinned_data
from ..linalg.spd import solver_backend
from ..topology import EdgeTable
from ..types import FloatArray, IntArray


def sorted_csr(K: sp.spmatrix) -> sp.csr_matrix:
    """``K`` as CSR with sorted indices, each entry once, its whole diagonal stored."""
    n = K.shape[0]
    K = sp.csr_matrix(K + sp.csr_matrix((np.zeros(n), (np.arange(n), np.arange(n))), (n, n)))
    K.sum_duplicates()
    K.sort_indices()
    return K


def graph_laplacian(table: EdgeTable) -> sp.csr_matrix:
    """``K = D − A`` of the mesh's edge graph (Tutte's weights), ``(n,n)`` CSR, sorted."""
    n = table.n
    i, j = table.edges[:, 0], table.edges[:, 1]
    deg = np.bincount(np.concatenate([i, j]), minlength=n).astype(np.float64)
    ones = np.ones(len(i))
    rows = np.concatenate([i, j, np.arange(n)])
    cols = np.concatenate([j, i, np.arange(n)])
    return sorted_csr(sp.coo_matrix((np.concatenate([-ones, -ones, deg]), (rows, cols)), (n, n)))


def cotan_laplacian(V: FloatArray, F: IntArray, cot: FloatArray | None = None) -> sp.csr_matrix:
    """``K = −C`` (cotangent weights, positive semidefinite), ``(n,n)`` CSR, sorted.

    ``K_ij = −½ (cot α_ij + cot β_ij)`` on an edge, ``K_ii = −Σ_j K_ij``: libigl's
    ``−cotmatrix`` to round-off, assembled here from the corner cotangents in one COO → CSR
    pass (faster than ``igl.cotmatrix`` plus the conversions, and with the diagonal stored).

    Parameters
    ----------
    V : (n,3) float
    F : (m,3) int
    cot : (m,3) float, optional
        The cotangent of every corner angle
        (:func:`~meshlap_core.laplacian.cotangents_intrinsic`), when the caller has them.
    """
    n = len(V)
    if cot is None:
        cot = cotangents_intrinsic(squared_edge_lengths(V, F))
    i = np.concatenate([F[:, 1], F[:, 2], F[:, 0]])  # the edge opposite corner k: (k+1, k+2)
    j = np.concatenate([F[:, 2], F[:, 0], F[:, 1]])
    w = 0.5 * np.concatenate([cot[:, 0], cot[:, 1], cot[:, 2]])
    diag = np.bincount(i, w, minlength=n) + np.bincount(j, w, minlength=n)
    ar = np.arange(n)
    rows = np.concatenate([i, j, ar])
    cols = np.concatenate([j, i, ar])
    K = sp.coo_matrix((np.concatenate([-w, -w, diag]), (rows, cols)), shape=(n, n)).tocsr()
    K.sum_duplicates()
    K.sort_indices()
    return K


NOT_DEFINITE = (
    "the map's linear system is not numerically positive definite: needle or cap faces (a "
    "corner angle near 0 or 180 degrees) make cotangent weights blow up; remesh the surface, "
    "or use tutte (uniform weights)"
)


def definite(factorize: Callable[[], Any]) -> Any:
    """``factorize()``, its ``LinAlgError`` (a matrix that is not numerically positive
    definite) turned into the :class:`MeshError` :data:`NOT_DEFINITE` naming ``F``."""
    try:
        return factorize()
    except np.linalg.LinAlgError:
        raise MeshError(NOT_DEFINITE, "F") from None


def factor_mode(n: int) -> str:
    """CHOLMOD's factorization for ``n`` unknowns: simplicial below
    :data:`~meshlap_core.diffusion.geodesic.SIMPLICIAL_MAX_N`, supernodal above."""
    return "simplicial" if n < SIMPLICIAL_MAX_N else "supernodal"


class DirichletSolver:
    """``K u = 0`` off the pinned vertices, ``u = values`` on them: factorized once.

    Parameters
    ----------
    K : (n,n) scipy.sparse.csr_matrix
        Symmetric positive semidefinite, sorted, diagonal stored (:func:`graph_laplacian`,
        :func:`cotan_laplacian`); positive definite once the pinned rows are removed (each
        component of the mesh holds a pinned vertex).
    pinned : (p,) int
        The vertices whose values are given.
    """

    def __init__(self, K: sp.csr_matrix, pinned: IntArray) -> None:
        self.K = K
        self.pinned = np.asarray(pinned, dtype=np.int64)
        self.diagonal = K.diagonal()
        shared = SharedAnalysis(K.indptr, K.indices, solver_backend(), factor_mode(K.shape[0]))
        self._factor = definite(
            lambda: shared.factor(pinned_data(K.indptr, K.indices, K.data, self.pinned))
        )

    def lift(self, values: Any) -> FloatArray:
        """The right-hand side ``(n,c)`` of the pinned ``values`` ``(p,c)``: ``−K u_pinned``
        on the free rows, ``K_ii·values`` on the pinned rows (which the factor decouples)."""
        values = np.asarray(values, dtype=np.float64)
        x = np.zeros((self.K.shape[0], values.shape[1]))
        x[self.pinned] = values
        lifted = -(self.K @ x)
        lifted[self.pinned] = self.diagonal[self.pinned, None] * values
        return lifted

    def solve_lifted(self, lifted: FloatArray, rhs: FloatArray | None = None) -> FloatArray:
        """The solution ``(n,c)`` for a :meth:`lift`-ed right-hand side plus ``rhs`` on the
        free rows (``rhs`` is read, not modified; its pinned rows are ignored)."""
        full = lifted if rhs is None else lifted + rhs
        if rhs is not None:
            full[self.pinned] = lifted[self.pinned]
        return np.asarray(self._factor.solve(full)).reshape(lifted.shape)

    def solve(self, values: Any, rhs: FloatArray | None = None) -> FloatArray:
        """The solution ``(n,c)`` of ``K u = rhs`` (default 0) at the free vertices with the
        pinned ``values`` ``(p,c)`` (exactly ``values`` there)."""
        values = np.asarray(values, dtype=np.float64)
        out = self.solve_lifted(self.lift(values), rhs)
        out[self.pinned] = values
        return out
