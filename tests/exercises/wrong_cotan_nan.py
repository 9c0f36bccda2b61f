"""Mistake: the right cot formula with no guard for a triangle of zero area: cot = dot / |cross|
divides by zero there (inf, then NaN in the diagonal)."""

import numpy as np
import scipy.sparse as sp


def cotan_laplacian(V, F):
    n = len(V)
    rows, cols, vals = [], [], []
    for c in range(3):
        a, b, o = F[:, c], F[:, (c + 1) % 3], F[:, (c + 2) % 3]
        u, w = V[b] - V[a], V[o] - V[a]
        h = 0.5 * np.einsum("ij,ij->i", u, w) / np.linalg.norm(np.cross(u, w), axis=1)
        rows += [b, o, b, o]
        cols += [o, b, b, o]
        vals += [h, h, -h, -h]
    r, c_, v = np.concatenate(rows), np.concatenate(cols), np.concatenate(vals)
    return sp.coo_matrix((v, (r, c_)), shape=(n, n)).tocsr()
