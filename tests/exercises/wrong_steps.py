"""Mistakes of the smoothing steps: x − λLx (explicit, sign flip), an explicit step where the
implicit one is asked (implicit_step), and a μ step with the sign of μ flipped (taubin_step)."""

import numpy as np
import scipy.sparse as sp


def _uniform(V, F):
    n = len(V)
    i = np.concatenate([F[:, 0], F[:, 1], F[:, 2], F[:, 1], F[:, 2], F[:, 0]])
    j = np.concatenate([F[:, 1], F[:, 2], F[:, 0], F[:, 0], F[:, 1], F[:, 2]])
    A = sp.csr_matrix((np.ones(len(i)), (i, j)), shape=(n, n))
    A.data[:] = 1.0
    deg = np.asarray(A.sum(axis=1)).ravel()
    inv = np.divide(1.0, deg, out=np.zeros(n), where=deg > 0)
    return sp.diags(inv) @ A - sp.diags((deg > 0).astype(float))


def explicit_step(V, F, lam):
    return V - lam * (_uniform(V, F) @ V)


def taubin_step(V, F, lam, mu):
    L = _uniform(V, F)
    V1 = V + lam * (L @ V)
    return V1 - mu * (L @ V1)
