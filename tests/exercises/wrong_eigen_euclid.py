"""Mistake: the right generalized eigenvalues, but eigenvectors of unit Euclidean length
(UᵀU = I) instead of M-orthonormal (UᵀMU = I)."""

import numpy as np
import scipy.linalg as sla


def eigenbasis(V, F, k):
    n = len(V)
    K = np.zeros((n, n))
    area = np.zeros(n)
    P = V[F]
    A = 0.5 * np.linalg.norm(np.cross(P[:, 1] - P[:, 0], P[:, 2] - P[:, 0]), axis=1)
    dots = np.stack(
        [((P[:, (c + 1) % 3] - P[:, c]) * (P[:, (c + 2) % 3] - P[:, c])).sum(1) for c in range(3)],
        axis=1,
    )
    cot = dots / (2 * A[:, None])
    for c in range(3):
        i, j = F[:, (c + 1) % 3], F[:, (c + 2) % 3]
        np.add.at(K, (i, j), -cot[:, c] / 2)
        np.add.at(K, (j, i), -cot[:, c] / 2)
        li = ((P[:, (c + 1) % 3] - P[:, c]) ** 2).sum(1)
        lj = ((P[:, (c + 2) % 3] - P[:, c]) ** 2).sum(1)
        vor = (li * cot[:, (c + 2) % 3] + lj * cot[:, (c + 1) % 3]) / 8
        obtuse = (dots < 0).any(axis=1)
        np.add.at(area, F[:, c], np.where(obtuse, np.where(dots[:, c] < 0, A / 2, A / 4), vor))
    K -= np.diag(K.sum(axis=1))
    lam, U = sla.eigh(K, np.diag(area))
    U = U[:, :k] / np.linalg.norm(U[:, :k], axis=0)
    return lam[:k], U
