"""Connected components of a pencil ``K u = λ M u`` and its exact null space.

Mesh-free: the components are those of the sparsity graph of ``K`` (for a mesh pencil, the
mesh's connected components).
"""

from __future__ import annotations

import numpy as np
import scipy.sparse as sp
from scipy.sparse.csgraph import connected_components

from .common import FloatArray, IntArray


def components(K: sp.csr_matrix) -> tuple[int, IntArray]:
    """Connected components of the sparsity graph of ``K`` (for a mesh pencil: the mesh's
    components); ``(count, labels (n,))``."""
    ncomp, labels = connected_components(K, directed=False)
    return int(ncomp), labels.astype(np.int64)


def null_space(m: FloatArray, labels: IntArray, ncomp: int) -> FloatArray:
    """``M``-orthonormal indicators of the components, ``(n, ncomp)``, F-ordered."""
    n = len(m)
    Z = np.zeros((n, ncomp), order="F")
    Z[np.arange(n), labels] = 1.0
    area = np.bincount(labels, weights=m, minlength=ncomp)
    Z /= np.sqrt(area)[None, :]
    return Z
