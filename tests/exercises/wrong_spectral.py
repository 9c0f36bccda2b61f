"""Mistakes of the spectral tasks: the ordinary eigenproblem K u = λ u (eigenbasis) and the
coefficients Uᵀ X instead of Uᵀ M X (spectral_reconstruction)."""

import numpy as np
import scipy.linalg as sla


def _stiffness(V, F):
    n = len(V)
    K = np.zeros((n, n))
    for c in range(3):
        a, b, o = F[:, c], F[:, (c + 1) % 3], F[:, (c + 2) % 3]
        u, w = V[b] - V[a], V[o] - V[a]
        h = 0.5 * np.einsum("ij,ij->i", u, w) / np.linalg.norm(np.cross(u, w), axis=1)
        np.add.at(K, (b, o), -h)
        np.add.at(K, (o, b), -h)
        np.add.at(K, (b, b), h)
        np.add.at(K, (o, o), h)
    return K


def eigenbasis(V, F, k):
    lam, U = sla.eigh(_stiffness(V, F))
    return lam[:k], U[:, :k]


def spectral_reconstruction(X, U, M):
    return U @ (U.T @ X)
