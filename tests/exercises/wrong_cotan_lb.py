"""Mistake: the pointwise Laplace–Beltrami M⁻¹C where the stiffness C is asked."""

import igl
import numpy as np
import scipy.sparse as sp


def cotan_laplacian(V, F):
    n = len(V)
    C = igl.cotmatrix(V, F).tocoo()
    C = sp.csr_matrix((C.data, (C.row, C.col)), shape=(n, n))
    m = np.zeros(n)
    d = igl.massmatrix(V, F, igl.MASSMATRIX_TYPE_VORONOI).diagonal()
    m[: len(d)] = d
    return sp.diags(np.divide(1.0, m, out=np.zeros(n), where=m > 0)) @ C
