"""Mistake: the right cotangent Laplacian, computed and returned in single precision (float32:
about 7 digits; the thin triangles' weights near ±1000 lose several)."""

import numpy as np
import scipy.sparse as sp


def cotan_laplacian(V, F):
    V = V.astype(np.float32)
    n = len(V)
    rows, cols, vals = [], [], []
    for c in range(3):
        a, b, o = F[:, c], F[:, (c + 1) % 3], F[:, (c + 2) % 3]
        u, w = V[b] - V[a], V[o] - V[a]
        dot, cross = np.einsum("ij,ij->i", u, w), np.linalg.norm(np.cross(u, w), axis=1)
        h = np.divide(dot, 2 * cross, out=np.zeros(len(F), np.float32), where=cross > 0)
        rows += [b, o, b, o]
        cols += [o, b, b, o]
        vals += [h, h, -h, -h]
    r, c_, v = np.concatenate(rows), np.concatenate(cols), np.concatenate(vals)
    return sp.coo_matrix((v, (r, c_)), shape=(n, n), dtype=np.float32).tocsr()
