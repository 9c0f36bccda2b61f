"""Mistake: a quarter of the cotangents (factor ½)."""

import numpy as np
import scipy.sparse as sp


def cotan_laplacian(V, F):
    n = len(V)
    rows, cols, vals = [], [], []
    for c in range(3):
        a, b, o = F[:, c], F[:, (c + 1) % 3], F[:, (c + 2) % 3]
        u, w = V[b] - V[a], V[o] - V[a]
        cot = np.einsum("ij,ij->i", u, w) / np.linalg.norm(np.cross(u, w), axis=1)
        weight = 0.25 * cot
        rows += [b, o, b, o]
        cols += [o, b, b, o]
        vals += [weight, weight, -weight, -weight]
    C = sp.coo_matrix(
        (np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))), shape=(n, n)
    ).tocsr()
    return C
