"""Mistake: both Taubin steps from the old positions, V + λLV + μLV (not sequential)."""

import igl
import numpy as np
import scipy.sparse as sp


def taubin_step(V, F, lam, mu):
    n = len(V)
    A = igl.adjacency_matrix(F).tocoo()
    A = sp.csr_matrix((np.ones(A.nnz), (A.row, A.col)), shape=(n, n))
    deg = np.asarray(A.sum(axis=1)).ravel()
    L = sp.diags(np.divide(1.0, deg, out=np.zeros(n), where=deg > 0)) @ A
    L = L - sp.diags((deg > 0).astype(float))
    return V + lam * (L @ V) + mu * (L @ V)
