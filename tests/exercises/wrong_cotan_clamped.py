"""Mistake: negative cot weights clamped at zero (``max(w, 0)``, "a Laplacian has positive
weights"): a non-Delaunay edge and an obtuse triangle lose their negative weight."""

import numpy as np
import scipy.sparse as sp


def cotan_laplacian(V, F):
    n = len(V)
    rows, cols, vals = [], [], []
    for c in range(3):
        a, b, o = F[:, c], F[:, (c + 1) % 3], F[:, (c + 2) % 3]
        u, w = V[b] - V[a], V[o] - V[a]
        dot, cross = np.einsum("ij,ij->i", u, w), np.linalg.norm(np.cross(u, w), axis=1)
        rows += [b, o]
        cols += [o, b]
        h = 0.5 * np.divide(dot, cross, out=np.zeros(len(F)), where=cross > 0)
        vals += [h, h]
    W = sp.coo_matrix((np.concatenate(vals), (np.concatenate(rows), np.concatenate(cols))),
                      shape=(n, n)).tocsr()  # fmt: skip
    W.data = np.maximum(W.data, 0.0)  # the mistake: the summed weight clamped at 0
    return (W - sp.diags(np.asarray(W.sum(axis=1)).ravel())).tocsr()
