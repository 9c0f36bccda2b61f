"""Mistake: the mean curvature normal from the uniform Laplacian, −½ L_u x."""

import numpy as np
import scipy.sparse as sp


def mean_curvature_normal(V, F):
    n = len(V)
    i = np.concatenate([F[:, 0], F[:, 1], F[:, 2], F[:, 1], F[:, 2], F[:, 0]])
    j = np.concatenate([F[:, 1], F[:, 2], F[:, 0], F[:, 0], F[:, 1], F[:, 2]])
    A = sp.csr_matrix((np.ones(len(i)), (i, j)), shape=(n, n))
    A.data[:] = 1.0
    deg = np.asarray(A.sum(axis=1)).ravel()
    inv = np.divide(1.0, deg, out=np.zeros(n), where=deg > 0)
    L = sp.diags(inv) @ A - sp.diags((deg > 0).astype(float))
    return -0.5 * (L @ V)
