"""Mistake: complex numbers — eigenpairs from ``scipy.linalg.eig`` (the general solver: complex
eigenvalues even where they are real), and areas from a complex square root."""

import numpy as np
import scipy.linalg as sla


def _cot_weights(V, F):
    n = len(V)
    C = np.zeros((n, n))
    for c in range(3):
        a, b, o = F[:, c], F[:, (c + 1) % 3], F[:, (c + 2) % 3]
        u, w = V[b] - V[a], V[o] - V[a]
        h = 0.5 * np.einsum("ij,ij->i", u, w) / np.linalg.norm(np.cross(u, w), axis=1)
        np.add.at(C, (b, o), h)
        np.add.at(C, (o, b), h)
    return C - np.diag(C.sum(axis=1))


def barycentric_areas(V, F):
    d2 = np.sum(np.cross(V[F[:, 1]] - V[F[:, 0]], V[F[:, 2]] - V[F[:, 0]]) ** 2, axis=1)
    a = 0.5 * np.emath.sqrt(d2 + 0j)  # complex dtype, zero imaginary part
    out = np.zeros(len(V), complex)
    for c in range(3):
        np.add.at(out, F[:, c], a / 3)
    return out


def eigenbasis(V, F, k):
    K = -_cot_weights(V, F)
    m = barycentric_areas(V, F).real  # (the wrong area too; the dtype fails first)
    lam, U = sla.eig(K, np.diag(m))  # complex eigenvalues, whatever their imaginary parts
    order = np.argsort(lam.real)[:k]
    U = U[:, order] / np.sqrt(np.einsum("ik,i,ik->k", U[:, order], m, U[:, order]))
    return lam[order], U
