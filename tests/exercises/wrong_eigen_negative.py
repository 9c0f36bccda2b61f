"""Mistake: the eigenvalues of the (negative semidefinite) C itself: λ ≤ 0 (sign flip)."""

import igl
import numpy as np
import scipy.linalg as sla


def eigenbasis(V, F, k):
    C = igl.cotmatrix(V, F).toarray()
    M = np.diag(igl.massmatrix(V, F, igl.MASSMATRIX_TYPE_VORONOI).diagonal())
    lam, U = sla.eigh(C, M)
    order = np.argsort(-lam)[:k]  # the k closest to 0: the smooth modes, with λ ≤ 0
    return lam[order], U[:, order]
