"""The cotangent stiffness every deformation method starts from, built fast and guarded.

``K = −C`` with ``C_ij = ½(cot α_ij + cot β_ij)`` and ``C_ii = −Σ_j C_ij`` (positive
semidefinite, ``K·1 = 0``): libigl's ``cotmatrix`` (C++, its CSC arrays read as CSR without a
conversion: the matrix is symmetric), or on a mesh with a degenerate face the project's guarded
:func:`~meshlap_core.laplacian.cotan_stiffness_intrinsic` (zero weights there, where libigl's
cotangents blow up).
"""

from __future__ import annotations

import igl
import numpy as np
import scipy.sparse as sp

from ..laplacian import cotan_stiffness_intrinsic, squared_edge_lengths
from ..types import BoolArray, FloatArray, IntArray


def stiffness(
    V: FloatArray, F: IntArray, solid: BoolArray, l2: FloatArray | None = None
) -> sp.csr_matrix:
    """The cotangent stiffness ``K = −C`` ``(n,n)``: libigl's ``cotmatrix`` negated (its CSC
    arrays read as CSR: the same symmetric matrix, no conversion); with a degenerate face
    (``solid`` false somewhere), where libigl's cotangents blow up, the guarded
    :func:`~meshlap_core.laplacian.cotan_stiffness_intrinsic` (zero weights there) from the
    squared edge lengths ``l2`` ``(m,3)`` (computed when not given)."""
    n = len(V)
    if len(F) == 0:
        return sp.csr_matrix((n, n))
    C = None if not solid.all() else igl.cotmatrix(V, F)
    if C is None or C.shape != (n, n) or not np.isfinite(C.data).all():
        l2 = squared_edge_lengths(V, F) if l2 is None else l2
        return (-cotan_stiffness_intrinsic(l2, F, n)).tocsr()
    return sp.csr_matrix((-C.data, C.indices, C.indptr), shape=(n, n))
